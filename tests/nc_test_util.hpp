// Helpers shared by the nc tests.
#pragma once

#include <string>

#ifndef LBR_SOURCE_DIR
#error "LBR_SOURCE_DIR must be defined by the build (tests/CMakeLists.txt)"
#endif

namespace lbr::test {

// A bundled part program (config/programs/NAME).
inline std::string program_file(const std::string& name) { return std::string(LBR_SOURCE_DIR) + "/config/programs/" + name; }

}  // namespace lbr::test
