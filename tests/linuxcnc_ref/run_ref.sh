#!/bin/sh
# Runs a G-code program on LinuxCNC's simulated machine without a display and writes the
# commanded X Y Z of every 1 ms servo period to OUT ("SAMPLE X Y Z" per line, mm).
# Usage: run_ref.sh PROGRAM OUT. Exit 77 when LinuxCNC is not installed. LREF_LIMIT_S: the
# longest the program may run in wall time (default 600 s; a loaded machine runs the simulator
# slower than real time, the samples stay 1 ms apart in motion time).
# Used by tests/nc_emulator_linuxcnc_test.cpp (docs/nc-frontend.md#linuxcnc-reference).
set -eu
here=$(cd "$(dirname "$0")" && pwd)
command -v linuxcnc >/dev/null 2>&1 || { echo "run_ref.sh: linuxcnc is not on PATH (Debian package linuxcnc-uspace)" >&2; exit 77; }
prog=$(realpath "$1")
out=$(realpath -m "$2")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
chmod 777 "$work"
sed "s|@DIR@|$here|g" "$here/sim.ini.in" > "$work/sim.ini"
printf 'T1 P1 Z0 D6 ;\n' > "$work/sim.tbl"
: > "$work/sim.var"
# rtapi_app refuses to run as root without a fallback user; its socket then lives in $work.
if [ "$(id -u)" = 0 ]; then
  RTAPI_UID=$(id -u nobody)
  RTAPI_FIFO_PATH="$work/.rtapi_fifo"
  export RTAPI_UID RTAPI_FIFO_PATH
fi
rm -f "$out.status"
export LREF_PROG="$prog" LREF_OUT="$out"
cd "$work"
# A run that hangs (seen on loaded machines) must not hold CI: at most LREF_TIMEOUT_S.
timeout "${LREF_TIMEOUT_S:-300}" linuxcnc "$work/sim.ini" > "$work/log.txt" 2>&1 || true
status=$(cat "$out.status" 2>/dev/null || echo "run_ref.sh: the driver did not run")
rm -f "$out.status"
[ "$status" = ok ] || { echo "$status" >&2; tail -20 "$work/log.txt" >&2; exit 1; }
