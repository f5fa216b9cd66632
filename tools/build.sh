#!/usr/bin/env bash
# Configures and builds lbrsim into build/ (Release with debug info).
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLBR_BUILD_TESTS=ON -DLBR_BUILD_BENCH=ON "$@"
cmake --build build --parallel "$(nproc)"
