// Thread scaling of the offline kernel: each workload (bench/programs, docs/benchmarks.md) on
// the sampled stream, run with one thread and with N threads in turn, `--repeat` pairs in one
// process. Prints the median kernel time of each and the median of the pairwise ratios (a
// pair shares the machine's state of the moment, so the ratio holds when its speed drifts),
// and writes DIR/scaling.csv.
#include <algorithm>
#include <cstdio>
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

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"lbr_bench_scaling: kernel time with one thread vs N threads, alternating, per workload"};
  std::string dir = "bench-out", programs = "bench/programs", grid = "auto";
  int threads = 2, repeat = 15;
  std::vector<std::string> workloads{"low", "medium", "high"};
  cli.add_option("--out", dir, "Output directory")->capture_default_str();
  cli.add_option("--programs", programs, "Directory of low/medium/high.ngc")->capture_default_str();
  cli.add_option("--threads", threads, "Threads to compare with one")->capture_default_str()->check(CLI::Range(2, 256));
  cli.add_option("--grid", grid, "Region grid (NXxNY or auto)")->capture_default_str();
  cli.add_option("--repeat", repeat, "Pairs of runs per workload")->capture_default_str()->check(CLI::Range(1, 1000));
  cli.add_option("--workloads", workloads, "Workloads")->capture_default_str();
  CLI11_PARSE(cli, argc, argv);
  std::filesystem::create_directories(dir);
  const std::string csv = dir + "/scaling.csv";
  FILE* f = std::fopen(csv.c_str(), "w");
  if (f == nullptr) {
    std::fprintf(stderr, "cannot write %s\n", csv.c_str());
    return 1;
  }
  std::fprintf(f, "workload,grid,threads,repeat,one_thread_s,n_threads_s,ratio\n");
  for (const std::string& w : workloads) {
    app::Profile prof = app::default_profile();
    app::apply_regions(prof, grid, "--grid");
    const nc::Toolpath program = app::load_toolpath(programs + "/" + w + ".ngc", prof);
    const nc::Toolpath path = nc::sampled_toolpath(program, app::emulator_limits(prof));
    std::vector<double> one, many, ratio;
    for (int i = 0; i < repeat; ++i) {
      prof.threads = 1;
      one.push_back(app::run_batch(prof, path).wall_time_s);
      prof.threads = threads;
      many.push_back(app::run_batch(prof, path).wall_time_s);
      ratio.push_back(one.back() / many.back());
    }
    const double m1 = median(one), mn = median(many), mr = median(ratio);
    std::fprintf(f, "%s,%s,%d,%d,%.5f,%.5f,%.3f\n", w.c_str(), grid.c_str(), threads, repeat, m1, mn, mr);
    std::fflush(f);
    std::printf("%-7s %-6s 1 thread %8.4f s  %d threads %8.4f s  ratio %.2f (median of %d pairs; min %.2f, max %.2f)\n",
                w.c_str(), grid.c_str(), m1, threads, mn, mr, repeat, *std::min_element(ratio.begin(), ratio.end()),
                *std::max_element(ratio.begin(), ratio.end()));
  }
  std::fclose(f);
  std::printf("wrote %s\n", csv.c_str());
  return 0;
}
