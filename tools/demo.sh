#!/usr/bin/env bash
# One command for a newcomer: install dependencies, build, run the main job on the built-in
# default (the bundled demo part program on the default 3-axis mill profile).
# Outputs go to lbrsim-out/ (metrics.json, levels.lbrs).
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup-debian.sh
tools/build.sh
build/app/lbrsim batch --out lbrsim-out "$@"
