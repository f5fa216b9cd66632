// gfx/src/hud.hpp — private: the heads-up display, lines of text drawn with stb_easy_font
// (Debian libstb-dev) over a translucent panel, in window pixels.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <epoxy/gl.h>

namespace lbr::gfx::detail {

class Hud {
 public:
  Hud();  // GL context current
  ~Hud();
  Hud(const Hud&) = delete;
  Hud& operator=(const Hud&) = delete;
  // Draws `text` (lines separated by '\n') at the top-left of a w × h viewport.
  void draw(const std::string& text, int w, int h, float scale = 2.0f);
  // Draws `text` on an opaque red band across the bottom of the viewport (alarms).
  void draw_alarm_band(const std::string& text, int w, int h, float scale = 2.0f);
  // Draws a legend at the right edge, half-way down: line i of `text` after a square of
  // colour swatches[i].
  void draw_legend(const std::string& text, const std::vector<std::array<std::uint8_t, 3>>& swatches, int w, int h,
                   float scale = 2.0f);

 private:
  struct Panel {
    float x = 0, y = 0;          // top-left of the panel [font units]
    float min_width = 0;         // at least this wide [font units]
    std::uint8_t bg[4] = {10, 12, 16, 170};
    const std::vector<std::array<std::uint8_t, 3>>* swatches = nullptr;  // one per line, left of the text
  };
  void draw_panel(const std::string& text, int w, int h, float scale, const Panel& panel);

  GLuint prog_ = 0, vao_ = 0, vbo_ = 0, ebo_ = 0;
  GLint u_screen_ = -1;
  std::vector<char> buf_;
  std::vector<GLuint> idx_;
};

}  // namespace lbr::gfx::detail
