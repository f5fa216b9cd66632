// The worker pool behind ParallelSubtractor: the calling thread prepares a batch
// (SubtractEngine::prepare()), then the threads run SubtractEngine::run() together, each
// with its own workspace (levels' sections, then the clips, taken from shared counters;
// runs of equal levels are clipped once). The calling thread is worker 0.
//
// A batch takes well under a millisecond once the kernel is fast (low: ~0.33 ms on one
// thread), so the hand-over must cost microseconds: workers and the caller spin on atomics
// for a short while (kSpin) before they block on the condition variables, which are only
// signalled when someone actually sleeps.
#include "geom/parallel_subtractor.hpp"

#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "subtract_engine.hpp"

namespace lbr::geom {

namespace {

// How long a thread spins before it blocks: longer than the gap between two batches of
// the offline runner, far shorter than a scheduler tick.
constexpr auto kSpin = std::chrono::microseconds(200);

// Spins until pred() holds or kSpin has passed; returns pred().
template <class Pred>
bool spin_until(Pred pred) {
  const auto end = std::chrono::steady_clock::now() + kSpin;
  for (int i = 0;; ++i) {
    if (pred()) return true;
    detail::cpu_relax();
    if ((i & 63) == 63 && std::chrono::steady_clock::now() > end) return pred();
  }
}

// A thread waiting at the barrier spins this often, then yields this often, then sleeps
// kBarrierNap at a time (a wait of about a millisecond or more).
constexpr unsigned kBarrierSpins = 4096;
constexpr unsigned kBarrierYields = 1024;
constexpr auto kBarrierNap = std::chrono::microseconds(50);

}  // namespace

class ParallelSubtractor::Impl {
 public:
  explicit Impl(int threads);
  ~Impl();
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  [[nodiscard]] int threads() const noexcept { return static_cast<int>(workspaces_.size()); }
  SubtractStats subtract(LbrSolid& solid, std::span<const SweepRef> batch);
  SubtractStats run(LbrSolid& solid, const BatchSource& source, const BatchDone& done);

 private:
  void worker(int index);
  void stop_workers() noexcept;  // asks the workers to stop and joins them
  SubtractStats dispatch(LbrSolid& solid);  // runs shared_[cur_] on all threads

  void barrier() noexcept;  // spinning barrier over all threads (then yields)

  std::vector<std::unique_ptr<detail::SubtractWorkspace>> workspaces_;
  detail::SubtractShared shared_[2];  // the current batch's and, in run(), the next one's
  int cur_ = 0;                      // index of the current batch's in shared_
  // run(): the next batch, pulled from source_ and prepared into shared_[1 - cur_] by the
  // worker that takes ahead_'s item; ahead_more_ says whether there was one.
  const BatchSource* source_ = nullptr;
  std::vector<SweepRef> batches_[2];
  bool ahead_more_ = false;
  detail::SubtractAhead ahead_;
  const detail::SubtractAhead* ahead_ptr_ = nullptr;  // &ahead_ or none; published like solid_
  std::function<void()> sync_;
  std::atomic<int> arrived_{0};
  std::atomic<unsigned> phase_{0};
  std::vector<SubtractStats> results_;
  std::vector<std::thread> threads_;
  std::mutex m_;
  std::condition_variable start_, done_;
  LbrSolid* solid_ = nullptr;  // with shared_[cur_], published by generation_ (release/acquire)
  std::atomic<unsigned long> generation_{0};
  std::atomic<int> pending_{0};
  std::atomic<int> started_{0};  // workers running
  cpu_set_t allowed_{};          // the process's processors, when have_mask_
  bool have_mask_ = false;
  std::atomic<bool> stop_{false};
  int sleepers_ = 0;          // workers blocked on start_ (guarded by m_)
  bool caller_waiting_ = false;  // the caller blocked on done_ (guarded by m_)
};

ParallelSubtractor::Impl::Impl(int threads) {
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  for (int i = 0; i < threads; ++i) workspaces_.push_back(std::make_unique<detail::SubtractWorkspace>());
  results_.resize(workspaces_.size());
  sync_ = [this] { barrier(); };
  ahead_.prepare = [this] {
    std::vector<SweepRef>& next = batches_[1 - cur_];
    next.clear();
    ahead_more_ = (*source_)(next);
    if (!ahead_more_) next.clear();
    detail::SubtractEngine(*solid_).prepare(next, *ahead_.shared);  // (empty: nothing to cut, no offsets)
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
  try {
    for (int i = 1; i < threads; ++i) {
      threads_.emplace_back([this, i] { worker(i); });
      if (!elsewhere.empty()) {
        cpu_set_t one;
        CPU_ZERO(&one);
        CPU_SET(elsewhere[static_cast<std::size_t>(i - 1) % elsewhere.size()], &one);
        (void)pthread_setaffinity_np(threads_.back().native_handle(), sizeof(one), &one);
      }
    }
  } catch (...) {  // (std::system_error) the started workers end before the error leaves
    stop_workers();
    throw;
  }
  // Return once every worker runs (waits for work): the first batch must not pay for
  // thread start-up (about 0.6 ms, as much as two small batches).
  while (started_.load(std::memory_order_acquire) < threads - 1) std::this_thread::yield();
}

void ParallelSubtractor::Impl::barrier() noexcept {
  const int n = threads();
  const unsigned phase = phase_.load(std::memory_order_acquire);
  if (arrived_.fetch_add(1, std::memory_order_acq_rel) == n - 1) {
    arrived_.store(0, std::memory_order_relaxed);
    phase_.fetch_add(1, std::memory_order_release);
    return;
  }
  // Spin, then yield (more threads than cores), then sleep: a SCHED_FIFO thread that only
  // yields never lets a SCHED_OTHER thread of its core run, which starves whatever the
  // late thread may wait for (a writer holding a lock) until the kernel's RT throttling
  // steps in, after up to a second.
  for (unsigned i = 0; phase_.load(std::memory_order_acquire) == phase; ++i) {
    if (i < kBarrierSpins) detail::cpu_relax();
    else if (i < kBarrierSpins + kBarrierYields) std::this_thread::yield();
    else std::this_thread::sleep_for(kBarrierNap);
  }
}

ParallelSubtractor::Impl::~Impl() { stop_workers(); }

void ParallelSubtractor::Impl::stop_workers() noexcept {
  {
    std::lock_guard lk(m_);
    stop_.store(true);
  }
  start_.notify_all();
  for (std::thread& t : threads_) t.join();
}

void ParallelSubtractor::Impl::worker(int index) {
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
    results_[index] = detail::SubtractEngine(*solid_).run(shared_[cur_], *workspaces_[index], index, threads(), sync_, ahead_ptr_);
    if (pending_.fetch_sub(1, std::memory_order_acq_rel) == 1) {
      std::lock_guard lk(m_);
      if (caller_waiting_) done_.notify_one();
    }
  }
}

SubtractStats ParallelSubtractor::Impl::subtract(LbrSolid& solid, std::span<const SweepRef> batch) {
  if (threads_.empty()) return detail::SubtractEngine(solid).subtract(batch, *workspaces_[0]);
  detail::SubtractEngine(solid).prepare(batch, shared_[cur_]);  // before the workers start: they only read it
  ahead_ptr_ = nullptr;
  return dispatch(solid);
}

SubtractStats ParallelSubtractor::Impl::run(LbrSolid& solid, const BatchSource& source, const BatchDone& done) {
  SubtractStats total;
  if (threads_.empty()) {
    std::vector<SweepRef>& batch = batches_[0];
    for (batch.clear(); source(batch); batch.clear()) {
      const SubtractStats s = detail::SubtractEngine(solid).subtract(batch, *workspaces_[0]);
      total += s;
      if (done) done(s);
    }
    return total;
  }
  source_ = &source;
  batches_[cur_].clear();
  if (!source(batches_[cur_])) return total;
  detail::SubtractEngine(solid).prepare(batches_[cur_], shared_[cur_]);
  for (;;) {
    ahead_.shared = &shared_[1 - cur_];
    ahead_ptr_ = &ahead_;
    const SubtractStats s = dispatch(solid);
    total += s;
    if (done) done(s);
    if (!ahead_more_) break;
    cur_ = 1 - cur_;
  }
  source_ = nullptr;
  ahead_ptr_ = nullptr;
  return total;
}

SubtractStats ParallelSubtractor::Impl::dispatch(LbrSolid& solid) {
  solid_ = &solid;
  pending_.store(static_cast<int>(threads_.size()), std::memory_order_relaxed);
  {
    std::lock_guard lk(m_);
    generation_.fetch_add(1, std::memory_order_release);
    if (sleepers_ > 0) start_.notify_all();
  }
  results_[0] = detail::SubtractEngine(solid).run(shared_[cur_], *workspaces_[0], 0, threads(), sync_, ahead_ptr_);
  auto done = [&] { return pending_.load(std::memory_order_acquire) == 0; };
  if (!spin_until(done)) {
    std::unique_lock lk(m_);
    caller_waiting_ = true;
    done_.wait(lk, done);
    caller_waiting_ = false;
  }
  SubtractStats total;
  for (const auto& r : results_) total += r;
  return total;
}

ParallelSubtractor::ParallelSubtractor(int threads) : impl_(std::make_unique<Impl>(threads)) {}
ParallelSubtractor::~ParallelSubtractor() = default;
int ParallelSubtractor::threads() const noexcept { return impl_->threads(); }
SubtractStats ParallelSubtractor::subtract(LbrSolid& solid, std::span<const SweepRef> batch) {
  return impl_->subtract(solid, batch);
}
SubtractStats ParallelSubtractor::run(LbrSolid& solid, const BatchSource& source, const BatchDone& done) {
  return impl_->run(solid, source, done);
}

}  // namespace lbr::geom
