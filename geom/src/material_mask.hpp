// Private: a conservative raster of one cell's material, which tells a tilted piece whose
// section meets no material before it is refined (level_sections.cpp, build_tilted()).
#pragma once

#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "geom/lbr_solid.hpp"
#include "geom/sweep.hpp"

namespace lbr::geom::detail {

// Up to kMaxSide x kMaxSide pixels of about kPixelMm over the region's rectangle; a pixel's
// bit is set wherever material may lie in it: every pixel that a contour's edge passes
// through or touches (the edge's x-range in each pixel row, widened by kEdgePad pixels), and
// every pixel whose centre lies inside the material (even-odd over the cell's contours,
// which do not cross). A pixel that no edge touches lies wholly inside or wholly outside,
// as its centre does, so a clear bit means no material anywhere in it. Built from a cell in
// O(edges + crossings + rows); `version` is the cell's version it was built from
// (LevelMaterial rebuilds it when that matters, rebuild_due()). Holds one 64-bit word per
// row: a 15 mm cell 480 bytes, a 3.75 mm cell 120.
class CellMask {
 public:
  static constexpr int kMaxSide = 64;       // pixels per row at most: one std::uint64_t
  static constexpr double kPixelMm = 0.25;  // the pixel size aimed at (finer for small cells)
  static constexpr double kEdgePad = 1e-3;  // [pixels]: the rounding of edges' pixel coordinates

  // Back-off of rebuilds that clear nothing: after `misses` rebuilds in a row that cleared
  // no polygon before the next one, the next waits for 2^misses changes of the cell (one
  // when the mask has cleared a polygon since it was built).
  static constexpr int kMaxMisses = 4;

  // Rasterises `cell` over `region` [units]; `crossings` is a reusable buffer (row, x).
  // Allocates the rows on its first build.
  void build(const Cell& cell, const Rect& region, std::vector<std::pair<int, double>>& crossings);
  // True when some pixel that the convex polygon `poly` [mm] overlaps may hold material.
  [[nodiscard]] bool may_meet(std::span<const SectionPoint> poly) const noexcept;
  // Whether a polygon the mask does not clear is worth a rebuild from a cell at
  // `cell_version`: the cell has changed since the build at least 2^misses times (once when
  // the mask has cleared a polygon since). Live calls cut a little at a time beside the
  // material: 99.9 % of rebuilds on finish5x's live stand-in still met the polygon
  // (docs/performance.md, "Mask rebuilds that clear nothing").
  [[nodiscard]] bool rebuild_due(std::uint32_t cell_version) const noexcept {
    return cell_version - version >= (cleared ? std::uint32_t{1} : std::uint32_t{1} << misses);
  }

  std::uint32_t version = 0;  // the cell's version it was built from
  bool built = false;         // false: to be built before use
  bool cleared = false;       // it has cleared a polygon since it was built
  std::uint8_t misses = 0;    // rebuilds in a row after which it cleared nothing (<= kMaxMisses)

 private:
  void mark_edge(double ax, double ay, double bx, double by) noexcept;
  void fill_rows(std::vector<std::pair<int, double>>& crossings) noexcept;
  [[nodiscard]] int column(double v) const noexcept;  // v [pixels] clamped to a column
  [[nodiscard]] int row(double v) const noexcept;     // v [pixels] clamped to a row
  [[nodiscard]] std::uint64_t span(int c0, int c1) const noexcept;  // bits c0..c1
  [[nodiscard]] double px(double x_mm) const noexcept;
  [[nodiscard]] double py(double y_mm) const noexcept;

  std::vector<std::uint64_t> rows_;  // ny_ rows, nx_ bits each
  int nx_ = 0, ny_ = 0;
  double x0_ = 0.0, y0_ = 0.0;  // the region's corner [units]
  double sx_ = 0.0, sy_ = 0.0;  // pixels per unit
};

// A block of regions of a solid's grid: inclusive region indices along x and y.
struct RegionRange {
  int ix0 = 0, ix1 = -1, iy0 = 0, iy1 = -1;  // empty: ix1 < ix0
  [[nodiscard]] bool empty() const noexcept { return ix1 < ix0 || iy1 < iy0; }
  [[nodiscard]] static RegionRange all(const LbrSolid& s) noexcept { return {0, s.regions_x() - 1, 0, s.regions_y() - 1}; }
};

// The box [units] of the rectangle [xlo, xhi] x [ylo, yhi] [mm], rounded outwards (and
// clamped far inside Coord's range). The bounds must not be NaN.
[[nodiscard]] Rect units_box_outward(double xlo, double ylo, double xhi, double yhi) noexcept;
// The regions of borders `xs`, `ys` [units] (interval_of()) that box `b` [units] reaches; a
// box that starts on a border reaches the region before it too.
[[nodiscard]] RegionRange regions_reached(const std::vector<Coord>& xs, const std::vector<Coord>& ys, const Rect& b) noexcept;

// The material of one level before a batch, for Sweep::tilted_pieces(): the box of its
// cells, and their masks. A subtraction only removes material, and the masks are forgotten
// whenever the solid may have had material put back (its removal epoch), so a mask built
// before the cell's last changes holds all of its material and more: a polygon it clears
// is clear. It is rebuilt only when it does not clear one. Region borders, cells and masks
// are the solid's; `crossings` is the calling thread's buffer. Only the thread that builds
// the level may use it.
//
// `box` is the box of the cells of `regions` (all of them by default): the caller passes the
// regions its polygons can reach (the batch's tilted sweeps), so the box holds all the
// material those polygons may meet. A live call's few sweeps reach a handful of a 16x16
// grid's 256 regions, and reading every cell of the level cost 3.3 % of such calls'
// instructions (docs/performance.md, "Live calls: the level's material box").
class LevelMaterial final : public PlaneMaterial {
 public:
  LevelMaterial(const LbrSolid& solid, int level, const std::vector<Coord>& xs, const std::vector<Coord>& ys,
                std::vector<CellMask>& masks, std::vector<std::pair<int, double>>& crossings) noexcept
      : LevelMaterial(solid, level, xs, ys, masks, crossings, RegionRange::all(solid)) {}
  LevelMaterial(const LbrSolid& solid, int level, const std::vector<Coord>& xs, const std::vector<Coord>& ys,
                std::vector<CellMask>& masks, std::vector<std::pair<int, double>>& crossings,
                const RegionRange& regions) noexcept;
  [[nodiscard]] bool may_meet(std::span<const SectionPoint> poly) const override;

 private:
  const LbrSolid& s_;
  int level_;
  const std::vector<Coord>& xs_;  // region borders [units], regions + 1 each (interval_of())
  const std::vector<Coord>& ys_;
  std::vector<CellMask>& masks_;    // per cell, or empty: every polygon may meet material
  std::vector<std::pair<int, double>>& crossings_;
};

}  // namespace lbr::geom::detail
