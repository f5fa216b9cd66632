// app/src/live/source.hpp — the live source named by `--source` (can:, serial:, replay:,
// emulator:). Setup: throws std::runtime_error on a bad spec, an unknown tool in an emulated
// program, or a device that cannot be found.
#pragma once

#include <memory>
#include <string>

#include "app/profile.hpp"
#include "hal/source.hpp"

namespace lbr::app::live {

[[nodiscard]] std::unique_ptr<hal::Source> make_source(const Profile& profile, const std::string& spec, double speed);

}  // namespace lbr::app::live
