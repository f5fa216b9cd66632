// STL reading and writing (verify/stl.hpp).
#include "verify/stl.hpp"

#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include "geom/units.hpp"

namespace lbr::verify {

namespace {

constexpr std::size_t kHeaderBytes = 84, kTriangleBytes = 50;

// A coordinate the kernel can hold: finite and within geom's safe range (±107 m). NaN, inf
// and huge values were accepted before and reached the slicer (found by fuzz_stl).
bool usable(double v) noexcept { return std::isfinite(v) && std::abs(v) <= geom::kSafeRangeMm; }
std::string range_text() { return "a finite coordinate within ±" + std::to_string(static_cast<long>(geom::kSafeRangeMm)) + " mm"; }

float read_f32(const char* p) noexcept {
  float f;
  std::memcpy(&f, p, 4);  // little-endian hosts only (x86-64, aarch64)
  return f;
}

StlMesh parse_binary(std::string_view b, const std::string& name) {
  std::uint32_t n = 0;
  std::memcpy(&n, b.data() + 80, 4);
  StlMesh m;
  m.triangles.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::size_t at = kHeaderBytes + std::size_t{i} * kTriangleBytes + 12;  // skip the normal
    for (int k = 0; k < 3; ++k) {
      geom::Vec3& v = m.triangles[i].v[k];
      v = {read_f32(b.data() + at + 12 * k), read_f32(b.data() + at + 12 * k + 4), read_f32(b.data() + at + 12 * k + 8)};
      if (!usable(v.x) || !usable(v.y) || !usable(v.z))
        throw StlError(name + ": at byte " + std::to_string(at + 12 * k) + ": triangle " + std::to_string(i + 1) +
                       ", vertex " + std::to_string(k + 1) + ": expected " + range_text());
    }
  }
  return m;
}

// Whitespace-separated words of an ASCII STL with their line numbers.
class Words {
 public:
  explicit Words(std::string_view s) : s_(s) {}
  bool next(std::string_view& w) {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_])) != 0) line_ += s_[pos_++] == '\n' ? 1 : 0;
    if (pos_ >= s_.size()) return false;
    const std::size_t b = pos_;
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_])) == 0) ++pos_;
    w = s_.substr(b, pos_ - b);
    return true;
  }
  void skip_line() {
    while (pos_ < s_.size() && s_[pos_] != '\n') ++pos_;
  }
  [[nodiscard]] int line() const noexcept { return line_; }

 private:
  std::string_view s_;
  std::size_t pos_ = 0;
  int line_ = 1;
};

void expect(Words& w, std::string_view want, const std::string& name) {
  std::string_view got;
  if (!w.next(got) || got != want)
    throw StlError(name + ":" + std::to_string(w.line()) + ": expected '" + std::string(want) + "', found '" +
                   std::string(got) + "'");
}

double number(Words& w, const std::string& name) {
  std::string_view s;
  double v = 0.0;
  if (!w.next(s) || std::from_chars(s.data(), s.data() + s.size(), v).ec != std::errc{})
    throw StlError(name + ":" + std::to_string(w.line()) + ": expected a number, found '" + std::string(s) + "'");
  return v;
}

double coordinate(Words& w, const std::string& name) {
  const double v = number(w, name);
  if (!usable(v)) throw StlError(name + ":" + std::to_string(w.line()) + ": expected " + range_text());
  return v;
}

StlMesh parse_ascii(std::string_view s, const std::string& name) {
  Words w(s);
  expect(w, "solid", name);
  w.skip_line();  // the solid's name
  StlMesh m;
  std::string_view word;
  while (w.next(word)) {
    if (word == "endsolid") return m;
    if (word != "facet")
      throw StlError(name + ":" + std::to_string(w.line()) + ": expected 'facet' or 'endsolid', found '" +
                     std::string(word) + "'");
    expect(w, "normal", name);
    for (int k = 0; k < 3; ++k) (void)number(w, name);
    expect(w, "outer", name);
    expect(w, "loop", name);
    Triangle t;
    for (geom::Vec3& v : t.v) {
      expect(w, "vertex", name);
      v.x = coordinate(w, name);
      v.y = coordinate(w, name);
      v.z = coordinate(w, name);
    }
    expect(w, "endloop", name);
    expect(w, "endfacet", name);
    m.triangles.push_back(t);
  }
  throw StlError(name + ":" + std::to_string(w.line()) + ": expected 'endsolid' before the end of the file");
}

}  // namespace

geom::Box3 StlMesh::bounds() const noexcept {
  geom::Box3 b;
  for (const Triangle& t : triangles)
    for (const geom::Vec3& v : t.v) b.add(v);
  return b;
}

double StlMesh::volume_mm3() const noexcept {
  double six_v = 0.0;
  for (const Triangle& t : triangles) six_v += geom::dot(t.v[0], geom::cross(t.v[1], t.v[2]));
  return six_v / 6.0;
}

StlMesh parse_stl(std::string_view bytes, const std::string& name) {
  if (bytes.size() >= kHeaderBytes) {
    std::uint32_t n = 0;
    std::memcpy(&n, bytes.data() + 80, 4);
    if (bytes.size() == kHeaderBytes + std::size_t{n} * kTriangleBytes) return parse_binary(bytes, name);
  }
  if (bytes.substr(0, 5) == "solid") return parse_ascii(bytes, name);
  throw StlError(name + ": expected an STL file: binary (84 + 50 bytes a triangle; this file has " +
                 std::to_string(bytes.size()) + " bytes) or ASCII (beginning with 'solid')");
}

StlMesh read_stl(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw StlError(path + ": cannot open the design model");
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_stl(ss.str(), path);
}

std::string stl_binary(const StlMesh& mesh) {
  std::string out(kHeaderBytes + mesh.triangles.size() * kTriangleBytes, '\0');
  std::memcpy(out.data(), "binary STL", 10);
  const auto n = static_cast<std::uint32_t>(mesh.triangles.size());
  std::memcpy(out.data() + 80, &n, 4);
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    char* p = out.data() + kHeaderBytes + i * kTriangleBytes + 12;
    for (int k = 0; k < 3; ++k) {
      const geom::Vec3& v = mesh.triangles[i].v[k];
      const std::array<float, 3> f{static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)};
      std::memcpy(p + 12 * k, f.data(), 12);
    }
  }
  return out;
}

std::string stl_ascii(const StlMesh& mesh, const std::string& solid_name) {
  std::ostringstream o;
  o.precision(9);
  o << "solid " << solid_name << '\n';
  for (const Triangle& t : mesh.triangles) {
    o << "  facet normal 0 0 0\n    outer loop\n";
    for (const geom::Vec3& v : t.v) o << "      vertex " << v.x << ' ' << v.y << ' ' << v.z << '\n';
    o << "    endloop\n  endfacet\n";
  }
  o << "endsolid " << solid_name << '\n';
  return o.str();
}

EdgeCheck check_edges(const StlMesh& mesh) {
  using Key = std::array<double, 3>;
  std::map<Key, std::size_t> ids;
  auto id = [&](const geom::Vec3& v) { return ids.emplace(Key{v.x, v.y, v.z}, ids.size()).first->second; };
  std::map<std::pair<std::size_t, std::size_t>, int> uses;
  for (const Triangle& t : mesh.triangles) {
    const std::size_t a[3] = {id(t.v[0]), id(t.v[1]), id(t.v[2])};
    for (int k = 0; k < 3; ++k) ++uses[std::minmax(a[k], a[(k + 1) % 3])];
  }
  EdgeCheck c;
  for (const auto& [edge, n] : uses) {
    if (n == 1) ++c.boundary_edges;
    if (n > 2) ++c.non_manifold_edges;
  }
  return c;
}

}  // namespace lbr::verify
