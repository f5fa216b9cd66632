// verify/intrusion.hpp — how much stock material a sweep meets, without removing it.
//
// The sweep is cut by each level's mid-plane (the same planes the kernel subtracts on) and
// its section intersected with the level's stock polygons in the regions it overlaps (a
// Clipper intersection per touched cell), so the volume is what LbrSolid::subtract() would
// remove with that sweep: exact up to the level discretisation and the chord tolerance.
//
// Not real-time: allocates (Clipper, growing buffers); read-only on the solid.
#pragma once

#include <clipper.hpp>

#include "geom/lbr_solid.hpp"
#include "geom/sweep.hpp"

namespace lbr::verify {

struct Intrusion {
  double volume_mm3 = 0.0;  // material inside the sweep [mm3]
  double deep_mm3 = 0.0;    // > 0 when material lies inside the sweep shrunk by the margin
                            // (summed until the first level that has some) [mm3]
  double depth_mm = 0.0;    // Z extent of the levels where it met material [mm]
  int region = -1;          // region holding the largest share of that material
};

class IntrusionProbe {
 public:
  // The material of `solid` inside the milling sweep `sweep`; deep_mm3 counts only the
  // material farther than `margin_mm` inside each section polygon (a sweep that grazes a
  // wall within the margin, e.g. by the chord tolerance of two polygonised circles, has
  // deep_mm3 = 0).
  // With `contact_only`, the levels are walked from the bottom up only until the first deep
  // contact: deep_mm3 > 0 tells the same, volume_mm3 and depth_mm are those levels' only.
  [[nodiscard]] Intrusion measure(const geom::LbrSolid& solid, const geom::Sweep& sweep, double margin_mm,
                                  bool contact_only = false);

 private:
  void clip_to_rect(const geom::Path& p, const geom::Rect& r);
  // subject_ = the cell's contours cut to `r`; then the area they share with `clip` [mm2].
  void cell_subject(const geom::Cell& cell, const geom::Rect& r);
  [[nodiscard]] double subject_overlap_mm2(const geom::Paths& clip);
  void shrink_section(double margin_mm);
  // The highest level at or below `from` with material in one of regions_, or -1.
  [[nodiscard]] int top_material_level(const geom::LbrSolid& solid, int from) const;
  void regions_under(const geom::LbrSolid& solid, const geom::Rect& r);

  geom::SectionScratch scratch_;
  geom::Paths section_, shrunk_, subject_, result_;
  geom::Path tmp_a_, tmp_b_;
  ClipperLib::ClipperOffset offset_;
  std::vector<int> regions_;
  std::vector<double> region_volume_;
  ClipperLib::Clipper clipper_;
};

}  // namespace lbr::verify
