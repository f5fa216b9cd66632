// verify/events.hpp — what the collision and process checks report (docs/verification.md).
//
// An Event is one finding: a kind, a severity, where in the program (file:line, or the
// sample sequence of a live stream), which move and tool, where on the part and how much
// material was involved. Consecutive moves with the same finding are one event (`moves`
// counts them, `last_line` is the last one's line): a program that forgets G43 raises one
// event per run of offending moves, not one per move.
//
// Plain value types and setup-time formatting; everything here may allocate.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "geom/types.hpp"

namespace lbr::verify {

enum class EventKind : unsigned char {
  RapidIntoMaterial,  // a rapid (G0) sweep removes material
  ShankInMaterial,    // the tool between the flutes' end and the holder face meets material
  HolderInMaterial,   // the tool holder meets material
  SpindleOff,         // a move removes material while the spindle is off (M5) or S is 0
  Plunge,             // a non-centre-cutting tool descends steeper than the ramp limit into material under its centre
  FeedLimit,          // a feed move removes material faster than [checks] max_cutting_feed_mm_per_min
  OverTravel,         // a move ends outside the machine's axis travel ([machine] travel_*)
  DesignGouge,        // the final stock lacks design material deeper than the design tolerance
  SpindleNoseInMaterial,  // the spindle nose above the holder ([checks] spindle_nose_*: mill5 heads) meets material
  ToolChangeInMaterial,   // the tool just loaded stands in material (a longer tool changed near the part)
};
enum class Severity : unsigned char { Warning, Error };

[[nodiscard]] const char* to_string(EventKind k) noexcept;  // "rapid-into-material", ...
[[nodiscard]] const char* to_string(Severity s) noexcept;   // "warning", "error"
[[nodiscard]] Severity severity_of(EventKind k) noexcept;

struct Event {
  EventKind kind = EventKind::RapidIntoMaterial;
  double t_s = 0.0;             // end time of the first offending move [s] (0: not timed)
  std::string source;           // program file (empty for a live stream)
  int line = 0;                 // 1-based source line of the first offending move (0: unknown)
  int last_line = 0;            // line of the last move of the run
  std::uint64_t moves = 1;      // consecutive offending moves merged into this event
  geom::MoveId move = 0;        // move id of the first offending move (sample sequence, live)
  geom::MoveId last_move = 0;   // move id of the last offending move of the run
  int tool = 0;
  int channel = 0;
  geom::Vec3 position;          // tool tip at the end of the first offending move [mm]
  double volume_mm3 = 0.0;      // material met, summed over the run [mm3]
  double depth_mm = 0.0;        // largest Z extent of the material met by one move [mm]
  int region = -1;              // stock region where the first move met the most material
  int axis = -1;                // over-travel: the axis (nc::Axis: 0..5 = X..C) that left its travel
  // The kind's own figure, the largest of the run: spindle-off the S word in effect;
  // plunge the descent angle from the plane normal to the tool axis [deg]; feed-limit the
  // programmed feed [mm/min]; over-travel the distance beyond the limit [mm | deg].
  double value = 0.0;
  [[nodiscard]] Severity severity() const noexcept { return severity_of(kind); }
};

// The letter of Event::axis ("X" .. "C"), or "" when it has none.
[[nodiscard]] std::string axis_name(int axis);

// Counts of a list of events by severity.
struct EventCounts {
  std::size_t errors = 0, warnings = 0;
};
[[nodiscard]] EventCounts count(const std::vector<Event>& events) noexcept;

// The events as CSV, one line each after a header (columns in docs/verification.md).
[[nodiscard]] std::string events_csv(const std::vector<Event>& events);
// One line for a person: "FILE:LINE: error: shank-in-material: tool 1, 12 moves, 341.2 mm3 ...".
[[nodiscard]] std::string describe(const Event& e);

// Appends `e` to `events`, or merges it into one of the last events (one move may raise
// several kinds) when that one is the same kind, tool, channel and axis and `e`'s move follows
// its last move directly (same id: another sub-step
// of a rotary move; id + 1: the next segment or sample).
// Returns the index of the event `e` went to.
std::size_t add_event(std::vector<Event>& events, const Event& e);

}  // namespace lbr::verify
