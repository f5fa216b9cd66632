// Reconstruction of LBR levels into a closed triangle mesh. docs/mesh.md explains why the
// result is closed; the comments here point at the step each rule protects.
#include "mesh/reconstruct.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>
#include <utility>

#include "reconstruct_detail.hpp"

namespace lbr::mesh {

BuildStats& BuildStats::operator+=(const BuildStats& o) noexcept {
  planes_built += o.planes_built;
  levels_built += o.levels_built;
  regions_built += o.regions_built;
  triangles += o.triangles;
  defects += o.defects;
  forced_ears += o.forced_ears;
  return *this;
}

using namespace detail;

struct Reconstructor::Cache {
  int nx = 0, ny = 0, levels = 0;
  std::vector<RegionCache> regions;
  std::vector<std::uint8_t> plane_dirty, wall_dirty, region_dirty;
  CapScratch cap_scratch;

  std::size_t pidx(int r, int k) const noexcept { return static_cast<std::size_t>(r) * (levels + 1) + k; }
  std::size_t widx(int r, int l) const noexcept { return static_cast<std::size_t>(r) * levels + l; }

  void build_plane(const geom::LbrSolid& s, int r, int k, const MeshOptions& opt);
  void build_wall(const geom::LbrSolid& s, int r, int l);
  void assemble(const geom::LbrSolid& s, int r);
  BuildStats run(const geom::LbrSolid& s, const MeshOptions& opt);
};

void Reconstructor::Cache::build_plane(const geom::LbrSolid& s, int r, int k, const MeshOptions& opt) {
  detail::build_plane(s, r, k, opt, regions[r].planes[k], cap_scratch);
}

void Reconstructor::Cache::build_wall(const geom::LbrSolid& s, int r, int l) {
  detail::build_wall(s, r, l, regions[r].planes, regions[r].walls[l]);
}

void Reconstructor::Cache::assemble(const geom::LbrSolid& s, int r) {
  RegionCache& rc = regions[r];
  MeshBuffers& out = rc.out;
  const std::uint64_t generation = out.generation;
  out = MeshBuffers{};
  out.generation = generation + 1;
  struct AKey {
    VertexKey k;
    int cls;
  };
  struct AHash {
    std::size_t operator()(const AKey& a) const noexcept {
      return PointHash{}(Point{a.k.x, a.k.y}) ^ (static_cast<std::size_t>(a.k.height) * 0x51ED27u) ^
             static_cast<std::size_t>(a.cls);
    }
  };
  struct AEq {
    bool operator()(const AKey& a, const AKey& b) const noexcept { return a.k == b.k && a.cls == b.cls; }
  };
  std::unordered_map<AKey, std::uint32_t, AHash, AEq> index;
  std::vector<double> pos, nrm;
  const double ox = geom::to_mm(s.stock_rect().x0), oy = geom::to_mm(s.stock_rect().y0), oz = s.z_bottom_mm();

  auto add_tri = [&](const Tri& t) {
    // Vertices are identified by position (x, y, height), not by the plane they came from:
    // a joined wall whose two ends moved to the same mid-plane has collapsed, its two vertex
    // columns are one vertex and its triangles have no area. Dropping them keeps every edge
    // paired (each directed edge of a dropped triangle is a loop or cancels against its
    // reverse in the same triangle), so the surface stays closed without zero-area facets.
    const std::array<VertexKey, 3> key{VertexKey{t.p[0].X, t.p[0].Y, t.height[0]},
                                       VertexKey{t.p[1].X, t.p[1].Y, t.height[1]},
                                       VertexKey{t.p[2].X, t.p[2].Y, t.height[2]}};
    if (key[0] == key[1] || key[1] == key[2] || key[0] == key[2]) return;
    std::array<std::array<double, 3>, 3> q{};
    std::array<MoveId, 3> attr{};
    for (int v = 0; v < 3; ++v) {
      attr[v] = t.attr[v];
      q[v] = {geom::to_mm(t.p[v].X) - ox, geom::to_mm(t.p[v].Y) - oy, t.z[v] - oz};
    }
    const std::array<double, 3> e1{q[1][0] - q[0][0], q[1][1] - q[0][1], q[1][2] - q[0][2]};
    const std::array<double, 3> e2{q[2][0] - q[0][0], q[2][1] - q[0][1], q[2][2] - q[0][2]};
    const std::array<double, 3> n{e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                                  e1[0] * e2[1] - e1[1] * e2[0]};
    out.volume_mm3 += (q[0][0] * (q[1][1] * q[2][2] - q[1][2] * q[2][1]) -
                       q[0][1] * (q[1][0] * q[2][2] - q[1][2] * q[2][0]) +
                       q[0][2] * (q[1][0] * q[2][1] - q[1][1] * q[2][0])) / 6.0;
    if (t.plane[0] == t.plane[1] && t.plane[1] == t.plane[2]) {
      double dz = 0;
      for (int v = 0; v < 3; ++v) dz = std::max(dz, std::abs(q[v][2] + oz - plane_z(s, t.plane[v])));
      out.join_bound_mm3 += 0.5 * std::abs(n[2]) * dz;
    }
    const bool flat = q[0][2] == q[1][2] && q[1][2] == q[2][2] && n[2] != 0.0;
    const int cls = flat ? (n[2] > 0 ? 1 : 2) : 0;
    for (int v = 0; v < 3; ++v) {
      const AKey ak{key[v], cls};
      auto [it, fresh] = index.try_emplace(ak, static_cast<std::uint32_t>(out.keys.size()));
      if (fresh) {
        out.keys.push_back(ak.k);
        for (int a = 0; a < 3; ++a) pos.push_back(q[v][a]);
        nrm.insert(nrm.end(), {0.0, 0.0, cls == 1 ? 1.0 : (cls == 2 ? -1.0 : 0.0)});
        out.attributes.push_back(static_cast<float>(attr[v]));
      }
      if (cls == 0)
        for (int a = 0; a < 3; ++a) nrm[3 * it->second + a] += n[a];
      out.indices.push_back(it->second);
    }
  };
  for (const PlaneData& pd : rc.planes)
    for (const Tri& t : pd.caps) add_tri(t);
  for (const WallData& wd : rc.walls) {
    for (const Tri& t : wd.tris) add_tri(t);
    out.rounding_bound_mm3 += wd.rounding_bound_mm3;
  }
  out.positions.resize(pos.size());
  out.normals.resize(nrm.size());
  for (std::size_t v = 0; v < out.keys.size(); ++v) {
    const double wx = nrm[3 * v], wy = nrm[3 * v + 1], wz = nrm[3 * v + 2];
    const double len = std::sqrt(wx * wx + wy * wy + wz * wz);
    for (int a = 0; a < 3; ++a) {
      const double o = a == 0 ? ox : (a == 1 ? oy : oz);
      out.positions[3 * v + a] = static_cast<float>(pos[3 * v + a] + o);
      out.normals[3 * v + a] = len > 0 ? static_cast<float>(nrm[3 * v + a] / len) : (a == 2 ? 1.0f : 0.0f);
    }
  }
}

Reconstructor::Reconstructor(MeshOptions opt) : opt_(opt) {}
Reconstructor::~Reconstructor() = default;
Reconstructor::Reconstructor(Reconstructor&&) noexcept = default;
Reconstructor& Reconstructor::operator=(Reconstructor&&) noexcept = default;

int Reconstructor::regions() const noexcept { return cache_ ? static_cast<int>(cache_->regions.size()) : 0; }
const MeshBuffers& Reconstructor::region(int r) const { return cache_->regions.at(static_cast<std::size_t>(r)).out; }
double Reconstructor::volume_mm3() const noexcept {
  double v = 0;
  if (cache_)
    for (const RegionCache& rc : cache_->regions) v += rc.out.volume_mm3;
  return v;
}
std::size_t Reconstructor::triangle_count() const noexcept {
  std::size_t n = 0;
  if (cache_)
    for (const RegionCache& rc : cache_->regions) n += rc.out.triangle_count();
  return n;
}

BuildStats Reconstructor::build(const geom::LbrSolid& s) {
  cache_ = std::make_unique<Cache>();
  Cache& c = *cache_;
  c.nx = s.regions_x();
  c.ny = s.regions_y();
  c.levels = s.levels();
  c.regions.resize(static_cast<std::size_t>(s.regions()));
  for (RegionCache& rc : c.regions) {
    rc.planes.resize(static_cast<std::size_t>(c.levels) + 1);
    rc.walls.resize(static_cast<std::size_t>(c.levels));
  }
  c.plane_dirty.assign(c.regions.size() * (c.levels + 1), 1);
  c.wall_dirty.assign(c.regions.size() * c.levels, 1);
  c.region_dirty.assign(c.regions.size(), 1);
  return c.run(s, opt_);
}

BuildStats Reconstructor::update(const geom::LbrSolid& s) {
  if (!cache_ || cache_->nx != s.regions_x() || cache_->ny != s.regions_y() || cache_->levels != s.levels())
    return build(s);
  Cache& c = *cache_;
  for (std::uint32_t ci : s.dirty_cells()) {
    const int r = static_cast<int>(ci / static_cast<std::uint32_t>(c.levels));
    const int l = static_cast<int>(ci % static_cast<std::uint32_t>(c.levels));
    // Plane p reads levels p-2 .. p+1 of its region and of its neighbours (joined-wall
    // decisions); walls read their two planes and the neighbours' same level.
    const int p0 = std::max(0, l - 1), p1 = std::min(c.levels, l + 2);
    c.wall_dirty[c.widx(r, l)] = 1;
    for (int p = p0; p <= p1; ++p) c.plane_dirty[c.pidx(r, p)] = 1;
    for (int sd = 0; sd < 4; ++sd) {
      const int n = neighbour(s, r, sd);
      if (n < 0) continue;
      for (int p = p0; p <= p1; ++p) c.plane_dirty[c.pidx(n, p)] = 1;
      c.wall_dirty[c.widx(n, l)] = 1;
    }
  }
  return c.run(s, opt_);
}

BuildStats Reconstructor::Cache::run(const geom::LbrSolid& s, const MeshOptions& opt) {
  Cache& c = *this;
  BuildStats st;
  const int nreg = static_cast<int>(c.regions.size());
  for (int r = 0; r < nreg; ++r)
    for (int k = 0; k <= c.levels; ++k) {
      if (!c.plane_dirty[c.pidx(r, k)]) continue;
      c.build_plane(s, r, k, opt);
      c.plane_dirty[c.pidx(r, k)] = 0;
      ++st.planes_built;
      if (k > 0) c.wall_dirty[c.widx(r, k - 1)] = 1;
      if (k < c.levels) c.wall_dirty[c.widx(r, k)] = 1;
      c.region_dirty[r] = 1;
    }
  for (int r = 0; r < nreg; ++r)
    for (int l = 0; l < c.levels; ++l) {
      if (!c.wall_dirty[c.widx(r, l)]) continue;
      c.build_wall(s, r, l);
      c.wall_dirty[c.widx(r, l)] = 0;
      ++st.levels_built;
      c.region_dirty[r] = 1;
    }
  for (int r = 0; r < nreg; ++r) {
    if (!c.region_dirty[r]) continue;
    c.assemble(s, r);
    c.region_dirty[r] = 0;
    ++st.regions_built;
    st.triangles += c.regions[r].out.triangle_count();
  }
  for (const auto& rc : c.regions) {
    for (const auto& pd : rc.planes) {
      st.defects += pd.defects;
      st.forced_ears += pd.forced;
    }
    for (const auto& wd : rc.walls) st.defects += wd.defects;
  }
  return st;
}

std::vector<MeshBuffers> reconstruct(const geom::LbrSolid& solid, const MeshOptions& opt, BuildStats* stats) {
  Reconstructor rec(opt);
  const BuildStats st = rec.build(solid);
  if (stats) *stats = st;
  std::vector<MeshBuffers> out;
  for (int r = 0; r < rec.regions(); ++r) out.push_back(rec.region(r));
  return out;
}

}  // namespace lbr::mesh
