#!/usr/bin/env bash
# Installs every Debian 12 package lbrsim needs to build, run, test and benchmark.
# Idempotent: installs only what is missing. Runs as root, or through sudo when available.
set -euo pipefail
if [ "${1:-}" = --help ] || [ "${1:-}" = -h ]; then  # usage: the comment above
  sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0
fi

PACKAGES=(
  # toolchain
  build-essential cmake ninja-build pkg-config git
  # libraries (found by CMake find_package / pkg-config)
  libpolyclipping-dev libtomlplusplus-dev libcli11-dev libspdlog-dev nlohmann-json3-dev
  libglfw3-dev libx11-dev libglm-dev libepoxy-dev libstb-dev libserial-dev linux-libc-dev libsystemd-dev
  # the executables' heap allocator (tcmalloc, CMakeLists.txt LBR_MALLOC)
  libgoogle-perftools-dev
  # Debian package (cmake --build build --target package) and its checks (ctest -L package)
  lintian debootstrap
  # operator UI (Dear ImGui with its OpenGL 3 backend, docs/ui.md)
  libimgui-dev
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev gnuplot-nox xvfb xauth
  # independent mesh checker for the exported STL (tests/cli_mesh_admesh.cmake)
  admesh
  # libFuzzer decoder targets (tools/test.sh builds them with clang)
  clang
  # HIL bench (tools/hil/hil-bench.sh): VM with Debian's kernel, vcan, busybox initramfs
  qemu-system-x86 busybox-static cpio
  # ... which also drives lbrsim from can-utils (candump -l, canplayer) inside the VM
  can-utils
  # LinuxCNC's rs274 interpreter: optional at run time (lbrsim --interpreter rs274), needed for
  # the rs274 cross-check tests (they skip without it)
  linuxcnc-uspace
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup-debian: all ${#PACKAGES[@]} packages are installed"
  exit 0
fi

SUDO=()
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO=(sudo); else
    echo "setup-debian: not root and no sudo; install these packages: ${missing[*]}" >&2
    exit 1
  fi
fi
echo "setup-debian: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${SUDO[@]}" apt-get update -q
"${SUDO[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
