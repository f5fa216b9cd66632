// Throughput of LbrSolid::subtract on a realistic sampled stream: a pocket raster with a
// 10 mm flat end mill, moves of 0.067 mm (4 ms at 1000 mm/min), on 100 x 80 x 30 mm stock at
// Δ = 0.1 mm, for several region grids and batch sizes. Counters: moves/s and the
// simulation/real-time factor for 4 ms samples (factor < 1: faster than the machine).
#include <benchmark/benchmark.h>

#include "geom/lbr_solid.hpp"
#include "workloads.hpp"

using namespace lbr;

namespace {

void BM_SubtractStream(benchmark::State& state) {
  const int grid = static_cast<int>(state.range(0));
  const int batch = static_cast<int>(state.range(1));
  const double step = static_cast<double>(state.range(2)) / 1000.0;  // [mm]
  geom::Tool t;
  t.kind = geom::ToolKind::Flat;
  t.diameter_mm = 10.0;
  const geom::CutterShape shape = geom::CutterShape::build(t, 0.001);
  const auto pts = bench::raster(20, 20, 80, 60, -3, 5, step);
  geom::SolidSpec spec;
  spec.box = {{0, 0, -30}, {100, 80, 0}};
  spec.level_spacing_mm = 0.1;
  spec.regions_x = spec.regions_y = grid;
  std::size_t moves = 0;
  for (auto _ : state) {
    state.PauseTiming();
    geom::LbrSolid solid(spec);
    std::vector<geom::SweepRef> b;
    state.ResumeTiming();
    for (std::size_t i = 1; i < pts.size(); ++i) {
      b.push_back({&shape, {pts[i - 1], {0, 0, 1}}, {pts[i], {0, 0, 1}}, static_cast<geom::MoveId>(i)});
      if (static_cast<int>(b.size()) == batch) {
        solid.subtract(b);
        b.clear();
      }
    }
    if (!b.empty()) solid.subtract(b);
    moves += pts.size() - 1;
    benchmark::DoNotOptimize(solid.volume_mm3());
  }
  state.counters["moves_per_s"] = benchmark::Counter(static_cast<double>(moves), benchmark::Counter::kIsRate);
  // Wall time per move / 4 ms of machine time per move.
  state.counters["factor_4ms"] =
      benchmark::Counter(static_cast<double>(moves) * 0.004, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["moves"] = static_cast<double>(pts.size() - 1);
}

}  // namespace

// Args: region grid N (N x N), moves per subtract() call, move length [µm].
BENCHMARK(BM_SubtractStream)
    ->ArgsProduct({{1, 2, 4, 8}, {1, 64}, {67}})
    ->Args({4, 64, 50})
    ->Args({4, 64, 100})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->Repetitions(3)
    ->ReportAggregatesOnly(true);

BENCHMARK_MAIN();
