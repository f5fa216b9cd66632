// Analytic design models for the design-comparison tests: prisms extruded along X from a
// polygon in the (Y, Z) plane, written as a closed, outward-facing triangle mesh.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "verify/stl.hpp"

namespace lbr::test {

using YZ = std::array<double, 2>;

// The prism x0..x1 over `outline` (counter-clockwise in (Y, Z), i.e. seen from +X), whose
// caps are the convex polygons `parts` (counter-clockwise, tiling the outline with shared
// vertices, so every edge has exactly two triangles).
inline verify::StlMesh extrude_x(const std::vector<YZ>& outline, const std::vector<std::vector<YZ>>& parts, double x0,
                                 double x1) {
  verify::StlMesh m;
  auto at = [](double x, YZ p) { return geom::Vec3{x, p[0], p[1]}; };
  for (std::size_t i = 0; i < outline.size(); ++i) {
    const YZ a = outline[i], b = outline[(i + 1) % outline.size()];
    m.triangles.push_back({{at(x0, a), at(x0, b), at(x1, b)}});
    m.triangles.push_back({{at(x0, a), at(x1, b), at(x1, a)}});
  }
  for (const std::vector<YZ>& p : parts)
    for (std::size_t k = 1; k + 1 < p.size(); ++k) {
      m.triangles.push_back({{at(x1, p[0]), at(x1, p[k]), at(x1, p[k + 1])}});  // +X cap
      m.triangles.push_back({{at(x0, p[0]), at(x0, p[k + 1]), at(x0, p[k])}});  // -X cap
    }
  return m;
}

// An axis-aligned box.
inline verify::StlMesh box_mesh(geom::Vec3 lo, geom::Vec3 hi) {
  const std::vector<YZ> sq{{lo.y, lo.z}, {hi.y, lo.z}, {hi.y, hi.z}, {lo.y, hi.z}};
  return extrude_x(sq, {sq}, lo.x, hi.x);
}

// A box x0..x1 × y0..y1 × z0..z1 with a rectangular pocket y_lo..y_hi, depth `depth` from
// the top, running through the part along X (open at both X faces, so a flat end mill can
// cut it exactly, with no corner radii).
inline verify::StlMesh pocket_part(geom::Vec3 lo, geom::Vec3 hi, double y_lo, double y_hi, double depth) {
  const double zf = hi.z - depth;
  const std::vector<YZ> outline{{lo.y, lo.z}, {hi.y, lo.z}, {hi.y, hi.z}, {y_hi, hi.z},
                                {y_hi, zf},   {y_lo, zf},   {y_lo, hi.z}, {lo.y, hi.z}};
  const std::vector<std::vector<YZ>> parts{{{lo.y, lo.z}, {hi.y, lo.z}, {y_hi, zf}, {y_lo, zf}},
                                           {{hi.y, lo.z}, {hi.y, hi.z}, {y_hi, hi.z}, {y_hi, zf}},
                                           {{lo.y, lo.z}, {y_lo, zf}, {y_lo, hi.z}, {lo.y, hi.z}}};
  return extrude_x(outline, parts, lo.x, hi.x);
}

}  // namespace lbr::test
