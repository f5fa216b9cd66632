// Reconstruction benchmarks (issue 5): full rebuild and incremental update per move, on
// three synthetic workloads generated here (the project's low/medium/high programs do not
// exist yet): a 2.5D pocket (low), drilling + pocket around islands (medium), a ball-end 3D
// raster (high). Counters: ms per region (full build), µs per dirty level (incremental),
// triangles per second. Results: docs/performance.md.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <vector>

#include "geom/lbr_solid.hpp"
#include "geom/tool.hpp"
#include "mesh/reconstruct.hpp"

namespace {

using namespace lbr;

struct Move {
  const geom::CutterShape* shape;
  geom::Vec3 a, b;
};

struct Workload {
  geom::SolidSpec spec;
  std::vector<geom::CutterShape> tools;
  std::vector<Move> moves;
};

geom::CutterShape make(geom::ToolKind k, double d) {
  geom::Tool t;
  t.kind = k;
  t.diameter_mm = d;
  return geom::CutterShape::build(t, 0.005);
}

geom::SolidSpec stock(int nx, int ny) {
  geom::SolidSpec s;
  s.box = {{0, 0, 0}, {100, 80, 30}};
  s.level_spacing_mm = 0.1;
  s.regions_x = nx;
  s.regions_y = ny;
  return s;
}

std::unique_ptr<Workload> low() {
  auto w = std::make_unique<Workload>();
  w->spec = stock(4, 4);
  w->tools.reserve(2);
  w->tools.push_back(make(geom::ToolKind::Flat, 10));
  const geom::CutterShape* f = &w->tools[0];
  for (double z = 29; z >= 25; z -= 1)
    for (double y = 20; y <= 60; y += 5) w->moves.push_back({f, {20, y, z}, {80, y, z}});
  return w;
}

std::unique_ptr<Workload> medium() {
  auto w = std::make_unique<Workload>();
  w->spec = stock(8, 4);
  w->tools.reserve(2);
  w->tools.push_back(make(geom::ToolKind::Flat, 8));
  w->tools.push_back(make(geom::ToolKind::Drill, 6));
  const geom::CutterShape* f = &w->tools[0];
  const geom::CutterShape* d = &w->tools[1];
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 4; ++j) {
      const double x = 10 + 20 * i, y = 10 + 20 * j;
      w->moves.push_back({d, {x, y, 31}, {x, y, 18}});
    }
  // Pocket 15..85 x 15..65 around two islands (x 30..42, 58..70 at y 32..48).
  for (double z = 28; z >= 22; z -= 2)
    for (double y = 15; y <= 65; y += 6) {
      if (y > 27 && y < 53) {
        w->moves.push_back({f, {15, y, z}, {25, y, z}});
        w->moves.push_back({f, {47, y, z}, {53, y, z}});
        w->moves.push_back({f, {75, y, z}, {85, y, z}});
      } else {
        w->moves.push_back({f, {15, y, z}, {85, y, z}});
      }
    }
  return w;
}

std::unique_ptr<Workload> high() {
  auto w = std::make_unique<Workload>();
  w->spec = stock(8, 8);
  w->tools.reserve(1);
  w->tools.push_back(make(geom::ToolKind::Ball, 6));
  const geom::CutterShape* b = &w->tools[0];
  auto z = [](double x, double y) { return 25.0 + 3.0 * std::sin(x / 10.0) * std::cos(y / 15.0); };
  for (double y = 10; y <= 70; y += 1.0)
    for (double x = 10; x < 90; x += 4) w->moves.push_back({b, {x, y, z(x, y)}, {x + 4, y, z(x + 4, y)}});
  return w;
}

// Machines all moves but the last `tail`.
geom::LbrSolid machine(const Workload& w, std::size_t tail) {
  geom::LbrSolid s(w.spec);
  for (std::size_t i = 0; i + tail < w.moves.size(); ++i) {
    const Move& m = w.moves[i];
    const geom::SweepRef ref{m.shape, geom::Pose{m.a}, geom::Pose{m.b}, static_cast<geom::MoveId>(i + 1)};
    s.subtract(std::span<const geom::SweepRef>(&ref, 1));
  }
  return s;
}

using Factory = std::unique_ptr<Workload> (*)();

void BM_FullBuild(benchmark::State& state, Factory make_w) {
  const auto w = make_w();
  const geom::LbrSolid s = machine(*w, 0);
  std::size_t tris = 0;
  double seconds = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    mesh::Reconstructor rec;
    rec.build(s);
    tris = rec.triangle_count();
    benchmark::DoNotOptimize(tris);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  const double iters = static_cast<double>(state.iterations());
  state.counters["regions"] = s.regions();
  state.counters["levels"] = s.levels();
  state.counters["triangles"] = static_cast<double>(tris);
  state.counters["tri_per_s"] = benchmark::Counter(static_cast<double>(tris) * iters, benchmark::Counter::kIsRate);
  // Wall time per region [ms], a plain number: an inverted rate counter would be printed
  // with Google Benchmark's unit "s" although the value is in ms (issue 19).
  state.counters["ms_per_region"] = 1e3 * seconds / (iters * s.regions());
}

// Incremental: the last moves of the program, one at a time, each followed by update().
void BM_IncrementalMove(benchmark::State& state, Factory make_w) {
  const auto w = make_w();
  const std::size_t tail = 8;
  const geom::LbrSolid base = machine(*w, tail);
  std::uint64_t levels = 0, planes = 0, moves = 0;
  double seconds = 0;
  for (auto _ : state) {
    state.PauseTiming();
    geom::LbrSolid s = base;
    mesh::Reconstructor rec;
    rec.build(s);
    s.clear_dirty();
    state.ResumeTiming();
    for (std::size_t i = w->moves.size() - tail; i < w->moves.size(); ++i) {
      state.PauseTiming();
      const Move& m = w->moves[i];
      const geom::SweepRef ref{m.shape, geom::Pose{m.a}, geom::Pose{m.b}, static_cast<geom::MoveId>(i + 1)};
      s.subtract(std::span<const geom::SweepRef>(&ref, 1));
      state.ResumeTiming();
      const auto t0 = std::chrono::steady_clock::now();
      const mesh::BuildStats st = rec.update(s);
      seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      s.clear_dirty();
      levels += st.levels_built;
      planes += st.planes_built;
      ++moves;
    }
  }
  state.counters["ms_per_move"] = 1e3 * seconds / static_cast<double>(moves);
  state.counters["dirty_levels_per_move"] = static_cast<double>(levels) / static_cast<double>(moves);
  state.counters["us_per_dirty_level"] = 1e6 * seconds / static_cast<double>(std::max<std::uint64_t>(levels, 1));
}

BENCHMARK_CAPTURE(BM_FullBuild, low_pocket, &low)->Unit(benchmark::kMillisecond)->MinTime(1.0);
BENCHMARK_CAPTURE(BM_FullBuild, medium_drill_islands, &medium)->Unit(benchmark::kMillisecond)->MinTime(1.0);
BENCHMARK_CAPTURE(BM_FullBuild, high_ball_raster, &high)->Unit(benchmark::kMillisecond)->MinTime(1.0);
BENCHMARK_CAPTURE(BM_IncrementalMove, low_pocket, &low)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(BM_IncrementalMove, medium_drill_islands, &medium)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(BM_IncrementalMove, high_ball_raster, &high)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
