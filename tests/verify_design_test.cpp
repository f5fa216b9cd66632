// verify/: the STL reader and the comparison of the final stock with a design model
// (issue 16). The design is an analytic part on the built-in default profile (box
// 100 x 80 x 30, X0..100 Y0..80 Z-30..0, Δ 0.1; T1 flat D10): a pocket Y20..60, 5 deep,
// through along X, which the program below cuts exactly with seven passes.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <mutex>

#include <nlohmann/json.hpp>

#include "app/batch.hpp"
#include "app/live.hpp"
#include "app/outputs.hpp"
#include "app/profile.hpp"
#include "design_test_util.hpp"
#include "nc/gcode.hpp"
#include "verify/design.hpp"
#include "verify/stl.hpp"

using namespace lbr;

namespace {

// Pass i (0..6) at Y25 + 5i; `last_y` replaces the last one's Y55 (an over-cut). The passes
// run from X-10 to X110 (the tool outside the stock at both ends). Line 8 + 2i is pass i's
// cutting move; the last pass cuts on line 20.
std::string slot_program(double last_y = 55.0) {
  std::string s = "G21 G90 G17\nT1 M6 S1000 M3\nG43 H1\nG0 X-10 Y25 Z5\nG1 Z-5 F1000\nG1 Y25\n";
  for (int i = 0; i < 7; ++i) {
    const double y = i == 6 ? last_y : 25.0 + 5.0 * i;
    const char* x = i % 2 == 0 ? "X110" : "X-10";
    s += "G1 Y" + std::to_string(y) + "\nG1 " + x + "\n";
  }
  return s + "G0 Z5\nM30\n";
}

std::string write_temp(const std::string& name, const std::string& bytes) {
  const std::string path = (std::filesystem::temp_directory_path() / name).string();
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

app::BatchResult run_with_design(const std::string& program, const std::string& stl) {
  app::Profile p = app::default_profile();
  p.threads = 1;
  p.design = {stl, 0.02};
  const nc::Toolpath path = nc::interpret_gcode(program, "slot.ngc", app::gcode_options(p));
  return app::run_batch(p, path);
}

const verify::StlMesh kPart = test::pocket_part({0, 0, -30}, {100, 80, 0}, 20, 60, 5);

}  // namespace

TEST(StlReader, BinaryAndAsciiRoundTripACube) {
  const verify::StlMesh cube = test::box_mesh({0, 0, 0}, {10, 20, 30});
  ASSERT_EQ(cube.triangles.size(), 12u);
  EXPECT_NEAR(cube.volume_mm3(), 6000.0, 1e-9);
  for (const std::string& bytes : {verify::stl_binary(cube), verify::stl_ascii(cube)}) {
    const verify::StlMesh back = verify::parse_stl(bytes, "cube.stl");
    EXPECT_EQ(back.triangles.size(), 12u);
    EXPECT_NEAR(back.volume_mm3(), 6000.0, 1e-6);
    EXPECT_TRUE(verify::check_edges(back).closed_manifold());
  }
  EXPECT_EQ(verify::stl_binary(cube).size(), 84u + 12u * 50u);
}

TEST(StlReader, AnOpenMeshReportsItsBoundaryEdges) {
  verify::StlMesh cube = test::box_mesh({0, 0, 0}, {10, 10, 10});
  cube.triangles.pop_back();  // one triangle of a cap: its three edges lose their partner
  const verify::EdgeCheck e = verify::check_edges(cube);
  EXPECT_EQ(e.boundary_edges, 3u);
  EXPECT_EQ(e.non_manifold_edges, 0u);
  app::Profile p = app::default_profile();
  const geom::LbrSolid solid(p.solid);
  try {
    verify::check_design(cube, solid, "open.stl");
    FAIL() << "an open mesh was accepted";
  } catch (const verify::DesignError& err) {
    EXPECT_NE(std::string(err.what()).find("3 boundary edges"), std::string::npos) << err.what();
  }
}

TEST(StlReader, AsciiErrorsNameTheLine) {
  try {
    (void)verify::parse_stl("solid x\n facet normal 0 0 1\n outer loop\n vertex 1 2\n", "bad.stl");
    FAIL();
  } catch (const verify::StlError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.stl:5: expected a number"), std::string::npos) << e.what();
  }
}

TEST(DesignCheck, InchesAndOutsideTheStockAreRejected) {
  app::Profile p = app::default_profile();
  const geom::LbrSolid solid(p.solid);
  const verify::StlMesh inches = test::box_mesh({0, 0, -30.0 / 25.4}, {100.0 / 25.4, 80.0 / 25.4, 0});
  EXPECT_THROW(verify::check_design(inches, solid, "in.stl"), verify::DesignError);
  const verify::StlMesh outside = test::box_mesh({0, 0, -30}, {100, 80, 5});
  try {
    verify::check_design(outside, solid, "out.stl");
    FAIL();
  } catch (const verify::DesignError& e) {
    EXPECT_NE(std::string(e.what()).find("inside the stock"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(verify::check_design(kPart, solid, "part.stl"));
}

TEST(DesignSlice, SectionsOfThePocketPartHaveTheAnalyticVolume) {
  app::Profile p = app::default_profile();
  const geom::LbrSolid solid(p.solid);
  const std::vector<geom::Paths> d = verify::slice_design(kPart, solid);
  const verify::DesignReport rep = verify::compare_design(d, solid, 0.02);  // uncut stock
  EXPECT_NEAR(rep.design_volume_mm3, 100.0 * (80.0 * 30.0 - 40.0 * 5.0), 1e-3);
  EXPECT_NEAR(rep.gouge_mm3, 0.0, 1e-6);
  EXPECT_NEAR(rep.excess_mm3, 100.0 * (40.0 - 2 * 0.02) * 5.0, 1e-3);  // the uncut pocket beyond the tolerance
  EXPECT_NEAR(rep.max_excess_mm, 20.0, 1e-3);              // the pocket's middle, 20 from its walls
}

TEST(DesignCompare, AnExactCutLeavesNoGougeAndNoExcess) {
  const std::string stl = write_temp("lbr_design_exact.stl", verify::stl_binary(kPart));
  const app::BatchResult r = run_with_design(slot_program(), stl);
  ASSERT_TRUE(r.design.has_value());
  const verify::DesignReport& d = *r.design;
  // Bound: a sliver of 1 µm (rounding, chord) along 2 walls x 100 mm x 5 mm = 1 mm3.
  EXPECT_LT(d.gouge_mm3, 1.0);
  EXPECT_LT(d.max_gouge_mm, 0.005);
  EXPECT_LT(d.excess_mm3, 1.0);
  EXPECT_NEAR(r.removed_volume_mm3, 100.0 * 40.0 * 5.0, 1.0);
  EXPECT_TRUE(r.events.empty()) << verify::describe(r.events.at(0));  // no gouge event, no process event
}

TEST(DesignCompare, AnOverCutPassIsMeasuredAndLocated) {
  const std::string stl = write_temp("lbr_design_over.stl", verify::stl_ascii(kPart));
  const app::BatchResult r = run_with_design(slot_program(55.3), stl);
  ASSERT_TRUE(r.design.has_value());
  const verify::DesignReport& d = *r.design;
  const double expected = 0.3 * 100.0 * 5.0;  // the wall Y60 moved to Y60.3 over X0..100, Z-5..0
  EXPECT_NEAR(d.gouge_mm3, expected, 0.02 * expected);
  EXPECT_NEAR(d.max_gouge_mm, 0.3, 0.02 * 0.3);
  EXPECT_NEAR(d.max_gouge_at.y, 60.3, 0.01);
  EXPECT_GT(d.max_gouge_at.z, -5.0);
  EXPECT_EQ(d.gouge_line, 20);
  EXPECT_EQ(d.gouge_source, "slot.ngc");
  EXPECT_LT(d.excess_mm3, 1.0);
  // The gouge is deeper than the 0.02 mm tolerance: one design-gouge error (--fail-on error exits 3).
  ASSERT_EQ(r.events.size(), 1u);
  const verify::Event& e = r.events[0];
  EXPECT_EQ(e.kind, verify::EventKind::DesignGouge);
  EXPECT_EQ(e.severity(), verify::Severity::Error);
  EXPECT_EQ(e.line, 20);
  EXPECT_EQ(e.tool, 1);
  EXPECT_DOUBLE_EQ(e.depth_mm, d.max_gouge_mm);
  EXPECT_DOUBLE_EQ(e.volume_mm3, d.gouge_mm3);
  ASSERT_FALSE(d.levels.empty());
  EXPECT_EQ(d.levels.size(), 50u);  // the 50 levels of the pocket's depth
  const std::string csv = verify::deviation_csv(d);
  EXPECT_EQ(csv.substr(0, csv.find('\n')), "level,z_mm,gouge_mm3,excess_mm3,max_gouge_mm,max_excess_mm");
  app::Profile p = app::default_profile();
  p.design = {stl, 0.02};
  const std::string json = app::batch_metrics_json(r, p, "slot.ngc");
  for (const char* key : {"\"design_gouge_mm3\"", "\"design_excess_mm3\"", "\"max_gouge_mm\"", "\"max_gouge_line\": 20",
                          "\"max_gouge_at_mm\""})
    EXPECT_NE(json.find(key), std::string::npos) << key;
  // The values as written (the wall at Y60.3 is exact: 0.3 mm deep, 150 mm3).
  const nlohmann::json m = nlohmann::json::parse(json);
  const auto find = [&](const char* key) -> const nlohmann::json& {
    for (const auto& [k, v] : m.items())
      if (k == key) return v;
    for (const auto& [k, v] : m.items())
      if (v.is_object() && v.contains(key)) return v.at(key);
    ADD_FAILURE() << key << " not in metrics.json";
    return m;
  };
  EXPECT_NEAR(find("design_gouge_mm3").get<double>(), expected, 0.02 * expected);
  EXPECT_NEAR(find("max_gouge_mm").get<double>(), 0.3, 0.001);
}

// Regression (fuzz_stl): NaN, infinite and huge coordinates were accepted and reached the
// slicer; they are refused with the place named (ASCII: the line; binary: byte, triangle, vertex).
TEST(StlReader, RegressionNonFiniteOrHugeVerticesAreRefused) {
  const std::string tri = "solid t\n facet normal 0 0 1\n outer loop\n vertex 0 0 0\n vertex 1 0 0\n vertex X 1 0\n"
                          " endloop\n endfacet\nendsolid t\n";
  for (const char* bad : {"nan", "inf", "-1e300", "200000"}) {
    std::string text = tri;
    text.replace(text.find('X'), 1, bad);
    try {
      (void)verify::parse_stl(text, "bad.stl");
      FAIL() << bad << " was accepted";
    } catch (const verify::StlError& e) {
      EXPECT_NE(std::string(e.what()).find("bad.stl:6: expected a finite coordinate within"), std::string::npos) << e.what();
    }
  }
  std::string ok = tri;
  ok.replace(ok.find('X'), 1, "107000");  // inside the kernel's ±107374 mm
  EXPECT_EQ(verify::parse_stl(ok, "ok.stl").triangles.size(), 1u);

  verify::StlMesh m = test::box_mesh({0, 0, 0}, {1, 1, 1});
  m.triangles[3].v[2].y = std::numeric_limits<double>::infinity();  // written as float inf
  try {
    (void)verify::parse_stl(verify::stl_binary(m), "bad-binary.stl");
    FAIL() << "an infinite binary vertex was accepted";
  } catch (const verify::StlError& e) {
    EXPECT_NE(std::string(e.what()).find("bad-binary.stl: at byte " + std::to_string(84 + 3 * 50 + 12 + 24) +
                                         ": triangle 4, vertex 3: expected a finite coordinate"),
              std::string::npos)
        << e.what();
  }
}

// `lbrsim run --design` (docs/verification.md#live-design): the emulator streams the over-cut
// program as fast as possible and the final stock is compared by the batch runner's
// comparison: the same gouge (150 mm3 analytic) and depth as batch, within 1 %, a
// design-gouge event (not attributed to a line: live mode keeps no move list), and the
// deviation.csv / metrics.json keys that batch writes.
TEST(DesignCompare, RunComparesTheFinalStockLikeBatch) {
  const std::string stl = write_temp("lbr_design_live.stl", verify::stl_binary(kPart));
  const std::string program = write_temp("lbr_design_live.ngc", slot_program(55.3));
  const app::BatchResult b = run_with_design(slot_program(55.3), stl);
  ASSERT_TRUE(b.design.has_value());
  app::Profile p = app::default_profile();
  p.design = {stl, 0.02};
  app::LiveOptions o;
  o.source = "emulator:" + program;
  // Paced (not --speed 0, which can end before the first 50 ms snapshot on a fast machine):
  // the run lasts a few tenths of a second, so several periodic comparisons happen.
  o.speed = 50.0;
  std::size_t sliced_levels = 0;
  o.on_design = [&](const std::vector<geom::Paths>& d) { sliced_levels = d.size(); };
  // Snapshots every 50 ms: each is compared on the writer's thread; the gouge only grows.
  p.live.snapshot_s = 0.05;
  o.snapshot_dir = (std::filesystem::temp_directory_path() / "lbr_design_live_snap").string();
  std::mutex mu;
  std::vector<double> periodic_gouge;
  double final_gouge = -1;
  o.on_design_report = [&](const verify::DesignReport& d, bool final) {
    const std::lock_guard<std::mutex> lock(mu);
    if (final) final_gouge = d.gouge_mm3;
    else periodic_gouge.push_back(d.gouge_mm3);
  };
  const std::atomic<bool> stop{false};
  const app::LiveResult r = app::run_live(p, o, stop);
  EXPECT_GE(periodic_gouge.size(), 1u);
  for (std::size_t k = 1; k < periodic_gouge.size(); ++k) EXPECT_LE(periodic_gouge[k - 1], periodic_gouge[k] + 1e-6);
  if (!periodic_gouge.empty()) {
    EXPECT_LE(periodic_gouge.back(), final_gouge + 1e-6);
  }
  EXPECT_EQ(sliced_levels, static_cast<std::size_t>(r.solid.levels()));
  ASSERT_TRUE(r.design.has_value());
  const verify::DesignReport& d = *r.design;
  const double expected = 0.3 * 100.0 * 5.0;
  EXPECT_NEAR(d.gouge_mm3, expected, 0.02 * expected);
  EXPECT_NEAR(d.gouge_mm3, b.design->gouge_mm3, 0.01 * b.design->gouge_mm3);
  EXPECT_NEAR(d.max_gouge_mm, b.design->max_gouge_mm, 0.01 * 0.3);
  EXPECT_NEAR(d.max_gouge_at.y, 60.3, 0.01);
  EXPECT_NEAR(d.excess_mm3, b.design->excess_mm3, 1.0);
  EXPECT_EQ(d.levels.size(), b.design->levels.size());
  EXPECT_EQ(d.gouge_line, 0);
  ASSERT_EQ(r.events.size(), 1u) << verify::describe(r.events.at(1));
  EXPECT_EQ(r.events[0].kind, verify::EventKind::DesignGouge);
  EXPECT_DOUBLE_EQ(r.events[0].volume_mm3, d.gouge_mm3);
  EXPECT_DOUBLE_EQ(final_gouge, d.gouge_mm3);
  const std::string dir = (std::filesystem::temp_directory_path() / "lbr_design_live_out").string();
  app::write_live_outputs(dir, r, p);
  std::ifstream csv(dir + "/deviation.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header, "level,z_mm,gouge_mm3,excess_mm3,max_gouge_mm,max_excess_mm");
  const nlohmann::json j = nlohmann::json::parse(app::live_metrics_json(r, p));
  EXPECT_DOUBLE_EQ(j.at("design_gouge_mm3").get<double>(), d.gouge_mm3);
  EXPECT_DOUBLE_EQ(j.at("max_gouge_mm").get<double>(), d.max_gouge_mm);
  EXPECT_EQ(j.at("events").at(0).at("kind"), "design-gouge");
  EXPECT_EQ(j.at("event_errors"), 1);
}
