// Install-prefix search paths: the current directory first (what the command line says),
// then the installed folders, so a packaged lbrsim run from anywhere finds the profiles in
// /etc/lbrsim and the bundled programs in /usr/share/lbrsim/programs.
#include "app/install_paths.hpp"

#include <filesystem>
#include <initializer_list>
#include <system_error>

#ifndef LBRSIM_VERSION
#define LBRSIM_VERSION "dev"
#endif
#ifndef LBRSIM_PROFILE_DIR
#define LBRSIM_PROFILE_DIR "/etc/lbrsim"
#endif
#ifndef LBRSIM_DATA_DIR
#define LBRSIM_DATA_DIR "/usr/share/lbrsim"
#endif

namespace lbr::app {

const char* version() noexcept { return LBRSIM_VERSION; }
const char* installed_profile_dir() noexcept { return LBRSIM_PROFILE_DIR; }
const char* installed_data_dir() noexcept { return LBRSIM_DATA_DIR; }

namespace {

bool is_file(const std::filesystem::path& p) {
  std::error_code ec;
  return std::filesystem::is_regular_file(p, ec);
}

std::string first_existing(const std::string& path, std::initializer_list<std::filesystem::path> candidates) {
  if (path.empty() || is_file(path) || std::filesystem::path(path).is_absolute()) return path;
  for (const std::filesystem::path& c : candidates)
    if (is_file(c)) return c.string();
  return path;
}

}  // namespace

std::string find_profile(const std::string& path) {
  const std::filesystem::path dir(installed_profile_dir());
  return first_existing(path, {dir / path, dir / (path + ".toml")});
}

std::string find_program(const std::string& path) {
  const std::filesystem::path dir = std::filesystem::path(installed_data_dir()) / "programs";
  return first_existing(path, {dir / path, dir / std::filesystem::path(path).filename()});
}

}  // namespace lbr::app
