// Throughput of the NC front ends and the machine emulator (results: docs/performance.md).
//   bench_nc_frontend [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <sstream>
#include <string>

#include "nc/emulator.hpp"
#include "nc/gcode.hpp"
#include "nc/rs274.hpp"

namespace {

using namespace lbr::nc;

GcodeOptions options() {
  GcodeOptions o;
  o.tool_lengths = {{1, 60}, {2, 50}, {3, 70}};
  o.work_offsets[0] = {0, 0, -250, 0, 0, 0};
  return o;
}

// A CAM-like program of `n` lines: zig-zag feeds with a small arc at every turn.
std::string synthetic_program(int n) {
  std::ostringstream p;
  p << "G21 G90 G17 G94\nT1 M6\nG43 H1 G0 X0 Y0 Z5\nG1 Z-1 F800\n";
  for (int i = 0; i < n; ++i) {
    const double y = 0.5 * (i / 2);
    if (i % 2 == 0) p << "G1 X" << (i % 4 == 0 ? 100 : 0) << " Y" << y << " F1500\n";
    else p << "G" << (i % 4 == 1 ? 3 : 2) << " X" << (i % 4 == 1 ? 100 : 0) << " Y" << y + 0.5 << " R0.25\n";
  }
  p << "M30\n";
  return p.str();
}

std::string synthetic_canon(int n) {
  std::ostringstream c;
  c << "    1 N..... USE_LENGTH_UNITS(CANON_UNITS_MM)\n    2 N1     SET_FEED_RATE(1500.0000)\n";
  char line[160];
  for (int i = 0; i < n; ++i) {
    std::snprintf(line, sizeof line, "%5d N%-5d STRAIGHT_FEED(%.4f, %.4f, -1.0000, 0.0000, 0.0000, 0.0000)\n", i + 3,
                  i + 2, (i % 2) * 100.0, 0.5 * i);
    c << line;
  }
  return c.str();
}

void BM_InterpretSynthetic(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const std::string text = synthetic_program(n);
  const GcodeOptions o = options();
  std::size_t segments = 0;
  for (auto _ : state) {
    const Toolpath tp = interpret_gcode(text, "synthetic.ngc", o);
    segments = tp.segments.size();
    benchmark::DoNotOptimize(segments);
  }
  state.counters["lines/s"] = benchmark::Counter(n + 5, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["segments"] = static_cast<double>(segments);
}
BENCHMARK(BM_InterpretSynthetic)->Arg(100000)->Unit(benchmark::kMillisecond);

void BM_InterpretCamPocket(benchmark::State& state) {
  const std::string text = read_text_file(std::string(LBR_SOURCE_DIR) + "/config/programs/cam-pocket.ngc");
  const long lines = static_cast<long>(std::count(text.begin(), text.end(), '\n'));
  const GcodeOptions o = options();
  for (auto _ : state) benchmark::DoNotOptimize(interpret_gcode(text, "cam-pocket.ngc", o));
  state.counters["lines/s"] = benchmark::Counter(static_cast<double>(lines), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_InterpretCamPocket)->Unit(benchmark::kMicrosecond);

void BM_ParseRs274Canon(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const std::string text = synthetic_canon(n);
  const GcodeOptions o = options();
  for (auto _ : state) benchmark::DoNotOptimize(parse_rs274_canon(text, "canon", o));
  state.counters["lines/s"] = benchmark::Counter(n, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_ParseRs274Canon)->Arg(100000)->Unit(benchmark::kMillisecond);

EmulatorLimits limits() {
  EmulatorLimits l;
  l.max_velocity = {15000, 15000, 10000, 3600, 3600, 3600};
  l.max_accel = {2000, 2000, 1500, 720, 720, 720};
  l.sample_period_ms = 1.0;
  return l;
}

// Real-time path: one next() per sample (the emulator is rewound when it runs out).
void BM_EmulatorNext(benchmark::State& state) {
  const Toolpath tp = load_gcode(std::string(LBR_SOURCE_DIR) + "/config/programs/cam-pocket.ngc", options());
  Emulator em(tp, limits());
  Sample s;
  for (auto _ : state) {
    if (!em.next(s)) {
      em.reset();
      (void)em.next(s);
    }
    benchmark::DoNotOptimize(s);
  }
  state.counters["samples/s"] = benchmark::Counter(1, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_EmulatorNext);

void BM_EmulatorPlan(benchmark::State& state) {
  const Toolpath tp = interpret_gcode(synthetic_program(100000), "synthetic.ngc", options());
  for (auto _ : state) benchmark::DoNotOptimize(Emulator(tp, limits()).total_time_s());
  state.counters["segments/s"] =
      benchmark::Counter(static_cast<double>(tp.segments.size()), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_EmulatorPlan)->Unit(benchmark::kMillisecond);

}  // namespace
