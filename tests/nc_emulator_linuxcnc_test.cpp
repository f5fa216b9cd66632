// The emulator's planner against LinuxCNC's own trajectory planner: the same programs run on
// LinuxCNC's simulated machine (tests/linuxcnc_ref/run_ref.sh, headless, commanded joint
// positions every 1 ms servo period) and through the built-in interpreter + nc::Emulator with
// the same limits (200 mm/s, 1000 mm/s² per axis). Checks: cycle time within 3 %, every
// emulator sample within the case's tolerance of LinuxCNC's sampled path. Label linuxcnc
// (real time: about two minutes); skipped when LinuxCNC cannot start here. With
// LBR_LINUXCNC_REUSE set, the samples of the previous run are compared again.
// Table of results: docs/nc-frontend.md#linuxcnc-reference.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "nc/emulator.hpp"
#include "nc/gcode.hpp"
#include "nc_test_util.hpp"

namespace {

using namespace lbr::nc;
namespace fs = std::filesystem;

using P3 = std::array<double, 3>;

EmulatorLimits reference_limits() {
  EmulatorLimits l;
  l.rapid_mm_per_min = 12000;
  l.max_velocity = {12000, 12000, 12000, 3600, 3600, 3600};
  l.max_accel = {1000, 1000, 1000, 720, 720, 720};
  l.sample_period_ms = 1.0;
  return l;
}

fs::path work_dir() {
  fs::path d = fs::temp_directory_path() / "lbr_emulator_linuxcnc";
  fs::create_directories(d);
  return d;
}

// The first `lines` lines of a bundled benchmark program without tool changes and tool
// length (the simulator has no such tool), ended by M2.
std::string program_cut(const std::string& file, int lines) {
  std::ifstream in(std::string(LBR_SOURCE_DIR) + "/bench/programs/" + file);
  std::ostringstream out;
  std::string l;
  for (int n = 0; n < lines && std::getline(in, l); ++n) {
    if (l.rfind('T', 0) == 0 || l.find("G43") != std::string::npos || l == "%") continue;
    out << l << "\n";
  }
  out << "G0 Z5\nM2\n";
  return out.str();
}

struct Reference {
  bool ran = false;
  std::string why;          // when not ran
  std::vector<P3> samples;  // one per ms
};

Reference read_samples(const fs::path& file) {
  Reference r;
  std::ifstream in(file);
  long seq = 0;
  P3 p{};
  while (in >> seq >> p[0] >> p[1] >> p[2]) r.samples.push_back(p);
  r.ran = !r.samples.empty();
  if (!r.ran) r.why = "no samples in " + file.string();
  return r;
}

Reference run_linuxcnc(const fs::path& program) {
  Reference r;
  const fs::path out = work_dir() / (program.stem().string() + ".samples");
  const fs::path err = work_dir() / (program.stem().string() + ".err");
  const std::string cmd = std::string(LBR_SOURCE_DIR) + "/tests/linuxcnc_ref/run_ref.sh '" + program.string() + "' '" +
                          out.string() + "' 2> '" + err.string() + "'";
  int rc = std::system(cmd.c_str());
  if (rc != 0) rc = std::system(cmd.c_str());  // a loaded machine sometimes starts it too slowly
  if (rc != 0) {
    std::ifstream e(err);
    std::getline(e, r.why);
    if (r.why.empty()) r.why = "run_ref.sh exited with " + std::to_string(rc);
    return r;
  }
  return read_samples(out);
}

// The samples from the one before the first move to the last that moves (the recording
// starts seconds before the program and ends after it).
std::vector<P3> moving_span(const std::vector<P3>& s) {
  std::size_t first = 0, last = 0;
  for (std::size_t k = 1; k < s.size(); ++k) {
    if (s[k] == s[k - 1]) continue;
    if (last == 0) first = k - 1;
    last = k;
  }
  return last == 0 ? std::vector<P3>{} : std::vector<P3>(s.begin() + static_cast<long>(first), s.begin() + static_cast<long>(last) + 1);
}

double dist_to_segment(const P3& p, const P3& a, const P3& b) {
  double ab2 = 0, t = 0;
  for (int i = 0; i < 3; ++i) ab2 += (b[i] - a[i]) * (b[i] - a[i]), t += (p[i] - a[i]) * (b[i] - a[i]);
  t = ab2 > 0 ? std::clamp(t / ab2, 0.0, 1.0) : 0.0;
  double d2 = 0;
  for (int i = 0; i < 3; ++i) d2 += (a[i] + t * (b[i] - a[i]) - p[i]) * (a[i] + t * (b[i] - a[i]) - p[i]);
  return std::sqrt(d2);
}

// Largest distance of a sample of `a` from the polyline through `b`, searched near the same
// fraction of the run (both follow the same path in the same order).
double max_path_distance(const std::vector<P3>& a, const std::vector<P3>& b) {
  double worst = 0.0;
  const double scale = static_cast<double>(b.size()) / static_cast<double>(a.size());
  const long window = 500 + static_cast<long>(b.size()) / 20;
  for (std::size_t k = 0; k < a.size(); ++k) {
    const long c = static_cast<long>(static_cast<double>(k) * scale);
    const long lo = std::max(0L, c - window), hi = std::min(static_cast<long>(b.size()) - 1, c + window);
    double best = 1e300;
    for (long j = lo; j < hi; ++j) best = std::min(best, dist_to_segment(a[k], b[static_cast<std::size_t>(j)], b[static_cast<std::size_t>(j + 1)]));
    worst = std::max(worst, best);
  }
  return worst;
}

struct Case {
  const char* name;
  std::string program;
  double path_tol_mm;  // emulator samples vs LinuxCNC's path
};

void compare(const Case& c) {
  const fs::path file = work_dir() / (std::string(c.name) + ".ngc");
  std::ofstream(file) << c.program;
  // Once LinuxCNC failed to run here, the other cases skip at once instead of waiting for
  // their own timeouts (a hung simulator would otherwise hold the suite for minutes each).
  static std::string broken;
  if (!broken.empty()) GTEST_SKIP() << "LinuxCNC reference did not run: " << broken;
  const bool reuse = std::getenv("LBR_LINUXCNC_REUSE") != nullptr;
  Reference ref = reuse ? read_samples(work_dir() / (std::string(c.name) + ".samples")) : run_linuxcnc(file);
  // Now and then (a loaded machine) the simulator runs the program but its sampler records no
  // motion: the reference failed, not the emulator. Once more, then it counts as not run.
  if (ref.ran && moving_span(ref.samples).size() <= 1 && !reuse) ref = run_linuxcnc(file);
  if (ref.ran && moving_span(ref.samples).size() <= 1) ref = Reference{false, "the recording holds no motion", {}};
  if (!ref.ran) {
    broken = ref.why;
    GTEST_SKIP() << "LinuxCNC reference did not run: " << ref.why;
  }
  const Toolpath path = load_gcode(file.string(), GcodeOptions{});
  Emulator em(path, reference_limits());
  std::vector<P3> ours;
  Sample s;
  std::ofstream dump(work_dir() / (std::string(c.name) + ".emulated"));  // beside LinuxCNC's, for inspection
  while (em.next(s)) {
    ours.push_back({s.axes[X], s.axes[Y], s.axes[Z]});
    dump << s.seq << ' ' << s.axes[X] << ' ' << s.axes[Y] << ' ' << s.axes[Z] << '\n';
  }
  const std::vector<P3> theirs = moving_span(ref.samples);
  ASSERT_GT(theirs.size(), 1u) << "LinuxCNC did not move";
  const double t_ref = static_cast<double>(theirs.size() - 1) * 1e-3;
  const double t_emu = em.total_time_s();
  const double d = max_path_distance(ours, theirs);
  std::cout << "| " << c.name << " | " << t_ref << " | " << t_emu << " | " << 100.0 * (t_emu - t_ref) / t_ref
            << " % | " << d << " |\n";
  EXPECT_NEAR(t_emu, t_ref, 0.03 * t_ref) << c.name;
  EXPECT_LE(d, c.path_tol_mm) << c.name;
}

const char* kSquare = "G21 G90 G17\nG0 X0 Y0 Z0\nF1500\nG1 X50\nG1 Y50\nG1 X0\nG1 Y0\nM2\n";

TEST(EmulatorVsLinuxcnc, SquareG64P005) { compare({"square-g64", std::string("G64 P0.05\n") + kSquare, 0.06}); }

TEST(EmulatorVsLinuxcnc, SquareG61) { compare({"square-g61", std::string("G61\n") + kSquare, 0.01}); }

TEST(EmulatorVsLinuxcnc, Finish3dDense) { compare({"finish3d-cut", program_cut("finish3d.ngc", 1500), 0.05}); }

TEST(EmulatorVsLinuxcnc, PocketWithArcs) {
  const char* prog =
      "G21 G90 G17 G64 P0.02\nG0 X0 Y0 Z5\nG0 X20 Y20\nG1 Z-2 F600\nF1200\n"
      "G1 X60\nG3 X70 Y30 R10\nG1 Y50\nG3 X60 Y60 R10\nG1 X30\nG3 X20 Y50 R10\nG1 Y30\n"
      "G1 X25 Y25\nG1 X55\nG3 X65 Y35 I0 J10\nG1 Y45\nG2 X55 Y55 I-10 J0\nG1 X35\n"
      "G0 Z5\nG0 X45 Y40\nG1 Z-1 F600\nG2 X45 Y40 I-8 J0 F1200\nG3 X45 Y40 I-4 J0\n"
      "G2 X45 Y40 Z-3 I-6 J0\nG0 Z5\nM2\n";
  compare({"pocket-arcs", prog, 0.03});
}

TEST(EmulatorVsLinuxcnc, Drilling) {
  const char* prog =
      "G21 G90 G17 G64 P0.02\nG0 X0 Y0 Z10\nF300\nG98 G81 X10 Y10 Z-5 R2\nX30\nX50\nY30\n"
      "G99 G83 X10 Y30 Z-12 R2 Q3\nX30 Y50\nG80\nG0 Z10\nM2\n";
  compare({"drilling", prog, 0.03});
}

}  // namespace
