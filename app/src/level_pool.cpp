#include "app/level_pool.hpp"

#include <algorithm>

namespace lbr::app {

LevelPool::LevelPool(int threads) {
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  for (int i = 0; i < threads; ++i) workspaces_.push_back(std::make_unique<geom::SubtractWorkspace>());
  results_.resize(workspaces_.size());
  for (int i = 1; i < threads; ++i) threads_.emplace_back([this, i] { worker(i); });
}

LevelPool::~LevelPool() {
  {
    std::lock_guard lk(m_);
    stop_ = true;
  }
  start_.notify_all();
  for (std::thread& t : threads_) t.join();
}

void LevelPool::worker(int index) {
  unsigned long seen = 0;
  for (;;) {
    std::unique_lock lk(m_);
    start_.wait(lk, [&] { return stop_ || generation_ != seen; });
    if (stop_) return;
    seen = generation_;
    geom::LbrSolid* solid = solid_;
    const auto batch = batch_;
    lk.unlock();
    results_[index] = solid->subtract_levels(batch, index, solid->levels(), *workspaces_[index], threads());
    lk.lock();
    if (--pending_ == 0) done_.notify_one();
  }
}

geom::SubtractStats LevelPool::subtract(geom::LbrSolid& solid, std::span<const geom::SweepRef> batch) {
  if (threads_.empty()) return solid.subtract(batch, *workspaces_[0]);
  {
    std::lock_guard lk(m_);
    solid_ = &solid;
    batch_ = batch;
    pending_ = static_cast<int>(threads_.size());
    ++generation_;
  }
  start_.notify_all();
  results_[0] = solid.subtract_levels(batch, 0, solid.levels(), *workspaces_[0], threads());
  std::unique_lock lk(m_);
  done_.wait(lk, [&] { return pending_ == 0; });
  geom::SubtractStats total;
  for (const auto& r : results_) total += r;
  return total;
}

}  // namespace lbr::app
