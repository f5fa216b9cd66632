// gfx/exchange.hpp — the hand-over from the geometry thread to the render thread
// (docs/rendering.md §1). No OpenGL here; app/ (live pipeline) and gfx/ both use it.
//
// Contract:
//  * The geometry thread owns the LbrSolid. Between two subtract() batches — the only time
//    the solid is consistent — it calls publish(). publish() never waits: if the render
//    thread has not yet taken the previous snapshot, it returns false at the cost of one
//    atomic load and the solid's dirty set keeps accumulating, so nothing is lost; the
//    next successful publish() carries every cell changed since the last one.
//  * A successful publish() copies the dirty cells (and tool poses, new path points, live
//    counters) into the single slot, clears the solid's dirty set and hands the slot over
//    with a release store. The exchange is therefore THE consumer of the solid's dirty set
//    on the live path: nothing else may call clear_dirty() on that solid.
//  * The render thread calls take() once per frame: if a snapshot is ready it swaps the
//    slot's buffers with its own (O(1)) and hands the slot back, so the slot is busy for a
//    few microseconds only. The render side keeps its own mirror solid (gfx::MeshMirror).
// One writer thread and one reader thread; no locks, no waiting on either side.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <span>
#include <vector>

#include "geom/lbr_solid.hpp"

namespace lbr::gfx {

// A tool at its current pose, for drawing. Dimensions [mm].
struct ToolState {
  int channel = 0;
  int tool = 0;            // tool number (0 = none loaded)
  geom::Pose pose;         // tip and axis, workpiece frame
  float radius_mm = 0;     // cutting radius
  float flute_mm = 0;      // cutting length from the tip
  float length_mm = 0;     // gauge length (tip to holder face)
  float holder_radius_mm = 0;
  float holder_length_mm = 0;
};
[[nodiscard]] ToolState tool_state(const geom::Tool& t, int tool_number, const geom::Pose& pose, int channel = 0);

// An alarm for the operator's status bar (e.g. a collision the geometry side found). Plain
// fixed-size storage: the geometry thread fills it without allocating; the text is
// NUL-terminated and cut at kAlarmTextChars - 1 characters.
enum class AlarmSeverity : std::uint8_t { Info, Warning, Error };
inline constexpr std::size_t kAlarmTextChars = 96;
inline constexpr int kMaxAlarms = 8;
struct Alarm {
  AlarmSeverity severity = AlarmSeverity::Info;
  std::array<char, kAlarmTextChars> text{};
};
// Copies `text` into `a` (cut to fit, NUL-terminated). Real-time safe, no allocation.
void set_alarm(Alarm& a, AlarmSeverity severity, const char* text) noexcept;

// Counters of the live pipeline shown in the HUD (all plain values, copied per snapshot).
struct LiveStats {
  double lag_ms = 0;             // now − receive time of the newest applied sample
  double sample_rate_hz = 0;
  std::uint64_t samples = 0;
  std::uint64_t ring_high_water = 0, ring_capacity = 0, ring_overruns = 0;
  std::uint64_t decode_errors = 0;
  std::uint64_t samples_coalesced = 0;  // folded into others while behind (exact; none lost)
  std::uint64_t samples_held = 0;       // waiting on the HAL side for room in the ring
  bool realtime = false;         // SCHED_FIFO granted to the HAL/geometry threads
  bool live = false;             // false: batch result or replay without live counters
  // Replay / program position for the status bar (negative: unknown).
  double machining_s = -1;       // simulated machining time reached [s]
  double total_s = -1;           // machining time of the whole program [s]
  std::int64_t program_line = -1;  // source line of the move being cut (1-based)
  bool paused = false;           // a replay paused by the operator
  // Alarms shown in red/amber in the status bar; the first `alarm_count` entries.
  std::array<Alarm, kMaxAlarms> alarms{};
  int alarm_count = 0;
};

struct CellUpdate {
  int region = 0, level = 0;
  geom::Cell cell;
};

inline constexpr int kMaxTools = 4;

struct Snapshot {
  std::uint64_t version = 0;           // publish count (1, 2, …)
  // Cells changed since the previous snapshot: the first `cell_count` entries. The vector
  // never shrinks, so its Cell objects keep their capacity when the buffers travel back to
  // the writer (the geometry thread then copies into existing storage instead of allocating).
  std::vector<CellUpdate> cells;
  std::size_t cell_count = 0;
  std::vector<geom::Vec3> path;        // tool tip points since the previous snapshot, oldest first
  std::array<ToolState, kMaxTools> tools{};
  int tool_count = 0;
  geom::MoveId last_move = 0;          // newest move id applied (heat colouring scale)
  LiveStats stats;
  std::uint64_t path_dropped = 0;      // points dropped because the writer's buffer was full
};

class SolidExchange {
 public:
  // `path_capacity`: tip points buffered on the writer side between snapshots (allocated
  // here, never grown).
  explicit SolidExchange(std::size_t path_capacity = 8192);
  SolidExchange(const SolidExchange&) = delete;
  SolidExchange& operator=(const SolidExchange&) = delete;

  // --- writer (geometry thread) ---
  // Records a tool tip position for the path display. Real-time safe, no allocation.
  void add_path_point(const geom::Vec3& tip) noexcept;
  // Publishes the solid's dirty cells with the tools and counters; see the contract above.
  // Never blocks. Returns false (doing nothing else) when the previous snapshot has not
  // been taken. Copies cells into reused slot storage: allocates only while the storage
  // grows (like the kernel itself, whose Clipper calls allocate).
  bool publish(geom::LbrSolid& solid, std::span<const ToolState> tools, geom::MoveId last_move,
               const LiveStats& stats);
  [[nodiscard]] std::uint64_t published() const noexcept { return published_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t skipped() const noexcept { return skipped_.load(std::memory_order_relaxed); }

  // --- reader (render thread) ---
  // If a snapshot is ready, swaps it into `out` (whose old buffers become the slot's
  // storage) and returns true. Never blocks; O(1).
  bool take(Snapshot& out) noexcept;

 private:
  enum : int { kEmpty = 0, kFull = 1 };
  alignas(64) std::atomic<int> state_{kEmpty};
  alignas(64) Snapshot slot_;
  // writer-only
  std::vector<geom::Vec3> path_;
  std::size_t path_capacity_;
  std::uint64_t path_dropped_ = 0;
  std::uint64_t version_ = 0;
  std::atomic<std::uint64_t> published_{0}, skipped_{0};
};

}  // namespace lbr::gfx
