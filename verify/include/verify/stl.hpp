// verify/stl.hpp — a small STL reader and writer for design models (docs/formats.md#stl).
//
// Binary STL (80-byte header, uint32 count, 50 bytes a triangle) and ASCII STL
// ("solid … facet normal … outer loop vertex x y z … endloop endfacet … endsolid"). The
// format is told by its size first (a binary file is exactly 84 + 50·n bytes, and binary
// headers often begin with "solid" too), then by its first word. Normals in the file are
// ignored: the vertex order gives the orientation. Units are millimetres.
//
// Setup-time code: allocates; errors throw StlError("NAME: what was expected").
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "geom/types.hpp"

namespace lbr::verify {

class StlError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Triangle {
  geom::Vec3 v[3];  // counter-clockwise seen from outside [mm]
};

struct StlMesh {
  std::vector<Triangle> triangles;
  [[nodiscard]] geom::Box3 bounds() const noexcept;
  // Enclosed volume by the divergence theorem (positive for outward normals) [mm3].
  [[nodiscard]] double volume_mm3() const noexcept;
};

// Parses `bytes` (the whole file); `name` prefixes the errors.
[[nodiscard]] StlMesh parse_stl(std::string_view bytes, const std::string& name);
// Reads and parses the file at `path`.
[[nodiscard]] StlMesh read_stl(const std::string& path);

[[nodiscard]] std::string stl_binary(const StlMesh& mesh);
[[nodiscard]] std::string stl_ascii(const StlMesh& mesh, const std::string& solid_name = "design");

// Edges of a mesh whose vertices are welded by exact coordinates: an edge used by one
// triangle is a boundary edge (the mesh is open), by more than two a non-manifold edge.
struct EdgeCheck {
  std::size_t boundary_edges = 0, non_manifold_edges = 0;
  [[nodiscard]] bool closed_manifold() const noexcept { return boundary_edges == 0 && non_manifold_edges == 0; }
};
[[nodiscard]] EdgeCheck check_edges(const StlMesh& mesh);

}  // namespace lbr::verify
