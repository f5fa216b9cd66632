#include "verify/events.hpp"

#include <algorithm>
#include <cinttypes>
#include <cstdio>

namespace lbr::verify {

const char* to_string(EventKind k) noexcept {
  switch (k) {
    case EventKind::RapidIntoMaterial: return "rapid-into-material";
    case EventKind::ShankInMaterial: return "shank-in-material";
    case EventKind::HolderInMaterial: return "holder-in-material";
  }
  return "?";
}

const char* to_string(Severity s) noexcept { return s == Severity::Error ? "error" : "warning"; }

Severity severity_of(EventKind k) noexcept {
  switch (k) {
    case EventKind::RapidIntoMaterial:
    case EventKind::ShankInMaterial:
    case EventKind::HolderInMaterial: return Severity::Error;
  }
  return Severity::Error;
}

EventCounts count(const std::vector<Event>& events) noexcept {
  EventCounts c;
  for (const Event& e : events) (e.severity() == Severity::Error ? c.errors : c.warnings) += 1;
  return c;
}

namespace {

// CSV field: quoted when it holds a comma, quote or line break (RFC 4180).
std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

}  // namespace

std::string events_csv(const std::vector<Event>& events) {
  std::string out =
      "kind,severity,time_s,source,line,last_line,moves,move,last_move,tool,channel,x_mm,y_mm,z_mm,volume_mm3,"
      "depth_mm,region\n";
  char buf[512];
  for (const Event& e : events) {
    out += to_string(e.kind);
    out += ',';
    out += to_string(e.severity());
    out += ',';
    std::snprintf(buf, sizeof buf, "%.4f,", e.t_s);
    out += buf;
    out += csv_field(e.source);
    std::snprintf(buf, sizeof buf, ",%d,%d,%" PRIu64 ",%u,%u,%d,%d,%.4f,%.4f,%.4f,%.4f,%.4f,%d\n", e.line,
                  e.last_line, e.moves, e.move, e.last_move, e.tool, e.channel, e.position.x, e.position.y,
                  e.position.z, e.volume_mm3, e.depth_mm, e.region);
    out += buf;
  }
  return out;
}

std::string describe(const Event& e) {
  std::string where = e.source.empty() ? "sample " + std::to_string(e.move) : e.source;
  if (!e.source.empty() && e.line > 0) where += ":" + std::to_string(e.line);
  char buf[256];
  std::snprintf(buf, sizeof buf, ": %s: %s: tool %d, %" PRIu64 " move%s", to_string(e.severity()), to_string(e.kind),
                e.tool, e.moves, e.moves == 1 ? "" : "s");
  std::string s = where + buf;
  if (e.moves > 1 && e.last_line > e.line) s += " (to line " + std::to_string(e.last_line) + ")";
  std::snprintf(buf, sizeof buf, ", %.3f mm3 of material, %.3f mm deep, at X%.3f Y%.3f Z%.3f", e.volume_mm3,
                e.depth_mm, e.position.x, e.position.y, e.position.z);
  return s + buf;
}

void add_event(std::vector<Event>& events, const Event& e) {
  // One move can raise several kinds at once (shank and holder), so the run to extend is
  // looked for among the last few events.
  constexpr std::size_t kKinds = 3;
  for (std::size_t back = 0; back < std::min(kKinds, events.size()); ++back) {
    Event& last = events[events.size() - 1 - back];
    const bool follows = e.move == last.last_move || e.move == last.last_move + 1;
    if (last.kind != e.kind || last.tool != e.tool || last.channel != e.channel || !follows) continue;
    if (e.move != last.last_move) ++last.moves;
    last.last_move = e.move;
    last.last_line = e.line;
    last.volume_mm3 += e.volume_mm3;
    last.depth_mm = std::max(last.depth_mm, e.depth_mm);
    return;
  }
  Event first = e;
  first.last_move = e.move;
  first.last_line = e.line;
  events.push_back(first);
}

}  // namespace lbr::verify
