// nc/movelist.hpp — the lbrsim move list (".moves"), a plain text tool path format for
// exercising the kernel directly. Grammar in docs/formats.md#move-list.
#pragma once

#include <string>

#include "nc/toolpath.hpp"

namespace lbr::nc {

// Parses move-list text. `name` is used in error messages. Throws ParseError.
[[nodiscard]] Toolpath parse_movelist(const std::string& text, const std::string& name);
// Reads and parses a file. Throws ParseError (line 0 when the file cannot be read).
[[nodiscard]] Toolpath load_movelist(const std::string& path);

}  // namespace lbr::nc
