// gfx/renderer.hpp — draws the stock (per-region GPU buffers), tools, recent tool path and
// HUD with OpenGL 3.3 core. All calls need the GL context current on the calling thread;
// one thread at a time (the render thread, or the main thread for headless capture).
// Allocates; never used on the real-time threads.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "gfx/camera.hpp"
#include "gfx/exchange.hpp"
#include "gfx/mirror.hpp"

namespace lbr::gfx {

enum class ColorMode { Plain, Heat, Regions, Deviation };
// Parses "plain", "heat", "regions", "deviation"; throws std::invalid_argument naming the choices.
[[nodiscard]] ColorMode parse_color_mode(const std::string& s);
[[nodiscard]] const char* to_string(ColorMode m) noexcept;

// Deviation colouring (docs/verification.md#deviation-colour): the colour of a vertex with
// signed deviation `d_mm` from the design model: 0 (within the tolerance) grey-green; a gouge
// (< 0) red and an excess (> 0) blue, each from a light shade near 0 to a deep one at
// |d| >= `scale_mm` (linear in between). The mesh shader computes the same colours.
[[nodiscard]] std::array<std::uint8_t, 3> deviation_rgb(float d_mm, float scale_mm) noexcept;
// The deviation the colours saturate at, per unit of the comparison's tolerance: the gradient
// spans the tolerance band's edge (half the tolerance) to ten tolerances (0.2 mm at 0.02).
inline constexpr double kDeviationScalePerTolerance = 10.0;
// One row of the deviation colours' legend.
struct LegendRow {
  std::array<std::uint8_t, 3> rgb;
  std::string text;
};
// The legend of deviation_rgb() at `scale_mm` (HUD, operator UI, --png): a gouge at the scale
// and at half of it, within the tolerance (scale / kDeviationScalePerTolerance), an excess at
// half the scale and at it.
[[nodiscard]] std::vector<LegendRow> deviation_legend(double scale_mm);
// Fills `out` with the signed deviation [mm] of every vertex of `mesh` (the app computes it
// from a design model, verify::vertex_deviation).
using DeviationFn = std::function<void(const mesh::MeshBuffers& mesh, std::vector<float>& out)>;

struct RenderOptions {
  ColorMode color = ColorMode::Plain;
  bool show_tools = true;
  bool show_path = true;
  bool show_hud = true;
  bool show_outline = false;  // the stock box's edges
  // Section plane (operator UI): -1 off, 0/1/2 a plane normal to X/Y/Z at section_mm
  // (workpiece frame); the part on the low side is kept (the high side when flipped).
  int section_axis = -1;
  double section_mm = 0;
  bool section_flip = false;
  std::string notice;  // a warning line on the HUD (e.g. input that does not match the profile)
  std::string design;  // the design comparison's figures on the HUD (--design: gouge, excess); empty: none
  DeviationFn deviation;  // ColorMode::Deviation's per-vertex values; empty: that mode draws plain
  double deviation_scale_mm = 0.2;  // deviation_rgb()'s scale_mm (the legend shows it)
  bool show_legend = true;          // the deviation legend at the right edge (off under the operator UI, which has its own)
  mesh::MeshOptions mesh;
  int max_regions_per_frame = 16;   // upper bound of the adaptive per-frame rebuild limit
  double mesh_budget_ms = 12.0;     // rebuild time per frame the limit adapts to [ms]
  std::size_t path_points = 50000;  // recent tool tip points kept for display
};

// Per-frame figures (also shown in the HUD).
struct FrameInfo {
  StepStats step;               // regions applied / rebuilt / pending, mesh time
  int region_limit = 0;         // the adaptive limit used this frame
  int regions_uploaded = 0;     // region buffers sent to the GPU
  int regions_visible = 0;      // regions inside the view frustum
  double upload_ms = 0, draw_ms = 0;
  std::uint64_t triangles = 0;  // stock triangles drawn
  std::uint64_t version = 0;    // newest snapshot received
};

// Frame-pacing figures the render thread hands to the HUD.
struct PacingInfo {
  double rate_hz = 0;           // target rate
  double period_ms = 0;         // last frame period
  double frame_ms = 0;          // last frame's work (rebuild + upload + draw) [ms]
  double p99_period_ms = 0;     // over the recent window
  std::uint64_t late_frames = 0;
};

struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;  // rows top first, 4 bytes per pixel
  std::vector<float> depth;        // window depth in [0, 1] per pixel, rows top first (optional)
  [[nodiscard]] const std::uint8_t* px(int x, int y) const noexcept {
    return &rgba[(static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) * 4];
  }
};

class Renderer {
 public:
  // Needs a current OpenGL 3.3 core context. Builds the mirror's meshes (all regions) and
  // compiles the shaders. Throws std::runtime_error with the GL log on shader errors.
  Renderer(const geom::LbrSolid& initial, const RenderOptions& opt = {});
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Takes a snapshot from the exchange: cells become pending in the mirror; tools, path
  // points, counters are kept for drawing.
  void receive(Snapshot& s);
  // Sets the tools and path directly (batch results, tests).
  void set_tools(std::span<const ToolState> tools);
  void set_path(std::span<const geom::Vec3> pts);
  void set_pacing(const PacingInfo& p) noexcept { pacing_ = p; }

  // One frame into the currently bound framebuffer of w × h pixels: bounded rebuild of
  // visible pending regions, upload of changed region buffers, draw.
  FrameInfo frame(const Camera& cam, int w, int h);
  // Same, into an offscreen framebuffer (hidden windows), without reading it back.
  FrameInfo frame_offscreen(const Camera& cam, int w, int h);
  // Same, into an offscreen framebuffer; returns the pixels (and depth when asked).
  Image render_offscreen(const Camera& cam, int w, int h, bool with_depth = false, FrameInfo* info = nullptr);

  [[nodiscard]] RenderOptions& options() noexcept { return opt_; }
  // What the HUD shows: the newest snapshot's counters, tools, the last frame's figures.
  [[nodiscard]] const LiveStats& live() const noexcept { return live_; }
  [[nodiscard]] std::span<const ToolState> tools() const noexcept {
    return {tools_.data(), static_cast<std::size_t>(tool_count_)};
  }
  [[nodiscard]] const FrameInfo& last_frame() const noexcept { return last_; }
  [[nodiscard]] const PacingInfo& pacing() const noexcept { return pacing_; }
  [[nodiscard]] const MeshMirror& mirror() const noexcept { return mirror_; }
  [[nodiscard]] geom::Box3 stock_box() const noexcept;
  // Number of times region r's buffers were uploaded (tests: what a frame touched).
  [[nodiscard]] std::uint64_t uploads(int region) const noexcept;

 private:
  struct Gl;
  // The steps of frame(), in order.
  void cull(const glm::dmat4& vp, FrameInfo& fi);
  void rebuild_visible(FrameInfo& fi);
  void upload_changed(FrameInfo& fi);
  void upload_path();
  void draw_stock(const Camera& cam, const glm::dmat4& vp, int w, int h, FrameInfo& fi);
  void set_scene_uniforms(const Camera& cam, const glm::dmat4& vp);
  void set_section();
  void draw_tools();
  void draw_path();
  void draw_outline();
  void draw_hud(int w, int h);
  void draw_alarms(int w, int h);
  void draw_legend(int w, int h);

  RenderOptions opt_;
  MeshMirror mirror_;
  std::unique_ptr<Gl> gl_;
  std::array<ToolState, kMaxTools> tools_{};
  int tool_count_ = 0;
  std::deque<geom::Vec3> path_;
  bool path_changed_ = true;
  geom::MoveId last_move_ = 0;
  LiveStats live_;
  PacingInfo pacing_;
  std::uint64_t version_ = 0;
  int limit_ = 4;
  std::vector<std::uint32_t> upload_idx_;
  std::vector<float> deviation_;  // a region's deviations for the upload (ColorMode::Deviation)
  std::vector<char> visible_;  // regions in the view frustum this frame
  FrameInfo last_;
};

// Writes RGBA rows (top first) as PNG. Throws std::runtime_error naming the path on failure.
void write_png(const std::string& path, const Image& img);

}  // namespace lbr::gfx
