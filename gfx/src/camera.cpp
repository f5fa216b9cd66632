#include "gfx/camera.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <glm/gtc/matrix_transform.hpp>

namespace lbr::gfx {

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kPitchLimit = kPi / 2;  // straight down: up() stays defined by the yaw
}  // namespace

StandardView parse_view(const std::string& s) {
  if (s == "top") return StandardView::Top;
  if (s == "front") return StandardView::Front;
  if (s == "side") return StandardView::Side;
  if (s == "iso") return StandardView::Iso;
  throw std::invalid_argument("unknown view '" + s + "' (expected top, front, side or iso)");
}

void Camera::set_view(StandardView v) noexcept {
  switch (v) {
    case StandardView::Top: yaw = -kPi / 2; pitch = kPitchLimit; break;
    case StandardView::Front: yaw = -kPi / 2; pitch = 0; break;
    case StandardView::Side: yaw = 0; pitch = 0; break;
    case StandardView::Iso: yaw = -kPi / 4; pitch = std::atan(1.0 / std::sqrt(2.0)); break;
  }
}

glm::dvec3 Camera::eye() const noexcept {
  const glm::dvec3 d{std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw), std::sin(pitch)};
  return target + distance * d;
}

glm::dvec3 Camera::up() const noexcept {
  // Perpendicular to the view direction, in the vertical plane through it: +Z for level
  // views; for the top view it tends to +Y (yaw = -90°).
  return {-std::sin(pitch) * std::cos(yaw), -std::sin(pitch) * std::sin(yaw), std::cos(pitch)};
}

glm::dmat4 Camera::view() const noexcept { return glm::lookAt(eye(), target, up()); }

glm::dmat4 Camera::projection(double aspect) const noexcept {
  const double znear = std::max(0.01, distance * 0.01), zfar = distance * 10.0 + 1000.0;
  if (ortho) {
    const double hh = ortho_half_h, hw = hh * aspect;
    return glm::ortho(-hw, hw, -hh, hh, znear, zfar);
  }
  return glm::perspective(fov_y, aspect, znear, zfar);
}

void Camera::fit(const geom::Box3& box, double aspect, double margin) noexcept {
  if (box.empty()) return;
  const glm::dvec3 lo{box.lo.x, box.lo.y, box.lo.z}, hi{box.hi.x, box.hi.y, box.hi.z};
  target = 0.5 * (lo + hi);
  // Extent of the box's corners in the camera's right/up directions.
  const glm::dvec3 fwd = glm::normalize(target - eye());
  const glm::dvec3 upv = up();
  const glm::dvec3 right = glm::normalize(glm::cross(fwd, upv));
  double half_w = 0, half_h = 0, half_d = 0;
  for (int i = 0; i < 8; ++i) {
    const glm::dvec3 c{(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z};
    const glm::dvec3 v = c - target;
    half_w = std::max(half_w, std::abs(glm::dot(v, right)));
    half_h = std::max(half_h, std::abs(glm::dot(v, upv)));
    half_d = std::max(half_d, std::abs(glm::dot(v, fwd)));
  }
  const double scale = 1.0 / std::max(1e-3, 1.0 - 2.0 * margin);
  const double need_h = std::max(half_h, half_w / std::max(aspect, 1e-6)) * scale;
  ortho_half_h = std::max(need_h, 1e-3);
  // Perspective: the box's near face (half_d in front of the target) must fit.
  distance = need_h / std::tan(0.5 * fov_y) + half_d;
  distance = std::max(distance, 2.0 * half_d + 1.0);
}

void Camera::orbit(double dx_px, double dy_px) noexcept {
  yaw -= dx_px * 0.008;
  pitch = std::clamp(pitch + dy_px * 0.008, -kPitchLimit, kPitchLimit);
}

void Camera::pan(double dx_px, double dy_px, double h_px) noexcept {
  const double world_per_px =
      (ortho ? 2.0 * ortho_half_h : 2.0 * distance * std::tan(0.5 * fov_y)) / std::max(h_px, 1.0);
  const glm::dvec3 fwd = glm::normalize(target - eye());
  const glm::dvec3 upv = up();
  const glm::dvec3 right = glm::normalize(glm::cross(fwd, upv));
  target += world_per_px * (-dx_px * right + dy_px * upv);
}

void Camera::zoom(double steps) noexcept {
  const double f = std::pow(0.85, steps);
  distance = std::max(1e-2, distance * f);
  ortho_half_h = std::max(1e-3, ortho_half_h * f);
}

glm::dvec2 Camera::project(const glm::dvec3& p, int w, int h) const noexcept {
  const glm::dvec4 c = projection(static_cast<double>(w) / h) * view() * glm::dvec4(p, 1.0);
  const glm::dvec3 ndc = glm::dvec3(c) / c.w;
  return {(ndc.x * 0.5 + 0.5) * w, (0.5 - ndc.y * 0.5) * h};
}

void Camera::ray(double x, double y, int w, int h, glm::dvec3& origin, glm::dvec3& dir) const noexcept {
  const glm::dmat4 inv = glm::inverse(projection(static_cast<double>(w) / h) * view());
  const double nx = 2.0 * x / w - 1.0, ny = 1.0 - 2.0 * y / h;
  const glm::dvec4 a = inv * glm::dvec4(nx, ny, -1.0, 1.0), b = inv * glm::dvec4(nx, ny, 1.0, 1.0);
  origin = glm::dvec3(a) / a.w;
  dir = glm::dvec3(b) / b.w - origin;
}

Frustum::Frustum(const glm::dmat4& m) noexcept {
  // Rows of the (column-major) matrix.
  auto row = [&](int i) { return glm::dvec4(m[0][i], m[1][i], m[2][i], m[3][i]); };
  planes_ = {row(3) + row(0), row(3) - row(0), row(3) + row(1), row(3) - row(1), row(3) + row(2), row(3) - row(2)};
}

bool Frustum::intersects(const geom::Box3& b) const noexcept {
  if (b.empty()) return false;
  for (const glm::dvec4& p : planes_) {
    // The box corner farthest along the plane normal.
    const glm::dvec3 c{p.x >= 0 ? b.hi.x : b.lo.x, p.y >= 0 ? b.hi.y : b.lo.y, p.z >= 0 ? b.hi.z : b.lo.z};
    if (p.x * c.x + p.y * c.y + p.z * c.z + p.w < 0) return false;
  }
  return true;
}

}  // namespace lbr::gfx
