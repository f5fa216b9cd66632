// cfg/error.hpp — the configuration error every profile reader throws, with the message
// "file:line: table.key: what was expected" (docs/profiles.md). Without toml++, so that
// code that only catches it need not include the parser.
#pragma once

#include <stdexcept>

namespace lbr::cfg {

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace lbr::cfg
