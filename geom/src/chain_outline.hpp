// Private: one outline for a run of consecutive vertical moves on one level.
//
// Consecutive moves of a tool path share a disk on every level they both reach (the end
// disk of one is the start disk of the next), and their sections overlap heavily: a dense
// finishing path puts 20-50 sections over every point of a level. Fed to the clip as
// separate polygons, those overlaps cost the Vatti sweep quadratically. Instead the run is
// written as one closed path that walks the right sides forward and the left sides back,
// joined at each shared disk either along the disk (on the outer side of a turn) or by a
// shallow notch into it (on the inner side; through its centre where the notch is not
// proven). A tight loop may keep only its outer chain, closed through the loop's centre.
// docs/lbr-conventions.md ("Joined sections") shows that its winding number is positive
// exactly on the union of the sections and zero elsewhere, so the clip's non-zero fill
// removes the same region.
#pragma once

#include <span>
#include <vector>

#include "geom/sweep.hpp"
#include "geom/types.hpp"

namespace lbr::geom::detail {

// Appends the outline of `moves` (at least two, consecutive: moves[k].c1 == moves[k+1].c0,
// all on the grid of n directions, unit circle `uc`) to `out` as one closed path in kernel
// units, collinear and repeated vertices dropped. `buf` is a reusable buffer. A tight loop
// (a centre inside every disk of the run, docs/lbr-conventions.md) may be written as its
// outer chain only, closed through that centre; `star` is then set. Returns false (and
// appends nothing) when fewer than three vertices remain.
bool append_outline(std::span<const MoveCaps> moves, int n, const std::vector<SectionScratch::P2>& uc,
                    std::vector<SectionScratch::P2>& buf, Paths& out, std::vector<Path>& spare, bool& star);

}  // namespace lbr::geom::detail
