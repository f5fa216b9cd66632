// Sheets that touch along an edge, pulled apart for export (sheets.hpp).
#include "sheets.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <numeric>

namespace lbr::mesh::detail {

namespace {

using V3 = std::array<double, 3>;

V3 sub(const V3& a, const V3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

V3 pos(const ExportMesh& m, std::uint32_t v) {
  return {m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]};
}

// Vertices at the same position (exact float bits) share a group id.
std::vector<std::uint32_t> weld(const ExportMesh& m) {
  const std::size_t n = m.vertex_count();
  std::vector<std::uint32_t> order(n), group(n);
  std::iota(order.begin(), order.end(), 0u);
  auto key = [&](std::uint32_t v) {
    return std::array<std::uint32_t, 3>{std::bit_cast<std::uint32_t>(m.positions[3 * v]),
                                        std::bit_cast<std::uint32_t>(m.positions[3 * v + 1]),
                                        std::bit_cast<std::uint32_t>(m.positions[3 * v + 2])};
  };
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return key(a) < key(b); });
  std::uint32_t g = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (i > 0 && key(order[i]) != key(order[i - 1])) ++g;
    group[order[i]] = g;
  }
  return group;
}

// Two triangles on the same three positions with opposite orientations bound nothing (a
// fin of zero thickness, e.g. a border wall piece one unit wide seen from both sides): both
// go. Each of their edges loses one use in each direction, so pairing stays balanced.
void drop_cancelling_pairs(ExportMesh& m, const std::vector<std::uint32_t>& group) {
  struct Face {
    std::array<std::uint32_t, 3> key;  // the positions, sorted
    bool odd;                          // the triangle's order is an odd permutation of key
    std::uint32_t t;
  };
  std::vector<Face> faces(m.triangle_count());
  for (std::uint32_t t = 0; t < faces.size(); ++t) {
    std::array<std::uint32_t, 3> g{group[m.indices[3 * t]], group[m.indices[3 * t + 1]], group[m.indices[3 * t + 2]]};
    bool odd = false;
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2 - i; ++j)
        if (g[j] > g[j + 1]) {
          std::swap(g[j], g[j + 1]);
          odd = !odd;
        }
    faces[t] = {g, odd, t};
  }
  std::sort(faces.begin(), faces.end(), [](const Face& a, const Face& b) {
    return a.key != b.key ? a.key < b.key : (a.odd != b.odd ? a.odd < b.odd : a.t < b.t);
  });
  std::vector<std::uint8_t> gone(faces.size(), 0);
  for (std::size_t i = 0; i < faces.size();) {
    std::size_t j = i, odd = 0;
    while (j < faces.size() && faces[j].key == faces[i].key) odd += faces[j++].odd ? 1 : 0;
    const std::size_t even = (j - i) - odd, pairs = std::min(even, odd);
    for (std::size_t k = 0; k < pairs; ++k) gone[faces[i + k].t] = gone[faces[i + even + k].t] = 1;
    i = j;
  }
  std::size_t w = 0;
  for (std::size_t t = 0; t < gone.size(); ++t) {
    if (gone[t]) continue;
    for (int v = 0; v < 3; ++v) m.indices[3 * w + v] = m.indices[3 * t + v];
    ++w;
  }
  m.indices.resize(3 * w);
}

// One use of an undirected edge {lo, hi} (group ids, lo < hi) by a triangle corner: the
// corner at lo, and whether the triangle runs lo -> hi.
struct EdgeUse {
  std::uint64_t key;
  std::uint32_t corner;
  bool forward;
};

std::vector<EdgeUse> edge_uses(const ExportMesh& m, const std::vector<std::uint32_t>& group) {
  std::vector<EdgeUse> uses;
  uses.reserve(m.indices.size());
  for (std::uint32_t t = 0; t < m.triangle_count(); ++t)
    for (std::uint32_t i = 0; i < 3; ++i) {
      const std::uint32_t a = group[m.indices[3 * t + i]], b = group[m.indices[3 * t + (i + 1) % 3]];
      if (a == b) continue;
      const bool fwd = a < b;
      const std::uint64_t key = (static_cast<std::uint64_t>(fwd ? a : b) << 32) | (fwd ? b : a);
      uses.push_back({key, 3 * t + (fwd ? i : (i + 1) % 3), fwd});
    }
  std::sort(uses.begin(), uses.end(), [](const EdgeUse& x, const EdgeUse& y) {
    return x.key != y.key ? x.key < y.key : x.corner < y.corner;
  });
  return uses;
}

struct UnionFind {
  std::vector<std::uint32_t> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  std::uint32_t find(std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void join(std::uint32_t a, std::uint32_t b) { parent[find(a)] = find(b); }
};

// The corner of triangle `corner / 3` at the other end of the edge that starts or ends at
// `corner` (the edge lo-hi: the corner at hi).
std::uint32_t corner_at_hi(const EdgeUse& u) {
  const std::uint32_t t = u.corner / 3, i = u.corner % 3;
  return 3 * t + (u.forward ? (i + 1) % 3 : (i + 2) % 3);
}

// An edge used otherwise than once each way and not paired: its triangles stay one sheet at
// both ends (no vertex is split across it).
void join_all(std::span<const EdgeUse> e, UnionFind& uf) {
  for (std::size_t k = 1; k < e.size(); ++k) {
    uf.join(e[0].corner, e[k].corner);
    uf.join(corner_at_hi(e[0]), corner_at_hi(e[k]));
  }
}

// The two sheets at a four-use edge: looking along lo -> hi, a triangle that runs hi -> lo
// bounds material on its side of increasing angle, one that runs lo -> hi on its side of
// decreasing angle; each of the first is paired with the next of the second.
void pair_four_uses(const ExportMesh& m, std::span<const EdgeUse> e, UnionFind& uf) {
  const V3 a = pos(m, m.indices[e[0].corner]), b = pos(m, m.indices[corner_at_hi(e[0])]);
  const V3 u = sub(b, a);
  const double uu = dot(u, u);
  if (uu <= 0.0) return join_all(e, uf);
  std::array<std::pair<double, std::size_t>, 4> ang{};
  V3 e1{}, e2{};
  for (std::size_t k = 0; k < 4; ++k) {
    const std::uint32_t t = e[k].corner / 3;
    const std::uint32_t third = 3 * t + (e[k].corner % 3 + (e[k].forward ? 2 : 1)) % 3;
    V3 r = sub(pos(m, m.indices[third]), a);
    const double s = dot(r, u) / uu;
    r = {r[0] - s * u[0], r[1] - s * u[1], r[2] - s * u[2]};
    if (k == 0) {
      e1 = r;
      e2 = cross(u, e1);
    }
    ang[k] = {std::atan2(dot(r, e2), dot(r, e1)), k};
  }
  // Coplanar triangles (equal angles: a cap and a wall's piece in one plane) are ordered so
  // that the uses alternate when they can; sheets that overlap with one orientation cannot.
  auto alternates = [&] {
    for (std::size_t k = 0; k < 4; ++k)
      if (e[ang[k].second].forward == e[ang[(k + 1) % 4].second].forward) return false;
    return true;
  };
  for (const bool forward_first : {true, false}) {
    std::sort(ang.begin(), ang.end(), [&](const auto& x, const auto& y) {
      if (x.first != y.first) return x.first < y.first;
      return (e[x.second].forward != forward_first) < (e[y.second].forward != forward_first);
    });
    if (alternates()) break;
  }
  if (!alternates()) return join_all(e, uf);
  for (std::size_t k = 0; k < 4; ++k) {
    const EdgeUse& r = e[ang[k].second];
    if (r.forward) continue;
    const EdgeUse& f = e[ang[(k + 1) % 4].second];
    uf.join(r.corner, f.corner);
    uf.join(corner_at_hi(r), corner_at_hi(f));
  }
}

// Joins the corners that an edge's pairing puts in one sheet (an edge used once each way,
// a four-use edge paired by pair_four_uses(), any other edge: all its uses).
void join_sheets(const ExportMesh& m, const std::vector<EdgeUse>& uses, UnionFind& uf) {
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    while (j < uses.size() && uses[j].key == uses[i].key) ++j;
    const std::span<const EdgeUse> e(uses.data() + i, j - i);
    const auto fwd = std::count_if(e.begin(), e.end(), [](const EdgeUse& x) { return x.forward; });
    if (e.size() == 2 && fwd == 1) {
      uf.join(e[0].corner, e[1].corner);
      uf.join(corner_at_hi(e[0]), corner_at_hi(e[1]));
    } else if (e.size() == 4 && fwd == 2) {
      pair_four_uses(m, e, uf);
    } else {
      join_all(e, uf);
    }
    i = j;
  }
}

// Moves the corners `cs` (one sheet at one position) to copies of their vertices, `gap_mm`
// towards the sheet's triangles.
std::size_t move_sheet(ExportMesh& m, std::span<const std::uint32_t> cs, float gap_mm) {
  const V3 p = pos(m, m.indices[cs[0]]);
  V3 d{0, 0, 0};
  for (std::uint32_t c : cs) {
    const std::uint32_t t = c / 3;
    for (int i = 0; i < 3; ++i) {
      const V3 q = pos(m, m.indices[3 * t + i]);
      for (int a = 0; a < 3; ++a) d[a] += q[a] - p[a];
    }
  }
  const double len = std::sqrt(dot(d, d));
  if (!(len > 0.0)) return 0;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> copies;  // original vertex -> copy
  for (std::uint32_t c : cs) {
    const std::uint32_t v = m.indices[c];
    auto it = std::find_if(copies.begin(), copies.end(), [v](const auto& x) { return x.first == v; });
    if (it == copies.end()) {
      const auto nv = static_cast<std::uint32_t>(m.vertex_count());
      for (int a = 0; a < 3; ++a) m.positions.push_back(static_cast<float>(p[a] + gap_mm * d[a] / len));
      m.source.push_back(m.source[v]);
      copies.emplace_back(v, nv);
      it = copies.end() - 1;
    }
    m.indices[c] = it->second;
  }
  return copies.size();
}

}  // namespace

ExportMesh concatenate(std::span<const MeshBuffers> regions) {
  ExportMesh m;
  std::uint32_t base = 0;
  for (const MeshBuffers& r : regions) {
    m.positions.insert(m.positions.end(), r.positions.begin(), r.positions.end());
    for (std::size_t v = 0; v < r.vertex_count(); ++v) m.source.push_back(base + static_cast<std::uint32_t>(v));
    for (std::uint32_t i : r.indices) m.indices.push_back(base + i);
    base += static_cast<std::uint32_t>(r.vertex_count());
  }
  return m;
}

std::size_t separate_touching_sheets(ExportMesh& m, float gap_mm) {
  const std::vector<std::uint32_t> group = weld(m);
  drop_cancelling_pairs(m, group);
  UnionFind uf(m.indices.size());
  join_sheets(m, edge_uses(m, group), uf);
  // (position group, sheet, corner), sorted: per position its sheets, largest kept.
  std::vector<std::array<std::uint32_t, 3>> corners(m.indices.size());
  for (std::uint32_t c = 0; c < m.indices.size(); ++c) corners[c] = {group[m.indices[c]], uf.find(c), c};
  std::sort(corners.begin(), corners.end());
  std::size_t added = 0;
  std::vector<std::uint32_t> cs;
  for (std::size_t i = 0; i < corners.size();) {
    std::size_t j = i, largest = i, largest_n = 0;
    std::size_t sheets = 0;
    while (j < corners.size() && corners[j][0] == corners[i][0]) {
      std::size_t k = j;
      while (k < corners.size() && corners[k][0] == corners[j][0] && corners[k][1] == corners[j][1]) ++k;
      if (k - j > largest_n) {
        largest_n = k - j;
        largest = j;
      }
      ++sheets;
      j = k;
    }
    for (std::size_t s = i; sheets > 1 && s < j;) {
      std::size_t k = s;
      cs.clear();
      while (k < j && corners[k][1] == corners[s][1]) cs.push_back(corners[k++][2]);
      if (s != largest) added += move_sheet(m, cs, gap_mm);
      s = k;
    }
    i = j;
  }
  return added;
}

}  // namespace lbr::mesh::detail
