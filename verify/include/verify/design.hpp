// verify/design.hpp — comparison of the final stock with a design model (issue 16,
// docs/verification.md#design-model-comparison).
//
// The design mesh (verify/stl.hpp) is sliced on the stock's level mid-planes (the planes the
// kernel cuts on) into Clipper polygons, and each (level, region) cell is compared with the
// stock: gouge = design − stock (design material that was cut), excess = stock −
// offset(design, +tolerance) (material left outside the design beyond the tolerance). Both
// are area × level thickness, so they are exact up to the level discretisation.
//
// Setup-time code: allocates; errors throw DesignError("NAME: what was expected").
#pragma once

#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "geom/lbr_solid.hpp"
#include "motion/path_sweeps.hpp"
#include "verify/collision.hpp"
#include "verify/stl.hpp"

namespace lbr::verify {

class DesignError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct DesignConfig {
  std::string stl_path;         // empty: no comparison
  double tolerance_mm = 0.02;   // stock closer than this outside the design is not excess
};

// Throws DesignError when `mesh` (read from `name`) cannot be compared with the stock of
// `solid`: not closed or not manifold (with the edge counts), inside out, outside the stock,
// or its bounding box 25.4 times smaller than the stock's (inches).
void check_design(const StlMesh& mesh, const geom::LbrSolid& solid, const std::string& name);

// The mesh's section on every level mid-plane of `solid` (index = level), the union of the
// closed loops of the triangle/plane segments under the NonZero rule [kernel units].
[[nodiscard]] std::vector<geom::Paths> slice_design(const StlMesh& mesh, const geom::LbrSolid& solid);

struct DesignLevel {
  int level = 0;
  double z_mm = 0.0;
  double gouge_mm3 = 0.0, excess_mm3 = 0.0;
  double max_gouge_mm = 0.0, max_excess_mm = 0.0;  // in-plane distance to the design boundary
};

struct DesignReport {
  double design_volume_mm3 = 0.0;  // the sliced design (Σ area · thickness)
  double gouge_mm3 = 0.0, excess_mm3 = 0.0;
  double max_gouge_mm = 0.0, max_excess_mm = 0.0;
  geom::Vec3 max_gouge_at;         // the deepest gouge point (z: its level's mid-plane) [mm]
  int max_gouge_level = -1;
  geom::Vec3 gouge_probe;          // a point just inside that gouge (towards the design boundary), for attribute_gouge()
  geom::MoveId gouge_move = 0;     // earliest move whose section contains it (0: none found)
  std::string gouge_source;        // that move's program and line (empty / 0: unknown)
  int gouge_line = 0;
  int gouge_tool = 0, gouge_channel = 0;  // that move's tool and channel
  double gouge_t_s = 0.0;                 // that move's end time [s] (0: not timed)
  std::vector<DesignLevel> levels; // the levels with a gouge or an excess, bottom up
};

// Compares the final stock `solid` with the design sections `design` (slice_design()).
[[nodiscard]] DesignReport compare_design(const std::vector<geom::Paths>& design, const geom::LbrSolid& solid,
                                          double tolerance_mm);

// Sets gouge_move / gouge_source / gouge_line: the earliest of `moves` (in cutting order)
// whose section on the level of the deepest gouge contains a point just inside that gouge
// (a turning move: whose revolved region there, {r >= r_min} or {r <= r_max}, holds it).
void attribute_gouge(DesignReport& report, const geom::LbrSolid& solid, std::span<const motion::TimedSweep> moves,
                     const MoveIndex& index);

// Signed deviation of each vertex of a stock surface mesh (positions and unit outward
// normals, 3 floats a vertex) from the design sections (docs/verification.md#deviation-colour):
// < 0 gouge (the point half the tolerance outside the stock along the normal lies inside
// the design, at least half the tolerance from its boundary: design material was cut), > 0
// excess (the point half the tolerance inside the stock lies as far outside the design), 0
// within the tolerance. The magnitude is that point's in-plane distance to the design
// section's boundary on its level, plus half the tolerance [mm].
void vertex_deviation(const std::vector<geom::Paths>& design, const geom::LbrSolid& solid,
                      std::span<const float> positions, std::span<const float> normals, double tolerance_mm,
                      std::vector<float>& out);
// A design-gouge event (docs/verification.md) when the deepest gouge is deeper than
// `tolerance_mm`: at the deepest point, with the whole gouge volume and the attributed move.
// The checks' counts and `--fail-on error` then cover it like any other error.
[[nodiscard]] std::optional<Event> gouge_event(const DesignReport& report, double tolerance_mm);

// The report's levels as CSV (columns in docs/formats.md#deviation-csv).
[[nodiscard]] std::string deviation_csv(const DesignReport& report);

}  // namespace lbr::verify
