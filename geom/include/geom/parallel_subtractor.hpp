// geom/parallel_subtractor.hpp — LbrSolid::subtract() spread over a fixed set of threads.
//
// Levels are independent in the LBR: the calling thread prepares a batch once (merging,
// sweeps, chains), then it and the workers build the levels' sections and clip the cells
// together, taking work from shared counters; runs of equal levels are clipped once. The
// result is byte for byte that of LbrSolid::subtract() for every thread count.
//
// Threads: the object is used by one thread at a time (the caller), which works as worker
// 0, and made and destroyed while no call runs. The workers take the scheduling policy of
// the thread that makes the object, live as long as the object and touch only the solid
// handed to the current call. Between calls they spin for up to 200 µs, then sleep.
// Not real-time safe: every call allocates (Clipper; buffers grow to the largest batch) and
// blocks until the workers are done. For the offline runner, and for the live geometry
// thread's long calls (app/src/live/geometry.cpp; its short ones call LbrSolid::subtract()).
#pragma once

#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "geom/lbr_solid.hpp"

namespace lbr::geom {

class ParallelSubtractor {
 public:
  // Setup: `threads` in all, the caller included (0: one per hardware thread; 1: no
  // workers, every call runs on the caller). Starts the workers and returns once they run.
  // Allocates; throws std::system_error when a thread cannot be started.
  explicit ParallelSubtractor(int threads = 0);
  // Stops and joins the workers. Not while a call runs.
  ~ParallelSubtractor();
  ParallelSubtractor(const ParallelSubtractor&) = delete;
  ParallelSubtractor& operator=(const ParallelSubtractor&) = delete;

  // Threads that share each subtraction, the caller included (>= 1).
  [[nodiscard]] int threads() const noexcept;

  // The same result and total statistics as solid.subtract(batch). Blocks until every
  // worker is done. Allocates; does not throw.
  SubtractStats subtract(LbrSolid& solid, std::span<const SweepRef> batch);

  // Fills `out` (given empty) with the next batch; false when there is none. Called on one
  // thread at a time, in order, but not always the caller's: a worker pulls the next batch
  // while the current one is clipped. Must not throw.
  using BatchSource = std::function<bool(std::vector<SweepRef>& out)>;
  // Called on the calling thread after each batch, with its statistics.
  using BatchDone = std::function<void(const SubtractStats&)>;
  // Subtracts the batches of `source` in order: the same result as solid.subtract() of each
  // in turn. The next batch is pulled and prepared (merging, sweeps, chain offsets) among
  // the current one's clips, so that neither the caller nor a worker waits for it between
  // batches. Returns the total statistics. Allocates; does not throw.
  SubtractStats run(LbrSolid& solid, const BatchSource& source, const BatchDone& done = {});

 private:
  class Impl;  // the worker pool (geom/src/parallel_subtractor.cpp)
  std::unique_ptr<Impl> impl_;
};

}  // namespace lbr::geom
