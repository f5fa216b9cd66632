// The moves of LinuxCNC's G70/G71/G72 lathe cycles (lathe_profile.hpp).
#include "lathe_profile.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace lbr::nc::detail {
namespace {

constexpr long kMaxPasses = 100000;

ProfilePoint pt(double level, double pass, bool rapid) {
  ProfilePoint p;
  p.level = level, p.pass = pass, p.rapid = rapid;
  return p;
}

// Where the line `level` crosses the closed region between the profile and the start level
// (half-open rule: an edge along the level does not cross it).
std::vector<double> crossings(const std::vector<ProfilePoint>& poly, double level) {
  std::vector<double> out;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const ProfilePoint& a = poly[i];
    const ProfilePoint& b = poly[(i + 1) % poly.size()];
    if ((a.level > level) == (b.level > level)) continue;
    const double t = (level - a.level) / (b.level - a.level);
    out.push_back(a.pass + t * (b.pass - a.pass));
  }
  std::sort(out.begin(), out.end());
  return out;
}

void add_profile(std::vector<ProfilePoint>& out, const std::vector<ProfilePoint>& profile, const ProfilePoint& start) {
  out.push_back(pt(profile.front().level, profile.front().pass, true));
  for (std::size_t i = 1; i < profile.size(); ++i) out.push_back(profile[i]);
  out.push_back(pt(start.level, profile.back().pass, true));
  out.push_back(pt(start.level, start.pass, true));
}

void check_profile(const std::vector<ProfilePoint>& profile) {
  if (profile.size() < 2) throw std::invalid_argument("the profile subroutine makes no move");
}

}  // namespace

std::vector<ProfilePoint> lathe_roughing(const std::vector<ProfilePoint>& profile, const ProfilePoint& start,
                                         double increment, double retract) {
  check_profile(profile);
  if (!(increment > 0.0)) throw std::invalid_argument("I (cut increment) must be > 0");
  double lo = profile.front().level, hi = lo;
  for (const ProfilePoint& p : profile) lo = std::min(lo, p.level), hi = std::max(hi, p.level);
  double s = 0.0;  // direction from the profile to the start level
  if (start.level >= hi - 1e-9) s = 1.0;
  else if (start.level <= lo + 1e-9) s = -1.0;
  else throw std::invalid_argument("the start point lies within the profile's range across the passes");
  const double far = s > 0 ? lo : hi;
  std::vector<ProfilePoint> poly = profile;
  poly.push_back(pt(start.level, profile.back().pass, false));
  poly.push_back(pt(start.level, profile.front().pass, false));
  std::vector<ProfilePoint> out;
  for (long k = 1;; ++k) {
    const double l = start.level - s * increment * static_cast<double>(k);
    if (s * (l - far) <= 1e-9) break;
    if (k > kMaxPasses) throw std::invalid_argument("more than " + std::to_string(kMaxPasses) + " passes");
    const std::vector<double> c = crossings(poly, l);
    if (c.empty()) continue;
    if (c.size() != 2)
      throw std::invalid_argument("the profile is not monotonic (type 2 profiles are not in the built-in interpreter)");
    const double end = std::abs(c[0] - start.pass) > std::abs(c[1] - start.pass) ? c[0] : c[1];
    out.push_back(pt(l, start.pass, true));
    out.push_back(pt(l, end, false));
    out.push_back(pt(l + s * retract, end, true));
    out.push_back(pt(l + s * retract, start.pass, true));
  }
  out.push_back(pt(start.level, start.pass, true));
  add_profile(out, profile, start);
  return out;
}

std::vector<ProfilePoint> lathe_finishing(const std::vector<ProfilePoint>& profile, const ProfilePoint& start) {
  check_profile(profile);
  std::vector<ProfilePoint> out;
  add_profile(out, profile, start);
  return out;
}

}  // namespace lbr::nc::detail
