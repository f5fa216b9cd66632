// nc/line_tracker.hpp — which line of a program a machine is executing, from the positions
// it reports (`lbrsim run --program` on a live source, docs/ui.md "Program line"): the
// nearest move of the program, searched forward along the path from the last match.
//
// The positions are taken in the program's frame (X Y Z of the tool tip, as the emulator
// reports them); rotary axes are not compared. Setup allocates; update() is real-time safe:
// no allocation, no exceptions, no locks, and its work is bounded by the search window
// except when the machine is far from every move in it (a re-lock over the whole program).
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "nc/toolpath.hpp"

namespace lbr::nc {

class LineTracker {
 public:
  // Moves of `path` (Rapid and Feed segments of non-zero XYZ length). `window_mm`: how far
  // along the path beyond the last match a search looks (at least `window_moves` moves, at
  // most 4096); `relock_mm`: a best match further than this searches the whole program.
  explicit LineTracker(const Toolpath& path, double window_mm = 50.0, std::size_t window_moves = 64,
                       double relock_mm = 2.0);

  // The source line of the move nearest to position q, searched from the last match forward;
  // 0 when the program has no moves. Ties go to the earlier move, and a move the position
  // is travelling against (a retract over its own plunge) loses to one it travels along.
  int update(const AxisVector& q) noexcept;
  // Back to the program's start.
  void reset() noexcept;

  [[nodiscard]] std::size_t moves() const noexcept { return moves_.size(); }
  [[nodiscard]] std::size_t move_index() const noexcept { return cur_; }
  [[nodiscard]] std::size_t relocks() const noexcept { return relocks_; }

 private:
  struct Move {
    std::array<double, 3> a{}, d{};  // start and end − start [mm]
    double len2 = 0;                 // |d|²
    double s0 = 0;                   // path length at the start [mm]
    int line = 0;
  };
  [[nodiscard]] double score(const Move& m, const std::array<double, 3>& p) const noexcept;

  std::vector<Move> moves_;
  double window_mm_, relock_mm_;
  std::size_t window_moves_;
  std::size_t cur_ = 0, relocks_ = 0;
  std::array<double, 3> prev_{}, motion_{};
  bool have_prev_ = false;
};

}  // namespace lbr::nc
