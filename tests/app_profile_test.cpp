// Profiles: the default profile, key validation with file:line, command-line overrides.
#include <gtest/gtest.h>

#include "geom/serialize.hpp"

#include "app/batch.hpp"
#include "app/outputs.hpp"
#include "app/profile.hpp"
#include "nc/movelist.hpp"

using namespace lbr;

namespace {
std::string error_of(const std::string& text) {
  try {
    (void)app::parse_profile(text, "p.toml");
  } catch (const app::ProfileError& e) {
    return e.what();
  }
  return "";
}
const std::string kStock = "[stock]\nshape = \"box\"\nmin_mm = [0, 0, -10]\nmax_mm = [50, 40, 0]\n";
}  // namespace

TEST(Profile, DefaultProfile) {
  const app::Profile p = app::default_profile();
  EXPECT_EQ(p.kin.kind, nc::MachineKind::Mill3);
  EXPECT_EQ(p.solid.level_spacing_mm, 0.1);
  EXPECT_EQ(p.solid.regions_x, 4);
  EXPECT_EQ(p.solid.box.max.x, 100.0);
  ASSERT_EQ(p.tooling.tools.size(), 5u);
  EXPECT_EQ(p.tooling.tools.at(5).kind, geom::ToolKind::Bull);
  EXPECT_EQ(p.tooling.tools.at(5).corner_radius_mm, 2.0);
  EXPECT_EQ(p.tooling.tools.at(3).angle_deg, 118.0);
}

TEST(Profile, MinimalProfileGetsDefaults) {
  const app::Profile p = app::parse_profile(kStock, "p.toml");
  EXPECT_EQ(p.solid.level_spacing_mm, 0.1);
  EXPECT_EQ(p.machine.rapid_mm_per_min, 15000.0);
  EXPECT_TRUE(p.tooling.tools.empty());
}

TEST(Profile, ErrorsNameFileLineAndKey) {
  EXPECT_EQ(error_of("[lbr]\nlevel_spacing_mm = 0.1\n"), "p.toml:1: stock: missing table [stock]");
  EXPECT_EQ(error_of(kStock + "\n[lbr]\nlevel_spacing_mm = \"fine\"\n"), "p.toml:7: lbr.level_spacing_mm: expected a number [mm]");
  EXPECT_EQ(error_of(kStock + "\n[lbr]\nregions = \"4by4\"\n"),
            "p.toml:7: lbr.regions: expected \"NXxNY\" with 1 <= NX, NY <= 256 (e.g. \"4x4\") or \"auto\", got '4by4'");
  EXPECT_EQ(error_of(kStock + "\n[lbr]\nlevel_spacing = 0.1\n"), "p.toml:7: lbr.level_spacing: unknown key");
  EXPECT_EQ(error_of(kStock + "\n[lbr]\nlive_regions = \"16\"\n"),
            "p.toml:7: lbr.live_regions: expected \"NXxNY\" with 1 <= NX, NY <= 256 (e.g. \"4x4\") or \"auto\", got '16'");
  EXPECT_EQ(error_of(kStock + "\n[[tool]]\nnumber = 1\nkind = \"drill\"\n"),
            "p.toml:6: tool.diameter_mm: missing (a number [mm] is required)");
  EXPECT_EQ(error_of(kStock + "\n[[tool]]\nnumber = 1\nkind = \"spoon\"\ndiameter_mm = 3\n"),
            "p.toml:8: tool.kind: expected one of flat, ball, bull, drill, vbit, turning, boring, grooving; got 'spoon'");
  EXPECT_EQ(error_of(kStock + "\n[[tool]]\nnumber = 2\nkind = \"flat\"\ndiameter_mm = 3\n[[tool]]\nnumber = 2\nkind = \"ball\"\ndiameter_mm = 3\n"),
            "p.toml:11: tool.number: tool 2 is defined twice");
  EXPECT_EQ(error_of("[stock]\nshape = \"box\"\nmin_mm = [0, 0]\n"), "p.toml:3: stock.min_mm: expected an array of 3 numbers [mm]");
  EXPECT_EQ(error_of("[machine]\nkind = \"mill9\"\n" + kStock), "p.toml:2: machine.kind: expected \"mill3\", \"mill5\", \"lathe\" or \"lathe-c\", got 'mill9'");
  EXPECT_EQ(error_of("[stock\n"), "p.toml:1: Error while parsing table header: expected ']', saw '\\n'");
}

TEST(Profile, CommandLineOverrides) {
  app::Profile p = app::default_profile();
  app::apply_stock_override(p, "cylinder:40,-50,0");
  EXPECT_EQ(p.solid.shape, geom::SolidSpec::Shape::Cylinder);
  EXPECT_EQ(p.solid.cylinder.diameter_mm, 40.0);
  app::apply_tool_override(p, "7:bull:12:1.5");
  EXPECT_EQ(p.tooling.tools.at(7).corner_radius_mm, 1.5);
  app::apply_tool_override(p, "1:vbit:10:60");
  EXPECT_EQ(p.tooling.tools.at(1).kind, geom::ToolKind::VBit);
  EXPECT_EQ(p.tooling.tools.at(1).angle_deg, 60.0);
  app::apply_regions(p, "8x2", "--regions");
  EXPECT_EQ(p.solid.regions_x, 8);
  EXPECT_EQ(p.solid.regions_y, 2);
  EXPECT_THROW(app::apply_tool_override(p, "1:bull:10"), app::ProfileError);
  EXPECT_THROW(app::apply_stock_override(p, "box:1,2,3"), app::ProfileError);
  try {
    app::apply_tool_override(p, "2:flat:abc");
    FAIL();
  } catch (const app::ProfileError& e) {
    EXPECT_STREQ(e.what(), "--tool 2:flat:abc: 'abc' is not a number");
  }
}

TEST(Profile, AutoRegionGrid) {
  geom::SolidSpec s;
  s.box = {{0, 0, 0}, {100, 80, 10}};
  EXPECT_EQ(app::auto_region_grid(s, 10.0), std::make_pair(4, 4));
  EXPECT_EQ(app::auto_region_grid(s, 2.0), std::make_pair(16, 16));
}

TEST(Batch, RunsAMoveListAndReportsMachiningTime) {
  app::Profile p = app::parse_profile(kStock, "p.toml");
  app::apply_tool_override(p, "1:flat:10");
  const nc::Toolpath tp = nc::parse_movelist(
      "lbr-moves 1\nstart 10 20 5\ntool 1\nrapid 10 20 -2\nfeed 600\nline 40 20 -2\n", "t.moves");
  const app::BatchResult r = app::run_batch(p, tp);
  // 7 mm rapid at 15 m/min + 30 mm at 600 mm/min.
  EXPECT_NEAR(r.machining_time_s, 7.0 / 15000.0 * 60.0 + 3.0, 1e-12);
  EXPECT_EQ(r.moves, 2u);
  const double slot = (2 * 5.0 * 30.0 + M_PI * 25.0) * 2.0;
  // Boundary within ±tol/2 of the exact stadium (perimeter 91.4 mm, tol 1 µm, depth 2 mm).
  EXPECT_NEAR(r.removed_volume_mm3, slot, 91.5 * 0.001 * 2.0);
  EXPECT_NEAR(r.stock_volume_mm3, 20000.0, 1e-6);

  const nc::Toolpath bad = nc::parse_movelist("lbr-moves 1\ntool 4\nrapid 1 1 1\n", "t.moves");
  try {
    (void)app::run_batch(p, bad);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "t.moves:2: tool 4 is not in the tool table of p.toml");
  }
}

TEST(Batch, WorkerThreadsGiveTheSameSolid) {
  // The level pool must reproduce the single-threaded result cell for cell.
  app::Profile p = app::default_profile();
  const nc::Toolpath tp = app::demo_toolpath();
  p.threads = 1;
  const app::BatchResult one = app::run_batch(p, tp);
  EXPECT_EQ(one.threads, 1);
  EXPECT_GT(one.stats.cells_reused, 0u);
  for (int threads : {2, 3}) {
    p.threads = threads;
    const app::BatchResult many = app::run_batch(p, tp);
    EXPECT_EQ(many.threads, threads);
    EXPECT_DOUBLE_EQ(one.removed_volume_mm3, many.removed_volume_mm3);
    EXPECT_EQ(geom::to_bytes(one.solid), geom::to_bytes(many.solid)) << threads << " threads";
    EXPECT_EQ(one.stats.cells_changed, many.stats.cells_changed);
    EXPECT_EQ(one.stats.cells_clipped, many.stats.cells_clipped);
    EXPECT_EQ(one.stats.cells_reused, many.stats.cells_reused);
    EXPECT_EQ(one.solid.dirty_cells(), many.solid.dirty_cells());
  }
}

// [nc] keys reach the G-code front ends (issue 14): start tool, subroutine folders relative
// to the profile's folder, and an error naming file, line and key.
TEST(Profile, NcSectionReachesTheInterpreterOptions) {
  const app::Profile p =
      app::parse_profile(std::string(kStock) + "\n[nc]\nstart_tool = 2\nsubroutine_path = [\"subs\", \"/abs/lib\"]\n",
                         "/cfg/m.toml");
  const nc::GcodeOptions o = app::gcode_options(p);
  EXPECT_EQ(o.start_tool, 2);
  ASSERT_EQ(o.subroutine_path.size(), 2u);
  EXPECT_EQ(o.subroutine_path[0], "/cfg/subs");
  EXPECT_EQ(o.subroutine_path[1], "/abs/lib");
  EXPECT_NE(error_of(std::string(kStock) + "\n[nc]\nstart_tol = 1\n").find("nc.start_tol: unknown key"), std::string::npos);
}

// [nc] dialect selects the built-in interpreter's program syntax (docs/nc-frontend.md#fanuc-dialect).
TEST(Profile, NcDialectReachesTheInterpreterOptions) {
  EXPECT_EQ(app::gcode_options(app::parse_profile(std::string(kStock), "m.toml")).dialect, nc::Dialect::Rs274ngc);
  const app::Profile p = app::parse_profile(std::string(kStock) + "\n[nc]\ndialect = \"fanuc\"\n", "m.toml");
  EXPECT_EQ(app::gcode_options(p).dialect, nc::Dialect::Fanuc);
  const std::string e = error_of(std::string(kStock) + "\n[nc]\ndialect = \"iso\"\n");
  EXPECT_NE(e.find("nc.dialect: expected rs274ngc or fanuc; got 'iso'"), std::string::npos) << e;
}
