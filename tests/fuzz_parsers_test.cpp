// Seeded random mutation of valid inputs for every parser of this module set: the move list,
// the profile and the levels file. Each mutated input either parses or fails with the
// parser's own error type carrying a position inside the input; nothing else may escape.
// Seed: LBR_TEST_SEED (printed); iterations are fixed so the test is bounded.
#include <cstdlib>
#include <random>
#include <regex>

#include <gtest/gtest.h>

#include "app/outputs.hpp"
#include "app/profile.hpp"
#include "geom/serialize.hpp"
#include "nc/movelist.hpp"
#include "test_util.hpp"

using namespace lbr;

namespace {

unsigned seed() {
  const char* e = std::getenv("LBR_TEST_SEED");
  const unsigned s = e != nullptr ? static_cast<unsigned>(std::strtoul(e, nullptr, 10)) : 424242u;
  std::printf("LBR_TEST_SEED=%u\n", s);
  return s;
}

template <class Bytes>
Bytes mutate(const Bytes& in, std::mt19937& rng) {
  Bytes out = in;
  std::uniform_int_distribution<int> op(0, 3), byte(0, 255), count(1, 4);
  const int n = count(rng);
  for (int i = 0; i < n && !out.empty(); ++i) {
    std::uniform_int_distribution<std::size_t> pos(0, out.size() - 1);
    const std::size_t p = pos(rng);
    switch (op(rng)) {
      case 0: out[p] = static_cast<typename Bytes::value_type>(byte(rng)); break;
      case 1: out.erase(out.begin() + static_cast<long>(p)); break;
      case 2: out.insert(out.begin() + static_cast<long>(p), static_cast<typename Bytes::value_type>(byte(rng))); break;
      default: {  // duplicate a slice
        const std::size_t len = std::min<std::size_t>(out.size() - p, 16);
        Bytes slice(out.begin() + static_cast<long>(p), out.begin() + static_cast<long>(p + len));
        out.insert(out.begin() + static_cast<long>(p), slice.begin(), slice.end());
      }
    }
  }
  return out;
}

int lines_of(const std::string& s) { return 1 + static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

}  // namespace

TEST(Fuzz, MoveListParser) {
  std::mt19937 rng(seed());
  const std::string valid = "lbr-moves 1\nstart 0 0 10\ntool 1\nfeed 900\nrapid 1 2 3\nline 4 5 -1 0 0 1\ndwell 1\n";
  int ok = 0, errors = 0;
  for (int i = 0; i < 3000; ++i) {
    const std::string in = mutate(valid, rng);
    try {
      (void)nc::parse_movelist(in, "f.moves");
      ++ok;
    } catch (const nc::ParseError& e) {
      ++errors;
      ASSERT_GE(e.line(), 1) << in;
      ASSERT_LE(e.line(), lines_of(in)) << in;
      ASSERT_EQ(std::string(e.what()).rfind("f.moves:" + std::to_string(e.line()) + ": ", 0), 0u) << e.what();
    }
  }
  EXPECT_GT(ok, 0);
  EXPECT_GT(errors, 100);
}

TEST(Fuzz, ProfileParser) {
  std::mt19937 rng(seed() + 1);
  const std::string valid = app::default_profile_text();
  const std::regex located("^p\\.toml:([0-9]+): .+");
  int ok = 0, errors = 0;
  for (int i = 0; i < 1500; ++i) {
    const std::string in = mutate(valid, rng);
    try {
      (void)app::parse_profile(in, "p.toml");
      ++ok;
    } catch (const app::ProfileError& e) {
      ++errors;
      std::smatch m;
      const std::string msg = e.what();
      ASSERT_TRUE(std::regex_match(msg, m, located)) << msg;
      ASSERT_LE(std::stoi(m[1]), lines_of(in)) << msg;
    }
  }
  EXPECT_GT(ok, 0);
  EXPECT_GT(errors, 100);
}

TEST(Fuzz, LevelsFileReader) {
  std::mt19937 rng(seed() + 2);
  geom::LbrSolid s(test::box_spec({0, 0, -2}, {20, 10, 0}, 0.5, 2, 1));
  const auto c = geom::CutterShape::build(test::tool(geom::ToolKind::Ball, 4), 0.01);
  test::cut(s, c, test::at(2, 5, -1), test::at(18, 5, -1));
  const std::vector<std::uint8_t> valid = geom::to_bytes(s);
  int errors = 0;
  for (int i = 0; i < 1500; ++i) {
    const auto in = mutate(valid, rng);
    try {
      const geom::LbrSolid r = geom::from_bytes(in);
      ASSERT_EQ(r.levels(), s.levels());
    } catch (const std::runtime_error& e) {
      ++errors;
      ASSERT_EQ(std::string(e.what()).rfind("LBRS: ", 0), 0u) << e.what();
    }
  }
  EXPECT_GT(errors, 100);
}
