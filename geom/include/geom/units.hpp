// geom/units.hpp — the one place where millimetres (double) become kernel units (int64).
//
// Kernel unit: 0.1 µm (1e-4 mm). The safe range is |coordinate| <= kSafeRange units
// (2^30 - 1, about ±107 m): inside it Clipper keeps to its fast 64-bit arithmetic and
// products of coordinates never overflow. Anything outside is rejected at the boundary.
#pragma once

#include <cmath>
#include <cstdint>

#include <clipper.hpp>

namespace lbr::geom {

using Coord = ClipperLib::cInt;                      // [0.1 µm], 64-bit
inline constexpr double kUnitsPerMm = 10000.0;       // [units/mm]
inline constexpr double kMmPerUnit = 1.0 / kUnitsPerMm;
inline constexpr Coord kSafeRange = (Coord{1} << 30) - 1;  // [units], ±107.37 m
inline constexpr double kSafeRangeMm = static_cast<double>(kSafeRange) * kMmPerUnit;

// Round a length in mm to kernel units. Real-time safe, no allocation.
// Callers guarantee |mm| <= kSafeRangeMm (LbrSolid and Sweep check their inputs).
[[nodiscard]] inline Coord to_units(double mm) noexcept {
  // Round half away from zero, like llround, without the libm call (hot in section code).
  const double u = mm * kUnitsPerMm;
  return static_cast<Coord>(u + (u >= 0.0 ? 0.5 : -0.5));
}
[[nodiscard]] inline double to_mm(Coord units) noexcept {
  return static_cast<double>(units) * kMmPerUnit;
}
// Area in units² to mm².
[[nodiscard]] inline double area_to_mm2(double units2) noexcept {
  return units2 * kMmPerUnit * kMmPerUnit;
}

}  // namespace lbr::geom
