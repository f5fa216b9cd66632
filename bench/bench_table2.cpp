// Reproduction of the paper's Table 2: simulation time / machining time for the three
// benchmark workloads (bench/programs, docs/benchmarks.md) over region grids, on the sampled
// stream (4 ms, as live mode sees it), one kernel thread unless --threads says otherwise.
// Writes DIR/table2.csv and, with gnuplot, DIR/table2.png, and prints the paper's figures
// beside ours.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/batch.hpp"
#include "app/outputs.hpp"
#include "app/profile.hpp"
#include "nc/emulator.hpp"

using namespace lbr;

namespace {

struct PaperRow {
  const char* grid;
  double factor;
};
// Paper, Table 2 (grid, factor) per model.
const std::vector<PaperRow> kPaperLow{{"1x1", 10.2}, {"2x2", 1.7}, {"4x2", 1.3}, {"8x2", 1.02}};
const std::vector<PaperRow> kPaperMedium{{"1x1", 9.6}, {"2x4", 1.10}, {"4x8", 1.01}, {"8x16", 1.45}};
const std::vector<PaperRow> kPaperHigh{{"1x1", 9.3}, {"4x2", 2.04}, {"8x4", 1.13}, {"8x8", 1.04}, {"16x16", 1.23}};

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"lbr_bench_table2: factor = simulation time / machining time per workload and region grid"};
  std::string dir = "bench-out", programs = "bench/programs";
  int threads = 1;
  std::vector<std::string> grids{"1x1", "2x2", "4x2", "4x4", "8x4", "8x8", "16x16", "auto"};
  std::vector<std::string> workloads{"low", "medium", "high"};
  bool plot_only = false;
  cli.add_option("--out", dir, "Output directory")->capture_default_str();
  cli.add_option("--programs", programs, "Directory of low/medium/high.ngc")->capture_default_str();
  cli.add_option("--threads", threads, "Kernel threads")->capture_default_str();
  cli.add_option("--grids", grids, "Region grids")->capture_default_str();
  cli.add_option("--workloads", workloads, "Workloads")->capture_default_str();
  cli.add_flag("--plot-only", plot_only, "Only redraw DIR/table2.png from DIR/table2.csv");
  CLI11_PARSE(cli, argc, argv);
  std::filesystem::create_directories(dir);
  const std::string csv = dir + "/table2.csv";
  // The paper's rows, for the plot.
  const std::string paper_csv = dir + "/table2-paper.csv";
  if (FILE* pf = std::fopen(paper_csv.c_str(), "w")) {
    std::fprintf(pf, "workload,grid,regions,factor\n");
    for (const auto& [name, rows] : {std::pair{"low", &kPaperLow}, {"medium", &kPaperMedium}, {"high", &kPaperHigh}})
      for (const PaperRow& r : *rows) {
        int nx = 1, ny = 1;
        std::sscanf(r.grid, "%dx%d", &nx, &ny);
        std::fprintf(pf, "%s,%s,%d,%.3f\n", name, r.grid, nx * ny, r.factor);
      }
    std::fclose(pf);
  }
  FILE* f = plot_only ? nullptr : std::fopen(csv.c_str(), "w");
  if (f == nullptr && !plot_only) return 1;
  if (!plot_only) {
  std::fprintf(f, "workload,grid,regions,machining_s,sim_s,factor,removed_mm3,vertices,peak_rss_mb\n");
  for (const std::string& w : workloads) {
    app::Profile prof = app::default_profile();
    prof.threads = threads;
    const nc::Toolpath program = app::load_toolpath(programs + "/" + w + ".ngc", prof);
    const nc::Toolpath path = nc::sampled_toolpath(program, app::emulator_limits(prof));
    const double machining = nc::emulated_time_s(program, app::emulator_limits(prof));
    for (const std::string& g : grids) {
      app::apply_regions(prof, g, "--grids");
      const app::BatchResult r = app::run_batch(prof, path);
      const double factor = r.wall_time_s / machining;
      std::fprintf(f, "%s,%s,%d,%.2f,%.4f,%.5f,%.3f,%zu,%.1f\n", w.c_str(), g.c_str(), r.solid.regions(), machining,
                   r.wall_time_s, factor, r.removed_volume_mm3, r.solid.vertex_count(), app::peak_rss_mb());
      std::fflush(f);
      std::printf("%-7s %-6s (%3dx%-3d) machining %7.2f s  simulated %8.3f s  factor %.5f  removed %.1f mm3\n", w.c_str(),
                  g.c_str(), r.solid.regions_x(), r.solid.regions_y(), machining, r.wall_time_s, factor,
                  r.removed_volume_mm3);
    }
  }
  std::fclose(f);
  }
  std::printf("\npaper, Table 2 (factor):\n");
  for (const auto& [name, rows] : {std::pair{"low", &kPaperLow}, {"medium", &kPaperMedium}, {"high", &kPaperHigh}}) {
    std::printf("  %-7s", name);
    for (const PaperRow& r : *rows) std::printf("  %s: %.2f", r.grid, r.factor);
    std::printf("\n");
  }
  const std::string png = dir + "/table2.png";
  const std::string cmd =
      "command -v gnuplot >/dev/null 2>&1 && gnuplot -e \"set terminal pngcairo size 900,600 noenhanced; set output '" + png +
      "'; set datafile separator ','; set logscale y; set yrange [0.0001:20]; set key outside; set ylabel 'factor = "
      "simulation / machining time'; set xlabel 'regions'; set logscale x 2; set title 'Table 2: lbrsim (one core, "
      "sampled 4 ms) vs the paper'; "
      "plot for [w in 'low medium high'] '" + csv +
      "' using (strcol(2) eq 'auto' ? 1/0 : column(3)):(strcol(1) eq w ? column(6) : 1/0) with linespoints title "
      "'lbrsim '.w, for [w in 'low medium high'] '" + paper_csv +
      "' using 3:(strcol(1) eq w ? column(4) : 1/0) with linespoints dashtype 2 title 'paper '.w, 1 with lines "
      "title 'real time (factor 1)'\"";
  if (std::system(cmd.c_str()) == 0) std::printf("wrote %s and %s\n", csv.c_str(), png.c_str());
  else std::printf("wrote %s\n", csv.c_str());
  return 0;
}
