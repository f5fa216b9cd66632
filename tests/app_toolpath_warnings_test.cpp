// app::toolpath_warnings: an empty program and feed moves without a tool are said, once each
// (issue 14: LinuxCNC's arcspiral.ngc, 5 822 segments, never loads a tool and cut nothing
// without a word).
#include <gtest/gtest.h>

#include "app/batch.hpp"

using namespace lbr;

namespace {

nc::Segment feed(int tool, int line) {
  nc::Segment s;
  s.kind = nc::SegmentKind::Feed;
  s.feed_mm_per_min = 500.0;
  s.tool = tool;
  s.line = line;
  return s;
}

}  // namespace

TEST(ToolpathWarnings, AnEmptyProgramIsSaid) {
  nc::Toolpath p;
  p.source = "empty.ngc";
  const auto w = app::toolpath_warnings(p);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0], "empty.ngc: the program holds no moves; nothing is cut");
}

TEST(ToolpathWarnings, FeedMovesWithoutAToolAreCountedOnceWithTheFirstLine) {
  nc::Toolpath p;
  p.source = "spiral.ngc";
  nc::Segment rapid;
  rapid.kind = nc::SegmentKind::Rapid;
  rapid.line = 3;
  p.segments = {rapid, feed(0, 4), feed(0, 5), feed(0, 9)};
  const auto w = app::toolpath_warnings(p);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0].rfind("spiral.ngc:4: 3 feed moves run with no tool loaded (tool 0)", 0), 0u) << w[0];
  EXPECT_NE(w[0].find("--start-tool N (profile: [nc] start_tool)"), std::string::npos) << w[0];
}

TEST(ToolpathWarnings, AProgramThatLoadsAToolIsQuiet) {
  nc::Toolpath p;
  p.source = "pocket.ngc";
  p.segments = {feed(1, 4), feed(1, 5)};
  EXPECT_TRUE(app::toolpath_warnings(p).empty());
}
