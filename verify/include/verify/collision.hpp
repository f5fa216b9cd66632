// verify/collision.hpp — collision and process checks of each move against the stock as it
// is at that moment (docs/verification.md).
//
// Checks: a rapid sweep that removes material (rapid-into-material); the non-cutting parts
// of a milling tool, the shank (between the flutes' end and the gauge length, at the shank
// diameter) and the holder (from the gauge length up, at the holder diameter), meeting
// material (shank-in-material, holder-in-material), and the spindle nose above the holder
// (spindle-nose-in-material, [checks] spindle_nose_*); the tool just loaded standing in
// material (tool-change-in-material); a cutting sweep that removes material
// while the segment's spindle is off (spindle-off) or faster than the feed limit
// (feed-limit); the centre core of a non-centre-cutting tool meeting material on a descent
// steeper than the ramp limit (plunge-non-centre-cutting). Turning moves (geom::LatheSweep)
// go through the same checks of the cutting sweep (rapid, spindle off, feed limit) and
// their holder ([[tool]] holder_width_mm …) through holder-in-material.
// check_travel() checks a tool path's axis positions against the machine's travel.
//
// The batch runner asks `check()` before subtracting a batch of moves. The stock before the
// batch holds at least the material present at any move of it (cutting only removes), so a
// move found clean against it is clean at its own moment. A move that meets material and is
// not the first of the batch is not judged: `check()` returns its index, the caller
// subtracts the moves before it and asks again, so every event is measured against the
// exact stock of its moment and clean programs pay no extra kernel calls.
//
// Setup-time and batch-time code: allocates; not for the real-time path.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "geom/lbr_solid.hpp"
#include "motion/path_sweeps.hpp"
#include "motion/tool_table.hpp"
#include "nc/toolpath.hpp"
#include "verify/events.hpp"
#include "verify/intrusion.hpp"

namespace lbr::verify {

struct CheckConfig {
  bool enabled = true;
  // Material closer than this to a sweep's boundary is not a finding: a rapid or a holder
  // may graze a wall by less (chord tolerance of two polygonised circles, cusps) [mm].
  double tolerance_mm = 0.01;
  // feed-limit: feed moves faster than this that remove material [mm/min]; 0: not checked.
  double max_cutting_feed_mm_per_min = 0.0;
  // plunge-non-centre-cutting: a descent along the tool axis steeper than this (from the
  // plane normal to the axis) is a plunge [deg].
  double max_ramp_angle_deg = 3.0;
  // spindle-nose-in-material: the spindle nose, a cylinder of this diameter and length from
  // the holder's top face (tip + length_mm + holder_length_mm) up the tool axis; the same for
  // every tool (a machine part, e.g. a mill5 head's nose) [mm]; diameter 0: not checked.
  double spindle_nose_diameter_mm = 0.0;
  double spindle_nose_length_mm = 0.0;
};

// A sampled stream has no G0 (live mode, batch --sampled): a step is a rapid when it moves the
// tip faster than kFastMargin times rapid_threshold_mm_per_min() — the emulator caps feeds at
// the limit exactly and sampled positions carry rounding (docs/verification.md#live).
inline constexpr double kFastMargin = 1.05;
// The profile's max cutting feed: `max_feed_mm_per_min` ([machine] max_feed_mm_per_min), or
// half of `rapid_mm_per_min` when the profile sets no feed cap (0) [mm/min].
[[nodiscard]] inline double rapid_threshold_mm_per_min(double max_feed_mm_per_min, double rapid_mm_per_min) noexcept {
  return max_feed_mm_per_min > 0.0 ? max_feed_mm_per_min : 0.5 * rapid_mm_per_min;
}

// The centre core of a non-centre-cutting tool (the part of the end face that does not cut)
// is taken as this fraction of its cutting diameter (docs/verification.md).
inline constexpr double kNonCuttingCoreFraction = 0.25;

// Which program segment made a move: move ids → (source, segment), for the ids the batch
// runner gives (docs/formats.md#move-ids): a path's segments get ids base + index + 1.
class MoveIndex {
 public:
  // Ids base + 1 .. base + path.segments.size() belong to `path` (kept by reference).
  void add(const nc::Toolpath& path, geom::MoveId base);
  // The segment of move `id` and its program, or null when the id is not known.
  [[nodiscard]] const nc::Segment* find(geom::MoveId id, const std::string** source) const noexcept;

 private:
  struct Range {
    geom::MoveId base;
    const nc::Toolpath* path;
  };
  std::vector<Range> ranges_;  // ascending base
};

class CollisionChecker {
 public:
  // Builds the shank and holder shapes of every milling tool of `tools` (which must outlive
  // the checker) and the holders of its turning tools that have one.
  CollisionChecker(const CheckConfig& config, const motion::ToolTable& tools, const MoveIndex& index);

  // Checks moves [from, to) against `solid`, the stock just before moves[from]. Returns the
  // index of the first move after `from` that starts a run of findings (it meets material
  // and the move before it raised other kinds or none; its check must be repeated once the
  // moves before it are subtracted), or `to` when there is none. Findings of moves[from],
  // of the clean moves and of the moves that continue a run (the same kinds as the move
  // before them) are final and go to `events`: a run of offending moves is measured against
  // the stock at the start of its batch, so a program that forgets G43 costs a few batches,
  // not one batch per move. Such a move is tested for contact only (the probe stops at the
  // first level it meets): it adds to the run's `moves` and `last_line`, not to its volume
  // or depth (docs/verification.md, "Runs of findings").
  std::size_t check(const geom::LbrSolid& solid, std::span<const motion::TimedSweep> moves, std::size_t from,
                    std::size_t to, std::vector<Event>& events);
  // The same for a live sample stream, which has no program to tell rapids by: moves[i] is
  // a rapid when rapid[i] is non-zero (the caller's speed test, docs/verification.md#live).
  // `runs` false (live: sub-batches are short and each event is timed against its sweep):
  // every sweep after the first that meets material ends the call, so only moves[from] can
  // have findings. `runs` true (the batch runner, also for --sampled): as the first check().
  std::size_t check(const geom::LbrSolid& solid, std::span<const motion::TimedSweep> moves,
                    std::span<const std::uint8_t> rapid, std::size_t from, std::size_t to, std::vector<Event>& events,
                    bool runs = false);

  // After check(…, runs = true) whose moves [from, end) were subtracted: a run of the cutting
  // sweep's own kinds (rapid-into-material, spindle-off, feed-limit) that continued past
  // moves[from] ends its batch, and its events take `removed_mm3`, the volume the kernel
  // removed for those moves, in place of the lower bound the contact tests give (the first
  // move's measured volume is replaced, not added twice). `whole` false (the caller subtracted
  // fewer moves than check() returned): nothing changes. Either way the pending run is dropped.
  void settle(double removed_mm3, bool whole, std::vector<Event>& events);
  [[nodiscard]] const CheckConfig& config() const noexcept { return config_; }

 private:
  struct Parts {
    geom::CutterShape shank, holder, core, nose;
    double shank_from_mm = 0.0;   // shank bottom above the tip [mm]
    double holder_from_mm = 0.0;  // holder face above the tip [mm]
    double nose_from_mm = 0.0;    // spindle nose face above the tip [mm]
    bool has_shank = false;
    bool has_nose = false;        // [checks] spindle_nose_diameter_mm set
    bool centre_cutting = true;   // false: `core` is the end face's non-cutting centre
    // The cutting part moved inwards by the probe margin, normal to its surface, with its tip
    // `inner_raise_mm` up the axis: the deep test of the cutting sweep (IntrusionProbe).
    geom::CutterShape inner;
    double inner_raise_mm = 0.0;
    double inner_margin_mm = 0.0;  // the margin it is moved inwards by
    bool has_inner = false;       // false: the tool is too small for it (a margin in the plane)
  };
  // A turning tool's holder: its shape and where it sits from the insert's reference point.
  struct InsertHolder {
    geom::TurningShape shape;
    geom::TurningShape::P2 offset{0.0, 0.0};  // holder reference - insert reference (r, z) [mm]
  };
  struct Finding {
    EventKind kind;
    Intrusion what;
    double value = 0.0;  // Event::value
  };
  // Both check()s; `runs`: moves that continue a run of findings stay in the batch.
  std::size_t check_moves(const geom::LbrSolid& solid, std::span<const motion::TimedSweep> moves,
                          std::span<const std::uint8_t> rapid, std::size_t from, std::size_t to,
                          std::vector<Event>& events, bool runs);
  static constexpr int kMaxFindings = 7;
  bool contact_only_ = false;  // check(): the move continues a run (IntrusionProbe::measure)
  // The last check()'s run of the cutting sweep's kinds: its length from moves[from] (0: none),
  // and each of moves[from]'s events of those kinds with the volume it measured (settle()).
  std::size_t run_moves_ = 0;
  std::vector<std::pair<std::size_t, double>> settle_;
  using Findings = Finding[kMaxFindings];
  // The findings of one move against `solid`; returns how many were written. `rapid`: 1 / 0
  // the move is / is not a rapid, -1 the move's program segment tells.
  int findings_of(const geom::LbrSolid& solid, const motion::TimedSweep& m, int rapid, Findings& out);
  // tool-change-in-material: when `m` is its channel's first milling move with a tool other
  // than the one before, the new tool standing at the move's start (a sweep of no length),
  // written to out[n]; returns the new count.
  int tool_change_finding(const geom::LbrSolid& solid, const motion::TimedSweep& m, Findings& out, int n);
  // Rapid, spindle-off and feed-limit (the cutting sweep; spindle and feed need the move's
  // program segment `seg`, which live streams lack: null), written from out[n]; returns the
  // new count.
  int segment_findings(const geom::LbrSolid& solid, const motion::TimedSweep& m, const nc::Segment* seg, int rapid,
                       Findings& out, int n);
  // The material a move's cutting sweep (milling or turning) meets.
  [[nodiscard]] Intrusion cutting_intrusion(const geom::LbrSolid& solid, const motion::TimedSweep& m);
  // The material the tool of `m` meets swept from `from` to `to`, its deep test by the inner
  // tool (Parts::inner) where it has one.
  [[nodiscard]] Intrusion tool_intrusion(const geom::LbrSolid& solid, const motion::TimedSweep& m, const geom::Pose& from,
                                         const geom::Pose& to);
  // A turning move's holder, written to out[n]; returns the new count.
  int holder_finding(const geom::LbrSolid& solid, const motion::TimedSweep& m, const InsertHolder& h, Findings& out,
                     int n);
  // Plunge (the non-cutting core), shank, holder and spindle nose, written from out[n];
  // returns the new count.
  int part_findings(const geom::LbrSolid& solid, const motion::TimedSweep& m, const Parts& p, Findings& out, int n);
  // A part's cylinder swept with the move, raised `from_mm` along the tool axis: its finding.
  bool raised_finding(const geom::LbrSolid& solid, const motion::TimedSweep& m, const geom::CutterShape& part,
                      double from_mm, EventKind kind, Finding& out);
  [[nodiscard]] Event event_of(const motion::TimedSweep& m, const Finding& f) const;

  // Per channel, the tool of the last move judged (-1: none yet; channels from kChannels on
  // are not followed). Fixed storage: the live checks run on the geometry thread.
  static constexpr int kChannels = 16;
  std::array<int, kChannels> last_tool_{};
  CheckConfig config_;
  const MoveIndex& index_;
  std::map<int, Parts> parts_;
  std::map<int, InsertHolder> holders_;  // turning tools with a holder
  IntrusionProbe probe_;
};

// over-travel: appends an event for every run of motion segments of `path` (channel
// `channel`, move ids base + index + 1) whose end lies outside [min, max] on an axis, in
// machine coordinates (nc::machine_axes): the axis, the distance beyond the limit (the
// run's largest) and the tool tip. The tool path alone decides, so it runs before the cut.
void check_travel(const nc::Toolpath& path, const nc::AxisVector& min, const nc::AxisVector& max, int channel,
                  geom::MoveId base, std::vector<Event>& events);

}  // namespace lbr::verify
