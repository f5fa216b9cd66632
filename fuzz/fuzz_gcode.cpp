// libFuzzer target: the built-in G-code interpreter either returns a Toolpath with finite
// positions and valid source lines, or throws ParseError naming a line of the input; in both
// dialects (RS274/NGC and Fanuc).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "nc/gcode.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const long lines = 1 + std::count(text.begin(), text.end(), '\n');
  for (const lbr::nc::Dialect d : {lbr::nc::Dialect::Rs274ngc, lbr::nc::Dialect::Fanuc}) {
    lbr::nc::GcodeOptions o;
    o.dialect = d;
    o.tool_lengths = {{1, 60.0}, {2, 50.0}};
    o.chord_tol_mm = 0.01;
    // An endless loop (GOTO, WHILE) is refused after this many blocks, not a fuzzer timeout.
    // 20 000 keeps such an input at ~0.1 s in the sanitizer build (200 000 took ~0.85 s, the
    // campaigns' "slow units"); the refusal path is the same at any count.
    o.max_blocks = 20000;
    // And a loop of large arcs is refused after this many segments, not an out-of-memory
    // (campaign 2026-11-28: a Fanuc GOTO loop of a full circle with I-48000 reached 2.5 GB). The refusal
    // path is the same at any count.
    o.max_segments = 20000;
    try {
      const lbr::nc::Toolpath tp = lbr::nc::interpret_gcode(text, "fuzz.ngc", o);
      for (const lbr::nc::Segment& s : tp.segments) {
        for (double v : s.end)
          if (!std::isfinite(v)) __builtin_trap();
        if (s.line < 1 || s.line > lines) __builtin_trap();
      }
    } catch (const lbr::nc::ParseError& e) {
      if (e.line() < 1 || e.line() > lines) __builtin_trap();
    }
  }
  return 0;
}
