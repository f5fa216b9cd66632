#include "gfx/capture.hpp"

#include <stdexcept>

#include "gfx/window.hpp"

namespace lbr::gfx {

void parse_size(const std::string& s, int& w, int& h) {
  const auto x = s.find('x');
  try {
    if (x == std::string::npos) throw std::invalid_argument("");
    std::size_t a = 0, b = 0;
    const int ww = std::stoi(s.substr(0, x), &a), hh = std::stoi(s.substr(x + 1), &b);
    if (a != x || b != s.size() - x - 1 || ww < 16 || hh < 16 || ww > 16384 || hh > 16384) throw std::invalid_argument("");
    w = ww;
    h = hh;
  } catch (const std::exception&) {
    throw std::invalid_argument("bad size '" + s + "' (expected WxH, e.g. 1024x768, 16..16384 each)");
  }
}

void capture_png(const geom::LbrSolid& solid, const std::string& path, const CaptureOptions& opt,
                 std::span<const ToolState> tools, std::span<const geom::Vec3> tool_path) {
  Window win(64, 64, false, "lbrsim capture");
  RenderOptions ro;
  ro.color = opt.color;
  ro.show_hud = opt.hud;
  ro.show_tools = !tools.empty();
  ro.show_path = !tool_path.empty();
  ro.deviation = opt.deviation;
  ro.deviation_scale_mm = opt.deviation_scale_mm;
  Renderer ren(solid, ro);
  ren.set_tools(tools);
  ren.set_path(tool_path);
  Camera cam;
  cam.set_view(opt.view);
  cam.ortho = opt.ortho;
  cam.fit(ren.stock_box(), static_cast<double>(opt.width) / opt.height);
  write_png(path, ren.render_offscreen(cam, opt.width, opt.height));
}

}  // namespace lbr::gfx
