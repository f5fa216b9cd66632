// libFuzzer target: the rs274 canonical-output parser returns a Toolpath or throws ParseError.
#include <cstddef>
#include <cstdint>
#include <string>

#include "nc/rs274.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  lbr::nc::GcodeOptions o;
  o.chord_tol_mm = 0.01;
  try {
    (void)lbr::nc::parse_rs274_canon(text, "fuzz.canon", o);
  } catch (const lbr::nc::ParseError&) {
  }
  return 0;
}
