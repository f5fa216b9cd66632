// Independent reference for the removed volume of a 3-axis ball/bull/flat program: a fine
// height field computed from the tool path alone (no LBR code). A vertical-axis ball, bull or
// flat end mill moving in straight lines removes exactly the material above the lower envelope
// of its swept lower surface (its sides and shank are no wider than its cutting diameter), so
//   removed = Σ over an XY grid of cells (stock top − max(stock bottom, min over moves of the
//             tool's lower surface over the cell centre)) · cell area   (only where positive).
// Per move a → b and cell centre q, the lowest point of the swept tool over q is the minimum
// over t ∈ [0, 1] of E(t) = z(t) + L(ρ(t)), ρ(t) = |q − xy(t)|, L the tool's lower profile
// (0 on the flat, r − sqrt(r² − (ρ − (R − r))²) on the corner). E is convex in t (L convex and
// non-decreasing, ρ convex in t, z linear): ball, closed form; bull/flat, bisection on the
// sign of E'(t) to 1e-9 of the move.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "geom/lbr_solid.hpp"
#include "geom/tool.hpp"
#include "nc/toolpath.hpp"

namespace lbr::bench {

struct ReferenceVolume {
  double removed_mm3 = 0;
  double cell_mm = 0;
  long cells = 0;
  long moves = 0;      // linear moves evaluated
  double seconds = 0;  // time to compute it
};

namespace detail {

struct Profile1 {
  double R, r, a;  // radius, corner radius, flat radius R − r
  [[nodiscard]] double lower(double rho) const {
    if (rho <= a) return 0.0;
    const double u = std::min(rho - a, r);
    return r - std::sqrt(std::max(0.0, r * r - u * u));
  }
  [[nodiscard]] double slope(double rho) const {  // dL/dρ
    if (rho <= a) return 0.0;
    const double u = rho - a, s = r * r - u * u;
    return s <= 1e-300 ? 1e300 : u / std::sqrt(s);
  }
};

}  // namespace detail

// Throws std::invalid_argument for a tool that is not ball, bull or flat, or a box-less stock.
inline ReferenceVolume reference_removed_volume(const nc::Toolpath& path, const std::map<int, geom::Tool>& tools,
                                                const geom::SolidSpec& stock, double cell_mm) {
  if (stock.shape != geom::SolidSpec::Shape::Box) throw std::invalid_argument("reference volume: box stock only");
  const auto t0 = std::chrono::steady_clock::now();
  const geom::Vec3 lo = stock.box.min, hi = stock.box.max;
  const int nx = static_cast<int>(std::ceil((hi.x - lo.x) / cell_mm - 1e-9));
  const int ny = static_cast<int>(std::ceil((hi.y - lo.y) / cell_mm - 1e-9));
  std::vector<double> env(static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny), hi.z);
  ReferenceVolume out;
  out.cell_mm = cell_mm;
  out.cells = static_cast<long>(env.size());
  nc::AxisVector pos = path.start;
  for (const nc::Segment& s : path.segments) {
    const nc::AxisVector from = pos;
    pos = s.end;
    if (s.kind != nc::SegmentKind::Rapid && s.kind != nc::SegmentKind::Feed) continue;
    if (s.tool == 0) continue;
    const auto it = tools.find(s.tool);
    if (it == tools.end()) throw std::invalid_argument("reference volume: tool " + std::to_string(s.tool) + " undefined");
    const geom::Tool& tool = it->second;
    detail::Profile1 pr{0.5 * tool.diameter_mm, 0.0, 0.0};
    switch (tool.kind) {
      case geom::ToolKind::Ball: pr.r = pr.R; break;
      case geom::ToolKind::Bull: pr.r = tool.corner_radius_mm; break;
      case geom::ToolKind::Flat: pr.r = 0.0; break;
      default: throw std::invalid_argument("reference volume: ball, bull and flat tools only");
    }
    pr.a = pr.R - pr.r;
    const double ax = from[nc::X], ay = from[nc::Y], az = from[nc::Z];
    const double dx = pos[nc::X] - ax, dy = pos[nc::Y] - ay, dz = pos[nc::Z] - az;
    if (std::min(az, az + dz) >= hi.z) continue;  // the tip stays above the stock
    ++out.moves;
    const double len2 = dx * dx + dy * dy, R2 = pr.R * pr.R;
    const int i0 = std::max(0, static_cast<int>(std::floor((std::min(ax, ax + dx) - pr.R - lo.x) / cell_mm)));
    const int i1 = std::min(nx - 1, static_cast<int>(std::ceil((std::max(ax, ax + dx) + pr.R - lo.x) / cell_mm)));
    const int j0 = std::max(0, static_cast<int>(std::floor((std::min(ay, ay + dy) - pr.R - lo.y) / cell_mm)));
    const int j1 = std::min(ny - 1, static_cast<int>(std::ceil((std::max(ay, ay + dy) + pr.R - lo.y) / cell_mm)));
    for (int j = j0; j <= j1; ++j) {
      const double qy = lo.y + (j + 0.5) * cell_mm - ay;
      for (int i = i0; i <= i1; ++i) {
        const double qx = lo.x + (i + 0.5) * cell_mm - ax;
        double& cur = env[static_cast<std::size_t>(j) * static_cast<std::size_t>(nx) + static_cast<std::size_t>(i)];
        const double w2 = qx * qx + qy * qy;
        double e;
        if (len2 < 1e-18) {  // vertical move: the lower end counts
          if (w2 > R2) continue;
          e = std::min(az, az + dz) + pr.lower(std::sqrt(w2));
        } else {
          const double ts = (qx * dx + qy * dy) / len2;     // foot of q on the move's XY line
          const double h2 = std::max(0.0, w2 - ts * ts * len2);  // squared distance to that line
          if (h2 >= R2) continue;
          const double half = std::sqrt((R2 - h2) / len2);
          const double tl = std::max(0.0, ts - half), th = std::min(1.0, ts + half);
          if (tl > th) continue;
          // Lower bound: ρ >= its distance to the line, z >= the lower end.
          if (std::min(az + tl * dz, az + th * dz) + pr.lower(std::sqrt(h2)) >= cur) continue;
          const auto E = [&](double t) {
            const double u = t - ts;
            return az + t * dz + pr.lower(std::sqrt(h2 + u * u * len2));
          };
          double t;
          if (pr.a == 0.0) {  // ball: stationary point of m·u − sqrt(k² − len2·u²) in closed form
            const double k2 = R2 - h2;
            const double u = -dz * std::sqrt(k2) / std::sqrt(len2 * (len2 + dz * dz));
            t = std::clamp(ts + u, tl, th);
          } else {  // bisection on the sign of E'(t), E convex
            double a = tl, b = th;
            for (int it2 = 0; it2 < 40 && b - a > 1e-9; ++it2) {
              const double m = 0.5 * (a + b), u = m - ts, rho = std::sqrt(h2 + u * u * len2);
              const double d = dz + (rho > 0 ? pr.slope(rho) * u * len2 / rho : 0.0);
              if (d > 0) b = m;
              else a = m;
            }
            t = 0.5 * (a + b);
          }
          e = std::min({E(t), E(tl), E(th)});
        }
        if (e < cur) cur = e;
      }
    }
  }
  double sum = 0.0;
  for (const double z : env) sum += hi.z - std::max(lo.z, std::min(z, hi.z));
  out.removed_mm3 = sum * cell_mm * cell_mm;
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace lbr::bench
