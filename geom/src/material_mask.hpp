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

// kSide x kSide pixels over the region's rectangle; a pixel's bit is set wherever material
// may lie in it: every pixel that a contour's edge passes through or touches (the edge's
// x-range in each pixel row, widened by kEdgePad pixels), and every pixel whose centre lies
// inside the material (even-odd over the cell's contours, which do not cross). A pixel
// that no edge touches lies wholly inside or wholly outside, as its centre does, so a clear
// bit means no material anywhere in it. Built from a cell in O(edges + crossings + kSide);
// used as long as the cell's version is the one it was built from.
class CellMask {
 public:
  static constexpr int kSide = 64;  // bits per row: one std::uint64_t
  static constexpr double kEdgePad = 1e-3;  // [pixels]: the rounding of edges' pixel coordinates

  // Rasterises `cell` over `region` [units]; `crossings` is a reusable buffer (row, x).
  void build(const Cell& cell, const Rect& region, std::vector<std::pair<int, double>>& crossings);
  // True when some pixel that the convex polygon `poly` [mm] overlaps may hold material.
  [[nodiscard]] bool may_meet(std::span<const SectionPoint> poly) const noexcept;

  std::uint32_t version = 0;  // the cell's version it was built from
  bool built = false;         // false: to be built before use

 private:
  void mark_edge(double ax, double ay, double bx, double by) noexcept;
  void fill_rows(std::vector<std::pair<int, double>>& crossings) noexcept;
  [[nodiscard]] double px(double x_mm) const noexcept;
  [[nodiscard]] double py(double y_mm) const noexcept;

  std::uint64_t rows_[kSide] = {};
  double x0_ = 0.0, y0_ = 0.0;  // the region's corner [units]
  double sx_ = 0.0, sy_ = 0.0;  // pixels per unit
};

// The material of one level before a batch, for Sweep::tilted_pieces(): the box of its
// cells, and their masks (built when a polygon first reaches a cell that changed since its
// mask was built). Region borders, cells and masks are the solid's; `crossings` is the
// calling thread's buffer. Only the thread that builds the level may use it.
class LevelMaterial final : public PlaneMaterial {
 public:
  LevelMaterial(const LbrSolid& solid, int level, std::span<const Coord> xs, std::span<const Coord> ys,
                std::vector<CellMask>& masks, std::vector<std::pair<int, double>>& crossings) noexcept;
  [[nodiscard]] bool may_meet(std::span<const SectionPoint> poly) const override;

 private:
  const LbrSolid& s_;
  int level_;
  std::span<const Coord> xs_, ys_;  // region borders [units], regions + 1 each
  std::vector<CellMask>& masks_;    // per cell, or empty: every polygon may meet material
  std::vector<std::pair<int, double>>& crossings_;
};

}  // namespace lbr::geom::detail
