// Corpus test (label corpus): every G-code program that Debian's linuxcnc-uspace ships and that
// LinuxCNC's own interpreter (rs274) accepts also runs through the built-in interpreter, and
// `lbrsim batch` on the default profile removes the same volume (within 0.1 %) from both tool
// paths, or refuses both for the same reason (e.g. a tool the profile lacks). Programs that
// need something the built-in interpreter refuses on purpose are listed with the reason in
// tests/data/nc_corpus_exclusions.txt. Skipped when linuxcnc-uspace is not installed.
//
// To fit CI time the kernel runs at Δ = 0.5 mm (the default is 0.1 mm) on one thread: both
// tool paths cut the same stock at the same levels, so the comparison stays exact for the
// question asked (do the two front ends describe the same motion?).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "app/batch.hpp"
#include "app/outputs.hpp"
#include "app/profile.hpp"
#include "nc/gcode.hpp"
#include "nc/rs274.hpp"

namespace {

using namespace lbr;

std::vector<std::string> corpus_files() {
  std::vector<std::string> files;
  FILE* p = ::popen("dpkg -L linuxcnc-uspace 2>/dev/null | grep '\\.ngc$' | sort", "r");
  if (p == nullptr) return files;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, p) != nullptr) {
    std::string s(buf);
    while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
    if (!s.empty()) files.push_back(s);
  }
  ::pclose(p);
  return files;
}

// "path-suffix  reason" per line; '#' starts a comment line.
std::map<std::string, std::string> exclusions() {
  std::map<std::string, std::string> m;
  std::ifstream f(std::string(LBR_SOURCE_DIR) + "/tests/data/nc_corpus_exclusions.txt");
  std::string line;
  while (std::getline(f, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream in(line);
    std::string path, reason;
    in >> path;
    std::getline(in, reason);
    m[path] = reason;
  }
  return m;
}

const std::string* excluded(const std::map<std::string, std::string>& ex, const std::string& file) {
  for (const auto& [suffix, reason] : ex)
    if (file.size() >= suffix.size() && file.compare(file.size() - suffix.size(), suffix.size(), suffix) == 0)
      return &reason;
  return nullptr;
}

struct Outcome {
  bool ok = false;
  std::string error;
  double removed_mm3 = 0.0;
};

Outcome cut(const app::Profile& profile, const std::string& file, app::Interpreter interp) {
  Outcome o;
  try {
    const nc::Toolpath tp = app::load_toolpath(file, profile, interp);
    o.removed_mm3 = app::run_batch(profile, tp).removed_volume_mm3;
    o.ok = true;
  } catch (const std::exception& e) {
    o.error = e.what();
  }
  return o;
}

TEST(NcCorpus, LinuxCncSamplesAgreeWithRs274) {
  const std::vector<std::string> files = corpus_files();
  if (files.empty() || nc::find_rs274().empty()) GTEST_SKIP() << "linuxcnc-uspace (rs274 and its sample programs) is not installed";
  const auto ex = exclusions();
  app::Profile profile = app::default_profile();
  profile.solid.level_spacing_mm = 0.5;
  profile.threads = 1;
  int rs274_ok = 0, builtin_ok = 0, agree = 0, skipped = 0;
  for (const std::string& f : files) {
    const Outcome rs = cut(profile, f, app::Interpreter::Rs274);
    if (!rs.ok && rs.error.find("rs274:") != std::string::npos) continue;  // LinuxCNC refuses it too
    ++rs274_ok;
    const Outcome bi = cut(profile, f, app::Interpreter::Builtin);
    if (bi.ok) ++builtin_ok;
    if (excluded(ex, f) != nullptr) {
      ++skipped;
      continue;
    }
    SCOPED_TRACE(f);
    if (!rs.ok) {
      EXPECT_FALSE(bi.ok) << "rs274 path refused by the batch (" << rs.error << "), built-in accepted";
      ++agree;
      continue;
    }
    if (!bi.ok) {
      ADD_FAILURE() << "built-in interpreter refuses what rs274 accepts: " << bi.error;
      continue;
    }
    const double tol = 1e-3 * std::max(rs.removed_mm3, bi.removed_mm3) + 1e-6;
    EXPECT_NEAR(bi.removed_mm3, rs.removed_mm3, tol);
    if (std::abs(bi.removed_mm3 - rs.removed_mm3) <= tol) ++agree;
  }
  std::printf("corpus: %zu files, %d accepted by rs274, %d of them by the built-in interpreter, %d agree, %d excluded\n",
              files.size(), rs274_ok, builtin_ok, agree, skipped);
  EXPECT_GT(rs274_ok, 100);
  EXPECT_EQ(agree + skipped, rs274_ok);
}

}  // namespace
