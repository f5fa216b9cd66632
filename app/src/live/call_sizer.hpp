// app/src/live/call_sizer.hpp — how much work the live geometry thread gives one kernel call.
//
// The lag of a sample is the time it waits for the geometry thread plus the kernel call that
// applies it, so the calls must be short while the thread keeps up, and long enough to keep
// up: each call pays a fixed cost for every (level, region) cell it clips (the cell's polygons
// go through the Vatti sweep whole), so cutting one batch into many small calls clips the same
// cells many times over (a fixed budget of 10 000 units instead of 60 000 made throughput
// fall below real time on finish3d, docs/performance.md "Live lag").
//
// The policy (docs/architecture.md "Live overload"):
//  - time target of the next call: `target_ns` while the oldest unapplied sample is younger
//    than that, growing with the backlog (`catch_up` × its age) up to `max_ns` — behind, a
//    longer call amortises the cells' fixed cost and the thread catches up;
//  - the cost model: kernel time ≈ ns_per_unit × work units (Geometry's estimate), fitted
//    online from every call's measured time. A call slower than the model raises the rate at
//    once (the next calls are smaller), a faster one lowers it slowly, so a phase of costly
//    work (a tight helix turn whose joins cross, a finishing pass over many levels of dense
//    cells) is followed within one call;
//  - a sub-batch takes sweeps while predict_ns(units) stays within the target (at least one);
//    a single sweep predicted above `split_factor` × target is cut into pieces.
//
// Real-time safe: no allocation, no exceptions, no locks; the clock is the caller's.
#pragma once

#include <algorithm>

#include <cstdint>

namespace lbr::app::live {

struct CallSizerConfig {
  std::int64_t target_ns = 2'000'000;      // call time while the thread keeps up
  std::int64_t max_ns = 40'000'000;        // call time at most, however far behind
  double catch_up = 0.5;                   // target grows by this × the backlog's age
  double initial_ns_per_unit = 1000.0;     // a unit was sized as about a microsecond
  double min_ns_per_unit = 20.0;           // the fit never goes below / above these
  double max_ns_per_unit = 100'000.0;
  double rise = 0.5;                       // EWMA weight of a call slower than the model
  double fall = 0.05;                      // ... of one faster than the model
  double split_factor = 2.0;               // one sweep above this × target is cut into pieces
};

class CallSizer {
 public:
  explicit CallSizer(const CallSizerConfig& c = {}) noexcept : c_(c), ns_per_unit_(c.initial_ns_per_unit) {}

  // Time target of the next call [ns] when the oldest sample not yet applied was received
  // `backlog_ns` ago.
  [[nodiscard]] std::int64_t target_ns(std::int64_t backlog_ns) const noexcept;
  // Work units that fit in `target_ns` by the model.
  [[nodiscard]] double budget_units(std::int64_t target_ns) const noexcept {
    return static_cast<double>(target_ns) / ns_per_unit_;
  }
  [[nodiscard]] double predict_ns(double units) const noexcept { return units * ns_per_unit_; }
  // Pieces to cut a single sweep of `units` into for `target_ns` (1: none), at most max_pieces.
  [[nodiscard]] int pieces(double units, std::int64_t target_ns, int max_pieces) const noexcept;
  // A call of `units` took `ns`.
  void observe(double units, std::int64_t ns) noexcept;
  [[nodiscard]] double ns_per_unit() const noexcept { return ns_per_unit_; }
  [[nodiscard]] const CallSizerConfig& config() const noexcept { return c_; }

 private:
  CallSizerConfig c_;
  double ns_per_unit_;
};

// The geometry thread's duty limit (pipeline.cpp, "Duty limit"): it earns `duty` seconds of
// work per second of wall time, banked up to `burst_ns`, and spends each tick's work; when
// overdrawn it rests until even. The debt is bounded by `burst_ns` too, so no rest is longer
// than burst_ns / duty however long the tick was.
class DutyBank {
 public:
  DutyBank(double duty, std::int64_t burst_ns, std::int64_t now_ns) noexcept
      : duty_(duty), burst_(static_cast<double>(burst_ns)), credit_(static_cast<double>(burst_ns)), t_(now_ns) {}
  // A tick worked from `t_tick_ns` to `now_ns`: the rest it calls for [ns] (0: none).
  [[nodiscard]] std::int64_t spend(std::int64_t t_tick_ns, std::int64_t now_ns) noexcept {
    const double earned = std::min(burst_, credit_ + duty_ * static_cast<double>(now_ns - t_));
    credit_ = std::max(-burst_, earned - static_cast<double>(now_ns - t_tick_ns));
    t_ = now_ns;
    return credit_ < 0.0 ? static_cast<std::int64_t>(-credit_ / duty_) : 0;
  }
  [[nodiscard]] double credit_ns() const noexcept { return credit_; }

 private:
  double duty_, burst_, credit_;
  std::int64_t t_;
};

}  // namespace lbr::app::live
