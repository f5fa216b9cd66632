// An independent check of an exported mesh (issue 13 item 6), written against the bytes of
// the STL / PLY files rather than the reconstructor's own vertex identities: vertices are
// identified by their exact float coordinates (as admesh's exact pass does), every float is
// converted exactly to an integer multiple of 2^-40 mm, and the predicates are exact.
//
// A closed, consistently oriented surface uses every undirected edge exactly twice, once in
// each direction; a degenerate facet has two equal vertices (admesh's "degenerate facet") or
// three collinear ones (zero area). Parts are the connected components of facets sharing an
// edge.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <numeric>
#include <span>
#include <string>
#include <tuple>
#include <vector>

namespace lbr::mesh::testing {

struct MeshCheck {
  std::size_t facets = 0;
  std::size_t coincident = 0;      // facets with two equal vertices (admesh: degenerate facets)
  std::size_t zero_area = 0;       // facets with three distinct collinear vertices
  std::size_t edges = 0;           // undirected edges
  std::size_t unpaired = 0;        // edges not used exactly once in each direction (open, or same-way)
  std::size_t same_direction = 0;  // of those: used twice, both times in the same direction
  std::size_t over_used = 0;       // of those: used more than twice
  std::size_t parts = 0;           // connected components (facets sharing an edge)
  std::string first_problem;
  [[nodiscard]] bool clean() const noexcept { return coincident == 0 && zero_area == 0 && unpaired == 0; }
  [[nodiscard]] std::string summary() const {
    return "facets " + std::to_string(facets) + ", coincident " + std::to_string(coincident) + ", zero-area " +
           std::to_string(zero_area) + ", edges " + std::to_string(edges) + ", unpaired " + std::to_string(unpaired) +
           " (same direction " + std::to_string(same_direction) + ", over-used " + std::to_string(over_used) +
           "), parts " + std::to_string(parts) + (first_problem.empty() ? "" : "; first: " + first_problem);
  }
};

using FacetF = std::array<float, 9>;  // three vertices x y z [mm]

namespace detail {
__extension__ typedef __int128 i128;
using P3 = std::array<std::int64_t, 3>;
// Every float coordinate of a part within ±2^20 mm is an exact multiple of 2^-40 mm unless
// it is below 2^-17 mm in magnitude (no kernel coordinate is: one unit is 1e-4 mm).
inline std::int64_t exact(float f) { return static_cast<std::int64_t>(std::ldexp(static_cast<double>(f), 40)); }
inline std::string str(const P3& p) {
  return "(" + std::to_string(std::ldexp(static_cast<double>(p[0]), -40)) + ", " +
         std::to_string(std::ldexp(static_cast<double>(p[1]), -40)) + ", " +
         std::to_string(std::ldexp(static_cast<double>(p[2]), -40)) + ")";
}
struct Dsu {
  std::vector<std::size_t> up;
  explicit Dsu(std::size_t n) : up(n) { std::iota(up.begin(), up.end(), std::size_t{0}); }
  std::size_t find(std::size_t a) {
    while (up[a] != a) a = up[a] = up[up[a]];
    return a;
  }
  void join(std::size_t a, std::size_t b) { up[find(a)] = find(b); }
};
}  // namespace detail

inline MeshCheck check_facets(std::span<const FacetF> facets) {
  using detail::P3;
  MeshCheck c;
  c.facets = facets.size();
  std::map<P3, std::size_t> ids;
  std::vector<std::array<std::size_t, 3>> tri;
  std::vector<P3> pts;
  tri.reserve(facets.size());
  for (const FacetF& f : facets) {
    std::array<std::size_t, 3> t{};
    std::array<P3, 3> q{};
    for (int v = 0; v < 3; ++v) {
      q[v] = {detail::exact(f[3 * v]), detail::exact(f[3 * v + 1]), detail::exact(f[3 * v + 2])};
      const auto [it, fresh] = ids.try_emplace(q[v], pts.size());
      if (fresh) pts.push_back(q[v]);
      t[v] = it->second;
    }
    tri.push_back(t);
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
      if (c.coincident++ == 0 && c.first_problem.empty()) c.first_problem = "coincident vertices at " + detail::str(q[0]);
      continue;
    }
    std::array<detail::i128, 3> e1{}, e2{};
    for (int a = 0; a < 3; ++a) {
      e1[a] = q[1][a] - q[0][a];
      e2[a] = q[2][a] - q[0][a];
    }
    const bool collinear = e1[1] * e2[2] == e1[2] * e2[1] && e1[2] * e2[0] == e1[0] * e2[2] &&
                           e1[0] * e2[1] == e1[1] * e2[0];
    if (collinear && c.zero_area++ == 0 && c.first_problem.empty())
      c.first_problem = "zero-area facet at " + detail::str(q[0]) + " " + detail::str(q[1]) + " " + detail::str(q[2]);
  }
  // Directed uses per undirected edge: [0] from the smaller id to the larger, [1] back.
  std::map<std::pair<std::size_t, std::size_t>, std::array<int, 2>> use;
  detail::Dsu dsu(tri.size());
  std::map<std::pair<std::size_t, std::size_t>, std::size_t> first_facet;
  for (std::size_t f = 0; f < tri.size(); ++f) {
    const auto& t = tri[f];
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
    for (int e = 0; e < 3; ++e) {
      const std::size_t a = t[e], b = t[(e + 1) % 3];
      const std::pair<std::size_t, std::size_t> key{std::min(a, b), std::max(a, b)};
      ++use[key][a < b ? 0 : 1];
      const auto [it, fresh] = first_facet.try_emplace(key, f);
      if (!fresh) dsu.join(f, it->second);
    }
  }
  c.edges = use.size();
  for (const auto& [e, n] : use) {
    if (n[0] == 1 && n[1] == 1) continue;
    ++c.unpaired;
    if (n[0] + n[1] > 2) ++c.over_used;
    else if (n[0] == 2 || n[1] == 2) ++c.same_direction;
    if (c.first_problem.empty())
      c.first_problem = "edge " + detail::str(pts[e.first]) + "-" + detail::str(pts[e.second]) + " used " +
                        std::to_string(n[0]) + "/" + std::to_string(n[1]);
  }
  for (std::size_t f = 0; f < tri.size(); ++f) {
    const auto& t = tri[f];
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
    if (dsu.find(f) == f) ++c.parts;
  }
  return c;
}

// Facets of a binary STL file (as written by mesh::to_binary_stl).
inline std::vector<FacetF> stl_facets(std::span<const std::uint8_t> stl) {
  std::vector<FacetF> out;
  if (stl.size() < 84) return out;
  std::uint32_t n = 0;
  std::memcpy(&n, stl.data() + 80, 4);
  if (stl.size() < 84 + std::size_t{50} * n) return out;
  out.resize(n);
  for (std::uint32_t f = 0; f < n; ++f) std::memcpy(out[f].data(), stl.data() + 84 + 50 * std::size_t{f} + 12, 36);
  return out;
}

// Facets of a binary PLY file as written by mesh::to_binary_ply (vertex: 7 float32; face:
// uchar count 3 + 3 int32). Empty when the layout differs.
inline std::vector<FacetF> ply_facets(std::span<const std::uint8_t> ply) {
  std::vector<FacetF> out;
  const std::string head(ply.begin(), ply.begin() + static_cast<std::ptrdiff_t>(std::min<std::size_t>(ply.size(), 1024)));
  const std::size_t end = head.find("end_header\n");
  const std::size_t pv = head.find("element vertex "), pf = head.find("element face ");
  if (end == std::string::npos || pv == std::string::npos || pf == std::string::npos) return out;
  const std::size_t nv = std::stoul(head.substr(pv + 15)), nf = std::stoul(head.substr(pf + 13));
  const std::size_t v0 = end + 11, f0 = v0 + 28 * nv;
  if (ply.size() != f0 + 13 * nf) return out;
  out.resize(nf);
  for (std::size_t f = 0; f < nf; ++f) {
    for (int v = 0; v < 3; ++v) {
      std::int32_t id = 0;
      std::memcpy(&id, ply.data() + f0 + 13 * f + 1 + 4 * v, 4);
      std::memcpy(out[f].data() + 3 * v, ply.data() + v0 + 28 * static_cast<std::size_t>(id), 12);
    }
  }
  return out;
}

}  // namespace lbr::mesh::testing
