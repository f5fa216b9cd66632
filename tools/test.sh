#!/usr/bin/env bash
# One command for a newcomer and for CI: install dependencies, build, run every test.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup-debian.sh
tools/build.sh
ctest --test-dir build --output-on-failure --parallel "$(nproc)" --timeout 600
