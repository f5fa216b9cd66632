// app/level_pool.hpp — batch-mode worker pool: one subtract() spread over threads by level.
//
// Levels are independent in the LBR, so each worker takes every n-th level of the batch
// (interleaved for balance) with its own SubtractWorkspace. The calling thread is worker 0.
// Used by the offline runner only; the live geometry thread subtracts on its own.
#pragma once

#include <condition_variable>
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

 private:
  void worker(int index);

  std::vector<std::unique_ptr<geom::SubtractWorkspace>> workspaces_;
  std::vector<geom::SubtractStats> results_;
  std::vector<std::thread> threads_;
  std::mutex m_;
  std::condition_variable start_, done_;
  geom::LbrSolid* solid_ = nullptr;
  std::span<const geom::SweepRef> batch_;
  unsigned long generation_ = 0;
  int pending_ = 0;
  bool stop_ = false;
};

}  // namespace lbr::app
