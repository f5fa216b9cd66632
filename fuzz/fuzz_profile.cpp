// libFuzzer target: the profile parser (TOML, docs/profiles.md) either returns a Profile or
// throws ProfileError located in the input ("NAME:LINE: ...", LINE within the input).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "app/profile.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const long lines = 1 + std::count(text.begin(), text.end(), '\n');
  try {
    (void)lbr::app::parse_profile(text, "fuzz.toml");
  } catch (const lbr::app::ProfileError& e) {
    const std::string msg = e.what();
    if (msg.rfind("fuzz.toml:", 0) != 0) __builtin_trap();
    const long line = std::strtol(msg.c_str() + 10, nullptr, 10);
    if (line < 1 || line > lines) __builtin_trap();
  }
  return 0;
}
