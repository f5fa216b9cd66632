// gfx/window.hpp — a GLFW window with an OpenGL 3.3 core context, visible (viewer) or
// hidden (headless capture). Creation, events and destruction must happen on the main
// thread (a GLFW rule); the context may be made current on another thread (the render
// thread) after release_context() on the main thread.
#pragma once

#include <stdexcept>
#include <string>

struct GLFWwindow;

namespace lbr::gfx {

// No display to open a window on (no DISPLAY / WAYLAND_DISPLAY, or the X server refused).
class DisplayError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// True when DISPLAY or WAYLAND_DISPLAY is set (a window can be attempted).
[[nodiscard]] bool display_available() noexcept;

// Called when the connection to the X server is lost (the server ended, as at the end of
// `xvfb-run`, or the session closed), on whichever thread made the failing request. Xlib
// ends the process when the handler returns, so a handler finishes what must not be lost
// (results) and leaves with std::_Exit. Process-wide; set it before creating windows;
// nullptr restores Xlib's default (print and exit(1)).
using DisplayLostHandler = void (*)();
void set_display_lost_handler(DisplayLostHandler handler) noexcept;

class Window {
 public:
  // Throws DisplayError (with a hint to use xvfb-run) when no display is available, and
  // std::runtime_error with GLFW's message when the context cannot be created. The context
  // is current on the calling thread afterwards.
  // `fullscreen` (kiosk): undecorated, covering the primary monitor at its current mode.
  Window(int width, int height, bool visible, const std::string& title = "lbrsim", bool fullscreen = false);
  ~Window();
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;

  [[nodiscard]] GLFWwindow* handle() const noexcept { return w_; }
  void make_current() noexcept;     // on the thread that will issue GL calls
  void release_context() noexcept;  // on the thread that currently holds it
  [[nodiscard]] bool visible() const noexcept { return visible_; }
  // GL_RENDERER and GL_VERSION strings (context must be current).
  [[nodiscard]] static std::string gl_description();

 private:
  GLFWwindow* w_ = nullptr;
  bool visible_ = false;
};

}  // namespace lbr::gfx
