// Move-list front end: decoded segments and exact error messages.
#include <cmath>

#include <gtest/gtest.h>

#include "nc/movelist.hpp"

using namespace lbr;

namespace {
std::string error_of(const std::string& text) {
  try {
    (void)nc::parse_movelist(text, "t.moves");
  } catch (const nc::ParseError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(MoveList, DecodesSegments) {
  const nc::Toolpath tp = nc::parse_movelist(
      "lbr-moves 1\n# comment\nstart 1 2 30\ntool 3\nrapid 10 20 5   # trailing comment\nfeed 1200\n"
      "line 10 20 -2\nline 40 20 -2 0 1 1\ndwell 0.5\n",
      "t.moves");
  EXPECT_EQ(tp.start[nc::Z], 30.0);
  ASSERT_EQ(tp.segments.size(), 5u);
  EXPECT_EQ(tp.segments[0].kind, nc::SegmentKind::ToolChange);
  EXPECT_EQ(tp.segments[0].tool, 3);
  EXPECT_EQ(tp.segments[1].kind, nc::SegmentKind::Rapid);
  EXPECT_EQ(tp.segments[1].line, 5);
  EXPECT_EQ(tp.segments[2].kind, nc::SegmentKind::Feed);
  EXPECT_EQ(tp.segments[2].feed_mm_per_min, 1200.0);
  EXPECT_EQ(tp.segments[2].end[nc::Z], -2.0);
  EXPECT_NEAR(tp.segments[3].tool_axis[1], std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(tp.segments[3].tool_axis[2], std::sqrt(0.5), 1e-15);
  EXPECT_EQ(tp.segments[4].kind, nc::SegmentKind::Dwell);
  EXPECT_EQ(tp.segments[4].dwell_s, 0.5);
  EXPECT_EQ(tp.segments[4].end[nc::X], 40.0);
}

TEST(MoveList, StartDefaultsToFirstMotion) {
  const nc::Toolpath tp = nc::parse_movelist("lbr-moves 1\ntool 1\nrapid 5 6 7\n", "t.moves");
  EXPECT_EQ(tp.start[nc::X], 5.0);
  EXPECT_EQ(tp.start[nc::Z], 7.0);
}

TEST(MoveList, ErrorsNameFileLineAndProblem) {
  EXPECT_EQ(error_of(""), "t.moves:1: empty file: a move list starts with 'lbr-moves 1'");
  EXPECT_EQ(error_of("tool 1\n"), "t.moves:1: a move list starts with the line 'lbr-moves 1'");
  EXPECT_EQ(error_of("lbr-moves 1\ntool 1\nline 1 2 3\n"), "t.moves:3: 'line' before any 'feed': no feed rate set");
  EXPECT_EQ(error_of("lbr-moves 1\nrapid 1 2 3\n"), "t.moves:2: 'rapid' before any 'tool': no tool in the spindle");
  EXPECT_EQ(error_of("lbr-moves 1\ntool 1\nrapid 1 2\n"), "t.moves:3: expected 'rapid X Y Z' or 'rapid X Y Z I J K'");
  EXPECT_EQ(error_of("lbr-moves 1\ntool 1\nrapid 1 2 nan\n"), "t.moves:3: 'rapid': a coordinate must be a finite number, got 'nan'");
  EXPECT_EQ(error_of("lbr-moves 1\ntool 1\nrapid 1 2 3 0 0 0\n"), "t.moves:3: tool axis I J K must not be the zero vector");
  EXPECT_EQ(error_of("lbr-moves 1\nfeed -5\n"), "t.moves:2: feed rate must be > 0 mm/min");
  EXPECT_EQ(error_of("lbr-moves 1\ntool 1.5\n"), "t.moves:2: tool number must be an integer in [0, 9999]");
  EXPECT_EQ(error_of("lbr-moves 1\narc 1 2 3\n"),
            "t.moves:2: unknown keyword 'arc' (expected start, tool, feed, rapid, line or dwell)");
  EXPECT_EQ(error_of("lbr-moves 1\ntool 1\nrapid 1 2 3\nstart 0 0 0\n"), "t.moves:4: 'start' must come before the first move");
}
