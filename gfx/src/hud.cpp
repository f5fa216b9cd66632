#include "hud.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>

#include "gl_util.hpp"

// stb_easy_font is header-only with static functions; unused ones would warn.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wold-style-cast"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wshadow"
#include <stb_easy_font.h>
#pragma GCC diagnostic pop

namespace lbr::gfx::detail {

namespace {

// stb_easy_font vertex: x, y, z floats + RGBA bytes (16 bytes).
struct FontVertex {
  float x, y, z;
  std::uint8_t c[4];
};
static_assert(sizeof(FontVertex) == 16);

const char* kVs = R"(#version 330 core
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec4 a_col;
uniform vec3 u_screen;  // width, height, scale
out vec4 v_col;
void main() {
  vec2 p = a_pos.xy * u_screen.z;
  gl_Position = vec4(p.x / u_screen.x * 2.0 - 1.0, 1.0 - p.y / u_screen.y * 2.0, 0.0, 1.0);
  v_col = a_col;
})";
const char* kFs = R"(#version 330 core
in vec4 v_col;
out vec4 o_col;
void main() { o_col = v_col; })";

constexpr float kSwatchWidth = 14.0f;  // font units a swatch column takes

// Lines and the longest line of `text` [characters].
std::pair<std::size_t, std::size_t> text_extent(const std::string& text) {
  std::size_t lines = 1, longest = 0, cur = 0;
  for (char ch : text) {
    if (ch == '\n') { ++lines; longest = std::max(longest, cur); cur = 0; } else { ++cur; }
  }
  return {lines, std::max(longest, cur)};
}

}  // namespace

Hud::Hud() {
  prog_ = make_program(kVs, kFs, "hud");
  u_screen_ = glGetUniformLocation(prog_, "u_screen");
  glGenVertexArrays(1, &vao_);
  glGenBuffers(1, &vbo_);
  glGenBuffers(1, &ebo_);
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(FontVertex), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 4, GL_UNSIGNED_BYTE, GL_TRUE, sizeof(FontVertex),
                        reinterpret_cast<const void*>(offsetof(FontVertex, c)));
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ebo_);
  glBindVertexArray(0);
}

Hud::~Hud() {
  glDeleteBuffers(1, &ebo_);
  glDeleteBuffers(1, &vbo_);
  glDeleteVertexArrays(1, &vao_);
  glDeleteProgram(prog_);
}

void Hud::draw(const std::string& text, int w, int h, float scale) { draw_panel(text, w, h, scale, Panel{}); }

void Hud::draw_alarm_band(const std::string& text, int w, int h, float scale) {
  if (text.empty() || w <= 0 || h <= 0) return;
  const auto [lines, longest] = text_extent(text);
  const float pw = 6.0f * static_cast<float>(longest) + 8.0f, ph = 12.0f * static_cast<float>(lines) + 4.0f;
  scale = std::clamp(static_cast<float>(w) / pw, 1.0f, scale);  // as draw_panel() will
  Panel band;
  band.y = static_cast<float>(h) / scale - ph;
  band.min_width = static_cast<float>(w) / scale;
  const std::uint8_t red[4] = {140, 15, 13, 255};  // the status bar's alarm colour (ui.cpp), opaque
  std::copy_n(red, 4, band.bg);
  draw_panel(text, w, h, scale, band);
}

void Hud::draw_legend(const std::string& text, const std::vector<std::array<std::uint8_t, 3>>& swatches, int w, int h,
                      float scale) {
  if (text.empty() || w <= 0 || h <= 0) return;
  const auto [lines, longest] = text_extent(text);
  const float tw = 6.0f * static_cast<float>(longest) + 8.0f + kSwatchWidth, ph = 12.0f * static_cast<float>(lines) + 4.0f;
  scale = std::clamp(static_cast<float>(w) / tw, 1.0f, scale);  // as draw_panel() will
  Panel p;  // at the right edge, half-way down: clear of the HUD (top left) and the alarm band (bottom)
  p.x = std::max(0.0f, static_cast<float>(w) / scale - tw - 4.0f);
  p.y = std::max(0.0f, 0.5f * (static_cast<float>(h) / scale - ph));
  p.swatches = &swatches;
  draw_panel(text, w, h, scale, p);
}

void Hud::draw_panel(const std::string& text, int w, int h, float scale, const Panel& panel) {
  if (text.empty() || w <= 0 || h <= 0) return;
  // Panel first (one quad), then the glyph quads.
  std::vector<FontVertex> verts;
  const auto [lines, longest] = text_extent(text);
  const float sw = panel.swatches != nullptr ? kSwatchWidth : 0.0f;
  const float tw = 6.0f * static_cast<float>(longest) + 8.0f + sw, ph = 12.0f * static_cast<float>(lines) + 4.0f;
  scale = std::clamp(static_cast<float>(w) / tw, 1.0f, scale);  // fit narrow viewports
  const float pw = std::max(tw, panel.min_width), x0 = panel.x, y0 = panel.y;
  for (auto [x, y] : {std::pair{x0, y0}, {x0 + pw, y0}, {x0 + pw, y0 + ph}, {x0, y0 + ph}}) {
    FontVertex v{x, y, 0, {panel.bg[0], panel.bg[1], panel.bg[2], panel.bg[3]}};
    verts.push_back(v);
  }
  if (panel.swatches != nullptr) {
    for (std::size_t i = 0; i < std::min(lines, panel.swatches->size()); ++i) {
      const auto& c = (*panel.swatches)[i];
      const float sx = x0 + 4.0f, sy = y0 + 3.0f + 12.0f * static_cast<float>(i);
      for (auto [x, y] : {std::pair{sx, sy}, {sx + 10.0f, sy}, {sx + 10.0f, sy + 9.0f}, {sx, sy + 9.0f}})
        verts.push_back(FontVertex{x, y, 0, {c[0], c[1], c[2], 255}});
    }
  }
  buf_.resize(text.size() * 270 + 1024);
  std::string copy = text;
  unsigned char col[4] = {235, 240, 245, 255};
  const int quads =
      stb_easy_font_print(x0 + 4.0f + sw, y0 + 4.0f, copy.data(), col, buf_.data(), static_cast<int>(buf_.size()));
  const auto* fv = reinterpret_cast<const FontVertex*>(buf_.data());
  verts.insert(verts.end(), fv, fv + 4 * quads);
  const std::size_t nq = verts.size() / 4;
  idx_.clear();
  for (std::size_t q = 0; q < nq; ++q) {
    const auto b = static_cast<GLuint>(4 * q);
    for (GLuint o : {0u, 1u, 2u, 0u, 2u, 3u}) idx_.push_back(b + o);
  }
  glDisable(GL_DEPTH_TEST);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glUseProgram(prog_);
  glUniform3f(u_screen_, static_cast<float>(w), static_cast<float>(h), scale);
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(verts.size() * sizeof(FontVertex)), verts.data(), GL_STREAM_DRAW);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(idx_.size() * sizeof(GLuint)), idx_.data(),
               GL_STREAM_DRAW);
  glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(idx_.size()), GL_UNSIGNED_INT, nullptr);
  glBindVertexArray(0);
  glDisable(GL_BLEND);
  glEnable(GL_DEPTH_TEST);
}

}  // namespace lbr::gfx::detail
