// Reproduction of the paper's Figure 4: time of one 3D boolean (difference) between two LBR
// solids as a function of the points per level and the number of levels. Each solid has one
// region; the stock is a cylinder polygonised to P points per level, the tool solid a second
// cylinder of P points offset by half a radius, so every level yields a real clip.
// Writes DIR/fig4.csv (points, levels, median_ms, min_ms, max_ms over 5 runs) and, when
// gnuplot is installed, DIR/fig4.png.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include "geom/lbr_solid.hpp"

using namespace lbr;

namespace {

// Chord tolerance that makes a circle of radius r come out with about p points.
double tol_for_points(double r, int p) { return r * (1.0 - std::cos(std::numbers::pi / p)); }

geom::LbrSolid cylinder(double cx, double r, int points, int levels) {
  geom::SolidSpec s;
  s.shape = geom::SolidSpec::Shape::Cylinder;
  s.cylinder = {cx, 0.0, 2 * r, 0.0, static_cast<double>(levels)};
  s.level_spacing_mm = 1.0;
  s.regions_x = s.regions_y = 1;
  s.chord_tol_mm = std::max(1e-4, tol_for_points(r, points));
  return geom::LbrSolid(s);
}

}  // namespace

int main(int argc, char** argv) {
  const std::string arg = argc > 1 ? argv[1] : "";
  if (arg == "--help" || arg == "-h" || argc > 2 || (!arg.empty() && arg[0] == '-')) {
    std::fprintf(arg == "--help" || arg == "-h" ? stdout : stderr,
                 "usage: %s [OUTDIR=bench-out]\n"
                 "Paper Fig. 4: the time of one 3D boolean (cylinder minus cylinder) against levels and points\n"
                 "per level; writes OUTDIR/fig4.csv and, with gnuplot, OUTDIR/fig4.png.\n",
                 argv[0]);
    return arg == "--help" || arg == "-h" ? 0 : 2;
  }
  const std::string dir = arg.empty() ? "bench-out" : arg;
  std::filesystem::create_directories(dir);
  const std::string csv = dir + "/fig4.csv";
  FILE* f = std::fopen(csv.c_str(), "w");
  if (f == nullptr) {
    std::fprintf(stderr, "cannot write %s\n", csv.c_str());
    return 1;
  }
  std::fprintf(f, "points,levels,median_ms,min_ms,max_ms\n");
  const double r = 400.0;  // large enough that 4096 points need a chord tolerance >= 0.1 µm
  for (int points : {64, 256, 1024, 4096}) {
    for (int levels : {50, 100, 200, 400, 800}) {
      const geom::LbrSolid tool = cylinder(r * 0.5, r, points, levels);
      std::vector<double> ms;
      for (int rep = 0; rep < 5; ++rep) {
        geom::LbrSolid stock = cylinder(0.0, r, points, levels);
        const auto t0 = std::chrono::steady_clock::now();
        const geom::SubtractStats st = stock.subtract_solid(tool);
        ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
        if (st.cells_changed != static_cast<std::uint64_t>(levels)) {
          std::fprintf(stderr, "unexpected: %llu cells changed\n", static_cast<unsigned long long>(st.cells_changed));
          return 1;
        }
      }
      std::sort(ms.begin(), ms.end());
      std::fprintf(f, "%d,%d,%.4f,%.4f,%.4f\n", points, levels, ms[2], ms.front(), ms.back());
      std::printf("points/level %5d  levels %4d  median %9.3f ms  (min %.3f, max %.3f)\n", points, levels, ms[2], ms.front(),
                  ms.back());
    }
  }
  std::fclose(f);
  const std::string png = dir + "/fig4.png";
  const std::string cmd =
      "command -v gnuplot >/dev/null 2>&1 && gnuplot -e \"set terminal pngcairo size 900,600 noenhanced; set output '" + png +
      "'; set datafile separator ','; set key top left; set logscale y; set xlabel 'levels'; set ylabel 'time of one "
      "3D boolean [ms]'; set title 'LBR boolean vs levels and points per level (lbrsim, cf. paper Fig. 4)'; "
      "plot for [p in '64 256 1024 4096'] '" + csv +
      "' using 2:(column(1)==p+0 ? column(3) : 1/0) with linespoints title p.' points/level'\"";
  if (std::system(cmd.c_str()) == 0) std::printf("wrote %s and %s\n", csv.c_str(), png.c_str());
  else std::printf("wrote %s (gnuplot not available: no plot)\n", csv.c_str());
  return 0;
}
