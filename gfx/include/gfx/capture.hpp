// gfx/capture.hpp — headless capture in one call: a hidden GLFW window (works under
// `xvfb-run -a` with Mesa llvmpipe), one frame offscreen, glReadPixels, PNG.
#pragma once

#include <span>
#include <string>

#include "gfx/camera.hpp"
#include "gfx/exchange.hpp"
#include "gfx/renderer.hpp"

namespace lbr::gfx {

struct CaptureOptions {
  StandardView view = StandardView::Iso;
  ColorMode color = ColorMode::Plain;
  int width = 1024, height = 768;
  bool ortho = false;  // orthographic projection (the default for the top view)
  bool hud = false;
  DeviationFn deviation;  // ColorMode::Deviation's per-vertex values (RenderOptions::deviation)
  double deviation_scale_mm = 0.2;  // RenderOptions::deviation_scale_mm (the image has the legend)
};

// Parses "WxH" (e.g. 1024x768); throws std::invalid_argument.
void parse_size(const std::string& s, int& w, int& h);

// Renders the solid (all regions, joined walls) with the given tools and path and writes a
// PNG. Throws DisplayError when there is no display (message suggests xvfb-run) and
// std::runtime_error on GL or I/O failure. Main thread only (creates a GLFW window).
void capture_png(const geom::LbrSolid& solid, const std::string& path, const CaptureOptions& opt,
                 std::span<const ToolState> tools = {}, std::span<const geom::Vec3> tool_path = {});

}  // namespace lbr::gfx
