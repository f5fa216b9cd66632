#include "app/level_pool.hpp"

#include <algorithm>
#include <chrono>

namespace lbr::app {

namespace {

// How long a thread spins before it blocks: longer than the gap between two batches of
// the offline runner, far shorter than a scheduler tick.
constexpr auto kSpin = std::chrono::microseconds(200);

inline void relax() noexcept {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

// Spins until pred() holds or kSpin has passed; returns pred().
template <class Pred>
bool spin_until(Pred pred) {
  const auto end = std::chrono::steady_clock::now() + kSpin;
  for (int i = 0;; ++i) {
    if (pred()) return true;
    relax();
    if ((i & 63) == 63 && std::chrono::steady_clock::now() > end) return pred();
  }
}

}  // namespace

LevelPool::LevelPool(int threads) {
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  for (int i = 0; i < threads; ++i) workspaces_.push_back(std::make_unique<geom::SubtractWorkspace>());
  results_.resize(workspaces_.size());
  sync_ = [this] { barrier(); };
  for (int i = 1; i < threads; ++i) threads_.emplace_back([this, i] { worker(i); });
}

void LevelPool::barrier() noexcept {
  const int n = threads();
  const unsigned phase = phase_.load(std::memory_order_acquire);
  if (arrived_.fetch_add(1, std::memory_order_acq_rel) == n - 1) {
    arrived_.store(0, std::memory_order_relaxed);
    phase_.fetch_add(1, std::memory_order_release);
    return;
  }
  for (unsigned i = 0; phase_.load(std::memory_order_acquire) == phase; ++i) {
    if (i < 4096) relax();
    else std::this_thread::yield();  // more threads than cores
  }
}

LevelPool::~LevelPool() {
  {
    std::lock_guard lk(m_);
    stop_.store(true);
  }
  start_.notify_all();
  for (std::thread& t : threads_) t.join();
}

void LevelPool::worker(int index) {
  unsigned long seen = 0;
  for (;;) {
    auto ready = [&] { return stop_.load(std::memory_order_acquire) || generation_.load(std::memory_order_acquire) != seen; };
    if (!spin_until(ready)) {
      std::unique_lock lk(m_);
      ++sleepers_;
      start_.wait(lk, ready);
      --sleepers_;
    }
    if (stop_.load(std::memory_order_acquire)) return;
    seen = generation_.load(std::memory_order_acquire);
    geom::LbrSolid* solid = solid_;
    const auto batch = batch_;
    results_[index] = solid->subtract_shared(batch, shared_, *workspaces_[index], index, threads(), sync_);
    if (pending_.fetch_sub(1, std::memory_order_acq_rel) == 1) {
      std::lock_guard lk(m_);
      if (caller_waiting_) done_.notify_one();
    }
  }
}

geom::SubtractStats LevelPool::subtract(geom::LbrSolid& solid, std::span<const geom::SweepRef> batch) {
  if (threads_.empty()) return solid.subtract(batch, *workspaces_[0]);
  solid_ = &solid;
  batch_ = batch;
  pending_.store(static_cast<int>(threads_.size()), std::memory_order_relaxed);
  {
    std::lock_guard lk(m_);
    generation_.fetch_add(1, std::memory_order_release);
    if (sleepers_ > 0) start_.notify_all();
  }
  results_[0] = solid.subtract_shared(batch, shared_, *workspaces_[0], 0, threads(), sync_);
  auto done = [&] { return pending_.load(std::memory_order_acquire) == 0; };
  if (!spin_until(done)) {
    std::unique_lock lk(m_);
    caller_waiting_ = true;
    done_.wait(lk, done);
    caller_waiting_ = false;
  }
  geom::SubtractStats total;
  for (const auto& r : results_) total += r;
  return total;
}

}  // namespace lbr::app
