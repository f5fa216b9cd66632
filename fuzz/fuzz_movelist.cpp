// libFuzzer target: the move list parser (.moves, docs/nc-frontend.md) either returns a
// Toolpath with finite positions and source lines inside the input, or throws ParseError
// naming a line of the input ("NAME:LINE: ...").
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "nc/movelist.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const long lines = 1 + std::count(text.begin(), text.end(), '\n');
  try {
    const lbr::nc::Toolpath tp = lbr::nc::parse_movelist(text, "fuzz.moves");
    for (const lbr::nc::Segment& s : tp.segments) {
      for (double v : s.end)
        if (!std::isfinite(v)) __builtin_trap();
      if (s.line < 1 || s.line > lines) __builtin_trap();
    }
  } catch (const lbr::nc::ParseError& e) {
    if (e.line() < 1 || e.line() > lines) __builtin_trap();
    if (std::string(e.what()).rfind("fuzz.moves:" + std::to_string(e.line()) + ": ", 0) != 0) __builtin_trap();
  }
  return 0;
}
