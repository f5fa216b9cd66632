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

// The profile from its start, the cycle ending at its end (as LinuxCNC).
void add_profile(std::vector<ProfilePoint>& out, const std::vector<ProfilePoint>& profile) {
  out.push_back(pt(profile.front().level, profile.front().pass, true));
  for (std::size_t i = 1; i < profile.size(); ++i) out.push_back(profile[i]);
}

// Where a pass at `level` starts: on the line from the start point to the profile's start.
double entry(const ProfilePoint& start, const ProfilePoint& p0, double level) {
  if (std::abs(start.level - p0.level) < 1e-12) return start.pass;
  return p0.pass + (level - p0.level) / (start.level - p0.level) * (start.pass - p0.pass);
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
  const ProfilePoint& p0 = profile.front();
  if (s * (profile.back().level - p0.level) <= 0.0) {
    // A profile that does not run towards the start level gets no roughing passes from
    // LinuxCNC: across to the profile's start at the start level, fed to it, then along it.
    std::vector<ProfilePoint> out{pt(start.level, p0.pass, true), pt(p0.level, p0.pass, false)};
    for (std::size_t i = 1; i < profile.size(); ++i) out.push_back(profile[i]);
    return out;
  }
  std::vector<ProfilePoint> poly = profile;  // closed by the start level and the approach line
  poly.push_back(pt(start.level, profile.back().pass, false));
  poly.push_back(start);
  std::vector<ProfilePoint> out;
  for (long k = 0;; ++k) {
    const double l = start.level - s * increment * static_cast<double>(k);
    if (s * (l - far) <= 1e-9) break;
    if (k > kMaxPasses) throw std::invalid_argument("more than " + std::to_string(kMaxPasses) + " passes");
    const std::vector<double> c = crossings(poly, l - s * 1e-9);
    if (c.empty()) continue;
    if (c.size() != 2)
      throw std::invalid_argument("the profile is not monotonic (type 2 profiles are not in the built-in interpreter)");
    const double in = entry(start, profile.front(), l);
    const double end = std::abs(c[0] - in) > std::abs(c[1] - in) ? c[0] : c[1];
    const double back = end < in ? 1.0 : -1.0;  // retract at 45 degrees, back along the pass
    out.push_back(pt(l, in, true));
    out.push_back(pt(l, end, false));
    out.push_back(pt(l + s * retract, end + back * retract, true));
    out.push_back(pt(l + s * retract, in - back * retract, true));
    out.push_back(pt(l, in, true));
  }
  add_profile(out, profile);
  const ProfilePoint& pn = profile.back();  // the profile is closed to the start level
  if (std::abs(pn.level - start.level) > 1e-12) out.push_back(pt(start.level, pn.pass, false));
  return out;
}

std::vector<ProfilePoint> lathe_finishing(const std::vector<ProfilePoint>& profile, const ProfilePoint& start) {
  check_profile(profile);
  std::vector<ProfilePoint> out{pt(start.level, start.pass, true)};
  const ProfilePoint &p0 = profile.front(), &pn = profile.back();
  // A profile that runs back towards the start point along the pass axis is approached along
  // that axis first, at the start level (as rs274 does; a rule read from its output).
  if (std::abs(pn.pass - start.pass) < std::abs(p0.pass - start.pass)) out.push_back(pt(start.level, p0.pass, true));
  add_profile(out, profile);
  return out;
}

}  // namespace lbr::nc::detail
