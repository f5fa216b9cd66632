// Synthetic streams for the kernel benchmarks: a 2.5D pocket raster sampled as a 4 ms
// controller would report it (0.05–0.1 mm per sample at 750–1500 mm/min).
#pragma once

#include <cmath>
#include <vector>

#include "geom/types.hpp"

namespace lbr::bench {

// Zig-zag over [x0, x1] x [y0, y1] at depth z with the given stepover, split into moves of
// `step` mm. Starts with a plunge from z + 5.
inline std::vector<geom::Vec3> raster(double x0, double y0, double x1, double y1, double z, double stepover, double step) {
  std::vector<geom::Vec3> corners{{x0, y0, z + 5}, {x0, y0, z}};
  bool right = true;
  for (double y = y0; y <= y1 + 1e-9; y += stepover) {
    corners.push_back({right ? x0 : x1, y, z});
    corners.push_back({right ? x1 : x0, y, z});
    right = !right;
  }
  std::vector<geom::Vec3> pts{corners.front()};
  for (std::size_t i = 1; i < corners.size(); ++i) {
    const geom::Vec3 a = corners[i - 1], b = corners[i];
    const double len = geom::norm(b - a);
    const int n = std::max(1, static_cast<int>(std::ceil(len / step)));
    for (int k = 1; k <= n; ++k) pts.push_back(geom::lerp(a, b, static_cast<double>(k) / n));
  }
  return pts;
}

}  // namespace lbr::bench
