// Deviation colours (issue 16, docs/verification.md#deviation-colour): the PLY that
// `batch --ply --color deviation --design` writes. The analytic pocket part of
// verify_design_test.cpp (box 100 x 80 x 30, pocket Y20..60, 5 deep, through along X) cut by
// seven D10 passes, the last one 0.3 mm over (wall Y60 moved to Y60.3): red (gouge) vertices
// lie on that wall only; an exact cut has none, and neither has blue (excess) ones.
#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "app/batch.hpp"
#include "app/outputs.hpp"
#include "app/profile.hpp"
#include "design_test_util.hpp"
#include "gfx/renderer.hpp"
#include "nc/gcode.hpp"
#include "verify/stl.hpp"

using namespace lbr;

namespace {

// As verify_design_test.cpp: pass i at Y25 + 5i, the last one at `last_y`.
std::string slot_program(double last_y) {
  std::string s = "G21 G90 G17\nT1 M6\nG43 H1\nG0 X-10 Y25 Z5\nG1 Z-5 F1000\nG1 Y25\n";
  for (int i = 0; i < 7; ++i) {
    const double y = i == 6 ? last_y : 25.0 + 5.0 * i;
    s += "G1 Y" + std::to_string(y) + "\nG1 " + (i % 2 == 0 ? "X110" : "X-10") + "\n";
  }
  return s + "G0 Z5\nM30\n";
}

struct Vertex {
  float x, y, z;
  std::array<std::uint8_t, 3> rgb;
};

// The vertices of a binary PLY written by mesh::to_binary_ply with colours.
std::vector<Vertex> read_ply(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  const std::size_t end = bytes.find("end_header\n");
  EXPECT_NE(bytes.find("property uchar red\nproperty uchar green\nproperty uchar blue\n"), std::string::npos);
  const std::size_t at = bytes.find("element vertex ");
  const std::size_t n = std::stoul(bytes.substr(at + 15));
  std::vector<Vertex> out(n);
  const char* p = bytes.data() + end + 11;
  for (Vertex& v : out) {  // x y z nx ny nz move_id (float32), red green blue (uchar)
    std::memcpy(&v.x, p, 4), std::memcpy(&v.y, p + 4, 4), std::memcpy(&v.z, p + 8, 4);
    std::memcpy(v.rgb.data(), p + 28, 3);
    p += 31;
  }
  return out;
}

std::vector<Vertex> coloured_run(double last_y, const std::string& name) {
  const std::string stl = (std::filesystem::temp_directory_path() / (name + ".stl")).string();
  std::ofstream(stl, std::ios::binary) << verify::stl_binary(test::pocket_part({0, 0, -30}, {100, 80, 0}, 20, 60, 5));
  app::Profile p = app::default_profile();
  p.threads = 1;
  p.design = {stl, 0.02};
  const app::BatchResult r =
      app::run_batch(p, nc::interpret_gcode(slot_program(last_y), "slot.ngc", app::gcode_options(p)));
  const std::string ply = (std::filesystem::temp_directory_path() / (name + ".ply")).string();
  app::write_mesh_files(r.solid, "", ply, {&r.design_sections, 0.02});
  return read_ply(ply);
}

// The colour family of a PLY vertex: 0 within, -1 gouge (red), +1 excess (blue).
int family(const std::array<std::uint8_t, 3>& rgb) {
  if (rgb == gfx::deviation_rgb(0.0f, 0.2f)) return 0;
  return rgb[0] > rgb[2] ? -1 : 1;
}

}  // namespace

// Tolerance 0.02 mm: the colours saturate at 10 tolerances, 0.2 mm. The 0.3 mm over-cut is
// the deep red.
TEST(DeviationColour, AnOverCutWallIsRedAndNothingElseIs) {
  const std::vector<Vertex> v = coloured_run(55.3, "lbr_deviation_over");
  ASSERT_GT(v.size(), 100u);
  const auto deep_red = gfx::deviation_rgb(-1.0f, 0.2f);
  std::size_t reds = 0, blues = 0;
  for (const Vertex& p : v) {
    if (family(p.rgb) == 1) ++blues;
    if (family(p.rgb) != -1) continue;
    EXPECT_EQ(p.rgb, deep_red);
    ++reds;
    // On the over-cut wall: Y60.3, from the pocket floor Z-5 up to the top Z0.
    EXPECT_NEAR(p.y, 60.3, 0.01) << p.x << " " << p.y << " " << p.z;
    EXPECT_GE(p.z, -5.0f - 1e-4f);
    EXPECT_LE(p.z, 0.0f + 1e-4f);
  }
  EXPECT_GT(reds, 10u);
  EXPECT_EQ(blues, 0u);
}

TEST(DeviationColour, AnExactCutHasNoGougeOrExcessColour) {
  const std::vector<Vertex> v = coloured_run(55.0, "lbr_deviation_exact");
  const auto within = gfx::deviation_rgb(0.0f, 0.2f);
  std::size_t others = 0;
  for (const Vertex& p : v) others += p.rgb != within;
  EXPECT_EQ(others, 0u);
}

// The gradient: on a 0.1 mm over-cut the wall's values are 0.10–0.11 mm (the over-cut, up to
// half the tolerance more by the probe's offset along the vertex normal,
// docs/verification.md#deviation-colour): half-way from the light to the deep red, and
// clearly lighter than the 0.3 mm over-cut's deep red (-0.09 .. -0.12 mm asserted).
TEST(DeviationColour, AShallowerOverCutIsALighterRed) {
  const std::vector<Vertex> v = coloured_run(55.1, "lbr_deviation_shallow");
  const auto lighter = gfx::deviation_rgb(-0.09f, 0.2f), deeper = gfx::deviation_rgb(-0.12f, 0.2f);
  std::size_t reds = 0;
  for (const Vertex& p : v) {
    if (family(p.rgb) != -1) continue;
    ++reds;
    EXPECT_NEAR(p.y, 60.1, 0.01);
    for (int c = 0; c < 3; ++c) {  // every channel falls from the light to the deep shade
      EXPECT_LE(p.rgb[c], lighter[c]) << c;
      EXPECT_GE(p.rgb[c], deeper[c]) << c;
    }
  }
  EXPECT_GT(reds, 10u);
}

TEST(DeviationColour, GradientRunsFromLightToDeepAndSaturatesAtTheScale) {
  const auto light = gfx::deviation_rgb(-1e-4f, 0.2f), mid = gfx::deviation_rgb(-0.1f, 0.2f),
             deep = gfx::deviation_rgb(-0.2f, 0.2f);
  EXPECT_EQ(gfx::deviation_rgb(-5.0f, 0.2f), deep);
  EXPECT_EQ(deep, (std::array<std::uint8_t, 3>{181, 10, 10}));
  EXPECT_EQ(light, (std::array<std::uint8_t, 3>{240, 153, 140}));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(mid[c], 0.5 * (light[c] + deep[c]), 1.0) << c;
  EXPECT_EQ(gfx::deviation_rgb(0.2f, 0.2f), (std::array<std::uint8_t, 3>{20, 51, 199}));
  const std::vector<gfx::LegendRow> legend = gfx::deviation_legend(0.2);
  ASSERT_EQ(legend.size(), 5u);
  EXPECT_EQ(legend[0].rgb, deep);
  EXPECT_EQ(legend[0].text, "gouge >= 0.200 mm");
  EXPECT_EQ(legend[2].text, "within tolerance 0.020 mm");
  EXPECT_EQ(legend[2].rgb, gfx::deviation_rgb(0.0f, 0.2f));
  EXPECT_EQ(legend[4].rgb, gfx::deviation_rgb(0.2f, 0.2f));
}
