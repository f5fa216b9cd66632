// Windowed clips: a cell's contours reduced to what a small clip can reach, and restored
// after the difference (docs/lbr-conventions.md, "Windowed clips").
//
// A clip whose paths lie in a window W much smaller than the cell's material (a live sweep's
// section beside a long scalloped wall) still costs Clipper every subject vertex. Each
// contour is walked once and cut into runs of consecutive vertices that lie on one side of W
// (all left of it, or all right, below or above); a run of two or more edges is replaced by
// its chord (first vertex to last). The run and its chord close a loop whose points lie in
// the run's box, so outside W: winding numbers inside W, and so the difference there, do not
// change. After the difference each chord is put back as its run. This gives exactly the
// difference of the whole contours when the reduced contours have winding numbers 0 and 1
// only (then the result outside W is the reduced region itself, and putting the runs back
// restores the loops' winding numbers). Where that fails, some chord comes out of the
// difference split, missing or reversed, or some reduced vertex lies in a loop: both are
// tested, and the caller then clips the whole contours.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "geom/types.hpp"

namespace lbr::geom::detail {

struct WindowChord {
  Point a, b;                 // the chord a→b, an edge of the reduced contour
  std::uint32_t contour = 0;  // index into WindowScratch::src
  std::uint32_t from = 0;     // the run: src[from], src[from + 1], ... (cyclic), `count` vertices
  std::uint32_t count = 0;
  Rect box;                   // of the run (lies on one side of the window)
};

struct WindowScratch {
  std::vector<const Path*> src;     // the contours reduced, in order
  Paths reduced;                    // one per source contour
  std::vector<WindowChord> chords;  // sorted by (a.X, a.Y) once the reduction is done
  std::vector<std::uint32_t> found;  // per chord: how often the difference returned it
  Path expanded;
};

// Reduces the contours ws.src against the window w into ws.reduced. False when that does
// not pay (fewer than half of the vertices would go) or is not safe (a reduced vertex in or
// on a loop, two chords from one vertex): clip the whole contours.
[[nodiscard]] bool reduce_to_window(const Rect& w, WindowScratch& ws);

// Puts the runs back in place of the chords in every contour of `tree`. False when some
// chord is not in it exactly once in its own direction: the tree is then unusable (clip
// the whole contours).
[[nodiscard]] bool restore_runs(ClipperLib::PolyTree& tree, WindowScratch& ws);

}  // namespace lbr::geom::detail
