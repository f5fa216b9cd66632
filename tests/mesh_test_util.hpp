// Helpers shared by the mesh tests: building solids from simple programs and checking meshes.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <map>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "geom/lbr_solid.hpp"
#include "geom/tool.hpp"
#include "mesh/reconstruct.hpp"

namespace lbr::mesh::testing {

inline geom::SolidSpec box_spec(double x, double y, double z, double delta, int nx, int ny) {
  geom::SolidSpec s;
  s.box = {{0, 0, 0}, {x, y, z}};
  s.level_spacing_mm = delta;
  s.regions_x = nx;
  s.regions_y = ny;
  return s;
}

inline geom::CutterShape cutter(geom::ToolKind kind, double d, double param = 0.0) {
  geom::Tool t;
  t.kind = kind;
  t.diameter_mm = d;
  if (kind == geom::ToolKind::Bull) t.corner_radius_mm = param;
  if (kind == geom::ToolKind::Drill || kind == geom::ToolKind::VBit) t.angle_deg = param;
  return geom::CutterShape::build(t, 0.002);
}

inline void cut(geom::LbrSolid& s, const geom::CutterShape& c, geom::Vec3 a, geom::Vec3 b, geom::MoveId id) {
  const geom::SweepRef ref{&c, geom::Pose{a}, geom::Pose{b}, id};
  s.subtract(std::span<const geom::SweepRef>(&ref, 1));
}

// Directed-edge census over all regions by exact vertex identity. Returns the number of
// undirected edges that are not used exactly once in each direction, and the number of
// triangles with a repeated vertex.
struct EdgeCensus {
  std::size_t bad_edges = 0;    // used a different number of times in the two directions
  std::size_t nonmanifold = 0;  // balanced but used more than once each way
  std::size_t degenerate = 0, edges = 0;
  std::string first_bad;
};
inline EdgeCensus census(const std::vector<const MeshBuffers*>& regions) {
  using K = std::tuple<geom::Coord, geom::Coord, std::int32_t>;
  std::map<std::pair<K, K>, std::array<int, 2>> use;
  EdgeCensus c;
  for (const MeshBuffers* m : regions)
    for (std::size_t t = 0; t < m->triangle_count(); ++t) {
      K k[3];
      for (int v = 0; v < 3; ++v) {
        const VertexKey& q = m->keys[m->indices[3 * t + v]];
        k[v] = {q.x, q.y, q.height};
      }
      if (k[0] == k[1] || k[1] == k[2] || k[0] == k[2]) {
        ++c.degenerate;
        continue;
      }
      for (int e = 0; e < 3; ++e) {
        const K& a = k[e];
        const K& b = k[(e + 1) % 3];
        if (a < b) ++use[{a, b}][0];
        else ++use[{b, a}][1];
      }
    }
  c.edges = use.size();
  for (const auto& [e, n] : use)
    if (n[0] == n[1] && n[0] > 1) {
      ++c.nonmanifold;
    } else if (n[0] != 1 || n[1] != 1) {
      if (c.bad_edges == 0)
        c.first_bad = "(" + std::to_string(std::get<0>(e.first)) + "," + std::to_string(std::get<1>(e.first)) + "," +
                      std::to_string(std::get<2>(e.first)) + ")-(" + std::to_string(std::get<0>(e.second)) + "," +
                      std::to_string(std::get<1>(e.second)) + "," + std::to_string(std::get<2>(e.second)) +
                      ") uses " + std::to_string(n[0]) + "/" + std::to_string(n[1]);
      ++c.bad_edges;
    }
  return c;
}
inline EdgeCensus census(const Reconstructor& rec) {
  std::vector<const MeshBuffers*> v;
  for (int r = 0; r < rec.regions(); ++r) v.push_back(&rec.region(r));
  return census(v);
}

// Seeded random 3-axis program: straight moves of random tools inside the stock.
inline void random_program(geom::LbrSolid& s, std::uint32_t seed, int moves, std::vector<geom::CutterShape>& tools) {
  std::mt19937 rng(seed);
  tools.clear();
  tools.push_back(cutter(geom::ToolKind::Flat, 4.0));
  tools.push_back(cutter(geom::ToolKind::Ball, 3.0));
  tools.push_back(cutter(geom::ToolKind::Bull, 5.0, 1.0));
  tools.push_back(cutter(geom::ToolKind::Drill, 3.0, 118.0));
  const geom::BoxStock& b = s.spec().box;
  std::uniform_real_distribution<double> ux(b.min.x - 2, b.max.x + 2), uy(b.min.y - 2, b.max.y + 2),
      uz(b.min.z + 0.3, b.max.z + 0.5);
  std::uniform_int_distribution<int> ut(0, 3);
  for (int m = 0; m < moves; ++m) {
    const geom::CutterShape& c = tools[static_cast<std::size_t>(ut(rng))];
    const double z0 = uz(rng);
    const double z1 = (m % 3 == 0) ? uz(rng) : z0;
    cut(s, c, {ux(rng), uy(rng), z0}, {ux(rng), uy(rng), z1}, static_cast<geom::MoveId>(m + 1));
  }
}

inline double total_volume(const Reconstructor& rec) { return rec.volume_mm3(); }
inline double total_bound(const Reconstructor& rec, bool joined) {
  double b = 0;
  for (int r = 0; r < rec.regions(); ++r)
    b += rec.region(r).rounding_bound_mm3 + (joined ? rec.region(r).join_bound_mm3 : 0.0);
  return b;
}

}  // namespace lbr::mesh::testing
