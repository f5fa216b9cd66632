// Shared by the view-stream and UI tests: the volume that a PathStreamer's sweeps up to a
// time remove from a fresh solid, cut in one batch (the reference for seeks and replays).
#pragma once

#include <vector>

#include "app/view.hpp"
#include "geom/lbr_solid.hpp"

namespace lbr::test {

inline double removed_by_sweeps_mm3(const geom::SolidSpec& spec, const app::PathStreamer& s, double upto_s) {
  geom::LbrSolid ref(spec);
  std::vector<geom::SweepRef> batch;
  for (const motion::TimedSweep& t : s.sweeps()) {
    if (t.t_s > upto_s) break;
    batch.push_back(t.ref);
  }
  ref.subtract(batch);
  return ref.initial_volume_mm3() - ref.volume_mm3();
}

}  // namespace lbr::test
