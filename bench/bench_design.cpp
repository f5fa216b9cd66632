// The design-model comparison's phases on the bundled demo against its own reconstructed
// part (issue 16, docs/performance.md "Design comparison"): the run's final stock, the part
// as STL (mesh/ reconstruction, ~294 000 triangles), then each phase timed, best of N runs:
// parse, check_design (edge check), slice_design, compare_design, vertex_deviation over the
// reconstructed mesh (the --color deviation colours).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>

#include "app/batch.hpp"
#include "app/outputs.hpp"
#include "app/profile.hpp"
#include "mesh/export.hpp"
#include "mesh/reconstruct.hpp"
#include "verify/design.hpp"
#include "verify/stl.hpp"

using namespace lbr;

namespace {

double best_ms(int runs, const std::function<void()>& f) {
  double best = 1e300;
  for (int i = 0; i < runs; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    best = std::min(best, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  const int runs = argc > 1 ? std::max(1, std::atoi(argv[1])) : 3;
  app::Profile p = app::default_profile();
  p.threads = 1;
  const app::BatchResult r = app::run_batch(p, app::demo_toolpath());
  const std::vector<mesh::MeshBuffers> regions = mesh::reconstruct(r.solid);
  const std::vector<std::uint8_t> stl = mesh::to_binary_stl(regions);
  const std::string bytes(stl.begin(), stl.end());
  verify::StlMesh m;
  const double parse = best_ms(runs, [&] { m = verify::parse_stl(bytes, "demo.stl"); });
  const double check = best_ms(runs, [&] { verify::check_design(m, r.solid, "demo.stl"); });
  std::vector<geom::Paths> design;
  const double slice = best_ms(runs, [&] { design = verify::slice_design(m, r.solid); });
  const double compare = best_ms(runs, [&] { (void)verify::compare_design(design, r.solid, 0.02); });
  std::vector<float> dev;
  std::size_t vertices = 0;
  const double colour = best_ms(runs, [&] {
    vertices = 0;
    for (const mesh::MeshBuffers& b : regions) {
      verify::vertex_deviation(design, r.solid, b.positions, b.normals, 0.02, dev);
      vertices += dev.size();
    }
  });
  std::printf("demo vs its own part: %zu triangles, %d levels, %zu mesh vertices, best of %d\n", m.triangles.size(),
              r.solid.levels(), vertices, runs);
  std::printf("parse %.1f ms | check_design %.1f ms | slice_design %.1f ms | compare_design %.1f ms | "
              "vertex_deviation %.1f ms\n", parse, check, slice, compare, colour);
  return 0;
}
