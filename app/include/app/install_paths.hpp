// app/install_paths.hpp — where an installed lbrsim finds its profiles and bundled programs
// (docs/deployment.md#files). The folders are compiled in from the CMake install prefix.
// Setup code only: touches the file system, allocates.
#pragma once

#include <string>

namespace lbr::app {

// The project version (CMake's project(VERSION)): `lbrsim --version`, metrics.json, the package.
[[nodiscard]] const char* version() noexcept;

// Installed folders: profiles (<sysconfdir>/lbrsim, /etc/lbrsim for the package) and
// bundled data (<datadir>/lbrsim, /usr/share/lbrsim; programs in its programs/ folder).
[[nodiscard]] const char* installed_profile_dir() noexcept;
[[nodiscard]] const char* installed_data_dir() noexcept;

// A profile named on the command line: `path` as given when it exists (relative to the
// current directory, as before), else for a relative path the installed profile folder's
// PATH, then PATH.toml there (so `--profile live-6axis` finds /etc/lbrsim/live-6axis.toml).
// Returns `path` unchanged when none exists (the caller's error names it).
[[nodiscard]] std::string find_profile(const std::string& path);
// A part program: `path` when it exists, else for a relative path the installed programs
// folder's PATH, then the file name alone there (a profile's "../programs/x.ngc" installed
// under /etc/lbrsim). Returns `path` unchanged when none exists.
[[nodiscard]] std::string find_program(const std::string& path);

}  // namespace lbr::app
