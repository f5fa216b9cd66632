// gfx/viewer.hpp — the interactive viewer's main-thread side: GLFW event loop and mouse /
// keyboard bindings that edit the render thread's camera and options.
//
//   left drag: orbit   right or middle drag: pan   wheel: zoom
//   1 / T: top   2 / F: front   3 / S: side   4 / I: iso   0 / Home / Space: fit to part
//   C: cycle colour mode (plain, heat, regions)   P: path on/off   K: tools on/off
//   H: HUD on/off   O: orthographic / perspective   Esc / Q: close (kiosk: asks first)
// With the operator UI (docs/ui.md) a press on a UI window goes to the UI until released;
// everything else drives the camera as above.
#pragma once

#include <functional>

#include "gfx/render_thread.hpp"
#include "gfx/window.hpp"

namespace lbr::gfx {

// Routes pointer input (main thread) to the UI or to the camera. run_event_loop() feeds it
// from GLFW's callbacks; tests inject events through it as GLFW would.
class EventRouter {
 public:
  EventRouter(RenderThread& rt, int height_px) : rt_(rt), h_px_(height_px) {}
  // button: GLFW_MOUSE_BUTTON_* (0 left, 1 right, 2 middle); positions in window pixels.
  void button(int button, bool down, double x, double y);
  void cursor(double x, double y);
  void scroll(double dy);
  void set_height(int h_px) noexcept { h_px_ = h_px; }

 private:
  RenderThread& rt_;
  int h_px_ = 1;
  double x_ = 0, y_ = 0;
  bool orbiting_ = false, panning_ = false, ui_owns_ = false;
  // Measure mode: a left press on the 3D view is a tap until it moves further than a finger
  // wobbles; released as a tap, it picks a point, otherwise it drags as usual.
  bool tap_armed_ = false;
  double tap_x_ = 0, tap_y_ = 0;
};

// Installs the bindings and polls events on the calling (main) thread until the window is
// closed (kiosk: after the UI's confirmation), the render thread stops by itself, or
// `keep_going` returns false.
void run_event_loop(Window& win, RenderThread& rt, const std::function<bool()>& keep_going = {}, bool kiosk = false);

}  // namespace lbr::gfx
