#include "app/level_pool.hpp"

#include <algorithm>
#include <chrono>

#include <pthread.h>
#include <sched.h>

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
  ahead_.prepare = [this] {
    std::vector<geom::SweepRef>& next = batches_[1 - cur_];
    next.clear();
    ahead_more_ = (*source_)(next);
    if (!ahead_more_) next.clear();
    solid_->prepare_shared(next, *ahead_.shared);  // (empty: nothing to cut, no offsets)
  };
  // A new thread starts on its creator's processor, and this one stays busy: measured on a
  // two-core machine, a worker that started beside the caller stayed there for whole runs
  // (low: 1.2x instead of 1.7x). So each worker starts on a processor of the allowed set
  // other than the caller's, then takes the whole set back (no lasting pinning: other
  // processes keep the scheduler's placement).
  have_mask_ = sched_getaffinity(0, sizeof(allowed_), &allowed_) == 0;
  std::vector<int> elsewhere;
  const int here = sched_getcpu();
  if (have_mask_)
    for (int c = 0; c < CPU_SETSIZE; ++c)
      if (CPU_ISSET(c, &allowed_) && c != here) elsewhere.push_back(c);
  for (int i = 1; i < threads; ++i) {
    threads_.emplace_back([this, i] { worker(i); });
    if (!elsewhere.empty()) {
      cpu_set_t one;
      CPU_ZERO(&one);
      CPU_SET(elsewhere[static_cast<std::size_t>(i - 1) % elsewhere.size()], &one);
      (void)pthread_setaffinity_np(threads_.back().native_handle(), sizeof(one), &one);
    }
  }
  // Return once every worker runs (waits for work): the first batch must not pay for
  // thread start-up (about 0.6 ms, as much as two small batches).
  while (started_.load(std::memory_order_acquire) < threads - 1) std::this_thread::yield();
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
  if (have_mask_) (void)sched_setaffinity(0, sizeof(allowed_), &allowed_);  // (the constructor)
  started_.fetch_add(1, std::memory_order_release);
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
    results_[index] = solid_->subtract_shared(shared_[cur_], *workspaces_[index], index, threads(), sync_, ahead_ptr_);
    if (pending_.fetch_sub(1, std::memory_order_acq_rel) == 1) {
      std::lock_guard lk(m_);
      if (caller_waiting_) done_.notify_one();
    }
  }
}

geom::SubtractStats LevelPool::subtract(geom::LbrSolid& solid, std::span<const geom::SweepRef> batch) {
  if (threads_.empty()) return solid.subtract(batch, *workspaces_[0]);
  solid.prepare_shared(batch, shared_[cur_]);  // before the workers start: they only read it
  ahead_ptr_ = nullptr;
  return dispatch(solid);
}

geom::SubtractStats LevelPool::run(geom::LbrSolid& solid, const BatchSource& source, const BatchDone& done) {
  geom::SubtractStats total;
  if (threads_.empty()) {
    std::vector<geom::SweepRef>& batch = batches_[0];
    for (batch.clear(); source(batch); batch.clear()) {
      const geom::SubtractStats s = solid.subtract(batch, *workspaces_[0]);
      total += s;
      if (done) done(s);
    }
    return total;
  }
  source_ = &source;
  batches_[cur_].clear();
  if (!source(batches_[cur_])) return total;
  solid.prepare_shared(batches_[cur_], shared_[cur_]);
  for (;;) {
    ahead_.shared = &shared_[1 - cur_];
    ahead_ptr_ = &ahead_;
    const geom::SubtractStats s = dispatch(solid);
    total += s;
    if (done) done(s);
    if (!ahead_more_) break;
    shared_[1 - cur_].offsets_ready = true;  // built among this batch's clips
    cur_ = 1 - cur_;
  }
  source_ = nullptr;
  ahead_ptr_ = nullptr;
  return total;
}

geom::SubtractStats LevelPool::dispatch(geom::LbrSolid& solid) {
  solid_ = &solid;
  pending_.store(static_cast<int>(threads_.size()), std::memory_order_relaxed);
  {
    std::lock_guard lk(m_);
    generation_.fetch_add(1, std::memory_order_release);
    if (sleepers_ > 0) start_.notify_all();
  }
  results_[0] = solid.subtract_shared(shared_[cur_], *workspaces_[0], 0, threads(), sync_, ahead_ptr_);
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
