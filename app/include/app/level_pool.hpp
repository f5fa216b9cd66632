// app/level_pool.hpp — batch-mode worker pool: one subtract() spread over threads by level.
//
// Levels are independent in the LBR: the calling thread prepares the batch
// (LbrSolid::prepare_shared()), then the threads run LbrSolid::subtract_shared() together,
// each with its own SubtractWorkspace (levels' sections, then the clips, taken from shared
// counters; runs of equal levels are clipped once). The calling thread is worker 0.
// Used by the offline runner only; the live geometry thread subtracts on its own.
//
// A batch takes well under a millisecond once the kernel is fast (low: ~0.33 ms on one thread), so the
// hand-over must cost microseconds: workers and the caller spin on atomics for a short while
// (kSpin) before they block on the condition variables, which are only signalled when
// someone actually sleeps.
#pragma once

#include <sched.h>

#include <atomic>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <span>
#include <thread>
#include <vector>

#include "geom/lbr_solid.hpp"

namespace lbr::app {

class LevelPool {
 public:
  // threads = 0: one per hardware thread. threads = 1: no extra threads.
  explicit LevelPool(int threads = 0);
  ~LevelPool();
  LevelPool(const LevelPool&) = delete;
  LevelPool& operator=(const LevelPool&) = delete;

  [[nodiscard]] int threads() const noexcept { return static_cast<int>(workspaces_.size()); }
  // Same result as solid.subtract(batch). Blocks until every worker is done.
  geom::SubtractStats subtract(geom::LbrSolid& solid, std::span<const geom::SweepRef> batch);

  // Fills `out` with the next batch; false when there is none. Called on one thread at a
  // time, in order, but not always the caller's: a worker pulls the next batch.
  using BatchSource = std::function<bool(std::vector<geom::SweepRef>& out)>;
  // Called on the calling thread after each batch, with its statistics.
  using BatchDone = std::function<void(const geom::SubtractStats&)>;
  // Subtracts the batches of `source` in order; the same result as solid.subtract() of each
  // in turn. With workers, the next batch is pulled and prepared (merging, sweeps, chain
  // offsets) among the current one's clips, so that neither the caller nor a worker waits
  // for it between batches. Returns the total statistics.
  geom::SubtractStats run(geom::LbrSolid& solid, const BatchSource& source, const BatchDone& done = {});

 private:
  void worker(int index);
  geom::SubtractStats dispatch(geom::LbrSolid& solid);  // runs shared_[cur_] on all threads

  void barrier() noexcept;  // spinning barrier over all threads (then yields)

  std::vector<std::unique_ptr<geom::SubtractWorkspace>> workspaces_;
  geom::SubtractShared shared_[2];  // the current batch's and, in run(), the next one's
  int cur_ = 0;                      // index of the current batch's in shared_
  // run(): the next batch, pulled from source_ and prepared into shared_[1 - cur_] by the
  // worker that takes ahead_'s item; ahead_more_ says whether there was one.
  const BatchSource* source_ = nullptr;
  std::vector<geom::SweepRef> batches_[2];
  bool ahead_more_ = false;
  geom::SubtractAhead ahead_;
  const geom::SubtractAhead* ahead_ptr_ = nullptr;  // &ahead_ or none; published like solid_
  std::function<void()> sync_;
  std::atomic<int> arrived_{0};
  std::atomic<unsigned> phase_{0};
  std::vector<geom::SubtractStats> results_;
  std::vector<std::thread> threads_;
  std::mutex m_;
  std::condition_variable start_, done_;
  geom::LbrSolid* solid_ = nullptr;  // with shared_[cur_], published by generation_ (release/acquire)
  std::atomic<unsigned long> generation_{0};
  std::atomic<int> pending_{0};
  std::atomic<int> started_{0};  // workers running
  cpu_set_t allowed_{};          // the process's processors, when have_mask_
  bool have_mask_ = false;
  std::atomic<bool> stop_{false};
  int sleepers_ = 0;          // workers blocked on start_ (guarded by m_)
  bool caller_waiting_ = false;  // the caller blocked on done_ (guarded by m_)
};

}  // namespace lbr::app
