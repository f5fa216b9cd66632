// Helpers shared by the nc tests.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "nc/gcode.hpp"
#include "nc/toolpath.hpp"

#ifndef LBR_SOURCE_DIR
#error "LBR_SOURCE_DIR must be defined by the build (tests/CMakeLists.txt)"
#endif

namespace lbr::test {

// Rapid/feed end points of a tool path (dwells and tool changes left out).
inline std::vector<nc::AxisVector> ends(const nc::Toolpath& tp) {
  std::vector<nc::AxisVector> v;
  for (const nc::Segment& s : tp.segments)
    if (s.kind == nc::SegmentKind::Rapid || s.kind == nc::SegmentKind::Feed) v.push_back(s.end);
  return v;
}

// One mutation of the interpreters' seeded mutation tests: 1–6 random edits of `s` (delete,
// insert or replace a character of `alphabet`, or duplicate a piece of s).
template <class Rng>
void mutate(std::string& s, Rng& rng, const std::string& alphabet) {
  const int edits = 1 + static_cast<int>(rng() % 6);
  for (int e = 0; e < edits && !s.empty(); ++e) {
    const std::size_t pos = rng() % s.size();
    switch (rng() % 4) {
      case 0: s.erase(pos, 1 + rng() % 3); break;
      case 1: s.insert(pos, 1, alphabet[rng() % alphabet.size()]); break;
      case 2: s[pos] = alphabet[rng() % alphabet.size()]; break;
      default: s.insert(pos, s.substr(rng() % s.size(), rng() % 12)); break;
    }
  }
}

// A bundled part program (config/programs/NAME).
inline std::string program_file(const std::string& name) { return std::string(LBR_SOURCE_DIR) + "/config/programs/" + name; }

// Distance of p from the segment a–b in axis space (all nc::kAxes axes).
inline double axis_dist_to_segment(const nc::AxisVector& p, const nc::AxisVector& a, const nc::AxisVector& b) {
  double ab2 = 0, t = 0;
  for (int i = 0; i < nc::kAxes; ++i) {
    ab2 += (b[i] - a[i]) * (b[i] - a[i]);
    t += (p[i] - a[i]) * (b[i] - a[i]);
  }
  t = ab2 > 0 ? std::clamp(t / ab2, 0.0, 1.0) : 0.0;
  double d2 = 0;
  for (int i = 0; i < nc::kAxes; ++i) {
    const double q = a[i] + t * (b[i] - a[i]) - p[i];
    d2 += q * q;
  }
  return std::sqrt(d2);
}

// Every vertex of `a` lies within tol of `b`'s polyline, visited in order. Returns the
// largest distance seen, or +inf when a vertex has no match.
inline double directed_distance(const nc::Toolpath& a, const nc::Toolpath& b, double tol) {
  std::size_t j = 0;
  nc::AxisVector bfrom = b.start;
  double worst = 0.0;
  for (const nc::Segment& s : a.segments) {
    if (s.kind != nc::SegmentKind::Rapid && s.kind != nc::SegmentKind::Feed) continue;
    std::size_t k = j;
    nc::AxisVector from = bfrom;
    bool found = false;
    for (; k < b.segments.size(); ++k) {
      const double d = axis_dist_to_segment(s.end, from, b.segments[k].end);
      if (d <= tol) {
        worst = std::max(worst, d);
        found = true;
        break;
      }
      from = b.segments[k].end;
    }
    if (!found) {
      ADD_FAILURE() << "vertex of line " << s.line << " (" << s.end[nc::X] << ", " << s.end[nc::Y] << ", " << s.end[nc::Z]
                    << ") is not on the other path";
      return INFINITY;
    }
    j = k;
    bfrom = from;
  }
  return worst;
}

// The built-in interpreter on a program text (named t.ngc in messages).
inline nc::Toolpath run(const std::string& text, nc::GcodeOptions o = {}) { return nc::interpret_gcode(text, "t.ngc", o); }

// The interpreter's error message for a program text, or "<no error>".
inline std::string error_of(const std::string& text, nc::GcodeOptions o = {}) {
  try {
    (void)nc::interpret_gcode(text, "t.ngc", o);
  } catch (const nc::ParseError& e) {
    return e.what();
  }
  return "<no error>";
}

}  // namespace lbr::test
