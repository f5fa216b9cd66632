#include "ui.hpp"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>

#include <imgui.h>
#include <backends/imgui_impl_opengl3.h>

namespace lbr::gfx::detail {

namespace {

constexpr ImGuiWindowFlags kFixed = ImGuiWindowFlags_NoTitleBar | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoMove |
                                    ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoSavedSettings;

const ImVec4 kGreen{0.35f, 0.85f, 0.40f, 1.0f}, kAmber{1.0f, 0.75f, 0.20f, 1.0f}, kRed{1.0f, 0.30f, 0.25f, 1.0f},
    kGrey{0.65f, 0.67f, 0.70f, 1.0f};

double axis_of(const geom::Vec3& v, int a) { return a == 0 ? v.x : (a == 1 ? v.y : v.z); }

double percentile_sorted(const std::vector<double>& v, double q) {
  if (v.empty()) return 0.0;
  const auto i = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(i, v.size() - 1)];
}

}  // namespace

Ui::Ui(const UiConfig& cfg) : cfg_(cfg) {
  IMGUI_CHECKVERSION();
  ctx_ = ImGui::CreateContext();
  ImGui::SetCurrentContext(ctx_);
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;  // nothing written beside the working directory
  io.LogFilename = nullptr;
  const float s = std::clamp(cfg_.scale, 0.5f, 4.0f);
  ImFontConfig font;
  font.SizePixels = std::round(13.0f * s);
  io.Fonts->AddFontDefault(&font);
  ImGui::StyleColorsDark();
  ImGuiStyle& st = ImGui::GetStyle();
  st.WindowRounding = 0;
  st.FrameRounding = 3;
  st.ScaleAllSizes(s);
  st.WindowBorderSize = 0;
  st.Colors[ImGuiCol_WindowBg].w = 0.86f;
  lag_sorted_.reserve(lag_ms_.size());
  line_labels_.reserve(cfg_.program.size());
  for (std::size_t i = 0; i < cfg_.program.size(); ++i) line_labels_.push_back("##line " + std::to_string(i + 1));
  rects_.reserve(8);
  ImGui_ImplOpenGL3_Init("#version 330 core");
}

Ui::~Ui() {
  ImGui::SetCurrentContext(ctx_);
  ImGui_ImplOpenGL3_Shutdown();
  ImGui::DestroyContext(ctx_);
}

void Ui::feed(std::deque<UiEvent>& queue) {
  ImGui::SetCurrentContext(ctx_);
  ImGuiIO& io = ImGui::GetIO();
  // One button change per frame, and no move after it: the frame must see the press (or
  // release) where it happened, or a tap followed by a tap elsewhere would release on the
  // second control.
  bool button_changed = false;
  while (!queue.empty()) {
    const UiEvent& e = queue.front();
    if (button_changed && e.kind != UiEvent::Kind::Scroll) break;
    if (e.kind == UiEvent::Kind::Button && e.button >= 0 && e.button <= 2) {
      const auto b = static_cast<std::size_t>(e.button);
      button_changed = io.MouseDown[b] != e.down;
      io.MouseDown[b] = e.down;
    } else if (e.kind == UiEvent::Kind::Scroll) {
      io.MouseWheel += static_cast<float>(e.wheel);
    }
    io.MousePos = ImVec2(static_cast<float>(e.x), static_cast<float>(e.y));
    queue.pop_front();
  }
}

UiActions Ui::frame(const Renderer& ren, const UiFrameInput& in) {
  ImGui::SetCurrentContext(ctx_);
  ImGuiIO& io = ImGui::GetIO();
  io.DisplaySize = ImVec2(static_cast<float>(in.width), static_cast<float>(in.height));
  io.DeltaTime = static_cast<float>(std::max(in.dt_s, 1e-4));
  stock_ = ren.stock_box();
  track_lag(ren);
  since_data_s_ += in.dt_s;
  ImGui_ImplOpenGL3_NewFrame();
  ImGui::NewFrame();
  rects_.clear();
  items_.clear();
  UiActions act;
  act.opt = in.opt;
  status_bar(ren, in);
  view_panel(in, act);
  replay_h_ = 0;
  if (cfg_.replay != nullptr) replay_bar(ren);
  program_bottom_ = replay_h_;
  if (!cfg_.program.empty()) program_panel(ren, in);
  if (in.measuring) measure_panel(in);
  quit_dialog(in, act);
  ImGui::Render();
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  // Auto-sized windows are measured in their first frames (hidden, then placed): their
  // rectangles are published from the third frame on.
  if (ImGui::GetFrameCount() < 3) items_.clear();
  return act;
}

bool Ui::button(const char* label, const ImVec2& size) {
  const bool pressed = ImGui::Button(label, size);
  record(label);
  return pressed;
}

// A toggle drawn as a button that stays lit while on (touch: no tiny check boxes).
bool Ui::toggle_button(const char* label, bool on, const ImVec2& size) {
  if (on) ImGui::PushStyleColor(ImGuiCol_Button, ImGui::GetStyleColorVec4(ImGuiCol_ButtonActive));
  const bool pressed = button(label, size);
  if (on) ImGui::PopStyleColor();
  return pressed;
}

void Ui::record(const char* label) {
  const ImVec2 a = ImGui::GetItemRectMin(), b = ImGui::GetItemRectMax();
  items_.push_back({label, UiRect{a.x, a.y, b.x, b.y}});
}

void Ui::remember_window() {
  const ImVec2 p = ImGui::GetWindowPos(), s = ImGui::GetWindowSize();
  rects_.push_back({p.x, p.y, p.x + s.x, p.y + s.y});
}

void Ui::track_lag(const Renderer& ren) {
  const std::uint64_t v = ren.last_frame().version;
  if (v == last_version_) return;
  last_version_ = v;
  since_data_s_ = 0;
  if (!ren.live().live) return;
  lag_ms_[lag_next_] = ren.live().lag_ms;
  lag_next_ = (lag_next_ + 1) % lag_ms_.size();
  lag_n_ = std::min(lag_n_ + 1, lag_ms_.size());
}

// ---- status bar (bottom, full width) ---------------------------------------------------

void Ui::status_bar(const Renderer& ren, const UiFrameInput& in) {
  const LiveStats& L = ren.live();
  bool error = false;
  for (int i = 0; i < L.alarm_count && i < kMaxAlarms; ++i)
    error = error || L.alarms[static_cast<std::size_t>(i)].severity == AlarmSeverity::Error;
  const auto w = static_cast<float>(in.width), h = static_cast<float>(in.height);
  ImGui::SetNextWindowPos(ImVec2(0, h), ImGuiCond_Always, ImVec2(0, 1));
  ImGui::SetNextWindowSizeConstraints(ImVec2(w, 0), ImVec2(w, h));
  if (error) ImGui::PushStyleColor(ImGuiCol_WindowBg, ImVec4(0.55f, 0.06f, 0.05f, 0.95f));
  if (ImGui::Begin("##status", nullptr, kFixed | ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoScrollbar)) {
    status_line_source(ren);
    status_line_machining(ren);
    alarms_line(L, in.opt.notice);
    if (!in.opt.design.empty()) flow(kGrey, "DESIGN: %s", in.opt.design.c_str());
    remember_window();
    status_h_ = ImGui::GetWindowSize().y;
  }
  ImGui::End();
  if (error) ImGui::PopStyleColor();
}

// Text that continues the current line when it fits, or starts the next one (narrow panels).
void Ui::flow(const ImVec4& colour, const char* fmt, ...) {
  char buf[256];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(buf, sizeof buf, fmt, args);
  va_end(args);
  if (!line_start_) {
    ImGui::SameLine();
    if (ImGui::CalcTextSize(buf).x > ImGui::GetContentRegionAvail().x) ImGui::NewLine();
  }
  ImGui::TextColored(colour, "%s", buf);
  line_start_ = false;
}

// Source, connection, sample rate, lag, losses, ring, RT mode.
void Ui::status_line_source(const Renderer& ren) {
  const LiveStats& L = ren.live();
  line_start_ = true;
  const ImVec4 white = ImGui::GetStyleColorVec4(ImGuiCol_Text);
  flow(white, "%s", cfg_.source.empty() ? "source -" : cfg_.source.c_str());
  if (cfg_.replay != nullptr) {
    const bool paused = cfg_.replay->paused.load(std::memory_order_relaxed);
    flow(paused ? kAmber : kGreen, paused ? "| REPLAY PAUSED" : "| REPLAY");
  } else if (L.live) {
    const bool stale = since_data_s_ > 2.0;
    flow(stale ? kAmber : kGreen, stale ? "| LIVE: no data" : "| LIVE");
  } else {
    flow(kGrey, "| result (no live source)");
  }
  if (!L.live && L.samples == 0) return;
  lag_sorted_.assign(lag_ms_.begin(), lag_ms_.begin() + static_cast<std::ptrdiff_t>(lag_n_));
  std::sort(lag_sorted_.begin(), lag_sorted_.end());
  const unsigned long long lost = L.ring_overruns + L.decode_errors;
  flow(white, "| %.0f samples/s", L.sample_rate_hz);
  flow(white, "| lag %.1f ms (p50 %.1f, p99 %.1f)", L.lag_ms, percentile_sorted(lag_sorted_, 0.5),
       percentile_sorted(lag_sorted_, 0.99));
  flow(lost > 0 ? kAmber : white, "| lost %llu", lost);
  const double fill = L.ring_capacity ? static_cast<double>(L.ring_high_water) / static_cast<double>(L.ring_capacity) : 0.0;
  flow(white, "| ring %.0f %%", 100.0 * fill);
  flow(L.realtime ? kGreen : kGrey, "| %s", L.realtime ? "RT (SCHED_FIFO)" : "non-RT");
}

// Machining time and progress, tool, program line, frame figures.
void Ui::status_line_machining(const Renderer& ren) {
  const LiveStats& L = ren.live();
  char overlay[64];
  float frac = 0;
  if (L.machining_s >= 0 && L.total_s > 0) {
    frac = static_cast<float>(std::clamp(L.machining_s / L.total_s, 0.0, 1.0));
    std::snprintf(overlay, sizeof overlay, "%.1f / %.1f s", L.machining_s, L.total_s);
  } else if (L.machining_s >= 0) {
    std::snprintf(overlay, sizeof overlay, "%.1f s", L.machining_s);
  } else {
    std::snprintf(overlay, sizeof overlay, "machining time -");
  }
  ImGui::ProgressBar(frac, ImVec2(ImGui::GetFontSize() * 12, 0), overlay);
  line_start_ = false;
  const ImVec4 white = ImGui::GetStyleColorVec4(ImGuiCol_Text);
  const auto tools = ren.tools();
  if (tools.empty() || tools.front().tool == 0) flow(white, "| tool -");
  else if (tools.size() == 1) flow(white, "| tool T%d D%.2f mm", tools.front().tool, 2.0 * tools.front().radius_mm);
  else flow(white, "| tools T%d + %zu more", tools.front().tool, tools.size() - 1);
  if (L.program_line > 0) flow(white, "| line %lld", static_cast<long long>(L.program_line));
  else flow(white, "| line -");
  const FrameInfo& f = ren.last_frame();
  const PacingInfo& p = ren.pacing();
  flow(kGrey, "| frame %.1f ms, period p99 %.1f ms, late %llu, pending %d", p.frame_ms, p.p99_period_ms,
       static_cast<unsigned long long>(p.late_frames), f.step.regions_pending);
}

void Ui::alarms_line(const LiveStats& L, const std::string& notice) {
  const int n = std::min(L.alarm_count, kMaxAlarms);
  line_start_ = true;
  // The HUD's notice (e.g. live input that does not match the profile) as a warning.
  if (!notice.empty()) flow(kAmber, "WARNING: %s", notice.c_str());
  if (n <= 0 && notice.empty()) {
    ImGui::TextColored(kGreen, "no alarms");
    return;
  }
  for (int i = 0; i < n; ++i) {
    const Alarm& a = L.alarms[static_cast<std::size_t>(i)];
    const char* tag = a.severity == AlarmSeverity::Error ? "ALARM" : (a.severity == AlarmSeverity::Warning ? "WARNING" : "INFO");
    const ImVec4 c = a.severity == AlarmSeverity::Error ? ImVec4(1, 1, 1, 1) : (a.severity == AlarmSeverity::Warning ? kAmber : kGrey);
    flow(c, "%s: %s", tag, a.text.data());
  }
}

// ---- view panel (right edge) -----------------------------------------------------------

void Ui::view_panel(const UiFrameInput& in, UiActions& act) {
  const float pw = ImGui::GetFontSize() * 11.5f;
  const float max_h = std::max(100.0f, static_cast<float>(in.height) - status_h_);
  ImGui::SetNextWindowPos(ImVec2(static_cast<float>(in.width), 0), ImGuiCond_Always, ImVec2(1, 0));
  ImGui::SetNextWindowSizeConstraints(ImVec2(pw, 0), ImVec2(pw, max_h));
  if (ImGui::Begin("##view", nullptr, kFixed | ImGuiWindowFlags_AlwaysAutoResize)) {
    view_buttons(act);
    ImGui::Separator();
    display_toggles(act);
    const float half = (ImGui::GetContentRegionAvail().x - ImGui::GetStyle().ItemSpacing.x) * 0.5f;
    const ImVec2 b(half, ImGui::GetFrameHeight() * 1.3f);
    ImGui::TextUnformatted("one-finger drag");
    if (toggle_button("Orbit", !in.touch_pan, b)) act.touch_pan = 0;
    ImGui::SameLine();
    if (toggle_button("Pan", in.touch_pan, b)) act.touch_pan = 1;
    if (toggle_button("Measure", in.measuring, ImVec2(-1, b.y))) act.measure = in.measuring ? 0 : 1;
    ImGui::Separator();
    section_controls(act);
    if (cfg_.kiosk) {
      ImGui::Separator();
      if (button("Quit...", ImVec2(-1, b.y))) open_quit_ = true;  // opened at top level, where the dialog lives
    }
    remember_window();
  }
  ImGui::End();
}

void Ui::view_buttons(UiActions& act) {
  const float half = (ImGui::GetContentRegionAvail().x - ImGui::GetStyle().ItemSpacing.x) * 0.5f;
  const ImVec2 b(half, ImGui::GetFrameHeight() * 1.3f);
  const char* names[4] = {"Top", "Front", "Side", "Iso"};
  for (int v = 0; v < 4; ++v) {
    if (v % 2) ImGui::SameLine();
    if (button(names[v], b)) act.view = v;
  }
  if (button("Fit", b)) act.fit = true;
  ImGui::SameLine();
  if (button("Ortho", b)) act.toggle_ortho = true;
  if (button("Zoom +", b)) act.zoom_steps += 1;
  ImGui::SameLine();
  if (button("Zoom -", b)) act.zoom_steps -= 1;
}

void Ui::display_toggles(UiActions& act) {
  RenderOptions& o = act.opt;
  const float third = (ImGui::GetContentRegionAvail().x - 2 * ImGui::GetStyle().ItemSpacing.x) / 3.0f;
  const ImVec2 b3(third, ImGui::GetFrameHeight() * 1.3f);
  const char* modes[3] = {"Plain", "Heat", "Regions"};
  for (int m = 0; m < 3; ++m) {
    if (m) ImGui::SameLine();
    if (toggle_button(modes[m], static_cast<int>(o.color) == m, b3)) {
      o.color = static_cast<ColorMode>(m);
      act.options_changed = true;
    }
  }
  if (toggle_button("Tool", o.show_tools, b3)) { o.show_tools = !o.show_tools; act.options_changed = true; }
  ImGui::SameLine();
  if (toggle_button("Path", o.show_path, b3)) { o.show_path = !o.show_path; act.options_changed = true; }
  ImGui::SameLine();
  if (toggle_button("Stock", o.show_outline, b3)) { o.show_outline = !o.show_outline; act.options_changed = true; }
  if (o.color == ColorMode::Deviation && o.deviation) deviation_legend_rows(o.deviation_scale_mm);
}

void Ui::deviation_legend_rows(double scale_mm) {
  const float side = ImGui::GetTextLineHeight();
  for (const LegendRow& r : deviation_legend(scale_mm)) {
    const ImVec4 c(r.rgb[0] / 255.0f, r.rgb[1] / 255.0f, r.rgb[2] / 255.0f, 1.0f);
    ImGui::ColorButton(r.text.c_str(), c, ImGuiColorEditFlags_NoTooltip | ImGuiColorEditFlags_NoPicker, ImVec2(side, side));
    ImGui::SameLine();
    ImGui::TextUnformatted(r.text.c_str());
  }
}

void Ui::section_controls(UiActions& act) {
  RenderOptions& o = act.opt;
  const float quarter = (ImGui::GetContentRegionAvail().x - 3 * ImGui::GetStyle().ItemSpacing.x) / 4.0f;
  const ImVec2 b4(quarter, ImGui::GetFrameHeight() * 1.3f);
  ImGui::TextUnformatted("section");
  const char* axes[4] = {"Off", "X", "Y", "Z"};
  for (int a = -1; a < 3; ++a) {
    if (a >= 0) ImGui::SameLine();
    if (toggle_button(axes[a + 1], o.section_axis == a, b4)) {
      if (a >= 0 && o.section_axis != a) o.section_mm = 0.5 * (axis_of(stock_.lo, a) + axis_of(stock_.hi, a));
      o.section_axis = a;
      act.options_changed = true;
    }
  }
  if (o.section_axis < 0) return;
  const int a = o.section_axis;
  auto pos = static_cast<float>(o.section_mm);
  ImGui::SetNextItemWidth(-1);
  // Taller grab for fingers: frame padding grows with the style's scale.
  ImGui::PushStyleVar(ImGuiStyleVar_FramePadding, ImVec2(ImGui::GetStyle().FramePadding.x, ImGui::GetFontSize() * 0.6f));
  if (ImGui::SliderFloat("##section", &pos, static_cast<float>(axis_of(stock_.lo, a)),
                         static_cast<float>(axis_of(stock_.hi, a)), "%.2f mm")) {
    o.section_mm = pos;
    act.options_changed = true;
  }
  record("##section");
  ImGui::PopStyleVar();
  if (toggle_button("Flip side", o.section_flip, ImVec2(-1, b4.y))) {
    o.section_flip = !o.section_flip;
    act.options_changed = true;
  }
}

// ---- replay bar (top left) -------------------------------------------------------------

void Ui::replay_bar(const Renderer& ren) {
  ReplayControl& rc = *cfg_.replay;
  ImGui::SetNextWindowPos(ImVec2(0, 0), ImGuiCond_Always);
  if (ImGui::Begin("##replay", nullptr, kFixed | ImGuiWindowFlags_AlwaysAutoResize)) {
    const ImVec2 b(ImGui::GetFontSize() * 4.5f, ImGui::GetFrameHeight() * 1.3f);
    if (button("Restart", b)) rc.restart.store(true);
    ImGui::SameLine();
    const bool paused = rc.paused.load();
    if (button(paused ? "Play" : "Pause", b)) rc.paused.store(!paused);
    ImGui::SameLine();
    if (button("Step", b)) {
      rc.paused.store(true);
      rc.steps.fetch_add(1);
    }
    ImGui::SameLine();
    auto speed = static_cast<float>(rc.speed.load());
    ImGui::SetNextItemWidth(ImGui::GetFontSize() * 12);
    ImGui::PushStyleVar(ImGuiStyleVar_FramePadding, ImVec2(ImGui::GetStyle().FramePadding.x, ImGui::GetFontSize() * 0.6f));
    if (ImGui::SliderFloat("##speed", &speed, 0.1f, 100.0f, "speed %.2fx", ImGuiSliderFlags_Logarithmic))
      rc.speed.store(speed);
    record("##speed");
    time_slider(rc, ren.live());
    ImGui::PopStyleVar();
    remember_window();
    replay_h_ = ImGui::GetWindowSize().y;
  }
  ImGui::End();
}

// Machining time over the whole program; a release after dragging jumps there.
void Ui::time_slider(ReplayControl& rc, const LiveStats& L) {
  if (L.total_s <= 0) return;
  const bool dragging = seek_s_ >= 0;
  auto t = dragging ? seek_s_ : static_cast<float>(std::max(L.machining_s, 0.0));
  ImGui::SetNextItemWidth(-1);
  if (ImGui::SliderFloat("##time", &t, 0.0f, static_cast<float>(L.total_s), "t %.1f s")) seek_s_ = t;
  record("##time");
  if (ImGui::IsItemDeactivated()) {
    if (seek_s_ >= 0) rc.seek_s.store(seek_s_);
    seek_s_ = -1;
  }
}

// ---- program panel (left, below the replay bar) ----------------------------------------

void Ui::program_panel(const Renderer& ren, const UiFrameInput& in) {
  const float fs = ImGui::GetFontSize();
  const float top = replay_h_;
  const float h = std::max(4 * fs, (static_cast<float>(in.height) - status_h_ - top) * 0.5f);
  ImGui::SetNextWindowPos(ImVec2(0, top), ImGuiCond_Always);
  ImGui::SetNextWindowSize(ImVec2(fs * 22, h), ImGuiCond_Always);
  if (ImGui::Begin("##program", nullptr, kFixed)) {
    const std::int64_t cur = ren.live().program_line;
    const float row = ImGui::GetTextLineHeightWithSpacing();
    if (cur > 0 && cur != scrolled_line_) {  // keep the current line in the middle
      ImGui::SetScrollY(std::max(0.0f, static_cast<float>(cur - 1) * row - 0.5f * ImGui::GetWindowHeight()));
      scrolled_line_ = cur;
    }
    ImGuiListClipper clip;
    clip.Begin(static_cast<int>(cfg_.program.size()), row);
    while (clip.Step()) {
      for (int i = clip.DisplayStart; i < clip.DisplayEnd; ++i) {
        const auto k = static_cast<std::size_t>(i);
        char text[256];
        std::snprintf(text, sizeof text, "%5d  %s", i + 1, cfg_.program[k].c_str());
        ImGui::PushID(i);
        if (ImGui::Selectable(text, cur == i + 1) && cfg_.replay != nullptr) cfg_.replay->seek_line.store(i + 1);
        record(line_labels_[k].c_str());
        ImGui::PopID();
      }
    }
    remember_window();
    program_bottom_ = ImGui::GetWindowPos().y + ImGui::GetWindowSize().y;
  }
  ImGui::End();
}

// ---- measure panel (left, above the status bar) ----------------------------------------

void Ui::add_measure(const MeasurePoint& p) {
  if (measured_.size() >= 2) measured_.clear();
  measured_.push_back(p);
  measure_miss_ = false;
}

void Ui::measure_panel(const UiFrameInput& in) {
  const float fs = ImGui::GetFontSize();
  ImGui::SetNextWindowPos(ImVec2(0, static_cast<float>(in.height) - status_h_), ImGuiCond_Always, ImVec2(0, 1));
  const float max_h = std::max(fs * 4, static_cast<float>(in.height) - status_h_ - program_bottom_);
  ImGui::SetNextWindowSizeConstraints(ImVec2(fs * 25, 0), ImVec2(fs * 25, max_h));
  if (ImGui::Begin("##measure", nullptr, kFixed | ImGuiWindowFlags_AlwaysAutoResize)) {
    ImGui::TextUnformatted(measured_.size() == 1 ? "Measure: tap a second point" : "Measure: tap a point of the part");
    if (measure_miss_) ImGui::TextColored(kAmber, "no material under the last tap");
    for (std::size_t i = 0; i < measured_.size(); ++i) {
      const MeasurePoint& p = measured_[i];
      ImGui::Text("P%zu  X %.3f  Y %.3f  Z %.3f", i + 1, p.x_mm, p.y_mm, p.z_mm);
      ImGui::TextColored(kGrey, "    stock below %.3f mm, top Z %.3f", p.thickness_mm, p.surface_z_mm);
    }
    if (measured_.size() == 2) {
      const MeasurePoint &a = measured_[0], &b = measured_[1];
      const double dx = b.x_mm - a.x_mm, dy = b.y_mm - a.y_mm, dz = b.z_mm - a.z_mm;
      ImGui::Text("distance %.3f mm", std::sqrt(dx * dx + dy * dy + dz * dz));
      ImGui::TextColored(kGrey, "    dX %.3f  dY %.3f  dZ %.3f", dx, dy, dz);
    }
    if (button("Clear", ImVec2(fs * 6, ImGui::GetFrameHeight() * 1.3f))) {
      measured_.clear();
      measure_miss_ = false;
    }
    remember_window();
  }
  ImGui::End();
  mark_points(in);
}

// The picked points (and the line between them) over the 3D view.
void Ui::mark_points(const UiFrameInput& in) {
  ImDrawList* dl = ImGui::GetForegroundDrawList();
  const float r = ImGui::GetFontSize() * 0.3f;
  ImVec2 prev;
  for (std::size_t i = 0; i < measured_.size(); ++i) {
    const MeasurePoint& p = measured_[i];
    const glm::dvec2 q = in.cam.project({p.x_mm, p.y_mm, p.z_mm}, in.width, in.height);
    const ImVec2 at(static_cast<float>(q.x), static_cast<float>(q.y));
    if (i > 0) dl->AddLine(prev, at, ImGui::GetColorU32(kAmber), 2.0f);
    dl->AddCircleFilled(at, r, ImGui::GetColorU32(kAmber));
    dl->AddText(ImVec2(at.x + r, at.y - 2 * r - ImGui::GetFontSize() * 0.5f), ImGui::GetColorU32(kAmber), i == 0 ? "P1" : "P2");
    prev = at;
  }
}

// ---- quit confirmation (kiosk) ---------------------------------------------------------

void Ui::quit_dialog(const UiFrameInput& in, UiActions& act) {
  if ((in.ask_quit || open_quit_) && !ImGui::IsPopupOpen("Quit lbrsim?")) ImGui::OpenPopup("Quit lbrsim?");
  open_quit_ = false;
  modal_ = false;
  const ImVec2 centre(0.5f * static_cast<float>(in.width), 0.5f * static_cast<float>(in.height));
  ImGui::SetNextWindowPos(centre, ImGuiCond_Always, ImVec2(0.5f, 0.5f));
  if (ImGui::BeginPopupModal("Quit lbrsim?", nullptr, ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoMove)) {
    modal_ = true;
    ImGui::TextUnformatted("Stop the simulation and close the window?");
    const ImVec2 b(ImGui::GetFontSize() * 7, ImGui::GetFrameHeight() * 1.6f);
    if (button("Quit", b)) {
      act.quit = true;
      ImGui::CloseCurrentPopup();
    }
    ImGui::SameLine();
    if (button("Cancel", b)) ImGui::CloseCurrentPopup();
    ImGui::EndPopup();
  }
}

}  // namespace lbr::gfx::detail
