#include "measure.hpp"

#include <algorithm>
#include <cmath>

#include "geom/probe.hpp"

namespace lbr::gfx::detail {

namespace {

// Clips [t0, t1] to the side of the section plane that is drawn (RenderOptions: the low
// side, the high side when flipped); false when nothing is left.
bool clip_to_section(const RenderOptions& opt, const glm::dvec3& o, const glm::dvec3& d, double& t0, double& t1) {
  if (opt.section_axis < 0 || opt.section_axis > 2) return true;
  const int a = opt.section_axis;
  const double oa = o[a], da = d[a], s = opt.section_mm;
  const double sign = opt.section_flip ? -1.0 : 1.0;  // kept: sign · (oa + t·da − s) <= 0
  if (std::abs(da) < 1e-300) return sign * (oa - s) <= 0.0;
  const double t = (s - oa) / da;
  if (sign * da > 0.0) t1 = std::min(t1, t);
  else t0 = std::max(t0, t);
  return t0 <= t1;
}

}  // namespace

bool measure_at(const geom::LbrSolid& solid, const Camera& cam, const RenderOptions& opt, double x, double y, int w,
                int h, MeasurePoint& out) noexcept {
  if (w <= 0 || h <= 0) return false;
  glm::dvec3 o, d;
  cam.ray(x, y, w, h, o, d);
  double t0 = 0.0, t1 = 1.0;
  if (!clip_to_section(opt, o, d, t0, t1)) return false;
  const geom::RayHit hit = geom::cast_ray(solid, {o.x, o.y, o.z}, {d.x, d.y, d.z}, t0, t1);
  if (!hit.hit) return false;
  // The vertical just inside the material: a wall's hit lies on a contour, so step 1 µm
  // further along the sight line's horizontal direction.
  const double hx = d.x, hy = d.y, hn = std::hypot(hx, hy);
  const double nx = hn > 0 && !hit.top_face ? hit.point.x + 1e-3 * hx / hn : hit.point.x;
  const double ny = hn > 0 && !hit.top_face ? hit.point.y + 1e-3 * hy / hn : hit.point.y;
  const geom::Column c = geom::column_at(solid, nx, ny, hit.point.z);
  out.x_mm = hit.point.x;
  out.y_mm = hit.point.y;
  out.z_mm = hit.point.z;
  out.surface_z_mm = c.top_mm;  // column_at's top does not depend on its height limit
  out.thickness_mm = c.thickness_mm;
  out.top_face = hit.top_face;
  return true;
}

}  // namespace lbr::gfx::detail
