// Power-loss snapshots (app/snapshot.hpp): the file round trip, corrupt and truncated files
// reported with their byte offset, the newest valid of the two files chosen, and the
// writer's hand-over.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>

#include "app/profile.hpp"
#include "app/snapshot.hpp"
#include "geom/tool.hpp"

using namespace lbr;

namespace {

app::SnapshotState cut_state(std::uint64_t generation, double depth_mm) {
  const app::Profile p = app::default_profile();
  app::SnapshotState s;
  s.solid = geom::LbrSolid(p.solid);
  const geom::Tool& t = p.tooling.tools.begin()->second;
  const geom::CutterShape shape = geom::CutterShape::build(t, p.solid.chord_tol_mm);
  geom::SweepRef sw;
  sw.shape = &shape;
  sw.from = geom::Pose{{10, 10, -depth_mm}, {0, 0, 1}};
  sw.to = geom::Pose{{50, 30, -depth_mm}, {0, 0, 1}};
  sw.id = 1;
  s.solid.subtract(std::span<const geom::SweepRef>(&sw, 1));
  s.generation = generation;
  s.source_position = 1000 + generation;
  s.samples_applied = 990 + generation;
  s.record_offset = 4096;
  s.wall_time_s = 12.5;
  s.source = "emulator:demo";
  s.have[0] = true;
  s.last[0].seq = s.source_position;
  s.last[0].t_src_ns = 1'700'000'000'123'456'000;
  s.record_file = "/var/lib/lbrsim/mill/in.log";
  s.last[0].tool = 1;
  s.last[0].mask = 0b111;
  s.last[0].q = {50, 30, -depth_mm, 0, 0, 0};
  return s;
}

std::string fresh_dir(const std::string& name) {
  const std::string d = testing::TempDir() + "/snapshot_" + name;
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

std::vector<std::uint8_t> read_all(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

void write_all(const std::string& path, const std::vector<std::uint8_t>& b) {
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}

}  // namespace

TEST(Snapshot, Crc32OfTheCheckString) {
  const std::string s = "123456789";
  EXPECT_EQ(app::crc32(reinterpret_cast<const std::uint8_t*>(s.data()), s.size()), 0xCBF43926U);
}

TEST(Snapshot, RoundTripKeepsLevelsAndPositions) {
  const app::SnapshotState s = cut_state(7, 2.0);
  const app::SnapshotState d = app::decode_snapshot(app::encode_snapshot(s), "mem");
  EXPECT_EQ(d.generation, 7u);
  EXPECT_EQ(d.source_position, 1007u);
  EXPECT_EQ(d.samples_applied, 997u);
  EXPECT_EQ(d.record_offset, 4096u);
  EXPECT_DOUBLE_EQ(d.wall_time_s, 12.5);
  EXPECT_EQ(d.source, "emulator:demo");
  EXPECT_TRUE(d.have[0]);
  EXPECT_FALSE(d.have[1]);
  EXPECT_EQ(d.last[0].seq, 1007u);
  EXPECT_EQ(d.last[0].t_src_ns, 1'700'000'000'123'456'000);
  EXPECT_EQ(d.record_file, "/var/lib/lbrsim/mill/in.log");
  EXPECT_DOUBLE_EQ(d.last[0].q[2], -2.0);
  EXPECT_LT(s.solid.volume_mm3(), s.solid.initial_volume_mm3() - 100.0);  // the cut is there
  EXPECT_DOUBLE_EQ(d.solid.volume_mm3(), s.solid.volume_mm3());
  EXPECT_EQ(d.solid.levels(), s.solid.levels());
}

// Format version 1 (before the catch-up: no record file, no sender times) is still read.
TEST(Snapshot, VersionOneIsStillRead) {
  app::SnapshotState s = cut_state(3, 1.0);
  s.record_file.clear();
  std::vector<std::uint8_t> b = app::encode_snapshot(s);
  const std::size_t source_end = 56 + s.source.size();  // docs/snapshot.md: the source spec ends here
  b.erase(b.begin() + static_cast<std::ptrdiff_t>(source_end), b.begin() + static_cast<std::ptrdiff_t>(source_end + 4));
  for (int c = 0; c < hal::kMaxChannels; ++c) {  // per channel: drop the i64 sender time after the u64 sequence
    const std::size_t at = source_end + 4 + static_cast<std::size_t>(c) * 61 + 1 + 8;
    b.erase(b.begin() + static_cast<std::ptrdiff_t>(at), b.begin() + static_cast<std::ptrdiff_t>(at + 8));
  }
  b[8] = 1;  // format version
  b.resize(b.size() - 4);
  const std::uint32_t crc = app::crc32(b.data(), b.size());
  for (int k = 0; k < 4; ++k) b.push_back(static_cast<std::uint8_t>(crc >> (8 * k)));
  const app::SnapshotState d = app::decode_snapshot(b, "v1");
  EXPECT_EQ(d.generation, 3u);
  EXPECT_EQ(d.last[0].seq, 1003u);
  EXPECT_EQ(d.last[0].t_src_ns, 0);
  EXPECT_TRUE(d.record_file.empty());
  EXPECT_DOUBLE_EQ(d.solid.volume_mm3(), s.solid.volume_mm3());
}

TEST(Snapshot, CorruptAndTruncatedFilesAreRejectedWithTheirOffset) {
  std::vector<std::uint8_t> b = app::encode_snapshot(cut_state(1, 1.0));
  std::vector<std::uint8_t> flipped = b;
  flipped[flipped.size() / 2] ^= 0x40;
  try {
    (void)app::decode_snapshot(flipped, "f");
    FAIL() << "a flipped bit was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "f: at byte " + std::to_string(b.size() - 4) +
                                         ": CRC-32 mismatch (truncated or corrupt snapshot)");
  }
  const std::vector<std::uint8_t> cut(b.begin(), b.begin() + static_cast<std::ptrdiff_t>(b.size() / 3));
  EXPECT_THROW((void)app::decode_snapshot(cut, "t"), std::runtime_error);
  EXPECT_THROW((void)app::decode_snapshot({}, "empty"), std::runtime_error);
  std::vector<std::uint8_t> magic = b;
  magic[0] = 'X';
  try {
    (void)app::decode_snapshot(magic, "m");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "m: at byte 1: not a snapshot file (magic \"LBRSNAP1\" expected)");
  }
}

TEST(Snapshot, NewestValidOfTheTwoFilesIsUsed) {
  const std::string dir = fresh_dir("newest");
  {
    app::SnapshotWriter w(dir, 1);
    for (std::uint64_t g = 1; g <= 3; ++g) {
      app::SnapshotState* slot = nullptr;
      while ((slot = w.slot()) == nullptr) std::this_thread::sleep_for(std::chrono::milliseconds(1));
      *slot = cut_state(0, static_cast<double>(g));
      w.commit();
    }
    app::SnapshotState last = cut_state(0, 4.0);
    w.write_now(last);
    EXPECT_EQ(w.written(), 4u);
    EXPECT_EQ(w.failed(), 0u);
  }
  EXPECT_FALSE(std::filesystem::exists(dir + "/snapshot-a.lbrsnap.tmp"));
  app::LoadedSnapshot l = app::load_newest_snapshot(dir);
  ASSERT_TRUE(l.state);
  EXPECT_EQ(l.state->generation, 4u);  // generations 3 (b) and 4 (a) are kept
  EXPECT_DOUBLE_EQ(l.state->last[0].q[2], -4.0);
  EXPECT_TRUE(l.problems.empty());
  // Power cut while the newest was written: it is truncated; the one before is used.
  const std::string a = dir + "/snapshot-a.lbrsnap";
  std::vector<std::uint8_t> b = read_all(a);
  b.resize(b.size() - 100);
  write_all(a, b);
  l = app::load_newest_snapshot(dir);
  ASSERT_TRUE(l.state);
  EXPECT_EQ(l.state->generation, 3u);
  EXPECT_DOUBLE_EQ(l.state->last[0].q[2], -3.0);
  ASSERT_EQ(l.problems.size(), 1u);
  EXPECT_NE(l.problems[0].find("snapshot-a.lbrsnap: at byte"), std::string::npos) << l.problems[0];
}

TEST(Snapshot, NoSnapshotInAnEmptyFolder) {
  const app::LoadedSnapshot l = app::load_newest_snapshot(fresh_dir("empty"));
  EXPECT_FALSE(l.state);
  EXPECT_TRUE(l.problems.empty());
}

TEST(Snapshot, ProfileKeysForSnapshotsAndTheCanBitrate) {
  const app::Profile d = app::default_profile();
  EXPECT_DOUBLE_EQ(d.live.snapshot_s, 5.0);
  EXPECT_EQ(d.live.can.bitrate, 500000);
  const std::string base = app::default_profile_text();
  const app::Profile p = app::parse_profile(base + "\n[live]\nsnapshot_s = 0.5\n[live.can]\nbitrate = 250000\n", "p.toml");
  EXPECT_DOUBLE_EQ(p.live.snapshot_s, 0.5);
  EXPECT_EQ(p.live.can.bitrate, 250000);
  EXPECT_THROW((void)app::parse_profile(base + "\n[live]\nsnapshot_s = -1\n", "n.toml"), app::ProfileError);
  EXPECT_THROW((void)app::parse_profile(base + "\n[live.can]\nbitrate = 5\n", "b.toml"), app::ProfileError);
}
