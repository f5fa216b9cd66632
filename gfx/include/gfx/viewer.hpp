// gfx/viewer.hpp — the interactive viewer's main-thread side: GLFW event loop and mouse /
// keyboard bindings that edit the render thread's camera and options.
//
//   left drag: orbit   right or middle drag: pan   wheel: zoom
//   1 / T: top   2 / F: front   3 / S: side   4 / I: iso   0 / Home / Space: fit to part
//   C: cycle colour mode (plain, heat, regions)   P: path on/off   K: tools on/off
//   H: HUD on/off   O: orthographic / perspective   Esc / Q: close
#pragma once

#include <functional>

#include "gfx/render_thread.hpp"
#include "gfx/window.hpp"

namespace lbr::gfx {

// Installs the bindings and polls events on the calling (main) thread until the window is
// closed, the render thread stops by itself, or `keep_going` returns false.
void run_event_loop(Window& win, RenderThread& rt, const std::function<bool()>& keep_going = {});

}  // namespace lbr::gfx
