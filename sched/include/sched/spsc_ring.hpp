// sched/spsc_ring.hpp — bounded single-producer single-consumer ring (lock-free, wait-free).
//
// Shape after rigtorp/SPSCQueue: storage allocated once at construction; the write and
// read indices live on separate cache lines, each side keeps a cached copy of the other
// side's index and refreshes it only when the ring looks full (producer) or empty
// (consumer); only acquire/release ordering. On top of that:
//  - try_push/try_emplace never block: when full they return false and count an overrun;
//  - the high-water mark (largest occupancy seen by the producer) is exact: the producer
//    re-reads the consumer index only when its cached view would raise the mark.
// Thread safety: exactly one producer thread and one consumer thread. overruns(),
// high_water() and size() may be read from any thread (approximate while running).
// Real-time: every member except the constructor is RT-safe and does not allocate.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <stdexcept>
#include <type_traits>
#include <utility>

namespace lbr::sched {

inline constexpr std::size_t kCacheLine = 64;

template <class T>
class SpscRing {
 public:
  // Setup: allocates capacity + 1 slots (one stays free to tell full from empty).
  // Throws std::invalid_argument for capacity 0 or absurd sizes, std::bad_alloc.
  explicit SpscRing(std::size_t capacity) : capacity_(capacity) {
    if (capacity < 1 || capacity > (std::size_t{1} << 28))
      throw std::invalid_argument("SpscRing: capacity must be in [1, 2^28]");
    slots_ = capacity_ + 1;
    storage_ = static_cast<T*>(::operator new(sizeof(T) * slots_, std::align_val_t{alignof(Slot)}));
  }
  ~SpscRing() {
    while (front() != nullptr) pop();
    ::operator delete(storage_, std::align_val_t{alignof(Slot)});
  }
  SpscRing(const SpscRing&) = delete;
  SpscRing& operator=(const SpscRing&) = delete;

  // Producer. Constructs an element in place; false (and one overrun counted) when full.
  template <class... Args>
  [[nodiscard]] bool try_emplace(Args&&... args) noexcept(std::is_nothrow_constructible_v<T, Args&&...>) {
    static_assert(std::is_constructible_v<T, Args&&...>);
    const std::size_t w = write_.load(std::memory_order_relaxed);
    const std::size_t next = w + 1 == slots_ ? 0 : w + 1;
    if (next == read_cache_) {
      read_cache_ = read_.load(std::memory_order_acquire);
      if (next == read_cache_) {
        overruns_.store(overruns_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
        return false;
      }
    }
    new (&storage_[w]) T(std::forward<Args>(args)...);
    write_.store(next, std::memory_order_release);
    // Occupancy after this push as seen with the cached read index is an upper bound;
    // refresh the read index only when that bound would raise the mark.
    std::size_t occ = occupancy(next, read_cache_);
    if (occ > high_water_local_) {
      read_cache_ = read_.load(std::memory_order_acquire);
      occ = occupancy(next, read_cache_);
      if (occ > high_water_local_) {
        high_water_local_ = occ;
        high_water_.store(occ, std::memory_order_relaxed);
      }
    }
    return true;
  }
  [[nodiscard]] bool try_push(const T& v) noexcept(std::is_nothrow_copy_constructible_v<T>) { return try_emplace(v); }
  [[nodiscard]] bool try_push(T&& v) noexcept(std::is_nothrow_move_constructible_v<T>) { return try_emplace(std::move(v)); }

  // Consumer. Oldest element or nullptr when empty.
  [[nodiscard]] T* front() noexcept {
    const std::size_t r = read_.load(std::memory_order_relaxed);
    if (r == write_cache_) {
      write_cache_ = write_.load(std::memory_order_acquire);
      if (r == write_cache_) return nullptr;
    }
    return &storage_[r];
  }
  // Consumer. Destroys the oldest element; the ring must not be empty (front() != nullptr).
  void pop() noexcept {
    static_assert(std::is_nothrow_destructible_v<T>);
    const std::size_t r = read_.load(std::memory_order_relaxed);
    storage_[r].~T();
    read_.store(r + 1 == slots_ ? 0 : r + 1, std::memory_order_release);
  }
  // Consumer. Moves the oldest element into `out`; false when empty.
  [[nodiscard]] bool try_pop(T& out) noexcept(std::is_nothrow_move_assignable_v<T>) {
    T* p = front();
    if (p == nullptr) return false;
    out = std::move(*p);
    pop();
    return true;
  }

  [[nodiscard]] std::size_t capacity() const noexcept { return capacity_; }
  // Approximate when called while the other side runs.
  [[nodiscard]] std::size_t size() const noexcept {
    return occupancy(write_.load(std::memory_order_acquire), read_.load(std::memory_order_acquire));
  }
  [[nodiscard]] bool empty() const noexcept { return size() == 0; }
  // Failed pushes because the ring was full.
  [[nodiscard]] std::uint64_t overruns() const noexcept { return overruns_.load(std::memory_order_relaxed); }
  // Largest number of elements that were in the ring at once (exact, measured at push).
  [[nodiscard]] std::size_t high_water() const noexcept { return high_water_.load(std::memory_order_relaxed); }

 private:
  struct alignas(kCacheLine) Slot {};
  [[nodiscard]] std::size_t occupancy(std::size_t w, std::size_t r) const noexcept {
    return w >= r ? w - r : w + slots_ - r;
  }

  std::size_t capacity_ = 0, slots_ = 0;
  T* storage_ = nullptr;
  // Producer's line.
  alignas(kCacheLine) std::atomic<std::size_t> write_{0};
  std::size_t read_cache_ = 0;
  std::size_t high_water_local_ = 0;
  std::atomic<std::uint64_t> overruns_{0};
  std::atomic<std::size_t> high_water_{0};
  // Consumer's line.
  alignas(kCacheLine) std::atomic<std::size_t> read_{0};
  std::size_t write_cache_ = 0;
  // Keep whatever follows the ring off the consumer's line.
  alignas(kCacheLine) char pad_[1] = {};
};

}  // namespace lbr::sched
