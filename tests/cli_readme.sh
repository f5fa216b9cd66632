#!/usr/bin/env bash
# The README's own command lines, run as written where they can be (issue 19: the README
# must not drift from the program):  tests/cli_readme.sh BUILD_DIR SOURCE_DIR OUT_DIR
#
# Every indented line of README.md (its command blocks) is looked up in the table HOW below,
# by its exact text without the trailing `# comment`. A README line the table does not know,
# or a table entry the README no longer has, fails the test: a new or changed README line
# forces an update here. Each line runs in OUT_DIR with config/, bench/, tools/ and build/
# (-> BUILD_DIR) linked in, without DISPLAY (xvfb-run lines bring their own), and its outcome
# is asserted: exit status, the files it writes (non-empty), metrics.json removed volume > 0
# where a program runs, the hint text where a failure is expected.
#
# Adaptations (each entry says which): part.moves / part.ngc are short stand-in programs
# written here; real-time runs (run, view --animate) are stopped with `timeout -s INT`;
# benchmarks and the long scripts (demo.sh and test.sh install and build, bench-live,
# hil-bench) answer --help only; /dev/ttyUSB0 and can:can0 must fail with a hint, then the
# serial line runs again on a feeder's pseudo-terminal (that recording is in.log for the
# replay line); /tmp/lbr-pty becomes OUT_DIR/lbr-pty; lbr-genbench writes to a temporary
# folder, not bench/programs; rs274 lines are skipped without LinuxCNC's rs274 on PATH.
set -uo pipefail
. "$(dirname "$0")/cli_lib.sh"
B=$(cd "$1" && pwd) SRC=$(cd "$2" && pwd) OUT=$3
rm -rf "$OUT" && mkdir -p "$OUT/logs" "$OUT/work" && cd "$OUT/work" || exit 1
ln -s "$SRC/config" config && ln -s "$SRC/bench" bench && ln -s "$SRC/tools" tools && ln -s "$B" build || exit 1
unset DISPLAY WAYLAND_DISPLAY
T0=$(date +%s)
FAILS=0 N_RUN=0 N_ADAPTED=0 N_SKIPPED=0 N_LOG=0
LINE='' RC=0 LOG=''  # the line, its exit status and its output (OUT_DIR/logs/N.log)

fail() { echo "FAIL: $LINE"$'\n'"  $*" >&2; FAILS=$((FAILS + 1)); return 1; }
# Run a command line through bash in OUT_DIR/work (the README lines hold redirections, e.g. '>').
sh_line() {  # [timeout SECS] LINE
  local pre=()
  if [ "$1" = timeout ]; then pre=(timeout -s INT "$2"); shift 2; fi
  N_LOG=$((N_LOG + 1)) LOG=$OUT/logs/$N_LOG.log
  echo "$*" >"$LOG.cmd"
  "${pre[@]}" bash -c "exec $1" >"$LOG" 2>&1
  RC=$?
}

# --- assertions on the last line's outcome -------------------------------------------------------
rc() { [ "$RC" -eq "$1" ] || fail "exit status $RC, expected $1: $(tail -5 "$LOG")"; }
stopped() {  # a real-time run stopped by timeout -s INT (124) or already finished (0), not crashed
  [ "$RC" -eq 124 ] || [ "$RC" -eq 0 ] || fail "exit status $RC under timeout -s INT: $(tail -5 "$LOG")"
  ! grep -Eq "\[error\]|error:" "$LOG" || fail "error in the log: $(grep -E '\[error\]|error:' "$LOG" | head -3)"
}
no_warning() { ! grep -q "\[warning\]" "$LOG" || fail "warnings: $(grep '\[warning\]' "$LOG" | head -3)"; }
says() { grep -q -- "$1" "$LOG" || fail "output lacks '$1': $(tail -5 "$LOG")"; }
nonempty() { [ -s "$1" ] || fail "$1 missing or empty"; }
results() {  # DIR: metrics.json with removed volume > 0, a levels file
  nonempty "$1/metrics.json" && nonempty "$1/levels.lbrs" || return 1
  local removed
  removed=$(json_num "$1/metrics.json" removed_volume_mm3)
  awk -v v="${removed:-0}" 'BEGIN { exit !(v > 0) }' || fail "$1/metrics.json: removed_volume_mm3 ${removed:-?}"
}
lines_at_least() { [ "$(wc -l <"$1" 2>/dev/null || echo 0)" -ge "$2" ] || fail "$1: fewer than $2 lines"; }

# --- how a line is run ----------------------------------------------------------------------------
as_written() {  # CHECKS...: the line itself, exit 0, then the checks
  N_RUN=$((N_RUN + 1)); sh_line "$LINE"; rc 0 && for c in "$@"; do eval "$c" || return 1; done
}
realtime() {  # SECS CHECKS...: the line itself, stopped with timeout -s INT SECS
  local s=$1; shift
  N_ADAPTED=$((N_ADAPTED + 1)); sh_line timeout "$s" "$LINE"; stopped && for c in "$@"; do eval "$c" || return 1; done
}
help_only() {  # the line's program (after any xvfb-run -a) with --help: usage, exit 0, no files
  local exe before
  exe=$(sed 's/^xvfb-run -a //; s/ .*//' <<<"$LINE")
  if [ ! -x "$exe" ]; then skip "not built: $exe (LBR_BUILD_BENCH=OFF?)"; return 0; fi
  N_ADAPTED=$((N_ADAPTED + 1))
  before=$(ls -A)  # OUT_DIR/work
  sh_line timeout 20 "$exe --help"
  rc 0 || return 1
  case $exe in  # the scripts print their header comment; the executables their usage
  *.sh) [ -s "$LOG" ] || fail "$exe --help printed nothing" ;;
  *) says "[Uu]sage\|--benchmark_filter" ;;
  esac || return 1
  [ "$(ls -A)" = "$before" ] || fail "--help left files: $(diff <(echo "$before") <(ls -A) | grep '^>')"
}
skip() { N_SKIPPED=$((N_SKIPPED + 1)); echo "  skipped: $*"; }
fresh() { rm -rf lbrsim-out out live-out; }  # outputs are checked as written by this line

# --- stand-in programs for part.moves / part.ngc -----------------------------------------------
# part.moves: a ball end mill (the line's --tool 1:ball:6) along a U, 2 mm deep, in the line's
# stock box:0,0,-20,60,40,0. part.ngc: a pocket and a hole on the default profile's stock.
printf '%s\n' 'lbr-moves 1' 'start 30 20 30' 'tool 1' 'feed 1500' 'rapid 10 10 5' 'line 10 10 -2' \
  'line 50 10 -2' 'line 50 30 -2' 'line 10 30 -2' 'rapid 10 30 5' >part.moves
printf '%s\n' '%' '(README stand-in)' 'G21 G90 G17 G94' 'G28 G91 Z0' 'G90' 'T1 M6' 'G43 H1 G0 X30 Y30 Z5' \
  'G1 Z-2 F400' 'G1 X50 F1200' 'G1 Y50' 'G3 X40 Y60 R10' 'G1 X30' 'G1 Y30' 'G0 Z25' 'T3 M6' \
  'G43 H3 G0 X70 Y20 Z10' 'G98 G81 Z-6 R2 F200' 'G80' 'M30' '%' >part.ngc

# --- line handlers that need more than one of the above -------------------------------------------
FEED_PID=''
start_feeder() {  # PTY LINK, feeder arguments...: a serial feeder on a pty, bounded sample count
  local link=$1; shift
  rm -f "$link"
  "$B/tools/feeders/lbr-feed-serial" --pty-link "$link" "$@" >"$link.feed.json" 2>&1 &
  FEED_PID=$!
  for _ in $(seq 100); do [ -e "$link" ] && break; sleep 0.05; done
  [ -e "$link" ] || fail "feeder made no $link: $(cat "$link.feed.json")"
}
wait_feeder() {
  [ -n "$FEED_PID" ] || return 0
  wait "$FEED_PID" || fail "feeder exit status $?: $(cat "$OUT"/*.feed.json)"
  FEED_PID=''
}
serial_device() {  # README: serial:/dev/ttyUSB0 with the live-6axis profile, --record in.log
  N_ADAPTED=$((N_ADAPTED + 1))
  if [ -e /dev/ttyUSB0 ]; then
    echo "  /dev/ttyUSB0 exists here: not opened (a real device); the pty run below stands in"
  else
    sh_line timeout 20 "$LINE"  # no device: exit 1 with what to do
    rc 1 && says "serial:/dev/ttyUSB0: No such file or directory" && says "ls /dev/ttyUSB\* /dev/ttyACM\*" &&
      says "lbr-feed-serial --pty-link" || return 1
  fi
  # The same line on a feeder's pty (the feeder with the same profile, 2000 samples): samples
  # applied and a recording for the replay line.
  fresh; rm -f in.log
  start_feeder "$OUT/usb-pty" --profile config/profiles/live-6axis.toml --max-samples 2000 || return 1
  sh_line timeout 60 "${LINE//\/dev\/ttyUSB0/$OUT/usb-pty}"
  wait_feeder; rc 0 && results lbrsim-out && no_warning && lines_at_least in.log 500 || return 1
  REC_VOLUME=$(json_num lbrsim-out/metrics.json removed_volume_mm3)
}
REC_VOLUME=''
same_volume_as_recording() {  # the replay removes what the recorded run removed (0.1 %)
  local v
  v=$(json_num lbrsim-out/metrics.json removed_volume_mm3)
  awk -v a="${REC_VOLUME:-0}" -v b="${v:-0}" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(a > 0 && d <= 1e-3 * a) }' ||
    fail "replay removed ${v:-?} mm3, the recorded run ${REC_VOLUME:-?} mm3"
}
can_interface() {  # README: can:can0; here no such interface (or no AF_CAN): exit 1 with the hint
  N_ADAPTED=$((N_ADAPTED + 1))
  if ip link show can0 >/dev/null 2>&1; then skip "can0 exists here: not opened (a real bus)"; return 0; fi
  sh_line timeout 20 "$LINE"
  rc 1 && says "can:can0" && says "ip link" || return 1
  if grep -q "socket(PF_CAN)" "$LOG"; then says "modprobe can can_raw"; fi
  [ ! -e live-out/metrics.json ] || fail "live-out/metrics.json written by a run that never started"
}
feeder() {  # README: the serial feeder on /tmp/lbr-pty; here OUT_DIR/lbr-pty, 2000 samples; the next line reads
  N_ADAPTED=$((N_ADAPTED + 1))
  local args=${LINE#build/tools/feeders/lbr-feed-serial --pty-link /tmp/lbr-pty }
  [ "$args" != "$LINE" ] || { fail "feeder line no longer starts as the script expects"; return 1; }
  # shellcheck disable=SC2086  # the README's own arguments
  start_feeder "$OUT/lbr-pty" $args --max-samples 2000
}
serial_pty() {  # README: serial:/tmp/lbr-pty (the feeder line's pty): runs until the feeder ends
  N_ADAPTED=$((N_ADAPTED + 1))
  [ -n "$FEED_PID" ] || { fail "no feeder running (the feeder line must come first)"; return 1; }
  fresh
  sh_line timeout 60 "${LINE//\/tmp\/lbr-pty/$OUT/lbr-pty}"
  wait_feeder; rc 0 && results lbrsim-out || return 1
  ! grep -q "frames carry" "$LOG" || fail "mismatch warning with the same profile on both ends: $(grep 'frames carry' "$LOG")"
}
rs274() {  # CHECKS...: as written where LinuxCNC's rs274 is on PATH
  if ! command -v rs274 >/dev/null; then skip "no rs274 on PATH (Debian package linuxcnc-uspace)"; return 0; fi
  # (Regression: a program path without a folder used to fail in nc/src/rs274.cpp with
  # "cannot make absolute path"; the line runs as written.)
  N_RUN=$((N_RUN + 1)); sh_line "$LINE"
  rc 0 && for c in "$@"; do eval "$c" || return 1; done
}
genbench() {  # README: --out bench/programs; here a temporary folder: every bench/programs/*.ngc written
  N_ADAPTED=$((N_ADAPTED + 1))
  mkdir -p "$OUT/genbench"  # bench/programs exists; lbr-genbench makes no folder
  sh_line timeout 60 "${LINE/--out bench\/programs/--out $OUT/genbench}"
  rc 0 || return 1
  local f
  for f in "$SRC"/bench/programs/*.ngc; do nonempty "$OUT/genbench/${f##*/}" || return 1; done
}

# --- the README's command lines -------------------------------------------------------------------
# HOW[line] is evaluated with LINE set; it runs the line (or its adaptation) and asserts.
declare -A HOW
HOW['tools/demo.sh']='help_only'  # installs packages, builds into build/, runs the demo for minutes
HOW['tools/test.sh']='help_only'  # installs, builds and runs every test (this test among them)
HOW['build/app/lbrsim --help']='as_written "says Subcommands" "says batch"'
HOW['build/app/lbrsim batch --help']='as_written "says --program" "says --png"'
HOW['build/app/lbrsim batch --program config/programs/demo-pocket.moves --regions 8x8 --out out/']='fresh; as_written "results out"'
HOW['build/app/lbrsim batch --program part.moves --stock box:0,0,-20,60,40,0 --tool 1:ball:6 --level-spacing 0.05']='fresh; as_written "results lbrsim-out"'
HOW['build/app/lbrsim batch --program config/programs/cam-pocket.ngc --out out/']='fresh; as_written "results out"'
HOW['build/app/lbrsim batch --dialect fanuc --program config/programs/fanuc-flange.nc --out out/']='fresh; as_written "results out"'
HOW['build/app/lbrsim batch --program part.ngc --interpreter rs274 --sampled']='fresh; rs274 "results lbrsim-out"'
HOW['build/app/lbrsim emulate config/programs/cam-pocket.ngc --period 4ms --out samples.csv']='rm -f samples.csv; as_written "lines_at_least samples.csv 1000"'
HOW['build/app/lbrsim profile config/profiles/default-mill3.toml']='as_written "says ok"'
HOW['build/app/lbrsim run --source serial:/dev/ttyUSB0 --profile config/profiles/live-6axis.toml --record in.log']='serial_device'
HOW['build/app/lbrsim run --source can:can0 --out live-out/']='fresh; can_interface'
HOW['build/app/lbrsim run --source replay:in.log --speed 0']='fresh; as_written "results lbrsim-out" no_warning same_volume_as_recording'  # in.log: the serial line's pty run
HOW['build/app/lbrsim run --source emulator:config/programs/demo-pocket.moves']='fresh; realtime 4 "results lbrsim-out"'
HOW['build/tools/feeders/lbr-feed-serial --pty-link /tmp/lbr-pty --profile config/profiles/live-6axis.toml --corrupt-every 100']='feeder'
HOW['build/app/lbrsim run --source serial:/tmp/lbr-pty --profile config/profiles/live-6axis.toml']='serial_pty'
HOW['build/app/lbrsim profile --print-default > my-machine.toml']='rm -f my-machine.toml; as_written "nonempty my-machine.toml" "says_file my-machine.toml"'
HOW['build/app/lbrsim tune --program bench/programs/medium.ngc --write tuned.toml']='rm -f tuned.toml; as_written "nonempty tuned.toml" "says fastest"'
HOW['build/app/lbrsim batch --program part.ngc --sampled --threads 2 --stl part.stl --ply part.ply']='fresh; rm -f part.stl part.ply; as_written "results lbrsim-out" "nonempty part.stl" "nonempty part.ply"'
HOW['build/app/lbrsim batch --profile config/profiles/lathe.toml --program config/programs/lathe-shaft.ngc']='fresh; as_written "results lbrsim-out"'
HOW['build/app/lbrsim batch --profile config/profiles/lathe-c.toml --program config/programs/lathe-c-parts.ngc']='fresh; as_written "results lbrsim-out"'
HOW['build/app/lbrsim batch --profile config/profiles/mill5-ac.toml --program config/programs/mill5-tilted.ngc']='fresh; as_written "results lbrsim-out"'
HOW['build/app/lbrsim batch --profile config/profiles/twin-turret-lathe.toml']='fresh; as_written "results lbrsim-out"'
# No display here: under xvfb-run, stopped after a few seconds; it writes nothing, so: no error.
HOW['build/app/lbrsim view --animate --color heat']='LINE="xvfb-run -a $LINE"; realtime 4'
HOW['xvfb-run -a build/app/lbrsim batch --png part.png --view top --color heat']='fresh; rm -f part.png; as_written "results lbrsim-out" "nonempty part.png"'
HOW['xvfb-run -a build/app/lbrsim run --source emulator:demo --hidden --screenshot-every 300']='fresh; realtime 6 "results lbrsim-out" "nonempty lbrsim-out/frame-000000.png"'
HOW['build/bench/lbr_bench_subtract']='help_only'
HOW['build/bench/lbr_bench_fig4 bench-out']='help_only'
HOW['build/bench/lbr_bench_table2 --out bench-out']='help_only'
HOW['build/bench/lbr_bench_scaling --out bench-out']='help_only'
HOW['build/bench/lbr_mesh_bench']='help_only'
HOW['build/tools/genbench/lbr-genbench --out bench/programs']='genbench'
HOW['build/bench/lbr_bench_ring']='help_only'
HOW['xvfb-run -a build/bench/lbr_gfx_frame_bench bench/programs/high.ngc 60']='help_only'
HOW['tools/bench-live.sh build 60000']='help_only'
HOW['tools/hil/hil-bench.sh build']='help_only'
says_file() { grep -q '^\[machine\]' "$1" || fail "$1 holds no [machine] table"; }

# The README's command blocks: indented lines (four spaces), the trailing comment dropped.
mapfile -t README < <(sed -n 's/^    \([^ ].*\)$/\1/p' "$SRC/README.md" | sed 's/[[:space:]]\{1,\}#.*$//; s/[[:space:]]*$//')
[ "${#README[@]}" -ge 30 ] || { echo "FAIL: only ${#README[@]} command lines found in README.md" >&2; exit 1; }
declare -A SEEN
for LINE in "${README[@]}"; do
  SEEN[$LINE]=1
  if [ -z "${HOW[$LINE]+x}" ]; then
    fail "README command line unknown to tests/cli_readme.sh: add it to HOW (run as written or say how it is adapted)"
    continue
  fi
  t=$(date +%s%N)
  eval "${HOW[$LINE]}"
  printf '%5d ms  %s\n' $(( ($(date +%s%N) - t) / 1000000 )) "$LINE"
done
wait_feeder
for k in "${!HOW[@]}"; do
  [ -n "${SEEN[$k]+x}" ] || { LINE=$k; fail "in HOW but no longer in README.md: remove or update the entry"; }
done
echo "README lines: ${#README[@]} (run as written $N_RUN, adapted $N_ADAPTED, skipped $N_SKIPPED) in $(( $(date +%s) - T0 )) s"
[ "$FAILS" -eq 0 ] || { echo "$FAILS failure(s)" >&2; exit 1; }
echo "ok"
