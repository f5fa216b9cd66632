// mesh/reconstruct.hpp — model reconstruction (paper §3.4): the levels of an LbrSolid joined
// into a closed triangle mesh, one mesh per region, rebuilt incrementally from the kernel's
// dirty set. Design and proofs of closedness: docs/mesh.md.
//
// In short: the stair-step solid (level i extruded over its slab) is meshed exactly, with
// every vertex identified by (x, y [units], plane index). At each plane k between levels
// k-1 and k the two levels' contours are noded against each other (and against the
// neighbouring regions' vertices on the shared region borders), so that walls, caps and the
// neighbours' faces share every edge. Joined mode then moves vertices vertically only —
// never changing the triangles — so that narrow steps become ruled walls through the
// levels' mid-plane samples; closedness is untouched and the volume changes by at most the
// bound reported in MeshBuffers::join_bound_mm3.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "geom/lbr_solid.hpp"

namespace lbr::mesh {

enum class WallMode : std::uint8_t {
  Extruded,  // each level extruded over its slab (the paper's fallback; exact LBR volume)
  Joined,    // steps between corresponding contours replaced by ruled walls
};

struct MeshOptions {
  WallMode walls = WallMode::Joined;
  // A step (cap polygon between two levels) is joined when its bounding box is at most this
  // many level spacings wide in x or y: wider steps are floors and stay flat.
  double join_width_levels = 20.0;
};

// Exact identity of a mesh vertex, by position. Height index: 2k = plane k (z = bottom of
// level k; k = levels(): top), 2l+1 = mid-plane of level l (joined walls move vertices
// there). Two vertices with the same key are one vertex, also across regions.
struct VertexKey {
  geom::Coord x = 0, y = 0;  // [units]
  std::int32_t height = 0;
  friend bool operator==(const VertexKey&, const VertexKey&) = default;
};

// GL-ready buffers of one region. Triangles are counter-clockwise seen from outside.
struct MeshBuffers {
  std::vector<float> positions;        // x, y, z per vertex [mm]
  std::vector<float> normals;          // unit normal per vertex: smooth on walls, flat on floors
  std::vector<float> attributes;       // per vertex: id of the move that last cut there (0 = stock)
  std::vector<std::uint32_t> indices;  // 3 per triangle
  std::vector<VertexKey> keys;         // exact identity per vertex (flat and smooth copies share it)
  double volume_mm3 = 0;               // signed volume term w.r.t. the solid's min corner [mm³]
  double join_bound_mm3 = 0;           // Σ |Δz|·projected area of moved cap triangles [mm³]
  double rounding_bound_mm3 = 0;       // volume bound of rounded edge-intersection points [mm³]
  std::uint64_t generation = 0;        // incremented each time these buffers are reassembled
                                       // (gfx/ uploads a region again only when it changed)
  [[nodiscard]] std::size_t triangle_count() const noexcept { return indices.size() / 3; }
  [[nodiscard]] std::size_t vertex_count() const noexcept { return keys.size(); }
};

struct BuildStats {
  std::uint64_t planes_built = 0;    // (region, plane) cap sets recomputed
  std::uint64_t levels_built = 0;    // (region, level) wall sets recomputed
  std::uint64_t regions_built = 0;   // region buffers reassembled
  std::uint64_t triangles = 0;       // triangles in the reassembled regions
  std::uint64_t defects = 0;         // edges that could not be matched (0 expected; see docs)
  std::uint64_t forced_ears = 0;     // triangulator fallbacks (0 expected on valid input)
  BuildStats& operator+=(const BuildStats& o) noexcept;
};

class Reconstructor {
 public:
  explicit Reconstructor(MeshOptions opt = {});
  ~Reconstructor();
  Reconstructor(Reconstructor&&) noexcept;
  Reconstructor& operator=(Reconstructor&&) noexcept;

  // Rebuilds every region. Allocates; not for the real-time threads.
  BuildStats build(const geom::LbrSolid& solid);
  // Rebuilds what the cells marked dirty in `solid` (since its last clear_dirty()) affect:
  // the two planes of each dirty level in its region and the neighbours' planes and walls
  // that share its borders. The result is identical to build() on the same solid. Falls
  // back to build() when the grid changed. Does not clear the solid's dirty set. Allocates;
  // not for the real-time threads (run it on the render side, per DESIGN.md).
  BuildStats update(const geom::LbrSolid& solid);

  [[nodiscard]] int regions() const noexcept;
  [[nodiscard]] const MeshBuffers& region(int r) const;
  [[nodiscard]] const MeshOptions& options() const noexcept { return opt_; }
  [[nodiscard]] double volume_mm3() const noexcept;      // Σ over regions
  [[nodiscard]] std::size_t triangle_count() const noexcept;

 private:
  struct Cache;
  MeshOptions opt_;
  std::unique_ptr<Cache> cache_;
};

// One-call facade: full reconstruction of every region.
[[nodiscard]] std::vector<MeshBuffers> reconstruct(const geom::LbrSolid& solid, const MeshOptions& opt = {},
                                                   BuildStats* stats = nullptr);

}  // namespace lbr::mesh
