// verify/intrusion.hpp — how much stock material a sweep meets, without removing it.
//
// The sweep is cut by each level's mid-plane (the same planes the kernel subtracts on) and
// its section intersected with the level's stock polygons in the regions it overlaps (a
// Clipper intersection per touched cell), so the volume is what LbrSolid::subtract() would
// remove with that sweep: exact up to the level discretisation and the chord tolerance.
//
// Turning sweeps (geom::LatheSweep) are measured the same way, with the region the kernel
// removes on each level: {r >= r_min} (external tools) or {r <= r_max} (internal).
//
// Not real-time: allocates (Clipper, growing buffers); read-only on the solid.
#pragma once

#include <clipper.hpp>

#include <cstdint>
#include <vector>

#include "geom/lbr_solid.hpp"
#include "geom/sweep.hpp"
#include "geom/turning.hpp"

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
  // With `deep` (the same move of the tool moved inwards by margin_mm in 3D, normal to its
  // surface) the deep material is the material inside deep's sections instead: near a ball's
  // bottom, where the surface is almost level, two polygonisations of one tool within the
  // chord tolerance of it differ horizontally by many times that tolerance, and a margin
  // taken in the plane would report the film one leaves inside the other.
  [[nodiscard]] Intrusion measure(const geom::LbrSolid& solid, const geom::Sweep& sweep, double margin_mm,
                                  bool contact_only = false, const geom::Sweep* deep = nullptr);
  // The same for a turning sweep: the material inside its revolved region on each level.
  // With `shadow` (the same move's insert, when `sweep` is its holder) only the material
  // the shadow does not remove on that level counts: the insert leads its holder, so what
  // they both reach is cut before the holder gets there (docs/verification.md#turning).
  // deep_mm3 counts the material farther than `margin_mm` inside the region's circles.
  [[nodiscard]] Intrusion measure(const geom::LbrSolid& solid, const geom::LatheSweep& sweep, double margin_mm,
                                  bool contact_only = false, const geom::LatheSweep* shadow = nullptr);

 private:
  struct Source;  // the sweep the sections come from (intrusion.cpp)
  [[nodiscard]] Intrusion measure_source(const geom::LbrSolid& solid, const Source& src, double margin_mm,
                                         bool contact_only);
  // section_ = the source's section on plane z; false when it has none. A turning source
  // sets ring_in_ / ring_out_ and meets_[k] (whether region regions_[k]'s cell may meet the
  // ring) first, and builds no polygon when no cell may meet it.
  bool source_section(const geom::LbrSolid& solid, const Source& src, int level, double z_mm);
  // shrunk_ = the section moved inwards by the margin (the deep sweep's section on plane z_mm
  // when the source has one).
  void source_shrunk(const Source& src, double z_mm, double margin_mm);
  // Whether any cell of regions_ on `level` may meet the ring ring_in_ … ring_out_ (fills
  // meets_): not when its farthest point from the axis stays inside r_in, or its box stays
  // outside r_out (within the circles' polygonisation, half the chord tolerance).
  bool ring_meets_cells(const geom::LbrSolid& solid, int level, double chord_tol_mm);
  // The nearest and farthest distance of a cell's material from the spindle axis [mm],
  // cached per cell and content (version and area): a turning move's holder is tested on
  // every level it spans, and the stock changes only where it is cut.
  struct CellReach {
    std::uint32_t version = 0;
    double area_units2 = -1.0;  // < 0: not taken yet
    double near_mm = 0.0, far_mm = 0.0;
  };
  const CellReach& cell_reach(const geom::LbrSolid& solid, int region, int level);

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
  double ring_in_ = 0.0, ring_out_ = 0.0;  // turning sources: the ring of the current level [mm]
  std::vector<char> meets_;                 // turning sources: per regions_ entry, the cell may meet the ring
  std::vector<CellReach> reach_;  // per (region, level) of reach_solid_
  const geom::LbrSolid* reach_solid_ = nullptr;
  std::vector<int> regions_;
  std::vector<double> region_volume_;
  ClipperLib::Clipper clipper_;
};

}  // namespace lbr::verify
