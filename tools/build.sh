#!/usr/bin/env bash
# Configures and builds lbrsim into build/ (Release with debug info).
set -euo pipefail
if [ "${1:-}" = --help ] || [ "${1:-}" = -h ]; then  # usage: the comment above
  sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0
fi
cd "$(dirname "$0")/.."
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLBR_BUILD_TESTS=ON -DLBR_BUILD_BENCH=ON "$@"
cmake --build build --parallel "$(nproc)"
