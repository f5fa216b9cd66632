#include "gfx/viewer.hpp"

#include <cmath>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

namespace lbr::gfx {

namespace {

struct Input {
  RenderThread* rt = nullptr;
  EventRouter* router = nullptr;
  bool kiosk = false;
  double x = 0, y = 0;
};

constexpr double kTapSlopPx = 8.0;  // a tap may wobble this far [px]

Input* input_of(GLFWwindow* w) { return static_cast<Input*>(glfwGetWindowUserPointer(w)); }

}  // namespace

void EventRouter::button(int button, bool down, double x, double y) {
  x_ = x;
  y_ = y;
  const int b = button == GLFW_MOUSE_BUTTON_LEFT ? 0 : (button == GLFW_MOUSE_BUTTON_RIGHT ? 1 : 2);
  if (down && !orbiting_ && !panning_) ui_owns_ = rt_.ui_hit(x, y);
  if (ui_owns_) {
    rt_.ui_event({UiEvent::Kind::Button, x, y, b, down, 0});
    if (!down) ui_owns_ = false;
    return;
  }
  if (b == 0 && down && !orbiting_ && !panning_ && rt_.measuring()) {
    tap_armed_ = true;
    tap_x_ = x, tap_y_ = y;
    return;
  }
  if (b == 0 && !down && tap_armed_) {
    tap_armed_ = false;
    rt_.pick(x, y);
    return;
  }
  // One-finger (left) drag orbits, or pans when the UI's Pan switch is on; right/middle pan.
  const bool left_pans = rt_.touch_pan();
  if (b == 0) (left_pans ? panning_ : orbiting_) = down;
  if (b != 0) panning_ = down;
  if (!down) orbiting_ = panning_ = false;
}

void EventRouter::cursor(double x, double y) {
  const double dx = x - x_, dy = y - y_;
  x_ = x;
  y_ = y;
  rt_.ui_event({UiEvent::Kind::Move, x, y, 0, false, 0});
  if (ui_owns_) return;
  if (tap_armed_ && std::hypot(x - tap_x_, y - tap_y_) > kTapSlopPx) {  // a drag after all
    tap_armed_ = false;
    (rt_.touch_pan() ? panning_ : orbiting_) = true;
  }
  if (orbiting_) rt_.edit([&](Camera& c, RenderOptions&) { c.orbit(dx, dy); });
  else if (panning_) {
    const double h = h_px_;
    rt_.edit([&](Camera& c, RenderOptions&) { c.pan(dx, dy, h); });
  }
}

void EventRouter::scroll(double dy) {
  if (rt_.ui_hit(x_, y_)) {
    rt_.ui_event({UiEvent::Kind::Scroll, x_, y_, 0, false, dy});
    return;
  }
  rt_.edit([&](Camera& c, RenderOptions&) { c.zoom(dy); });
}

namespace {

void on_button(GLFWwindow* w, int button, int action, int) {
  Input* in = input_of(w);
  glfwGetCursorPos(w, &in->x, &in->y);
  in->router->button(button, action == GLFW_PRESS, in->x, in->y);
}

void on_cursor(GLFWwindow* w, double x, double y) { input_of(w)->router->cursor(x, y); }

void on_scroll(GLFWwindow* w, double, double dy) { input_of(w)->router->scroll(dy); }

void on_size(GLFWwindow* w, int width, int height) {
  Input* in = input_of(w);
  in->router->set_height(height);
  if (width > 0 && height > 0) in->rt->resize(width, height);
}

void on_key(GLFWwindow* w, int key, int, int action, int) {
  if (action != GLFW_PRESS) return;
  RenderThread& rt = *input_of(w)->rt;
  auto view = [&](StandardView v) {
    rt.edit([&](Camera& c, RenderOptions&) { c.set_view(v); });
    rt.request_fit();
  };
  switch (key) {
    case GLFW_KEY_1: case GLFW_KEY_T: view(StandardView::Top); break;
    case GLFW_KEY_2: case GLFW_KEY_F: view(StandardView::Front); break;
    case GLFW_KEY_3: case GLFW_KEY_S: view(StandardView::Side); break;
    case GLFW_KEY_4: case GLFW_KEY_I: view(StandardView::Iso); break;
    case GLFW_KEY_0: case GLFW_KEY_HOME: case GLFW_KEY_SPACE: rt.request_fit(); break;
    case GLFW_KEY_C:
      rt.edit([](Camera&, RenderOptions& o) {
        o.color = o.color == ColorMode::Plain ? ColorMode::Heat : (o.color == ColorMode::Heat ? ColorMode::Regions : ColorMode::Plain);
      });
      break;
    case GLFW_KEY_P: rt.edit([](Camera&, RenderOptions& o) { o.show_path = !o.show_path; }); break;
    case GLFW_KEY_K: rt.edit([](Camera&, RenderOptions& o) { o.show_tools = !o.show_tools; }); break;
    case GLFW_KEY_H: rt.edit([](Camera&, RenderOptions& o) { o.show_hud = !o.show_hud; }); break;
    case GLFW_KEY_O: rt.edit([](Camera& c, RenderOptions&) { c.ortho = !c.ortho; }); break;
    case GLFW_KEY_ESCAPE: case GLFW_KEY_Q:
      if (input_of(w)->kiosk) rt.ask_quit();  // kiosk: the UI asks for a confirmation
      else glfwSetWindowShouldClose(w, GLFW_TRUE);
      break;
    default: break;
  }
}

}  // namespace

void run_event_loop(Window& win, RenderThread& rt, const std::function<bool()>& keep_going, bool kiosk) {
  GLFWwindow* w = win.handle();
  int fw = 0, fh = 0;
  glfwGetFramebufferSize(w, &fw, &fh);
  EventRouter router(rt, fh > 0 ? fh : 1);
  Input in;
  in.rt = &rt;
  in.router = &router;
  in.kiosk = kiosk;
  // Kiosk: the window manager's close goes through the confirmation too.
  if (kiosk) glfwSetWindowCloseCallback(w, [](GLFWwindow* ww) {
    glfwSetWindowShouldClose(ww, GLFW_FALSE);
    input_of(ww)->rt->ask_quit();
  });
  if (fw > 0 && fh > 0) rt.resize(fw, fh);  // the framebuffer may differ from the window size (HiDPI)
  glfwSetWindowUserPointer(w, &in);
  glfwSetMouseButtonCallback(w, on_button);
  glfwSetCursorPosCallback(w, on_cursor);
  glfwSetScrollCallback(w, on_scroll);
  glfwSetFramebufferSizeCallback(w, on_size);
  glfwSetKeyCallback(w, on_key);
  while (!glfwWindowShouldClose(w) && !rt.quit_confirmed() && rt.running() && (!keep_going || keep_going()))
    glfwWaitEventsTimeout(0.05);
  glfwSetWindowCloseCallback(w, nullptr);
  glfwSetWindowUserPointer(w, nullptr);
  glfwSetMouseButtonCallback(w, nullptr);
  glfwSetCursorPosCallback(w, nullptr);
  glfwSetScrollCallback(w, nullptr);
  glfwSetFramebufferSizeCallback(w, nullptr);
  glfwSetKeyCallback(w, nullptr);
}

}  // namespace lbr::gfx
