// Reproduction of the paper's Table 2: simulation time / machining time for the three
// benchmark workloads (bench/programs, docs/benchmarks.md) over region grids, on the sampled
// stream (4 ms, as live mode sees it), one kernel thread unless --threads says otherwise.
// Writes DIR/table2.csv and, with gnuplot, DIR/table2.png, and prints the paper's figures
// beside ours.
// The issue 13 workloads (finish3d, helix, finish5x, and LinuxCNC's 5-axis samples when
// installed) run in both modes: the G-code segments (`lbrsim batch`) and the sampled stream
// (`lbrsim batch --sampled`: nc::sampled_toolpath of the emulator, as the batch command builds
// it). finish3d's removed volume is compared with an independent height-field reference
// (reference_volume.hpp).
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/batch.hpp"
#include "app/outputs.hpp"
#include "app/profile.hpp"
#include "nc/emulator.hpp"
#include "nc/gcode.hpp"
#include "reference_volume.hpp"

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


// A program with the profile it runs on and how (modes) it enters the table.
struct Workload {
  std::string name;
  app::Profile prof;
  nc::Toolpath program;
  bool both_modes = true;  // false: the paper's workloads, sampled only (as before)
  bool reference = false;  // compare the removed volume with the height-field reference
};

// LinuxCNC's 5-axis samples (package linuxcnc-uspace) and the rotary arrangement each needs.
struct LinuxcncSample {
  const char* name;
  kin::Rotary rotary;
};
const LinuxcncSample kLinuxcnc[] = {
    {"boat-xyzac", kin::Rotary::TableAC}, {"boat-xyzbc", kin::Rotary::TableBC}, {"impeller-7bl-xyzac", kin::Rotary::TableAC}};

// The mill5 profile of finish5x: mill5-ac plus the ball and bull tools of the program header.
app::Profile mill5_profile(const std::string& path) {
  app::Profile p = app::load_profile(path);
  app::apply_tool_override(p, "3:ball:6");
  app::apply_tool_override(p, "4:bull:10:2");
  return p;
}

// A LinuxCNC sample on the mill5 profile: M428/M429/M430 (that configuration's switchkins
// remaps; M428 = TCP on) dropped and TCP set, the tilt axis from the program's name. The
// programmed point is the tool tip, as on LinuxCNC's simulated machine (its tool table gives
// T1 length 0, and boat-xyzac and the impeller have no G43): tool 1 is in the spindle from the
// start and a G43 in front compensates its length, so the shank and holder stay where the
// program means them (without it the tip runs one tool length, 60 mm, below the program and
// drags the shank through the stock on every move: docs/performance.md).
std::optional<Workload> linuxcnc_workload(const LinuxcncSample& s, const std::string& dir, const std::string& mill5) {
  const std::string file = dir + "/" + s.name + ".ngc";
  std::ifstream in(file, std::ios::binary);
  if (!in) return std::nullopt;
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  const bool tcp = text.find("M428") != std::string::npos;
  text = std::regex_replace(text, std::regex("M4(28|29|30)"), "");
  const std::size_t at = text.rfind('%', 0) == 0 ? text.find('\n') + 1 : 0;  // after a leading %
  text.insert(at, "G43\n");
  Workload w{s.name, mill5_profile(mill5), {}, true, false};
  w.prof.kin.tcp = tcp;
  w.prof.kin.rotary = s.rotary;
  w.prof.nc.start_tool = 1;
  w.program = nc::interpret_gcode(text, file, app::gcode_options(w.prof));
  return w;
}

// One table row: into the CSV and on stdout.
void print_row(FILE* f, const Workload& w, const std::string& mode, const std::string& g, const std::string& checks,
               double machining, const nc::Toolpath& path, const app::BatchResult& r, const bench::ReferenceVolume* ref) {
  const double factor = r.wall_time_s / machining;
  const double err = ref ? (r.removed_volume_mm3 - ref->removed_mm3) / ref->removed_mm3 : 0.0;
  std::fprintf(f, "%s,%s,%d,%.2f,%.4f,%.5f,%.3f,%zu,%.1f,%s,%zu,", w.name.c_str(), g.c_str(), r.solid.regions(), machining,
               r.wall_time_s, factor, r.removed_volume_mm3, r.solid.vertex_count(), app::peak_rss_mb(), mode.c_str(),
               path.segments.size());
  if (ref) std::fprintf(f, "%.3f,%.6f,%s\n", ref->removed_mm3, err, checks.c_str());
  else std::fprintf(f, ",,%s\n", checks.c_str());
  std::fflush(f);
  if (w.both_modes)
    std::printf("%-8s %-8s %-6s (%3dx%-3d) checks %-3s %7zu moves  machining %7.2f s  simulated %8.3f s  factor %.5f  "
                "removed %.1f mm3",
                w.name.c_str(), mode.c_str(), g.c_str(), r.solid.regions_x(), r.solid.regions_y(), checks.c_str(),
                path.segments.size(), machining, r.wall_time_s, factor, r.removed_volume_mm3);
  else
    std::printf("%-7s %-6s (%3dx%-3d) checks %-3s machining %7.2f s  simulated %8.3f s  factor %.5f  removed %.1f mm3",
                w.name.c_str(), g.c_str(), r.solid.regions_x(), r.solid.regions_y(), checks.c_str(), machining,
                r.wall_time_s, factor, r.removed_volume_mm3);
  if (ref) std::printf("  vs reference %+.4f %%", 100.0 * err);
  if (!r.events.empty()) std::printf("  %zu events", r.events.size());
  std::printf("\n");
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"lbr_bench_table2: factor = simulation time / machining time per workload and region grid"};
  std::string dir = "bench-out", programs = "bench/programs", mill5 = "config/profiles/mill5-ac.toml";
  std::string linuxcnc =
      "/usr/share/doc/linuxcnc/examples/sample-configs/sim/axis/vismach/5axis/table-rotary-tilting/demos";
  int threads = 1;
  double ref_cell = 0.05;
  std::vector<std::string> grids{"1x1", "2x2", "4x2", "4x4", "8x4", "8x8", "16x16", "auto"};
  std::vector<std::string> workloads{"low", "medium", "high", "finish3d", "helix", "finish5x", "linuxcnc"};
  std::vector<std::string> modes{"segments", "sampled"};
  std::vector<std::string> checks{"on"};
  bool plot_only = false;
  cli.add_option("--out", dir, "Output directory")->capture_default_str();
  cli.add_option("--programs", programs, "Directory of the workloads' .ngc (lbr-genbench's output)")->capture_default_str();
  cli.add_option("--threads", threads, "Kernel threads")->capture_default_str();
  cli.add_option("--grids", grids, "Region grids")->capture_default_str();
  cli.add_option("--workloads", workloads,
                 "Workloads to run: low medium high (sampled only, as in the paper), finish3d helix finish5x (both "
                 "modes), linuxcnc (= boat-xyzac boat-xyzbc impeller-7bl-xyzac, skipped when not installed) or one of those")
      ->capture_default_str();
  cli.add_option("--modes", modes, "Modes of the issue 13 workloads: segments (lbrsim batch), sampled (--sampled)")
      ->capture_default_str();
  cli.add_option("--checks", checks, "Collision checks during the run: on (lbrsim batch's default), off, or both")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  cli.add_option("--mill5-profile", mill5, "Profile of finish5x and the LinuxCNC samples")->capture_default_str();
  cli.add_option("--linuxcnc-dir", linuxcnc, "Folder of LinuxCNC's boat/impeller samples")->capture_default_str();
  cli.add_option("--reference-cell", ref_cell, "Cell of finish3d's height-field reference [mm]; 0: no reference")
      ->capture_default_str();
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
  std::fprintf(f, "workload,grid,regions,machining_s,sim_s,factor,removed_mm3,vertices,peak_rss_mb,mode,moves,"
                  "reference_mm3,volume_error,checks\n");
  for (const std::string& name : workloads) {
    // Load the workload(s) the name stands for.
    std::vector<Workload> load;
    const bool paper = name == "low" || name == "medium" || name == "high";
    if (paper || name == "finish3d" || name == "helix") {
      Workload w{name, app::default_profile(), {}, !paper, name == "finish3d" && ref_cell > 0};
      w.program = app::load_toolpath(programs + "/" + name + ".ngc", w.prof);
      load.push_back(std::move(w));
    } else if (name == "finish5x") {
      Workload w{name, mill5_profile(mill5), {}, true, false};
      w.program = app::load_toolpath(programs + "/" + name + ".ngc", w.prof);
      load.push_back(std::move(w));
    } else {
      bool known = false;
      for (const LinuxcncSample& ls : kLinuxcnc) {
        if (name != "linuxcnc" && name != ls.name) continue;
        known = true;
        if (std::optional<Workload> w = linuxcnc_workload(ls, linuxcnc, mill5)) load.push_back(std::move(*w));
        else std::printf("%-18s skipped: %s/%s.ngc not found (LinuxCNC's samples, package linuxcnc-uspace)\n", ls.name,
                         linuxcnc.c_str(), ls.name);
      }
      if (!known) {
        std::fprintf(stderr, "unknown workload %s\n", name.c_str());
        return 2;
      }
    }
    for (Workload& w : load) {
      w.prof.threads = threads;
      const nc::EmulatorLimits limits = app::emulator_limits(w.prof);
      const double machining = nc::emulated_time_s(w.program, limits);
      std::optional<bench::ReferenceVolume> ref;
      if (w.reference) {
        ref = bench::reference_removed_volume(w.program, w.prof.tooling.tools, w.prof.solid, ref_cell);
        std::printf("%s reference: %.3f mm3 removed (height field, %.3f mm cells, %ld moves, %.1f s)\n", w.name.c_str(),
                    ref->removed_mm3, ref->cell_mm, ref->moves, ref->seconds);
      }
      for (const std::string& mode : w.both_modes ? modes : std::vector<std::string>{"sampled"}) {
        if (mode != "segments" && mode != "sampled") {
          std::fprintf(stderr, "unknown mode %s\n", mode.c_str());
          return 2;
        }
        // As lbrsim batch builds its input: the program's segments, or with --sampled the
        // emulator's sampled stream (nc::sampled_toolpath); the machining time is the emulator's.
        const nc::Toolpath path = mode == "sampled" ? nc::sampled_toolpath(w.program, limits) : w.program;
        for (const std::string& g : grids)
          for (const std::string& c : checks) {
            app::Profile prof = w.prof;
            app::apply_regions(prof, g, "--grids");
            prof.checks.enabled = c == "on";
            const app::BatchResult r = app::run_batch(prof, path);
            print_row(f, w, mode, g, c, machining, path, r, ref ? &*ref : nullptr);
          }
      }
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
