#!/usr/bin/env bash
# One command for a newcomer: install dependencies, build, and run the main job on the
# built-in default: the in-process machine emulator plays the bundled demo part program
# (config/programs/demo-pocket.moves) through the live HAL path (HAL thread -> lock-free ring
# -> geometry thread -> render thread) on the default 3-axis mill profile.
#  - With a display: a viewer window, in real time (close it or press Ctrl-C to stop early).
#  - Without one: 20x real time, rendered off-screen under a virtual X server, writing
#    progress pictures; the results are files.
# Either way lbrsim-out/ ends up with metrics.json, levels.lbrs and part.stl (and the PNGs).
# Extra arguments go to `lbrsim run` (e.g. --speed 5, --profile FILE, --source ...).
set -euo pipefail
if [ "${1:-}" = --help ] || [ "${1:-}" = -h ]; then  # usage: the comment above
  sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0
fi
cd "$(dirname "$0")/.."
tools/setup-debian.sh
tools/build.sh
mkdir -p lbrsim-out
if [ -n "${DISPLAY:-}${WAYLAND_DISPLAY:-}" ]; then
  exec build/app/lbrsim run --source emulator:demo --out lbrsim-out --stl lbrsim-out/part.stl "$@"
else
  echo "demo: no display; rendering off-screen (xvfb-run) at 20x real time into lbrsim-out/"
  exec xvfb-run -a build/app/lbrsim run --source emulator:demo --speed 20 --hidden --screenshot-every 90 \
    --screenshot-prefix lbrsim-out/frame- --out lbrsim-out --stl lbrsim-out/part.stl "$@"
fi
