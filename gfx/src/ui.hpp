// gfx/src/ui.hpp — private: the operator UI (docs/ui.md) with Dear ImGui (Debian
// libimgui-dev) and its OpenGL 3 backend. Render thread only: the GL context must be current
// on every call. Input arrives as UiEvents queued by the main thread (no GLFW backend: GLFW
// input functions belong to the main thread); what the operator asks for leaves as UiActions
// that the render thread applies to its camera and options under its own mutex.
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <string>
#include <utility>
#include <vector>

#include "gfx/camera.hpp"
#include "gfx/renderer.hpp"
#include "gfx/ui.hpp"

struct ImGuiContext;
struct ImVec2;
struct ImVec4;

namespace lbr::gfx::detail {

// What the operator asked for this frame. Option fields are meaningful when
// options_changed is set (the UI's copy of the options it edits).
struct UiActions {
  int view = -1;               // a StandardView to switch to (and fit), -1: none
  bool fit = false;
  double zoom_steps = 0;       // > 0: closer
  bool toggle_ortho = false;
  bool options_changed = false;
  RenderOptions opt;           // color, show_tools, show_path, show_outline, section_*
  int touch_pan = -1;          // one-finger drag: 0 orbit, 1 pan, -1 unchanged
  int measure = -1;            // Measure mode: 0 off, 1 on, -1 unchanged
  bool quit = false;           // confirmed quit (kiosk)
};

// The per-frame inputs of the UI beside the renderer's figures.
struct UiFrameInput {
  const Camera& cam;
  const RenderOptions& opt;
  bool touch_pan = false;
  bool measuring = false;      // Measure mode: taps on the part pick points
  bool ask_quit = false;       // the main thread asked for the quit confirmation (kiosk)
  int width = 0, height = 0;   // framebuffer [px]
  double dt_s = 1.0 / 30;
};

class Ui {
 public:
  explicit Ui(const UiConfig& cfg);  // GL context current
  ~Ui();
  Ui(const Ui&) = delete;
  Ui& operator=(const Ui&) = delete;

  // Takes the queued events this frame can apply. A button that changes twice (a tap)
  // waits for the next frame with everything behind it, since ImGui 1.86 sees only the
  // button state per frame.
  void feed(std::deque<UiEvent>& queue);
  // Builds and draws the UI over the frame in the bound framebuffer.
  UiActions frame(const Renderer& ren, const UiFrameInput& in);
  // Rectangles the UI covered this frame (main thread's hit test) and whether a modal
  // dialog takes all input.
  [[nodiscard]] const std::vector<UiRect>& rects() const noexcept { return rects_; }
  [[nodiscard]] bool modal() const noexcept { return modal_; }
  // The controls drawn last frame by label ("Top", "Pause", "##section", ...), for tests
  // and the documentation's screenshots.
  [[nodiscard]] const std::vector<std::pair<const char*, UiRect>>& items() const noexcept { return items_; }
  // Measure: a picked point (the third starts a new pair), or a tap that met no material.
  void add_measure(const MeasurePoint& p);
  void measure_missed() noexcept { measure_miss_ = true; }
  [[nodiscard]] const std::vector<MeasurePoint>& measured() const noexcept { return measured_; }

 private:
  void status_bar(const Renderer& ren, const UiFrameInput& in);
  void status_line_source(const Renderer& ren);
  void status_line_machining(const Renderer& ren);
  void alarms_line(const LiveStats& L, const std::string& notice);
  void flow(const ImVec4& colour, const char* fmt, ...) __attribute__((format(printf, 3, 4)));
  void view_panel(const UiFrameInput& in, UiActions& act);
  void view_buttons(UiActions& act);
  void display_toggles(UiActions& act);
  // The deviation colours' legend (gfx::deviation_legend) under the toggles.
  void deviation_legend_rows(double scale_mm);
  void section_controls(UiActions& act);
  void replay_bar(const Renderer& ren);
  void time_slider(ReplayControl& rc, const LiveStats& L);
  void program_panel(const Renderer& ren, const UiFrameInput& in);
  void measure_panel(const UiFrameInput& in);
  void mark_points(const UiFrameInput& in);
  void quit_dialog(const UiFrameInput& in, UiActions& act);
  void remember_window();
  bool button(const char* label, const ImVec2& size);
  bool toggle_button(const char* label, bool on, const ImVec2& size);
  void record(const char* label);
  void track_lag(const Renderer& ren);

  UiConfig cfg_;
  ImGuiContext* ctx_ = nullptr;
  std::vector<UiRect> rects_;
  std::vector<std::pair<const char*, UiRect>> items_;
  bool modal_ = false;
  bool open_quit_ = false;     // the panel's Quit... asks for the dialog
  bool line_start_ = true;     // flow(): the next text starts a line
  float status_h_ = 0;         // height of the status bar last frame [px]
  geom::Box3 stock_{};
  // Lag samples of the recent snapshots (p50/p99 in the status bar).
  std::array<double, 256> lag_ms_{};
  std::size_t lag_n_ = 0, lag_next_ = 0;
  std::vector<double> lag_sorted_;
  std::uint64_t last_version_ = 0;
  double since_data_s_ = 0;    // time since the last new snapshot [s]
  // Program panel: a label per line ("##line N", the rows' item names) and the line the
  // panel last scrolled to.
  std::vector<std::string> line_labels_;
  std::int64_t scrolled_line_ = -1;
  float replay_h_ = 0;         // height of the replay bar last frame [px]
  float seek_s_ = -1;          // the time slider's value while the operator drags it [s]
  float program_bottom_ = 0;   // lower edge of the program panel last frame [px]
  std::vector<MeasurePoint> measured_;  // at most two
  bool measure_miss_ = false;  // the last tap met no material
};

}  // namespace lbr::gfx::detail
