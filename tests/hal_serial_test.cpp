// Serial frame decoder: CRC check value, golden frame, and every fault kind (bad CRC,
// truncated, garbage prefix, bad length, sequence gap, duplicate, no-value pattern,
// out-of-range and jump rejection), resynchronisation inside a damaged frame; the serial
// source's hang-up / reconnect over a pseudo-terminal.
#include <gtest/gtest.h>
#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "hal/crc.hpp"
#include "hal/serial_codec.hpp"
#include "hal/source.hpp"
#include "hal/validate.hpp"

using namespace lbr::hal;

namespace {

// Independently computed (Python, bitwise CRC): seq 7, t 1000 µs, positions 1000, -2000, 30000.
const std::vector<std::uint8_t> kGolden = {0xA5, 0x5A, 0x18, 0x07, 0x00, 0x00, 0x00, 0xE8, 0x03, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
                                           0xE8, 0x03, 0x00, 0x00, 0x30, 0xF8, 0xFF, 0xFF, 0x30, 0x75, 0x00, 0x00, 0x4A, 0x9C};

std::vector<std::uint8_t> frame(std::uint32_t seq, std::vector<std::int32_t> pos, std::uint64_t t_us = 0) {
  SerialFrame f;
  f.seq = seq;
  f.t_us = t_us;
  f.n = static_cast<int>(pos.size());
  for (std::size_t i = 0; i < pos.size(); ++i) f.pos[i] = pos[i];
  std::vector<std::uint8_t> out(kSerialMaxFrame);
  out.resize(encode_serial_frame(f, out));
  return out;
}

struct Collect {
  std::vector<SerialFrame> frames;
  Counters c;
  SerialStreamDecoder d;
  void feed(const std::vector<std::uint8_t>& b) {
    d.feed(b, c, [&](const SerialFrame& f) { frames.push_back(f); });
  }
};

std::vector<std::uint8_t> cat(std::initializer_list<std::vector<std::uint8_t>> parts) {
  std::vector<std::uint8_t> r;
  for (const auto& p : parts) r.insert(r.end(), p.begin(), p.end());
  return r;
}

}  // namespace

TEST(Crc16CcittFalse, CheckValue) {
  const char* s = "123456789";
  EXPECT_EQ(crc16_ccitt_false({reinterpret_cast<const std::uint8_t*>(s), 9}), 0x29B1);
  EXPECT_EQ(crc16_ccitt_false({}), 0xFFFF);
}

TEST(SerialCodec, GoldenFrameEncodesAndDecodes) {
  EXPECT_EQ(frame(7, {1000, -2000, 30000}, 1000), kGolden);
  SerialFrame f;
  const SerialDecode d = decode_serial_frame(kGolden, f);
  ASSERT_EQ(d.status, SerialStatus::Ok);
  EXPECT_EQ(d.consumed, kGolden.size());
  EXPECT_EQ(f.seq, 7u);
  EXPECT_EQ(f.t_us, 1000u);
  ASSERT_EQ(f.n, 3);
  EXPECT_EQ(f.pos[0], 1000);
  EXPECT_EQ(f.pos[1], -2000);
  EXPECT_EQ(f.pos[2], 30000);
}

TEST(SerialCodec, TruncatedNeedsMoreAndDeliversNothing) {
  SerialFrame f;
  for (std::size_t n = 0; n < kGolden.size(); ++n) {
    const SerialDecode d = decode_serial_frame(std::span(kGolden.data(), n), f);
    EXPECT_EQ(d.status, SerialStatus::NeedMore) << n;
  }
  Collect c;
  c.feed(std::vector<std::uint8_t>(kGolden.begin(), kGolden.end() - 3));
  EXPECT_TRUE(c.frames.empty());
  c.feed(std::vector<std::uint8_t>(kGolden.end() - 3, kGolden.end()));  // the rest arrives later
  ASSERT_EQ(c.frames.size(), 1u);
  EXPECT_EQ(c.frames[0].pos[2], 30000);
}

TEST(SerialCodec, BadCrcIsCountedAndFollowingFrameRecovered) {
  auto bad = frame(1, {1, 2, 3});
  bad[16] ^= 0x40;  // flip a bit in a position
  Collect c;
  c.feed(cat({frame(0, {0, 0, 0}), bad, frame(2, {4, 5, 6})}));
  ASSERT_EQ(c.frames.size(), 2u);
  EXPECT_EQ(c.frames[1].seq, 2u);
  EXPECT_EQ(c.frames[1].pos[0], 4);
  EXPECT_EQ(c.c.get(Fault::CrcError), 1u);
  EXPECT_EQ(c.c.get(Fault::SeqGap), 1u);  // frame 1 is lost
}

TEST(SerialCodec, GarbagePrefixIsSkippedAndCounted) {
  const std::vector<std::uint8_t> garbage = {0x00, 0x11, 0xA5, 0x00, 0x5A, 0xFF, 0x13};
  Collect c;
  c.feed(cat({garbage, kGolden}));
  ASSERT_EQ(c.frames.size(), 1u);
  EXPECT_EQ(c.frames[0].seq, 7u);
  EXPECT_EQ(c.c.get(Fault::GarbageBytes), garbage.size());
  EXPECT_EQ(c.c.get(Fault::CrcError) + c.c.get(Fault::LengthError), 0u);
}

TEST(SerialCodec, ResyncInsideATruncatedFrame) {
  // A frame cut short by a sender reset, immediately followed by good frames: the decoder
  // must find the good frame that starts inside the bytes it first took for the bad one.
  auto cut = frame(10, {1, 2, 3});
  cut.resize(12);
  Collect c;
  c.feed(cat({cut, frame(11, {7, 8, 9}), frame(12, {10, 11, 12})}));
  ASSERT_EQ(c.frames.size(), 2u);
  EXPECT_EQ(c.frames[0].seq, 11u);
  EXPECT_EQ(c.frames[0].pos[0], 7);
  EXPECT_EQ(c.frames[1].seq, 12u);
  EXPECT_EQ(c.c.get(Fault::CrcError), 1u);
}

TEST(SerialCodec, BadLengthIsCounted) {
  auto bad = frame(1, {1, 2, 3});
  bad[2] = 13;  // not 12 + 4N
  Collect c;
  c.feed(cat({bad, frame(2, {1, 2, 3})}));
  ASSERT_EQ(c.frames.size(), 1u);
  EXPECT_EQ(c.frames[0].seq, 2u);
  EXPECT_EQ(c.c.get(Fault::LengthError), 1u);
}

TEST(SerialCodec, SequenceGapAndDuplicate) {
  Collect c;
  c.feed(cat({frame(100, {1, 1, 1}), frame(101, {2, 2, 2}), frame(101, {2, 2, 2}), frame(99, {0, 0, 0}),
              frame(105, {3, 3, 3})}));
  ASSERT_EQ(c.frames.size(), 3u);
  EXPECT_EQ(c.c.get(Fault::SeqDuplicate), 2u);  // the repeat and the older one
  EXPECT_EQ(c.c.get(Fault::SeqGap), 3u);        // 102, 103, 104
  EXPECT_EQ(c.d.gaps(), 3u);
}

TEST(SerialCodec, SequenceWrapIsNotAGap) {
  Collect c;
  c.feed(cat({frame(0xFFFFFFFFU, {1, 1, 1}), frame(0, {2, 2, 2})}));
  EXPECT_EQ(c.frames.size(), 2u);
  EXPECT_EQ(c.c.total(), 0u);
}

TEST(SerialMapping, NoValuePatternAndIncompleteFrames) {
  LiveConfig cfg;
  cfg.axes = default_axes();
  std::array<AxisSample, kMaxChannels> out{};
  Counters c;
  SerialFrame f;
  f.seq = 3;
  f.n = 3;
  f.pos = {1000, 2000, kNoValue};
  EXPECT_EQ(frame_to_samples(f, cfg, 0, out, c), 0);
  EXPECT_EQ(c.get(Fault::InvalidValue), 1u);
  f.n = 2;
  EXPECT_EQ(frame_to_samples(f, cfg, 0, out, c), 0);
  EXPECT_EQ(c.get(Fault::Incomplete), 1u);
  f.n = 3;
  f.pos = {1000, -2500, 3};
  ASSERT_EQ(frame_to_samples(f, cfg, 42, out, c), 1);
  EXPECT_DOUBLE_EQ(out[0].q[0], 1.0);
  EXPECT_DOUBLE_EQ(out[0].q[1], -2.5);
  EXPECT_DOUBLE_EQ(out[0].q[2], 0.003);
  EXPECT_EQ(out[0].mask, 0b111);
  EXPECT_EQ(out[0].t_rx_ns, 42);
  EXPECT_EQ(out[0].seq, 3u);
}

TEST(Validator, OutOfRangeAndJumpRejected) {
  LiveConfig cfg;
  cfg.axes = default_axes();
  for (auto& m : cfg.axes) {
    m.min = -10;
    m.max = 110;
    m.max_speed_per_s = 100.0;  // 6000 mm/min → 0.1 mm per 1 ms sample
  }
  cfg.jump_tolerance = 1.5;
  Validator v(cfg);
  Counters c;
  AxisSample s;
  s.mask = 0b111;
  s.seq = 1;
  s.q = {0, 0, 0, 0, 0, 0};
  EXPECT_TRUE(v.accept(s, c));
  s.seq = 2;
  s.q[0] = 0.1;  // max speed exactly
  EXPECT_TRUE(v.accept(s, c));
  s.seq = 3;
  s.q[0] = 0.5;  // 0.4 mm in 1 ms: jump
  EXPECT_FALSE(v.accept(s, c));
  EXPECT_EQ(c.get(Fault::Jump), 1u);
  s.seq = 6;  // 4 periods after the last accepted one: 0.4 mm allowed
  EXPECT_TRUE(v.accept(s, c));
  s.seq = 7;
  s.q[1] = 110.5;  // outside travel
  EXPECT_FALSE(v.accept(s, c));
  s.q[1] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(v.accept(s, c));
  EXPECT_EQ(c.get(Fault::OutOfRange), 2u);
  EXPECT_EQ(v.rejected(), 3u);
}

// live.serial.reconnect_ms: a hang-up (the pty master closed, the link gone) does not end the
// source; a new pty behind the same link is reopened, counted `reconnect`, and the frames
// missed meanwhile count as sequence gaps. With 0 the hang-up ends the source.
namespace {

struct PtyLink {
  int master = -1;
  PtyLink(const std::string& link) {
    int slave = -1;
    EXPECT_EQ(openpty(&master, &slave, nullptr, nullptr, nullptr), 0);
    termios t{};
    tcgetattr(slave, &t);
    cfmakeraw(&t);
    tcsetattr(slave, TCSANOW, &t);
    std::filesystem::remove(link);
    std::filesystem::create_symlink(ttyname(slave), link);
    ::close(slave);
  }
  void send(const std::vector<std::uint8_t>& b) const { ASSERT_EQ(::write(master, b.data(), b.size()), static_cast<ssize_t>(b.size())); }
  void hang_up(const std::string& link) {
    std::filesystem::remove(link);
    ::close(master);
    master = -1;
  }
  ~PtyLink() {
    if (master >= 0) ::close(master);
  }
};

struct CountingSink final : SampleSink {
  std::vector<std::uint64_t> seqs;
  void on_samples(std::span<const AxisSample> s) noexcept override {
    for (const AxisSample& a : s) seqs.push_back(a.seq);
  }
};

// Polls until `want` samples arrived or the source ends / 2 s pass; returns the last result.
PollResult poll_for(Source& src, CountingSink& sink, std::size_t want) {
  PollResult r = PollResult::Idle;
  for (int i = 0; i < 200 && sink.seqs.size() < want && r != PollResult::End; ++i) r = src.poll(10, sink);
  return r;
}

}  // namespace

TEST(SerialSource, ReconnectsAfterHangUpAndCountsTheGap) {
  const std::string dir = testing::TempDir() + "/lbr_serial_reconnect";
  std::filesystem::create_directories(dir);
  const std::string link = dir + "/pty";
  LiveConfig cfg;
  cfg.axes = default_axes();
  cfg.serial.reconnect_ms = 20.0;
  auto pty = std::make_unique<PtyLink>(link);
  auto src = make_serial_source(link, cfg);
  src->open();
  CountingSink sink;
  for (std::uint32_t s = 0; s < 5; ++s) pty->send(frame(s, {1, 2, 3}));
  pty->send({0xA5, 0x5A, 0x18, 0x05});  // the start of frame 5, cut by the hang-up
  EXPECT_NE(poll_for(*src, sink, 5), PollResult::End);
  ASSERT_EQ(sink.seqs.size(), 5U);
  pty->hang_up(link);
  for (int i = 0; i < 5; ++i) EXPECT_NE(src->poll(10, sink), PollResult::End);  // waits for the device
  pty = std::make_unique<PtyLink>(link);
  for (std::uint32_t s = 9; s < 12; ++s) pty->send(frame(s, {1, 2, 3}));
  EXPECT_NE(poll_for(*src, sink, 8), PollResult::End);
  EXPECT_EQ(sink.seqs, (std::vector<std::uint64_t>{0, 1, 2, 3, 4, 9, 10, 11}));
  EXPECT_EQ(src->counters().get(Fault::Reconnect), 1U);
  EXPECT_EQ(src->lost(), 4U);  // 5, 6, 7, 8
  EXPECT_EQ(src->counters().get(Fault::SeqGap), 4U);
  src->close();
}

TEST(SerialSource, HangUpEndsTheSourceWithoutReconnect) {
  const std::string dir = testing::TempDir() + "/lbr_serial_hangup";
  std::filesystem::create_directories(dir);
  const std::string link = dir + "/pty";
  LiveConfig cfg;
  cfg.axes = default_axes();
  PtyLink pty(link);
  auto src = make_serial_source(link, cfg);
  src->open();
  CountingSink sink;
  for (std::uint32_t s = 0; s < 3; ++s) pty.send(frame(s, {1, 2, 3}));
  EXPECT_NE(poll_for(*src, sink, 3), PollResult::End);
  pty.hang_up(link);
  EXPECT_EQ(poll_for(*src, sink, 100), PollResult::End);
  EXPECT_EQ(sink.seqs.size(), 3U);
  EXPECT_EQ(src->counters().get(Fault::Reconnect), 0U);
}

// Regression (UBSan in fuzz_serial, docs/reliability.md): a frame's 64-bit t_us × 1000
// overflowed int64. Wire timestamps beyond kMaxSerialTimeUs are invalid values now.
TEST(SerialMapping, RegressionTimestampBeyondInt64Nanoseconds) {
  LiveConfig cfg;
  cfg.axes = default_axes();
  std::array<AxisSample, kMaxChannels> out{};
  Counters c;
  SerialFrame f;
  f.seq = 1;
  f.n = 3;
  f.pos = {1, 2, 3};
  f.t_us = kMaxSerialTimeUs + 1;
  EXPECT_EQ(frame_to_samples(f, cfg, 0, out, c), 0);
  EXPECT_EQ(c.get(Fault::InvalidValue), 1u);
  f.t_us = ~std::uint64_t{0};
  EXPECT_EQ(frame_to_samples(f, cfg, 0, out, c), 0);
  f.t_us = kMaxSerialTimeUs;
  ASSERT_EQ(frame_to_samples(f, cfg, 0, out, c), 1);
  EXPECT_EQ(out[0].t_src_ns, static_cast<std::int64_t>(kMaxSerialTimeUs) * 1000);
}

// The 32-bit serial sequence wraps: the jump check takes the step modulo 2^32 (before, the
// wrap looked like 2^64 − 2^32 periods and let any jump through).
TEST(Validator, SequenceWrapIsOnePeriod) {
  LiveConfig cfg;
  cfg.axes = default_axes();
  for (auto& m : cfg.axes) m.max_speed_per_s = 100.0;
  Validator v(cfg);
  Counters c;
  AxisSample s;
  s.mask = 0b111;
  s.seq = 0xFFFFFFFFu;
  EXPECT_TRUE(v.accept(s, c));
  s.seq = 0;
  s.q[0] = 50.0;  // 50 mm in one period
  EXPECT_FALSE(v.accept(s, c));
  EXPECT_EQ(c.get(Fault::Jump), 1u);
  s.q[0] = 0.1;
  EXPECT_TRUE(v.accept(s, c));
}
