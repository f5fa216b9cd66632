// gfx/ui.hpp — the operator UI's public side (docs/ui.md): its configuration, the pointer
// events the main thread hands to it, and the replay control it drives. The UI itself
// (Dear ImGui, private to gfx/src/ui.*) runs on the render thread, inside the render
// thread's frame, and reads the same snapshot data the HUD reads.
#pragma once

#include <atomic>
#include <string>
#include <vector>

namespace lbr::gfx {

// Replay control shared by the UI (render thread, writes) and a replaying source (its own
// thread, reads). Lock-free atomics only: neither side ever waits for the other.
struct ReplayControl {
  std::atomic<bool> paused{false};
  std::atomic<double> speed{1.0};       // simulated seconds per wall second
  std::atomic<int> steps{0};            // single steps asked for while paused (source consumes)
  std::atomic<bool> restart{false};     // start again from the untouched stock (source clears it)
  // Jumps (the source clears them): re-simulate from the untouched stock up to machining
  // time seek_s [s] (>= 0), or to the end of program line seek_line's motion (> 0).
  std::atomic<double> seek_s{-1.0};
  std::atomic<long long> seek_line{0};
};

struct UiConfig {
  bool enabled = false;        // the interactive windows turn it on; offscreen/batch never
  float scale = 1.5f;          // profile [render] ui_scale: widget and font size factor
  bool kiosk = false;          // quitting needs a confirmation in the UI
  std::string source;          // what feeds the view (program, device), for the status bar
  ReplayControl* replay = nullptr;  // non-null: the replay bar is shown
  // The program's text, one entry per source line (line 1 first), for the program panel;
  // empty: no panel. With `replay`, tapping a line jumps there (ReplayControl::seek_line).
  std::vector<std::string> program;
};

// A pointer event in window pixels (origin top-left), from the main thread's GLFW callbacks.
struct UiEvent {
  enum class Kind { Move, Button, Scroll };
  Kind kind = Kind::Move;
  double x = 0, y = 0;
  int button = 0;      // 0 left, 1 right, 2 middle
  bool down = false;
  double wheel = 0;    // scroll steps (> 0: away from the user)
};

// A point the Measure tool picked (docs/ui.md): where the line of sight through the tap
// first meets the material, from the render side's copy of the level polygons [mm].
struct MeasurePoint {
  double x_mm = 0, y_mm = 0, z_mm = 0;
  double surface_z_mm = 0;  // top of the material on the vertical through (x, y)
  double thickness_mm = 0;  // material on that vertical below the point
  bool top_face = false;    // on a horizontal face (else a wall)
};

// A screen rectangle the UI occupies [px].
struct UiRect {
  float x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  [[nodiscard]] bool contains(double x, double y) const noexcept { return x >= x0 && x < x1 && y >= y0 && y < y1; }
};

}  // namespace lbr::gfx
