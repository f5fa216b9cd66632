#include "gfx/window.hpp"

#include <cstdlib>
#include <mutex>

#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <X11/Xlib.h>  // XSetIOErrorHandler only (GLFW's X11 backend owns the connection)

namespace lbr::gfx {

namespace {

std::mutex g_mutex;  // GLFW init refcount and last error (main thread only in practice)
int g_windows = 0;
std::string g_last_error;

DisplayLostHandler g_display_lost = nullptr;

int on_x_io_error(Display*) {
  if (g_display_lost != nullptr) g_display_lost();
  return 0;  // Xlib exits after this
}

void on_glfw_error(int code, const char* msg) {
  g_last_error = std::string(msg ? msg : "?") + " (GLFW error " + std::to_string(code) + ")";
}

}  // namespace

bool display_available() noexcept {
  const char* d = std::getenv("DISPLAY");
  const char* w = std::getenv("WAYLAND_DISPLAY");
  return (d && *d) || (w && *w);
}

void set_display_lost_handler(DisplayLostHandler handler) noexcept {
  g_display_lost = handler;
  XSetIOErrorHandler(handler != nullptr ? on_x_io_error : nullptr);
}

Window::Window(int width, int height, bool visible, const std::string& title, bool fullscreen) : visible_(visible) {
  if (!display_available())
    throw DisplayError(
        "no display: DISPLAY and WAYLAND_DISPLAY are not set, so no OpenGL window can be opened. "
        "For headless rendering run under a virtual X server, e.g. `xvfb-run -a lbrsim ...`");
  std::lock_guard lock(g_mutex);
  glfwSetErrorCallback(on_glfw_error);
  if (g_windows == 0 && !glfwInit())
    throw DisplayError("cannot initialise GLFW: " + g_last_error +
                       " (is the display reachable? headless: `xvfb-run -a lbrsim ...`)");
  glfwDefaultWindowHints();
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_VISIBLE, visible ? GLFW_TRUE : GLFW_FALSE);
  // 4x multisampling on visible windows with a hardware renderer; a software rasteriser
  // (llvmpipe) pays for every sample, so the window is recreated without it there.
  glfwWindowHint(GLFW_SAMPLES, visible ? 4 : 0);
  GLFWmonitor* monitor = nullptr;
  if (fullscreen && visible) {
    glfwWindowHint(GLFW_DECORATED, GLFW_FALSE);
    monitor = glfwGetPrimaryMonitor();
    if (const GLFWvidmode* mode = monitor ? glfwGetVideoMode(monitor) : nullptr) {
      width = mode->width;
      height = mode->height;
    }
  }
  w_ = glfwCreateWindow(width, height, title.c_str(), monitor, nullptr);
  if (w_ && visible) {
    glfwMakeContextCurrent(w_);
    const auto* r = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    const std::string renderer = r ? r : "";
    if (renderer.find("llvmpipe") != std::string::npos || renderer.find("softpipe") != std::string::npos) {
      glfwMakeContextCurrent(nullptr);
      glfwDestroyWindow(w_);
      glfwWindowHint(GLFW_SAMPLES, 0);
      w_ = glfwCreateWindow(width, height, title.c_str(), monitor, nullptr);
    }
  }
  if (!w_) {
    if (g_windows == 0) glfwTerminate();
    throw std::runtime_error("cannot create an OpenGL 3.3 core context: " + g_last_error);
  }
  ++g_windows;
  glfwMakeContextCurrent(w_);
}

Window::~Window() {
  std::lock_guard lock(g_mutex);
  glfwDestroyWindow(w_);
  if (--g_windows == 0) glfwTerminate();
}

void Window::make_current() noexcept { glfwMakeContextCurrent(w_); }
void Window::release_context() noexcept { glfwMakeContextCurrent(nullptr); }

std::string Window::gl_description() {
  const auto* r = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const auto* v = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  return std::string(r ? r : "?") + ", OpenGL " + (v ? v : "?");
}

}  // namespace lbr::gfx
