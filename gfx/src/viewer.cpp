#include "gfx/viewer.hpp"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

namespace lbr::gfx {

namespace {

struct Input {
  RenderThread* rt = nullptr;
  bool orbiting = false, panning = false;
  double x = 0, y = 0;
  int h = 1;
};

Input* input_of(GLFWwindow* w) { return static_cast<Input*>(glfwGetWindowUserPointer(w)); }

void on_button(GLFWwindow* w, int button, int action, int) {
  Input* in = input_of(w);
  const bool down = action == GLFW_PRESS;
  if (button == GLFW_MOUSE_BUTTON_LEFT) in->orbiting = down;
  if (button == GLFW_MOUSE_BUTTON_RIGHT || button == GLFW_MOUSE_BUTTON_MIDDLE) in->panning = down;
  glfwGetCursorPos(w, &in->x, &in->y);
}

void on_cursor(GLFWwindow* w, double x, double y) {
  Input* in = input_of(w);
  const double dx = x - in->x, dy = y - in->y;
  in->x = x;
  in->y = y;
  if (in->orbiting) in->rt->edit([&](Camera& c, RenderOptions&) { c.orbit(dx, dy); });
  else if (in->panning) {
    const double h = in->h;
    in->rt->edit([&](Camera& c, RenderOptions&) { c.pan(dx, dy, h); });
  }
}

void on_scroll(GLFWwindow* w, double, double dy) {
  input_of(w)->rt->edit([&](Camera& c, RenderOptions&) { c.zoom(dy); });
}

void on_size(GLFWwindow* w, int width, int height) {
  Input* in = input_of(w);
  in->h = height;
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
    case GLFW_KEY_ESCAPE: case GLFW_KEY_Q: glfwSetWindowShouldClose(w, GLFW_TRUE); break;
    default: break;
  }
}

}  // namespace

void run_event_loop(Window& win, RenderThread& rt, const std::function<bool()>& keep_going) {
  GLFWwindow* w = win.handle();
  Input in;
  in.rt = &rt;
  int fw = 0, fh = 0;
  glfwGetFramebufferSize(w, &fw, &fh);
  in.h = fh > 0 ? fh : 1;
  if (fw > 0 && fh > 0) rt.resize(fw, fh);  // the framebuffer may differ from the window size (HiDPI)
  glfwSetWindowUserPointer(w, &in);
  glfwSetMouseButtonCallback(w, on_button);
  glfwSetCursorPosCallback(w, on_cursor);
  glfwSetScrollCallback(w, on_scroll);
  glfwSetFramebufferSizeCallback(w, on_size);
  glfwSetKeyCallback(w, on_key);
  while (!glfwWindowShouldClose(w) && rt.running() && (!keep_going || keep_going())) glfwWaitEventsTimeout(0.05);
  glfwSetWindowUserPointer(w, nullptr);
  glfwSetMouseButtonCallback(w, nullptr);
  glfwSetCursorPosCallback(w, nullptr);
  glfwSetScrollCallback(w, nullptr);
  glfwSetFramebufferSizeCallback(w, nullptr);
  glfwSetKeyCallback(w, nullptr);
}

}  // namespace lbr::gfx
