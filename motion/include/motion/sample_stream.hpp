// motion/sample_stream.hpp — live axis samples → sweeps, per channel, merging straight runs.
//
// The live geometry thread (app/src/live/) feeds every sample it takes from the ring. Each
// channel keeps a pending run: consecutive samples extend one sweep while every merged
// sample's tool stays within `tol_mm` of the longer sweep (geom::pose_deviation_mm: the tip's
// offset, plus the tool axis's turn times the tool's reach while a rotary axis moves; geometry
// stays exact, docs/architecture.md); a single step that turns a rotary axis too far for one
// chord is cut into chords (kin::substeps) instead. Finished sweeps go into a batch buffer
// the caller subtracts.
//
// Rapid steps (live collision checks, docs/verification.md#live): with set_fast_step(), a
// step from one sample to the next is fast when the tip moves farther than the threshold
// per sequence number, and a run holds steps of one kind only, so every sweep is wholly
// fast or wholly not (batch_info()).
//
// Real-time contract: the constructor allocates (batch buffer, runs); take(), flush_all(),
// clear_batch() and the queries never allocate, throw or lock. When the batch buffer is
// full, the sink's on_batch_full() is called to empty it (the live pipeline subtracts early).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "geom/lbr_solid.hpp"  // SweepRef
#include "kin/kinematics.hpp"
#include "motion/tool_table.hpp"
#include "nc/toolpath.hpp"

namespace lbr::motion {

inline constexpr int kMaxChannels = 4;  // independent tool carriers (hal::kMaxChannels)

// Receives what the stream produces, on the thread that feeds it. Must not throw.
class SweepSink {
 public:
  virtual ~SweepSink() = default;
  // Every sweep as it is appended to the batch (e.g. its end point for the path display).
  virtual void on_sweep(const geom::SweepRef& s) noexcept = 0;
  // The batch buffer is full: consume `batch`; the stream clears it afterwards.
  virtual void on_batch_full(std::span<const geom::SweepRef> batch) noexcept = 0;
};

// What the stream knows of each sweep of its batch besides the geometry (batch_info()[i]
// belongs to batch()[i]).
struct SweepInfo {
  std::uint64_t first_seq = 0;  // the first sample after the sweep's start pose
  std::uint64_t last_seq = 0;   // the sample that ends it (its move id, not cut to 32 bits)
  int channel = 0;
  int tool = 0;                 // tool number
  bool fast = false;            // every step faster than set_fast_step() allows
};

class SampleStream {
 public:
  static constexpr std::size_t kMaxRun = 256;  // samples merged into one sweep at most

  // `kins`: the kinematics of channel i (kMaxChannels of them). `default_tool` cuts for
  // samples without a tool number. `batch_capacity`: sweeps buffered before on_batch_full().
  SampleStream(const ToolTable& tools, const std::array<kin::Kinematics, kMaxChannels>& kins, int default_tool,
               double tol_mm, std::size_t batch_capacity, SweepSink& sink);

  // One sample of `channel` (ignored if out of range): axis a of `q` is new when bit a of
  // `mask` is set, else it keeps its value. `tool` < 0: the default tool. `seq` becomes the
  // move id of the sweeps it ends.
  void take(int channel, std::uint64_t seq, int tool, std::span<const double> q, std::uint32_t mask) noexcept;
  // Ends every channel's pending run into the batch (at the end of a geometry tick).
  void flush_all() noexcept;
  // flush_all(), then every channel forgets where it was: its next sample is a pose, not the
  // end of a sweep (a break in the stream, e.g. a live machine after an outage).
  void forget_poses() noexcept;
  [[nodiscard]] std::span<const geom::SweepRef> batch() const noexcept { return batch_; }
  [[nodiscard]] std::span<const SweepInfo> batch_info() const noexcept { return info_; }
  void clear_batch() noexcept {
    batch_.clear();
    info_.clear();
  }
  // A step is fast when the tip moves more than `mm_per_seq` per sequence number (the
  // sample period times the speed limit); 0 (the default): no step is fast. Setup.
  void set_fast_step(double mm_per_seq) noexcept { fast_step_mm_ = mm_per_seq; }

  // What channel i holds now: whether it has seen a sample, its tool and latest tool pose.
  struct ChannelState {
    bool have = false;
    ToolRef tool;
    geom::Pose pose;
  };
  [[nodiscard]] ChannelState channel(int i) const noexcept;
  [[nodiscard]] geom::MoveId last_id() const noexcept { return last_id_; }

 private:
  struct Channel {
    bool have = false;
    nc::AxisVector q{};           // latest axis values (end of the pending run)
    ToolRef tool;                 // tool of the pending run
    std::vector<geom::Pose> run;  // run[0] = start of the pending sweep, then its samples
    std::uint64_t seq = 0;
    std::uint64_t run_first = 0;  // first sample of the pending run (after run[0])
    std::uint64_t run_last = 0;   // its last sample (run.back())
    bool run_fast = false;        // the pending run's steps are fast
  };

  void push(const Channel& c, const geom::Pose& from, const geom::Pose& to) noexcept;
  void flush(Channel& c) noexcept;
  void restart(Channel& c, const kin::Kinematics& k, const nc::AxisVector& q) noexcept;
  void substeps(Channel& c, const kin::Kinematics& k, const nc::AxisVector& q, int n, std::uint64_t dseq) noexcept;
  void extend(Channel& c, const kin::Kinematics& k, const nc::AxisVector& q, std::uint64_t dseq) noexcept;
  [[nodiscard]] bool fast(const geom::Vec3& a, const geom::Vec3& b, std::uint64_t dseq) const noexcept;

  const ToolTable& tools_;
  std::array<kin::Kinematics, kMaxChannels> kins_;
  ToolRef default_tool_;
  double tol_;
  SweepSink& sink_;
  std::vector<geom::SweepRef> batch_;
  std::vector<SweepInfo> info_;  // aligned with batch_
  double fast_step_mm_ = 0.0;
  std::array<Channel, kMaxChannels> ch_;
  geom::MoveId last_id_ = 0;
};

}  // namespace lbr::motion
