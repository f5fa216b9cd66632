// libFuzzer target: the rs274 canonical-output parser returns a Toolpath or throws ParseError.
#include <cstddef>
#include <cstdint>
#include <string>

#include "nc/rs274.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  lbr::nc::GcodeOptions o;
  o.chord_tol_mm = 0.01;
  // A few ARC_FEED lines of many turns or a huge radius make up to 10^6 chords each: the
  // toolpath is bounded as in fuzz_gcode, so such an input is an error, not an out-of-memory.
  o.max_segments = 20000;
  try {
    (void)lbr::nc::parse_rs274_canon(text, "fuzz.canon", o);
  } catch (const lbr::nc::ParseError&) {
  }
  return 0;
}
