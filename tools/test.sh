#!/usr/bin/env bash
# One command for a newcomer and for CI: install dependencies, build, run every test;
# then rebuild with AddressSanitizer + UndefinedBehaviorSanitizer and run the unit tests
# again (build-asan/); then the threaded tests (ring, RT threads, live pipeline, worker pool) under
# ThreadSanitizer (build-tsan/) and,
# where clang is installed, the libFuzzer decoder targets for a fixed number of runs
# (build-fuzz/, label fuzz). Set LBR_SKIP_SANITIZERS=1 to skip these stages locally. Before
# them, the Debian package test (label package; LBR_SKIP_PACKAGE=1 skips it).
set -euo pipefail
if [ "${1:-}" = --help ] || [ "${1:-}" = -h ]; then  # usage: the comment above
  sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0
fi
cd "$(dirname "$0")/.."
tools/setup-debian.sh
tools/build.sh -DLBR_BUILD_TESTS=ON
ctest --test-dir build --output-on-failure --parallel "$(nproc)" --timeout 600 -LE package
# The Debian package installed into a debootstrap root, and lintian (docs/deployment.md#tests;
# skipped without root; ~5 min the first time, ~1.5 min with build/package-test cached).
if [ "${LBR_SKIP_PACKAGE:-0}" != "1" ]; then
  echo "== Debian package =="
  ctest --test-dir build --output-on-failure -L package
fi

if [ "${LBR_SKIP_SANITIZERS:-0}" != "1" ]; then
  echo "== sanitizers: address,undefined =="
  cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DLBR_SANITIZE=address,undefined \
        -DLBR_BUILD_BENCH=OFF -DLBR_BUILD_TESTS=ON
  cmake --build build-asan --parallel "$(nproc)"
  UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 ASAN_OPTIONS=detect_leaks=1 \
    ctest --test-dir build-asan --output-on-failure --parallel "$(nproc)" --timeout 900 -L unit
fi

if [ "${LBR_SKIP_SANITIZERS:-0}" != "1" ]; then
  echo "== sanitizers: thread (ring, RT threads, live pipeline, kernel worker pool) =="
  cmake -S . -B build-tsan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DLBR_SANITIZE=thread -DLBR_TSAN_TESTS=ON \
        -DLBR_BUILD_BENCH=OFF -DLBR_BUILD_TESTS=ON
  cmake --build build-tsan --parallel "$(nproc)" --target sched_ring_test sched_ring_test_tsan sched_stats_test app_live_test app_profile_test geom_parallel_test kin_machine_test app_snapshot_test app_watchdog_test app_live_pool_test
  TSAN_OPTIONS=halt_on_error=1 ctest --test-dir build-tsan --output-on-failure --timeout 900 \
        -R '^(SpscRing|LatencyHistogram|RtThread|LiveRun|LiveProfile|LivePool|Snapshot|Watchdog)\.|^Batch\.WorkerThreads|^ParallelSubtractor\.|^Channels\.|^sched_ring_test_tsan$'
  if command -v clang++ >/dev/null 2>&1; then
    echo "== fuzzers (libFuzzer, fixed runs) =="
    CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLBR_BUILD_FUZZ=ON \
          -DLBR_SANITIZE=fuzzer-no-link,address,undefined \
          -DLBR_BUILD_BENCH=OFF -DLBR_BUILD_TESTS=ON
    # fuzz_profile links the whole application (every module's profile reader): it runs in the
    # campaigns (docs/reliability.md), not here, so this stage builds only the decoder libraries.
    cmake --build build-fuzz --parallel "$(nproc)" --target fuzz_serial fuzz_candump fuzz_canopen fuzz_gcode \
          fuzz_rs274_canon fuzz_movelist fuzz_lbrs fuzz_stl
    UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 ASAN_OPTIONS=detect_leaks=1 \
      ctest --test-dir build-fuzz --output-on-failure --parallel "$(nproc)" -L fuzz -R '^fuzz_' -E '^fuzz_profile$'
  fi
fi
