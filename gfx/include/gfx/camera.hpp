// gfx/camera.hpp — orbit camera (GLM), standard views, fit-to-part and frustum tests.
// No OpenGL here. Workpiece frame: +Z up (tool axis), mm. Plain value type; not thread-safe.
#pragma once

#include <array>
#include <string>

#include <glm/glm.hpp>

#include "geom/types.hpp"

namespace lbr::gfx {

enum class StandardView { Top, Front, Side, Iso };
// Parses "top", "front", "side", "iso"; throws std::invalid_argument naming the choices.
[[nodiscard]] StandardView parse_view(const std::string& s);

class Camera {
 public:
  // Orbit parameters: the eye is at target + distance · dir(yaw, pitch). yaw [rad] about +Z
  // from +X... measured so that yaw = -90° looks from -Y (front); pitch [rad] above the XY plane.
  glm::dvec3 target{0, 0, 0};
  double distance = 100;   // [mm]
  double yaw = 0, pitch = 0;
  double fov_y = glm::radians(35.0);  // perspective vertical field of view [rad]
  double ortho_half_h = 50;           // orthographic half height of the view [mm]
  bool ortho = false;

  // Sets yaw/pitch for a standard view (top: looking down -Z with +Y up; front: looking
  // along +Y; side: looking along -X; iso: from (+1, -1, +1)).
  void set_view(StandardView v) noexcept;
  // Centres `box` and sets distance / ortho_half_h so that it fills the viewport of the
  // given aspect (width / height) with `margin` (fraction of the view) left around it.
  void fit(const geom::Box3& box, double aspect, double margin = 0.05) noexcept;
  // Mouse interaction, in pixels of a viewport of height `h_px`.
  void orbit(double dx_px, double dy_px) noexcept;
  void pan(double dx_px, double dy_px, double h_px) noexcept;
  void zoom(double steps) noexcept;  // > 0: closer

  [[nodiscard]] glm::dvec3 eye() const noexcept;
  [[nodiscard]] glm::dvec3 up() const noexcept;
  [[nodiscard]] glm::dmat4 view() const noexcept;
  [[nodiscard]] glm::dmat4 projection(double aspect) const noexcept;
  // Window coordinates of a point (x right, y *down* from the top-left pixel corner, as in
  // a PNG), for a viewport of w × h pixels.
  [[nodiscard]] glm::dvec2 project(const glm::dvec3& p, int w, int h) const noexcept;
  // The inverse: the line of sight through window point (x, y) as origin (on the near plane)
  // + t · dir, t in [0, 1] reaching the far plane. project() of any point on it gives (x, y).
  void ray(double x, double y, int w, int h, glm::dvec3& origin, glm::dvec3& dir) const noexcept;
};

// The six planes of a view-projection matrix (Gribb–Hartmann), for box culling.
class Frustum {
 public:
  explicit Frustum(const glm::dmat4& view_projection) noexcept;
  // False only when the box lies completely outside one plane (conservative).
  [[nodiscard]] bool intersects(const geom::Box3& b) const noexcept;

 private:
  std::array<glm::dvec4, 6> planes_{};
};

}  // namespace lbr::gfx
