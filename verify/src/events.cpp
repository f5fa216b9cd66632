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
    case EventKind::SpindleOff: return "spindle-off";
    case EventKind::Plunge: return "plunge-non-centre-cutting";
    case EventKind::FeedLimit: return "feed-limit";
    case EventKind::OverTravel: return "over-travel";
    case EventKind::DesignGouge: return "design-gouge";
    case EventKind::SpindleNoseInMaterial: return "spindle-nose-in-material";
    case EventKind::ToolChangeInMaterial: return "tool-change-in-material";
  }
  return "?";
}

const char* to_string(Severity s) noexcept { return s == Severity::Error ? "error" : "warning"; }

Severity severity_of(EventKind k) noexcept {
  switch (k) {
    case EventKind::RapidIntoMaterial:
    case EventKind::ShankInMaterial:
    case EventKind::HolderInMaterial:
    case EventKind::SpindleOff:
    case EventKind::Plunge:
    case EventKind::OverTravel:
    case EventKind::DesignGouge:
    case EventKind::SpindleNoseInMaterial:
    case EventKind::ToolChangeInMaterial: return Severity::Error;
    case EventKind::FeedLimit: return Severity::Warning;
  }
  return Severity::Error;
}

std::string axis_name(int axis) {
  constexpr char kAxisLetters[] = "XYZABC";
  return axis >= 0 && axis < 6 ? std::string(1, kAxisLetters[axis]) : std::string();
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
      "depth_mm,region,axis,value\n";
  char buf[512];
  for (const Event& e : events) {
    out += to_string(e.kind);
    out += ',';
    out += to_string(e.severity());
    out += ',';
    std::snprintf(buf, sizeof buf, "%.4f,", e.t_s);
    out += buf;
    out += csv_field(e.source);
    std::snprintf(buf, sizeof buf, ",%d,%d,%" PRIu64 ",%u,%u,%d,%d,%.4f,%.4f,%.4f,%.4f,%.4f,%d,", e.line,
                  e.last_line, e.moves, e.move, e.last_move, e.tool, e.channel, e.position.x, e.position.y,
                  e.position.z, e.volume_mm3, e.depth_mm, e.region);
    out += buf;
    out += axis_name(e.axis);
    std::snprintf(buf, sizeof buf, ",%.4f\n", e.value);
    out += buf;
  }
  return out;
}

namespace {

// The figures of an event for a person: the material met, and the kind's own value.
std::string figures(const Event& e) {
  char buf[160];
  switch (e.kind) {
    case EventKind::OverTravel:
      std::snprintf(buf, sizeof buf, ", %s %.3f %s beyond its travel", axis_name(e.axis).c_str(), e.value,
                    e.axis >= 3 ? "deg" : "mm");
      return buf;
    case EventKind::FeedLimit: std::snprintf(buf, sizeof buf, ", feed %.1f mm/min", e.value); break;
    case EventKind::Plunge: std::snprintf(buf, sizeof buf, ", descending at %.1f deg", e.value); break;
    case EventKind::SpindleOff: std::snprintf(buf, sizeof buf, ", S%.0f", e.value); break;
    default: buf[0] = '\0'; break;
  }
  std::string s = buf;
  std::snprintf(buf, sizeof buf, ", %.3f mm3 of material, %.3f mm deep", e.volume_mm3, e.depth_mm);
  return s + buf;
}

}  // namespace

std::string describe(const Event& e) {
  std::string where = e.source.empty() ? "sample " + std::to_string(e.move) : e.source;
  if (!e.source.empty() && e.line > 0) where += ":" + std::to_string(e.line);
  char buf[256];
  std::snprintf(buf, sizeof buf, ": %s: %s: tool %d, %" PRIu64 " move%s", to_string(e.severity()), to_string(e.kind),
                e.tool, e.moves, e.moves == 1 ? "" : "s");
  std::string s = where + buf;
  if (e.moves > 1 && e.last_line > e.line) s += " (to line " + std::to_string(e.last_line) + ")";
  s += figures(e);
  std::snprintf(buf, sizeof buf, ", at X%.3f Y%.3f Z%.3f", e.position.x, e.position.y, e.position.z);
  return s + buf;
}

std::size_t add_event(std::vector<Event>& events, const Event& e) {
  // One move can raise several kinds at once (shank and holder), so the run to extend is
  // looked for among the last few events.
  constexpr std::size_t kKinds = 7;  // the kinds one move can raise in CollisionChecker::check()
  for (std::size_t back = 0; back < std::min(kKinds, events.size()); ++back) {
    Event& last = events[events.size() - 1 - back];
    const bool follows = e.move == last.last_move || e.move == last.last_move + 1;
    if (last.kind != e.kind || last.tool != e.tool || last.channel != e.channel || last.axis != e.axis || !follows)
      continue;
    if (e.move != last.last_move) ++last.moves;
    last.last_move = e.move;
    last.last_line = e.line;
    last.volume_mm3 += e.volume_mm3;
    last.depth_mm = std::max(last.depth_mm, e.depth_mm);
    last.value = std::max(last.value, e.value);
    return events.size() - 1 - back;
  }
  Event first = e;
  first.last_move = e.move;
  first.last_line = e.line;
  events.push_back(first);
  return events.size() - 1;
}

}  // namespace lbr::verify
