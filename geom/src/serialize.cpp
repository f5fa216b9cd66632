// LBRS level file: see docs/formats.md for the byte layout. Little-endian throughout.
#include "geom/serialize.hpp"

#include <bit>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace lbr::geom {

namespace {

static_assert(std::endian::native == std::endian::little, "the LBRS writer assumes a little-endian host");

constexpr char kMagic[4] = {'L', 'B', 'R', 'S'};
constexpr std::uint32_t kVersion = 1;

class Writer {
 public:
  std::vector<std::uint8_t> bytes;
  template <class T>
  void put(T v) {
    const auto* p = reinterpret_cast<const std::uint8_t*>(&v);
    bytes.insert(bytes.end(), p, p + sizeof(T));
  }
  void contour(const Contour& c) {
    put<std::uint32_t>(c.cut_by);
    put<std::uint32_t>(static_cast<std::uint32_t>(c.pts.size()));
    for (const Point& q : c.pts) {
      put<std::int64_t>(q.X);
      put<std::int64_t>(q.Y);
    }
  }
};

class Reader {
 public:
  explicit Reader(const std::vector<std::uint8_t>& b) : b_(b) {}
  template <class T>
  T get(const char* what) {
    if (pos_ + sizeof(T) > b_.size())
      throw std::runtime_error("LBRS: truncated at byte " + std::to_string(pos_) + " while reading " + what);
    T v;
    std::memcpy(&v, b_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  void fail(const std::string& what) const {
    throw std::runtime_error("LBRS: at byte " + std::to_string(pos_) + ": " + what);
  }
  [[nodiscard]] std::size_t pos() const { return pos_; }
  [[nodiscard]] std::size_t left() const { return b_.size() - pos_; }
  Contour contour() {
    Contour c;
    c.cut_by = get<std::uint32_t>("move id");
    const auto n = get<std::uint32_t>("vertex count");
    if (n < 3) fail("a contour needs at least 3 vertices, found " + std::to_string(n));
    if (static_cast<std::size_t>(n) * 16 > left()) fail("vertex count " + std::to_string(n) + " exceeds the file");
    c.pts.resize(n);
    for (auto& q : c.pts) {
      q.X = get<std::int64_t>("x");
      q.Y = get<std::int64_t>("y");
      if (q.X > kSafeRange || q.X < -kSafeRange || q.Y > kSafeRange || q.Y < -kSafeRange)
        fail("vertex outside the safe coordinate range");
    }
    return c;
  }

 private:
  const std::vector<std::uint8_t>& b_;
  std::size_t pos_ = 0;
};

}  // namespace

std::vector<std::uint8_t> to_bytes(const LbrSolid& s) {
  Writer w;
  const SolidSpec& sp = s.spec();
  for (char c : kMagic) w.put(c);
  w.put<std::uint32_t>(kVersion);
  w.put<std::uint32_t>(sp.shape == SolidSpec::Shape::Box ? 0 : 1);
  w.put<std::uint32_t>(sp.strictly_simple ? 1 : 0);
  w.put<std::uint32_t>(static_cast<std::uint32_t>(s.levels()));
  w.put<std::uint32_t>(static_cast<std::uint32_t>(s.regions_x()));
  w.put<std::uint32_t>(static_cast<std::uint32_t>(s.regions_y()));
  w.put<std::uint32_t>(0);
  w.put<double>(kMmPerUnit);
  w.put<double>(sp.level_spacing_mm);
  w.put<double>(sp.chord_tol_mm);
  if (sp.shape == SolidSpec::Shape::Box) {
    for (double v : {sp.box.min.x, sp.box.min.y, sp.box.min.z, sp.box.max.x, sp.box.max.y, sp.box.max.z}) w.put(v);
  } else {
    const CylinderStock& c = sp.cylinder;
    for (double v : {c.center_x_mm, c.center_y_mm, c.diameter_mm, c.z_min_mm, c.z_max_mm, 0.0}) w.put(v);
  }
  for (int r = 0; r < s.regions(); ++r) {
    for (int l = 0; l < s.levels(); ++l) {
      const Cell& c = s.cell(r, l);
      w.put<std::uint32_t>(static_cast<std::uint32_t>(c.polys.size()));
      for (const Polygon& p : c.polys) {
        w.put<std::uint32_t>(static_cast<std::uint32_t>(p.holes.size()));
        w.contour(p.outer);
        for (const Contour& h : p.holes) w.contour(h);
      }
    }
  }
  return std::move(w.bytes);
}

LbrSolid from_bytes(const std::vector<std::uint8_t>& bytes) {
  Reader r(bytes);
  for (char c : kMagic)
    if (r.get<char>("magic") != c) r.fail("not an LBRS file (magic \"LBRS\" expected)");
  const auto version = r.get<std::uint32_t>("version");
  if (version != kVersion) r.fail("unsupported version " + std::to_string(version) + " (expected 1)");
  SolidSpec sp;
  const auto shape = r.get<std::uint32_t>("shape");
  if (shape > 1) r.fail("shape must be 0 (box) or 1 (cylinder)");
  sp.shape = shape == 0 ? SolidSpec::Shape::Box : SolidSpec::Shape::Cylinder;
  sp.strictly_simple = (r.get<std::uint32_t>("flags") & 1u) != 0;
  const auto levels = r.get<std::uint32_t>("levels");
  sp.regions_x = static_cast<int>(r.get<std::uint32_t>("regions_x"));
  sp.regions_y = static_cast<int>(r.get<std::uint32_t>("regions_y"));
  (void)r.get<std::uint32_t>("reserved");
  if (r.get<double>("unit") != kMmPerUnit) r.fail("unit must be 0.0001 mm");
  sp.level_spacing_mm = r.get<double>("level spacing");
  sp.chord_tol_mm = r.get<double>("chord tolerance");
  double v[6];
  for (double& x : v) x = r.get<double>("stock");
  if (sp.shape == SolidSpec::Shape::Box) {
    sp.box = BoxStock{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}};
  } else {
    sp.cylinder = CylinderStock{v[0], v[1], v[2], v[3], v[4]};
  }
  // Every cell takes at least 4 bytes: a file too short for its grid is rejected before the
  // grid is allocated.
  if (static_cast<double>(levels) * sp.regions_x * sp.regions_y * 4.0 > static_cast<double>(r.left()))
    r.fail("grid of " + std::to_string(levels) + " levels x " + std::to_string(sp.regions_x) + "x" +
           std::to_string(sp.regions_y) + " regions does not fit in the file");
  // A header whose level count is not the stock's is refused before the grid is allocated
  // (a short file could otherwise allocate millions of cells first).
  if (const double n = LbrSolid::level_count(sp); std::isfinite(n) && n != static_cast<double>(levels))
    r.fail("level count " + std::to_string(levels) + " does not match stock and spacing (" +
           std::to_string(static_cast<long long>(std::clamp(n, -1e18, 1e18))) + ")");
  LbrSolid solid = [&] {
    try {
      return LbrSolid(sp, LbrSolid::CellsSetLater{});  // every cell is read below
    } catch (const std::invalid_argument& e) {
      r.fail(std::string("bad header: ") + e.what());
      throw;
    }
  }();
  if (static_cast<std::uint32_t>(solid.levels()) != levels)
    r.fail("level count " + std::to_string(levels) + " does not match stock and spacing (" +
           std::to_string(solid.levels()) + ")");
  for (int reg = 0; reg < solid.regions(); ++reg) {
    for (int l = 0; l < solid.levels(); ++l) {
      const auto np = r.get<std::uint32_t>("polygon count");
      if (static_cast<std::size_t>(np) * 12 > r.left()) r.fail("polygon count exceeds the file");
      std::vector<Polygon> polys(np);
      for (Polygon& p : polys) {
        const auto nh = r.get<std::uint32_t>("hole count");
        if (static_cast<std::size_t>(nh) * 8 > r.left()) r.fail("hole count exceeds the file");
        p.outer = r.contour();
        p.holes.reserve(nh);
        for (std::uint32_t h = 0; h < nh; ++h) p.holes.push_back(r.contour());
      }
      solid.set_cell(reg, l, std::move(polys));
    }
  }
  if (r.left() != 0) r.fail(std::to_string(r.left()) + " trailing bytes");
  solid.clear_dirty();
  return solid;
}

}  // namespace lbr::geom
