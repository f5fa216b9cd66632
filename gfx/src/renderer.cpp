#include "gfx/renderer.hpp"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include <epoxy/gl.h>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "gl_util.hpp"
#include "hud.hpp"

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wold-style-cast"
#include <stb_image_write.h>
#pragma GCC diagnostic pop

namespace lbr::gfx {

namespace detail {

namespace {
GLuint compile(GLenum type, const char* src, const char* name) {
  const GLuint s = glCreateShader(type);
  glShaderSource(s, 1, &src, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    glGetShaderInfoLog(s, sizeof log, nullptr, log);
    glDeleteShader(s);
    throw std::runtime_error(std::string("gfx: shader '") + name + "' does not compile: " + log);
  }
  return s;
}
}  // namespace

GLuint make_program(const char* vs, const char* fs, const char* name) {
  const GLuint v = compile(GL_VERTEX_SHADER, vs, name), f = compile(GL_FRAGMENT_SHADER, fs, name);
  const GLuint p = glCreateProgram();
  glAttachShader(p, v);
  glAttachShader(p, f);
  glLinkProgram(p);
  glDeleteShader(v);
  glDeleteShader(f);
  GLint ok = 0;
  glGetProgramiv(p, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    glGetProgramInfoLog(p, sizeof log, nullptr, log);
    glDeleteProgram(p);
    throw std::runtime_error(std::string("gfx: program '") + name + "' does not link: " + log);
  }
  return p;
}

}  // namespace detail

namespace {

const char* kMeshVs = R"(#version 330 core
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_nrm;
layout(location = 2) in float a_attr;
uniform mat4 u_vp;
uniform mat4 u_model;
uniform vec4 u_clip;  // section plane: kept where dot(u_clip, (p, 1)) >= 0 (GL_CLIP_DISTANCE0)
out vec3 v_pos;
out vec3 v_nrm;
out float v_attr;
void main() {
  vec4 w = u_model * vec4(a_pos, 1.0);
  v_pos = w.xyz;
  v_nrm = mat3(u_model) * a_nrm;
  v_attr = a_attr;
  gl_ClipDistance[0] = dot(u_clip, vec4(w.xyz, 1.0));
  gl_Position = u_vp * w;
})";

// Modes: 0 plain, 1 heat (by move id of the last cut), 2 region colour, 3 constant colour
// (tools), 4 unlit constant colour (path), 5 deviation (v_attr: signed deviation from the
// design model [mm], gfx::deviation_rgb()).
const char* kMeshFs = R"(#version 330 core
in vec3 v_pos;
in vec3 v_nrm;
in float v_attr;
uniform int u_mode;
uniform vec3 u_color;
uniform float u_max_attr;
uniform vec3 u_eye;
uniform vec3 u_key;       // direction towards the key light (world)
uniform vec3 u_stock_lo;
uniform vec3 u_stock_hi;
uniform int u_section;    // 1: a section plane is on; back faces seen through the cut are the cut face
out vec4 o_col;
vec3 heat(float t) {
  // dark blue -> blue -> cyan -> yellow -> red (older cuts cool, recent ones hot)
  vec3 c0 = vec3(0.10, 0.15, 0.55), c1 = vec3(0.10, 0.45, 0.95), c2 = vec3(0.15, 0.85, 0.85);
  vec3 c3 = vec3(0.98, 0.85, 0.15), c4 = vec3(0.90, 0.15, 0.08);
  t = clamp(t, 0.0, 1.0) * 4.0;
  if (t < 1.0) return mix(c0, c1, t);
  if (t < 2.0) return mix(c1, c2, t - 1.0);
  if (t < 3.0) return mix(c2, c3, t - 2.0);
  return mix(c3, c4, t - 3.0);
}
bool on_stock_face(vec3 p) {
  // Untouched stock faces lie on the stock box; heat colouring leaves them plain so that
  // cut ids interpolated over big cap triangles do not bleed onto them. The test takes the
  // triangle's own (flat) normal from the screen-space derivatives of the position: the
  // smoothed vertex normals of walls turn towards the neighbouring face near a stock corner,
  // and with them a band of an untouched side face lost its grey (issue 19).
  vec3 g = normalize(cross(dFdx(p), dFdy(p)));
  float e = 1e-3 * max(1.0, length(u_stock_hi - u_stock_lo));
  return ((abs(p.z - u_stock_hi.z) < e || abs(p.z - u_stock_lo.z) < e) && abs(g.z) > 0.9) ||
         ((abs(p.x - u_stock_lo.x) < e || abs(p.x - u_stock_hi.x) < e) && abs(g.x) > 0.9) ||
         ((abs(p.y - u_stock_lo.y) < e || abs(p.y - u_stock_hi.y) < e) && abs(g.y) > 0.9);
}
void main() {
  if (u_mode == 4) { o_col = vec4(u_color, 1.0); return; }
  if (u_section == 1 && !gl_FrontFacing) {
    // The inside of the closed stock surface, seen through the section plane: the filled
    // cut face, flat, with a diagonal hatch so that it reads as a cut.
    float k = mod(floor((gl_FragCoord.x + gl_FragCoord.y) / 6.0), 2.0);
    o_col = vec4(mix(vec3(0.80, 0.30, 0.22), vec3(0.70, 0.24, 0.18), k), 1.0);
    return;
  }
  vec3 n = normalize(v_nrm);
  vec3 V = normalize(u_eye - v_pos);
  if (dot(n, V) < 0.0) n = -n;
  vec3 base = u_color;
  if (u_mode == 1) {
    base = (v_attr < 0.5 || on_stock_face(v_pos)) ? vec3(0.60, 0.61, 0.63) : heat(v_attr / max(u_max_attr, 1.0));
  } else if (u_mode == 5) {
    float t = clamp(abs(v_attr) / max(u_max_attr, 1e-6), 0.0, 1.0);
    base = v_attr < 0.0 ? mix(vec3(0.94, 0.60, 0.55), vec3(0.71, 0.04, 0.04), t)
                        : (v_attr > 0.0 ? mix(vec3(0.60, 0.69, 0.96), vec3(0.08, 0.20, 0.78), t) : vec3(0.55, 0.66, 0.55));
  }
  vec3 L = normalize(u_key);
  vec3 F = normalize(vec3(-u_key.x, -u_key.y, 0.35));  // fill from the opposite side
  float d = max(dot(n, L), 0.0), f = max(dot(n, F), 0.0);
  vec3 H = normalize(L + V);
  // Specular ~ (n·h)^32 by squaring (cheaper than pow() on a software rasteriser).
  float s = max(dot(n, H), 0.0);
  s *= s; s *= s; s *= s; s *= s; s *= s;
  vec3 c = base * (0.30 + 0.64 * d + 0.22 * f) + vec3(0.3 * s);
  o_col = vec4(c, 1.0);
})";

glm::mat4 to_f(const glm::dmat4& m) { return glm::mat4(m); }

// Frame on a tool: +Z of the model along the tool axis.
glm::dmat4 tool_frame(const geom::Pose& p) {
  glm::dvec3 a{p.axis.x, p.axis.y, p.axis.z};
  if (glm::length(a) < 1e-9) a = {0, 0, 1};
  a = glm::normalize(a);
  const glm::dvec3 ref = std::abs(a.z) < 0.9 ? glm::dvec3(0, 0, 1) : glm::dvec3(1, 0, 0);
  const glm::dvec3 x = glm::normalize(glm::cross(ref, a)), y = glm::cross(a, x);
  glm::dmat4 m(1.0);
  m[0] = glm::dvec4(x, 0);
  m[1] = glm::dvec4(y, 0);
  m[2] = glm::dvec4(a, 0);
  m[3] = glm::dvec4(p.tip.x, p.tip.y, p.tip.z, 1);
  return m;
}

glm::vec3 region_color(int r) {
  // Well-spread hues, alternating lightness so that neighbours differ.
  const float h = std::fmod(static_cast<float>(r) * 0.61803398f, 1.0f);
  const float l = ((r % 2) == 0) ? 0.75f : 0.55f;
  const glm::vec3 k = glm::clamp(glm::abs(glm::mod(h * 6.0f + glm::vec3(0, 4, 2), 6.0f) - 3.0f) - 1.0f, 0.0f, 1.0f);
  return l * (0.35f + 0.65f * k);
}

}  // namespace

ColorMode parse_color_mode(const std::string& s) {
  if (s == "plain") return ColorMode::Plain;
  if (s == "heat") return ColorMode::Heat;
  if (s == "regions") return ColorMode::Regions;
  if (s == "deviation") return ColorMode::Deviation;
  throw std::invalid_argument("unknown colour mode '" + s + "' (expected plain, heat, regions or deviation)");
}

std::array<std::uint8_t, 3> deviation_rgb(float d_mm, float scale_mm) noexcept {
  // As kMeshFs's mode 5: light (0.94, 0.60, 0.55) to deep (0.71, 0.04, 0.04) red, light
  // (0.60, 0.69, 0.96) to deep (0.08, 0.20, 0.78) blue, within (0.55, 0.66, 0.55).
  if (d_mm == 0.0f) return {140, 168, 140};
  const float t = std::clamp(std::fabs(d_mm) / std::max(scale_mm, 1e-6f), 0.0f, 1.0f);
  auto mix = [t](float a, float b) { return static_cast<std::uint8_t>(std::lround(255.0f * (a + (b - a) * t))); };
  if (d_mm < 0.0f) return {mix(0.94f, 0.71f), mix(0.60f, 0.04f), mix(0.55f, 0.04f)};
  return {mix(0.60f, 0.08f), mix(0.69f, 0.20f), mix(0.96f, 0.78f)};
}

std::vector<LegendRow> deviation_legend(double scale_mm) {
  const auto s = static_cast<float>(scale_mm);
  char buf[64];
  std::vector<LegendRow> rows;
  auto row = [&](float d, const char* fmt, double v) {
    std::snprintf(buf, sizeof buf, fmt, v);
    rows.push_back({deviation_rgb(d, s), buf});
  };
  row(-s, "gouge >= %.3f mm", scale_mm);
  row(-0.5f * s, "gouge    %.3f mm", 0.5 * scale_mm);
  row(0.0f, "within tolerance %.3f mm", scale_mm / kDeviationScalePerTolerance);
  row(0.5f * s, "excess   %.3f mm", 0.5 * scale_mm);
  row(s, "excess >= %.3f mm", scale_mm);
  return rows;
}

const char* to_string(ColorMode m) noexcept {
  switch (m) {
    case ColorMode::Plain: return "plain";
    case ColorMode::Heat: return "heat";
    case ColorMode::Regions: return "regions";
    case ColorMode::Deviation: return "deviation";
  }
  return "?";
}

struct Renderer::Gl {
  struct Region {
    GLuint vao = 0, vbo[3] = {0, 0, 0}, ebo = 0;
    GLsizei count = 0;
    std::uint64_t generation = ~std::uint64_t{0};
    std::uint64_t uploads = 0;
    bool deviation = false;  // the attribute buffer holds deviations, not move ids
  };
  GLuint prog = 0;
  GLint u_vp = -1, u_model = -1, u_mode = -1, u_color = -1, u_max_attr = -1, u_eye = -1, u_key = -1, u_lo = -1,
        u_hi = -1, u_clip = -1, u_section = -1;
  std::vector<Region> regions;
  GLuint cyl_vao = 0, cyl_vbo[3] = {0, 0, 0}, cyl_ebo = 0;
  GLsizei cyl_count = 0;
  GLuint path_vao = 0, path_vbo = 0;
  GLuint box_vao = 0, box_vbo = 0;
  GLsizei path_count = 0;
  GLuint fbo = 0, fbo_color = 0, fbo_depth = 0;
  int fbo_w = 0, fbo_h = 0;
  std::unique_ptr<detail::Hud> hud;

  ~Gl() {
    for (Region& r : regions) {
      glDeleteBuffers(3, r.vbo);
      glDeleteBuffers(1, &r.ebo);
      glDeleteVertexArrays(1, &r.vao);
    }
    glDeleteBuffers(3, cyl_vbo);
    glDeleteBuffers(1, &cyl_ebo);
    glDeleteVertexArrays(1, &cyl_vao);
    glDeleteBuffers(1, &path_vbo);
    glDeleteVertexArrays(1, &path_vao);
    glDeleteBuffers(1, &box_vbo);
    glDeleteVertexArrays(1, &box_vao);
    if (fbo) {
      glDeleteFramebuffers(1, &fbo);
      glDeleteRenderbuffers(1, &fbo_color);
      glDeleteRenderbuffers(1, &fbo_depth);
    }
    glDeleteProgram(prog);
  }

  static void make_vao(GLuint& vao, GLuint* vbo, GLuint& ebo) {
    glGenVertexArrays(1, &vao);
    glGenBuffers(3, vbo);
    glGenBuffers(1, &ebo);
    glBindVertexArray(vao);
    const GLint sizes[3] = {3, 3, 1};
    for (GLuint a = 0; a < 3; ++a) {
      glBindBuffer(GL_ARRAY_BUFFER, vbo[a]);
      glEnableVertexAttribArray(a);
      glVertexAttribPointer(a, sizes[a], GL_FLOAT, GL_FALSE, 0, nullptr);
    }
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ebo);
    glBindVertexArray(0);
  }

  static void upload(GLuint vao, const GLuint* vbo, GLuint ebo, const std::vector<float>& pos, const std::vector<float>& nrm,
                     const std::vector<float>& attr, const std::vector<std::uint32_t>& idx) {
    glBindVertexArray(vao);
    const std::vector<float>* src[3] = {&pos, &nrm, &attr};
    for (int a = 0; a < 3; ++a) {
      glBindBuffer(GL_ARRAY_BUFFER, vbo[a]);
      glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(src[a]->size() * sizeof(float)), src[a]->data(),
                   GL_STATIC_DRAW);
    }
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ebo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(idx.size() * sizeof(std::uint32_t)), idx.data(),
                 GL_STATIC_DRAW);
    glBindVertexArray(0);
  }

  void make_cylinder() {
    // Unit cylinder r = 1, z in [0, 1], with caps; smooth side normals.
    constexpr int n = 40;
    std::vector<float> pos, nrm, attr;
    std::vector<std::uint32_t> idx;
    auto vert = [&](float x, float y, float z, float nx, float ny, float nz) {
      pos.insert(pos.end(), {x, y, z});
      nrm.insert(nrm.end(), {nx, ny, nz});
      attr.push_back(0);
      return static_cast<std::uint32_t>(attr.size() - 1);
    };
    for (int i = 0; i < n; ++i) {
      const float a0 = 6.2831853f * static_cast<float>(i) / n, a1 = 6.2831853f * static_cast<float>(i + 1) / n;
      const float c0 = std::cos(a0), s0 = std::sin(a0), c1 = std::cos(a1), s1 = std::sin(a1);
      const auto b0 = vert(c0, s0, 0, c0, s0, 0), b1 = vert(c1, s1, 0, c1, s1, 0);
      const auto t0 = vert(c0, s0, 1, c0, s0, 0), t1 = vert(c1, s1, 1, c1, s1, 0);
      idx.insert(idx.end(), {b0, b1, t1, b0, t1, t0});
      const auto bc = vert(0, 0, 0, 0, 0, -1), bb0 = vert(c0, s0, 0, 0, 0, -1), bb1 = vert(c1, s1, 0, 0, 0, -1);
      idx.insert(idx.end(), {bc, bb1, bb0});
      const auto tc = vert(0, 0, 1, 0, 0, 1), tt0 = vert(c0, s0, 1, 0, 0, 1), tt1 = vert(c1, s1, 1, 0, 0, 1);
      idx.insert(idx.end(), {tc, tt0, tt1});
    }
    make_vao(cyl_vao, cyl_vbo, cyl_ebo);
    upload(cyl_vao, cyl_vbo, cyl_ebo, pos, nrm, attr, idx);
    cyl_count = static_cast<GLsizei>(idx.size());
  }

  void ensure_fbo(int w, int h) {
    if (fbo && fbo_w == w && fbo_h == h) return;
    if (!fbo) {
      glGenFramebuffers(1, &fbo);
      glGenRenderbuffers(1, &fbo_color);
      glGenRenderbuffers(1, &fbo_depth);
    }
    glBindRenderbuffer(GL_RENDERBUFFER, fbo_color);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, w, h);
    glBindRenderbuffer(GL_RENDERBUFFER, fbo_depth);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, w, h);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, fbo_color);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, fbo_depth);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw std::runtime_error("gfx: offscreen framebuffer " + std::to_string(w) + "x" + std::to_string(h) +
                               " is incomplete");
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    fbo_w = w;
    fbo_h = h;
  }
};

Renderer::Renderer(const geom::LbrSolid& initial, const RenderOptions& opt)
    : opt_(opt), mirror_(initial, opt.mesh), gl_(std::make_unique<Gl>()) {
  Gl& g = *gl_;
  g.prog = detail::make_program(kMeshVs, kMeshFs, "mesh");
  g.u_vp = glGetUniformLocation(g.prog, "u_vp");
  g.u_model = glGetUniformLocation(g.prog, "u_model");
  g.u_mode = glGetUniformLocation(g.prog, "u_mode");
  g.u_color = glGetUniformLocation(g.prog, "u_color");
  g.u_max_attr = glGetUniformLocation(g.prog, "u_max_attr");
  g.u_eye = glGetUniformLocation(g.prog, "u_eye");
  g.u_key = glGetUniformLocation(g.prog, "u_key");
  g.u_lo = glGetUniformLocation(g.prog, "u_stock_lo");
  g.u_hi = glGetUniformLocation(g.prog, "u_stock_hi");
  g.u_clip = glGetUniformLocation(g.prog, "u_clip");
  g.u_section = glGetUniformLocation(g.prog, "u_section");
  g.regions.resize(static_cast<std::size_t>(mirror_.regions()));
  for (Gl::Region& r : g.regions) Gl::make_vao(r.vao, r.vbo, r.ebo);
  g.make_cylinder();
  glGenVertexArrays(1, &g.path_vao);
  glGenBuffers(1, &g.path_vbo);
  glBindVertexArray(g.path_vao);
  glBindBuffer(GL_ARRAY_BUFFER, g.path_vbo);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  glVertexAttrib3f(1, 0, 0, 1);
  glVertexAttrib1f(2, 0);
  glBindVertexArray(0);
  g.hud = std::make_unique<detail::Hud>();
  limit_ = std::max(1, std::min(opt_.max_regions_per_frame, 4));
  for (int r = 0; r < mirror_.regions(); ++r)
    for (float a : mirror_.meshes().region(r).attributes) last_move_ = std::max(last_move_, static_cast<geom::MoveId>(a));
}

Renderer::~Renderer() = default;

geom::Box3 Renderer::stock_box() const noexcept {
  const geom::LbrSolid& s = mirror_.solid();
  const geom::Rect r = s.stock_rect();
  geom::Box3 b;
  b.add({geom::to_mm(r.x0), geom::to_mm(r.y0), s.z_bottom_mm()});
  b.add({geom::to_mm(r.x1), geom::to_mm(r.y1), s.z_top_mm()});
  return b;
}

std::uint64_t Renderer::uploads(int region) const noexcept { return gl_->regions[static_cast<std::size_t>(region)].uploads; }

void Renderer::receive(Snapshot& s) {
  mirror_.receive(s);
  set_tools(std::span<const ToolState>(s.tools.data(), static_cast<std::size_t>(s.tool_count)));
  for (const geom::Vec3& p : s.path) path_.push_back(p);
  while (path_.size() > opt_.path_points) path_.pop_front();
  if (!s.path.empty()) path_changed_ = true;
  s.path.clear();
  last_move_ = std::max(last_move_, s.last_move);
  live_ = s.stats;
  version_ = s.version;
}

void Renderer::set_tools(std::span<const ToolState> tools) {
  tool_count_ = static_cast<int>(std::min<std::size_t>(tools.size(), kMaxTools));
  for (int i = 0; i < tool_count_; ++i) tools_[static_cast<std::size_t>(i)] = tools[static_cast<std::size_t>(i)];
}

void Renderer::set_path(std::span<const geom::Vec3> pts) {
  path_.assign(pts.begin(), pts.end());
  while (path_.size() > opt_.path_points) path_.pop_front();
  path_changed_ = true;
}

FrameInfo Renderer::frame(const Camera& cam, int w, int h) {
  using clock = std::chrono::steady_clock;
  FrameInfo fi;
  fi.version = version_;
  const double aspect = static_cast<double>(w) / std::max(h, 1);
  const glm::dmat4 vp = cam.projection(aspect) * cam.view();
  cull(vp, fi);
  rebuild_visible(fi);
  const auto t1 = clock::now();
  upload_changed(fi);
  if (path_changed_ && opt_.show_path) upload_path();
  const auto t2 = clock::now();
  fi.upload_ms = std::chrono::duration<double, std::milli>(t2 - t1).count();
  draw_stock(cam, vp, w, h, fi);
  glDisable(GL_CULL_FACE);
  if (opt_.show_tools) draw_tools();
  if (opt_.show_path && gl_->path_count > 1) draw_path();
  if (opt_.show_outline) draw_outline();
  glBindVertexArray(0);
  if (opt_.show_hud) draw_hud(w, h);
  if (opt_.show_legend && opt_.color == ColorMode::Deviation && opt_.deviation) draw_legend(w, h);
  fi.draw_ms = std::chrono::duration<double, std::milli>(clock::now() - t2).count();
  last_ = fi;
  return fi;
}

// Regions inside the view frustum.
void Renderer::cull(const glm::dmat4& vp, FrameInfo& fi) {
  const Frustum fr(vp);
  visible_.assign(static_cast<std::size_t>(mirror_.regions()), 0);
  for (int r = 0; r < mirror_.regions(); ++r) {
    visible_[static_cast<std::size_t>(r)] = fr.intersects(mirror_.region_box(r)) ? 1 : 0;
    fi.regions_visible += visible_[static_cast<std::size_t>(r)];
  }
}

// Bounded rebuild of visible pending regions; the limit adapts to the time budget.
void Renderer::rebuild_visible(FrameInfo& fi) {
  fi.region_limit = limit_;
  fi.step = mirror_.step([&](int r) { return visible_[static_cast<std::size_t>(r)] != 0; }, limit_);
  if (fi.step.regions_applied > 0) {
    if (fi.step.mesh_ms > opt_.mesh_budget_ms) limit_ = std::max(1, limit_ / 2);
    else if (fi.step.mesh_ms < 0.5 * opt_.mesh_budget_ms && fi.step.regions_applied >= limit_)
      limit_ = std::min(std::max(opt_.max_regions_per_frame, 1), limit_ + 1);
  }
}

// Uploads the regions whose buffers changed.
void Renderer::upload_changed(FrameInfo& fi) {
  for (int r = 0; r < mirror_.regions(); ++r) {
    Gl::Region& gr = gl_->regions[static_cast<std::size_t>(r)];
    const mesh::MeshBuffers& mb = mirror_.meshes().region(r);
    const bool deviation = opt_.color == ColorMode::Deviation && opt_.deviation;
    if (gr.generation == mb.generation && gr.deviation == deviation) continue;
    // Joined walls keep zero-area triangles for the mesh's edge identities (docs/mesh.md
    // §2); they draw nothing, so they are left out of the GPU index buffer.
    upload_idx_.clear();
    upload_idx_.reserve(mb.indices.size());
    const float* P = mb.positions.data();
    for (std::size_t i = 0; i + 2 < mb.indices.size(); i += 3) {
      const std::uint32_t a = mb.indices[i], b = mb.indices[i + 1], c = mb.indices[i + 2];
      const glm::vec3 pa(P[3 * a], P[3 * a + 1], P[3 * a + 2]), pb(P[3 * b], P[3 * b + 1], P[3 * b + 2]),
          pc(P[3 * c], P[3 * c + 1], P[3 * c + 2]);
      const glm::vec3 n = glm::cross(pb - pa, pc - pa);
      if (glm::dot(n, n) <= 1e-14f) continue;  // area below 5e-8 mm²
      upload_idx_.insert(upload_idx_.end(), {a, b, c});
    }
    if (deviation) opt_.deviation(mb, deviation_);
    Gl::upload(gr.vao, gr.vbo, gr.ebo, mb.positions, mb.normals, deviation ? deviation_ : mb.attributes, upload_idx_);
    gr.deviation = deviation;
    gr.count = static_cast<GLsizei>(upload_idx_.size());
    gr.generation = mb.generation;
    ++gr.uploads;
    ++fi.regions_uploaded;
  }
}

void Renderer::upload_path() {
  Gl& g = *gl_;
  std::vector<float> pts;
  pts.reserve(path_.size() * 3);
  for (const geom::Vec3& p : path_) pts.insert(pts.end(), {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)});
  glBindBuffer(GL_ARRAY_BUFFER, g.path_vbo);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(pts.size() * sizeof(float)), pts.data(), GL_STREAM_DRAW);
  g.path_count = static_cast<GLsizei>(path_.size());
  path_changed_ = false;
}

// Clears the framebuffer and draws the visible regions of the stock.
void Renderer::draw_stock(const Camera& cam, const glm::dmat4& vp, int w, int h, FrameInfo& fi) {
  Gl& g = *gl_;
  glViewport(0, 0, w, h);
  glClearColor(0.13f, 0.14f, 0.17f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);
  // The stock's surface is closed and counter-clockwise from outside (docs/mesh.md), so
  // back faces are never visible: culling them halves the rasteriser's work (llvmpipe).
  glEnable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  glFrontFace(GL_CCW);
  glUseProgram(g.prog);
  set_scene_uniforms(cam, vp);
  set_section();
  int mode = opt_.color == ColorMode::Plain ? 0 : (opt_.color == ColorMode::Heat ? 1 : 2);
  if (opt_.color == ColorMode::Deviation) mode = opt_.deviation ? 5 : 0;
  glUniform1i(g.u_mode, mode);
  glUniform3f(g.u_color, 0.66f, 0.68f, 0.71f);
  for (int r = 0; r < mirror_.regions(); ++r) {
    const Gl::Region& gr = g.regions[static_cast<std::size_t>(r)];
    if (!visible_[static_cast<std::size_t>(r)] || gr.count == 0) continue;
    if (mode == 2) {
      const glm::vec3 c = region_color(r);
      glUniform3fv(g.u_color, 1, glm::value_ptr(c));
    }
    glBindVertexArray(gr.vao);
    glDrawElements(GL_TRIANGLES, gr.count, GL_UNSIGNED_INT, nullptr);
    fi.triangles += static_cast<std::uint64_t>(gr.count / 3);
  }
  glDisable(GL_CLIP_DISTANCE0);  // tools and path are not cut
  glUniform1i(g.u_section, 0);
}

// The section plane (RenderOptions::section_axis): clips the stock, and shows its back
// faces (the inside seen through the cut) as the filled cut face, so culling is off.
void Renderer::set_section() {
  Gl& g = *gl_;
  const int axis = opt_.section_axis;
  if (axis < 0 || axis > 2) {
    glUniform4f(g.u_clip, 0, 0, 0, 1);
    glUniform1i(g.u_section, 0);
    return;
  }
  // Keep the side below the plane (x <= pos), or above it when flipped.
  const float sgn = opt_.section_flip ? 1.0f : -1.0f;
  glm::vec4 plane(0.0f);
  plane[axis] = sgn;
  plane.w = -sgn * static_cast<float>(opt_.section_mm);
  glUniform4fv(g.u_clip, 1, glm::value_ptr(plane));
  glUniform1i(g.u_section, 1);
  glEnable(GL_CLIP_DISTANCE0);
  glDisable(GL_CULL_FACE);
}

// Camera, light and colour-scale uniforms shared by everything drawn this frame.
void Renderer::set_scene_uniforms(const Camera& cam, const glm::dmat4& vp) {
  Gl& g = *gl_;
  const glm::mat4 vpf = to_f(vp);
  glUniformMatrix4fv(g.u_vp, 1, GL_FALSE, glm::value_ptr(vpf));
  const glm::mat4 ident(1.0f);
  glUniformMatrix4fv(g.u_model, 1, GL_FALSE, glm::value_ptr(ident));
  const glm::vec3 eye(cam.eye());
  glUniform3fv(g.u_eye, 1, glm::value_ptr(eye));
  // Key light from above-left of the viewer, fixed to the camera so every view is lit.
  const glm::dvec3 fwd = glm::normalize(cam.target - cam.eye()), up = cam.up();
  const glm::dvec3 right = glm::normalize(glm::cross(fwd, up));
  const glm::vec3 key(glm::normalize(-fwd + 0.6 * up - 0.45 * right));
  glUniform3fv(g.u_key, 1, glm::value_ptr(key));
  const geom::Box3 sb = stock_box();
  glUniform3f(g.u_lo, static_cast<float>(sb.lo.x), static_cast<float>(sb.lo.y), static_cast<float>(sb.lo.z));
  glUniform3f(g.u_hi, static_cast<float>(sb.hi.x), static_cast<float>(sb.hi.y), static_cast<float>(sb.hi.z));
  // Heat: the newest move id; deviation: the colours' scale [mm].
  glUniform1f(g.u_max_attr, opt_.color == ColorMode::Deviation ? static_cast<float>(opt_.deviation_scale_mm)
                                                               : static_cast<float>(std::max<geom::MoveId>(last_move_, 1)));
}

// Each tool as three cylinders (flutes, shank, holder) in its pose.
void Renderer::draw_tools() {
  Gl& g = *gl_;
  glUniform1i(g.u_mode, 3);
  glBindVertexArray(g.cyl_vao);
  for (int i = 0; i < tool_count_; ++i) {
    const ToolState& t = tools_[static_cast<std::size_t>(i)];
    if (t.tool == 0 || t.radius_mm <= 0) continue;
    const glm::dmat4 f = tool_frame(t.pose);
    struct Part {
      double z0, z1, r;
      glm::vec3 c;
    };
    const Part parts[3] = {
        {0, t.flute_mm, t.radius_mm, {0.85f, 0.55f, 0.20f}},
        {t.flute_mm, t.length_mm, t.radius_mm * 0.92, {0.70f, 0.71f, 0.74f}},
        {t.length_mm, t.length_mm + t.holder_length_mm, t.holder_radius_mm, {0.30f, 0.32f, 0.36f}}};
    for (const Part& p : parts) {
      if (p.z1 <= p.z0 || p.r <= 0) continue;
      const glm::dmat4 m = glm::scale(glm::translate(f, glm::dvec3(0, 0, p.z0)), glm::dvec3(p.r, p.r, p.z1 - p.z0));
      const glm::mat4 mf = to_f(m);
      glUniformMatrix4fv(g.u_model, 1, GL_FALSE, glm::value_ptr(mf));
      glUniform3fv(g.u_color, 1, glm::value_ptr(p.c));
      glDrawElements(GL_TRIANGLES, g.cyl_count, GL_UNSIGNED_INT, nullptr);
    }
  }
  const glm::mat4 ident(1.0f);
  glUniformMatrix4fv(g.u_model, 1, GL_FALSE, glm::value_ptr(ident));
}

// The stock box's twelve edges (operator UI "Stock"), unlit.
void Renderer::draw_outline() {
  Gl& g = *gl_;
  if (g.box_vao == 0) {
    glGenVertexArrays(1, &g.box_vao);
    glGenBuffers(1, &g.box_vbo);
    glBindVertexArray(g.box_vao);
    glBindBuffer(GL_ARRAY_BUFFER, g.box_vbo);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  }
  const geom::Box3 b = stock_box();
  const float x[2] = {static_cast<float>(b.lo.x), static_cast<float>(b.hi.x)};
  const float y[2] = {static_cast<float>(b.lo.y), static_cast<float>(b.hi.y)};
  const float z[2] = {static_cast<float>(b.lo.z), static_cast<float>(b.hi.z)};
  std::array<float, 72> v{};
  std::size_t n = 0;
  auto edge = [&](int i0, int j0, int k0, int i1, int j1, int k1) {
    for (float c : {x[i0], y[j0], z[k0], x[i1], y[j1], z[k1]}) v[n++] = c;
  };
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      edge(i, j, 0, i, j, 1);  // along Z
      edge(i, 0, j, i, 1, j);  // along Y
      edge(0, i, j, 1, i, j);  // along X
    }
  glBindVertexArray(g.box_vao);
  glBindBuffer(GL_ARRAY_BUFFER, g.box_vbo);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(sizeof v), v.data(), GL_STREAM_DRAW);
  glVertexAttrib3f(1, 0, 0, 1);
  glVertexAttrib1f(2, 0);
  glUniform1i(g.u_mode, 4);
  glUniform3f(g.u_color, 0.35f, 0.75f, 1.0f);
  glDrawArrays(GL_LINES, 0, 24);
}

void Renderer::draw_path() {
  Gl& g = *gl_;
  glUniform1i(g.u_mode, 4);
  glUniform3f(g.u_color, 1.0f, 0.85f, 0.2f);
  glBindVertexArray(g.path_vao);
  glDrawArrays(GL_LINE_STRIP, 0, g.path_count);
}

// The HUD text: the previous frame's figures, the live source's counters, the notice.
void Renderer::draw_hud(int w, int h) {
  char buf[1024];
  const LiveStats& L = live_;
  int n = std::snprintf(buf, sizeof buf,
                        "frame %.1f ms  period %.1f ms (p99 %.1f)  target %.0f Hz  late %llu\n"
                        "triangles %llu  regions rebuilt %d (applied %d, pending %d, limit %d)  mesh %.1f ms\n"
                        "view: %s colour  version %llu  last move %u\n",
                        pacing_.frame_ms, pacing_.period_ms, pacing_.p99_period_ms, pacing_.rate_hz,
                        static_cast<unsigned long long>(pacing_.late_frames), static_cast<unsigned long long>(last_.triangles),
                        last_.step.regions_rebuilt, last_.step.regions_applied, last_.step.regions_pending,
                        last_.region_limit, last_.step.mesh_ms, to_string(opt_.color),
                        static_cast<unsigned long long>(version_), last_move_);
  if (n > 0 && n < static_cast<int>(sizeof buf)) {
    if (L.live)
      std::snprintf(buf + n, sizeof buf - static_cast<std::size_t>(n),
                    "lag %.1f ms  samples %.0f Hz  ring hw %llu/%llu  overruns %llu  decode errors %llu\n"
                    "behind: coalesced %llu  held %llu\n"
                    "%s\n",
                    L.lag_ms, L.sample_rate_hz, static_cast<unsigned long long>(L.ring_high_water),
                    static_cast<unsigned long long>(L.ring_capacity), static_cast<unsigned long long>(L.ring_overruns),
                    static_cast<unsigned long long>(L.decode_errors), static_cast<unsigned long long>(L.samples_coalesced),
                    static_cast<unsigned long long>(L.samples_held), L.realtime ? "RT (SCHED_FIFO)" : "non-RT");
    else
      std::snprintf(buf + n, sizeof buf - static_cast<std::size_t>(n), "no live source (batch result)\n");
  }
  if (!opt_.notice.empty()) {
    const std::size_t used = std::strlen(buf);
    std::snprintf(buf + used, sizeof buf - used, "WARNING: %s\n", opt_.notice.c_str());
  }
  if (!opt_.design.empty()) {
    const std::size_t used = std::strlen(buf);
    std::snprintf(buf + used, sizeof buf - used, "DESIGN: %s\n", opt_.design.c_str());
  }
  gl_->hud->draw(buf, w, h);
  draw_alarms(w, h);
}

// The live alarms (collision events) on a red band across the bottom, as the operator UI's
// status bar shows them (docs/ui.md).
void Renderer::draw_alarms(int w, int h) {
  const LiveStats& L = live_;
  const int n = std::min(L.alarm_count, kMaxAlarms);
  if (n <= 0) return;
  char buf[kMaxAlarms * (kAlarmTextChars + 16)];
  std::size_t used = 0;
  buf[0] = '\0';
  for (int i = 0; i < n; ++i) {
    const Alarm& a = L.alarms[static_cast<std::size_t>(i)];
    const char* tag = a.severity == AlarmSeverity::Error ? "ALARM" : (a.severity == AlarmSeverity::Warning ? "WARNING" : "INFO");
    const int k = std::snprintf(buf + used, sizeof buf - used, "%s%s: %s", i > 0 ? "\n" : "", tag, a.text.data());
    if (k < 0 || static_cast<std::size_t>(k) >= sizeof buf - used) break;
    used += static_cast<std::size_t>(k);
  }
  gl_->hud->draw_alarm_band(buf, w, h);
}

// The deviation colours' legend at the right edge (deviation_legend()), smaller than the HUD.
void Renderer::draw_legend(int w, int h) {
  std::string text;
  std::vector<std::array<std::uint8_t, 3>> swatches;
  for (const LegendRow& r : deviation_legend(opt_.deviation_scale_mm)) {
    text += (text.empty() ? "" : "\n") + r.text;
    swatches.push_back(r.rgb);
  }
  gl_->hud->draw_legend(text, swatches, w, h, 1.5f);
}

FrameInfo Renderer::frame_offscreen(const Camera& cam, int w, int h) {
  gl_->ensure_fbo(w, h);
  glBindFramebuffer(GL_FRAMEBUFFER, gl_->fbo);
  const FrameInfo fi = frame(cam, w, h);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  return fi;
}

Image Renderer::render_offscreen(const Camera& cam, int w, int h, bool with_depth, FrameInfo* info) {
  Gl& g = *gl_;
  g.ensure_fbo(w, h);
  glBindFramebuffer(GL_FRAMEBUFFER, g.fbo);
  const FrameInfo fi = frame(cam, w, h);
  if (info) *info = fi;
  Image img;
  img.width = w;
  img.height = h;
  std::vector<std::uint8_t> raw(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, raw.data());
  img.rgba.resize(raw.size());
  const std::size_t row = static_cast<std::size_t>(w) * 4;
  for (int y = 0; y < h; ++y)
    std::copy_n(raw.data() + static_cast<std::size_t>(h - 1 - y) * row, row, img.rgba.data() + static_cast<std::size_t>(y) * row);
  if (with_depth) {
    std::vector<float> d(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
    glReadPixels(0, 0, w, h, GL_DEPTH_COMPONENT, GL_FLOAT, d.data());
    img.depth.resize(d.size());
    const std::size_t wr = static_cast<std::size_t>(w);
    for (int y = 0; y < h; ++y)
      std::copy_n(d.data() + static_cast<std::size_t>(h - 1 - y) * wr, wr, img.depth.data() + static_cast<std::size_t>(y) * wr);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  return img;
}

void write_png(const std::string& path, const Image& img) {
  if (img.width <= 0 || img.height <= 0 || img.rgba.size() != static_cast<std::size_t>(img.width) * img.height * 4)
    throw std::runtime_error("write_png: bad image for " + path);
  if (!stbi_write_png(path.c_str(), img.width, img.height, 4, img.rgba.data(), img.width * 4))
    throw std::runtime_error("cannot write PNG " + path);
}

}  // namespace lbr::gfx
