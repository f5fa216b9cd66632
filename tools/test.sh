#!/usr/bin/env bash
# One command for a newcomer and for CI: install dependencies, build, run every test;
# then rebuild with AddressSanitizer + UndefinedBehaviorSanitizer and run the unit tests
# again (build-asan/). Set LBR_SKIP_SANITIZERS=1 to skip the second stage locally.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup-debian.sh
tools/build.sh -DLBR_BUILD_TESTS=ON
ctest --test-dir build --output-on-failure --parallel "$(nproc)" --timeout 600

if [ "${LBR_SKIP_SANITIZERS:-0}" != "1" ]; then
  echo "== sanitizers: address,undefined =="
  cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DLBR_SANITIZE=address,undefined \
        -DLBR_BUILD_BENCH=OFF -DLBR_BUILD_TESTS=ON
  cmake --build build-asan --parallel "$(nproc)"
  UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 ASAN_OPTIONS=detect_leaks=1 \
    ctest --test-dir build-asan --output-on-failure --parallel "$(nproc)" --timeout 900 -L unit
fi
