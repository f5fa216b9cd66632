// Tests of the live geometry thread's Geometry, fed by hand: a sample of the default
// profile's six axes, and a Geometry over the default profile's stock with its ring.
#pragma once

#include <cstdint>
#include <memory>

#include "app/profile.hpp"
#include "geom/lbr_solid.hpp"
#include "hal/sample.hpp"
#include "live/geometry.hpp"
#include "motion/tool_table.hpp"
#include "sched/spsc_ring.hpp"

namespace lbr::test {

// Sample `seq` (received seq ms after start) at x, y, z with tool `tool`.
inline hal::AxisSample sample(std::uint64_t seq, double x, double y, double z, int tool = 1) {
  hal::AxisSample s;
  s.seq = seq;
  s.t_rx_ns = static_cast<std::int64_t>(seq) * 1'000'000;
  s.mask = 0x3F;
  s.tool = static_cast<std::int16_t>(tool);
  s.q = {x, y, z, 0, 0, 0};
  return s;
}

struct GeometryRig {
  app::Profile profile = app::default_profile();
  geom::LbrSolid solid{profile.solid};
  motion::ToolTable tools{profile.tooling, profile.solid.chord_tol_mm, profile.source};
  sched::SpscRing<hal::AxisSample> ring{4096};
  std::unique_ptr<app::live::Geometry> geo;
  std::uint64_t seq = 0;
  GeometryRig() {
    tools.build_all();
    geo = std::make_unique<app::live::Geometry>(solid, profile, tools, 1, ring, 0.001);
  }
  // A straight pass along X at y, z: `n` samples 0.1 mm apart, then one tick.
  std::size_t pass(double y, double z, int n) {
    for (int i = 0; i < n; ++i) (void)ring.try_push(sample(seq++, 10.0 + 0.1 * i, y, z));
    return geo->tick(4096);
  }
};

}  // namespace lbr::test
