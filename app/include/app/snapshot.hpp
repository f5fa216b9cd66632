// app/snapshot.hpp — power-loss snapshots of a live run (docs/snapshot.md has the format).
//
// A snapshot holds the stock (the LBRS level file of geom/serialize.hpp), where the source
// was (the source's sample number of the newest sample in the solid), the --record file and
// an offset in it from which the samples not in the solid can be replayed (catch-up), and
// each channel's newest applied sample (the start of the next sweep; its sender time tells
// which recorded samples the solid holds). Two files alternate in the snapshot folder (snapshot-a.lbrsnap, snapshot-b.lbrsnap);
// each is written to a temporary file, fsync'd and renamed over the older one, so a power
// cut leaves at least one complete snapshot. On start the newest valid one is used; a
// corrupt or truncated one is reported and the other used.
//
// Threads: the geometry thread hands a copy of the solid to SnapshotWriter at a batch
// boundary (offer(): never waits, never does I/O); the writer thread encodes and writes it.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "geom/lbr_solid.hpp"
#include "hal/sample.hpp"

namespace lbr::app {

// Power-loss catch-up: a snapshot's record offset is where the recording stood at least this
// long (receive time) before the newest applied sample, so that every sample still in
// flight then (a CAN cycle being assembled, a queue behind the geometry thread) is after it.
inline constexpr std::int64_t kCatchUpMarginNs = 1'000'000'000;

// A 1 mm cube of one level and one region: what SnapshotState holds until a solid is assigned.
[[nodiscard]] geom::SolidSpec placeholder_solid_spec();

struct SnapshotState {
  std::uint64_t generation = 0;       // written count; the higher of two valid files wins
  std::uint64_t source_position = 0;  // source's sample number (1, 2, …) of the newest sample in the solid
  std::uint64_t samples_applied = 0;  // samples applied since the run first started (coalesced included)
  // Power-loss catch-up: the --record file (empty: none) and a line boundary in it from which
  // every sample not in the solid can be replayed (the recording as it was at least
  // kCatchUpMarginNs of receive time before the newest applied sample; earlier ones are
  // skipped by sender time, SkipSink).
  std::uint64_t record_offset = 0;
  std::string record_file;
  double wall_time_s = 0;             // time the run had been going (all resumed parts together) [s]
  std::string source;                 // --source spec of the run
  // Newest applied sample of each channel (have[i] false: none yet), with its sender time.
  std::array<bool, hal::kMaxChannels> have{};
  std::array<hal::AxisSample, hal::kMaxChannels> last{};
  geom::LbrSolid solid{placeholder_solid_spec()};
};

// Encodes / decodes a snapshot file. decode throws std::runtime_error naming the byte offset
// ("NAME: at byte N: what was expected") on a bad magic, checksum, length or LBRS content.
[[nodiscard]] std::vector<std::uint8_t> encode_snapshot(const SnapshotState& s);
[[nodiscard]] SnapshotState decode_snapshot(const std::vector<std::uint8_t>& bytes, const std::string& name);
// CRC-32 (IEEE 802.3, reflected, as zlib's crc32).
[[nodiscard]] std::uint32_t crc32(const std::uint8_t* data, std::size_t n, std::uint32_t crc = 0) noexcept;

// Writes `bytes` so that a power cut leaves either the old or the new file: PATH.tmp,
// fsync, rename over PATH, fsync of the folder. Throws std::runtime_error with the path.
void write_file_durably(const std::string& path, const std::vector<std::uint8_t>& bytes);

struct LoadedSnapshot {
  std::optional<SnapshotState> state;  // the newest valid one, if any
  std::string file;                    // its path
  std::vector<std::string> problems;   // corrupt / truncated files that were passed over
};
// The newest valid snapshot in `dir` (none when the folder has none). Setup; allocates.
[[nodiscard]] LoadedSnapshot load_newest_snapshot(const std::string& dir);

// The writer thread and its one-slot hand-over from the geometry thread.
class SnapshotWriter {
 public:
  // Called on the writer thread after each periodic snapshot is written, with the state it
  // holds (the solid at a batch boundary), before the slot is freed: work on a consistent
  // copy of the stock off the real-time threads (run --design compares it, docs/verification.md#live-design).
  using AfterWrite = std::function<void(const SnapshotState&)>;
  // `dir` is created; `first_generation`: generation of the first file written (the one
  // after the resumed snapshot's). Starts the thread.
  SnapshotWriter(std::string dir, std::uint64_t first_generation, AfterWrite after_write = {});
  ~SnapshotWriter();  // finishes a pending write, joins
  SnapshotWriter(const SnapshotWriter&) = delete;
  SnapshotWriter& operator=(const SnapshotWriter&) = delete;

  // Geometry thread: the slot to fill when it is free, else nullptr (the writer is still
  // busy with the previous one; try again at the next batch). Never waits, no I/O. Copying
  // the solid into slot->solid reuses its storage (allocates only while that grows, like
  // the render exchange).
  [[nodiscard]] SnapshotState* slot() noexcept;
  // Geometry thread: hands the filled slot to the writer thread.
  void commit() noexcept;
  // Control thread, after the geometry thread has ended: writes `s` now (clean shutdown).
  void write_now(SnapshotState& s);

  [[nodiscard]] std::uint64_t written() const noexcept { return written_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t failed() const noexcept { return failed_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::string last_error() const;

 private:
  void loop();
  void write(SnapshotState& s);

  enum : int { kFree = 0, kFilled = 1 };
  std::string dir_;
  std::uint64_t generation_;
  AfterWrite after_write_;
  SnapshotState slot_;
  std::atomic<int> state_{kFree};
  std::atomic<bool> quit_{false};
  std::atomic<std::uint64_t> written_{0}, failed_{0};
  std::string error_;  // writer thread; read after join or under the slot being free
  std::thread thread_;
};

}  // namespace lbr::app
