#!/usr/bin/env bash
# Regression tests for issue 19 (what a new user trips on), one case per ctest test:
#   tests/cli_issue19.sh CASE BUILD_DIR SOURCE_DIR OUT_DIR
# Each case asserts quantities (files and their content, exit codes, pixel counts, warning
# text within a time bound), not whole outputs.
set -uo pipefail
. "$(dirname "$0")/cli_lib.sh"
CASE=$1 B=$2 SRC=$3 OUT=$4
LBRSIM=$B/app/lbrsim PROBE=$B/tests/png_probe
rm -rf "$OUT" && mkdir -p "$OUT" && cd "$OUT" || exit 1
fail() { echo "FAIL [$CASE]: $*" >&2; exit 1; }
results_ok() {  # DIR: metrics.json with applied samples and removed volume, a non-trivial levels file
  [ -s "$1/metrics.json" ] || fail "$1/metrics.json missing"
  [ "$(stat -c %s "$1/levels.lbrs" 2>/dev/null || echo 0)" -gt 1000 ] || fail "$1/levels.lbrs missing or empty"
  local applied removed
  applied=$(json_num "$1/metrics.json" samples_applied) removed=$(json_num "$1/metrics.json" removed_volume_mm3)
  [ "${applied:-0}" -gt 0 ] || fail "samples_applied ${applied:-?} in $1/metrics.json"
  awk -v v="${removed:-0}" 'BEGIN { exit !(v > 0) }' || fail "removed_volume_mm3 ${removed:-?}"
}

case $CASE in
stop_under_xvfb)  # item 1: SIGINT to xvfb-run and lbrsim (timeout's process group) keeps the results
  timeout -s INT 6 xvfb-run -a "$LBRSIM" run --source emulator:demo --hidden --screenshot-every 300 --out x >log 2>&1
  rc=$?
  [ $rc -eq 124 ] || fail "timeout rc $rc (expected 124: the run was still going)"
  grep -q "XIO" log && ! grep -q "results written" log && fail "XIO error without results: $(tail -3 log)"
  results_ok x
  [ -s x/frame-000000.png ] || fail "default screenshot prefix: x/frame-000000.png missing"
  ls lbrsim-frame-* >/dev/null 2>&1 && fail "screenshots written into the working directory"
  ;;
display_lost)  # item 1: the X server goes away mid-run, then a stop: results and exit 0
  command -v Xvfb >/dev/null || { echo "no Xvfb: skipped"; exit 0; }
  exec 5>disp
  Xvfb -displayfd 5 -nolisten tcp >/dev/null 2>&1 &
  xpid=$!
  for _ in $(seq 50); do [ -s disp ] && break; sleep 0.1; done
  DISPLAY=:$(cat disp) "$LBRSIM" run --source emulator:demo --speed 5 --hidden --screenshot-every 30 --out x >log 2>&1 &
  lpid=$!
  sleep 3; kill $xpid; sleep 1; kill -INT $lpid
  wait $lpid; rc=$?
  [ $rc -eq 0 ] || fail "rc $rc after a lost display: $(tail -3 log)"
  results_ok x
  ;;
serial_mismatch)  # item 2: 3-position frames into a 6-axis profile: warning within a second
  "$B/tools/feeders/lbr-feed-serial" --pty-link "$OUT/pty" --max-samples 4000 >feed.log 2>&1 &
  for _ in $(seq 50); do [ -e pty ] && break; sleep 0.1; done
  t0=$(date +%s%N)
  "$LBRSIM" run --source serial:"$OUT/pty" --profile "$SRC/config/profiles/live-6axis.toml" --no-window --quiet --out x \
    >log 2>&1 &
  lpid=$!
  msg="frames carry 3 positions, the profile maps 6"
  while ! grep -q "$msg" log && [ $(( ($(date +%s%N) - t0) / 1000000 )) -lt 3000 ]; do sleep 0.02; done
  dt=$(( ($(date +%s%N) - t0) / 1000000 ))
  grep -q "\[warning\].*$msg" log || fail "no warning '$msg' within 3 s: $(cat log)"
  [ $dt -le 1000 ] || fail "warning after $dt ms (> 1 s)"
  kill -INT $lpid; wait $lpid
  grep -q "$msg" x/metrics.json || fail "metrics.json warnings lack the mismatch"
  # The README's pair of lines (same profile on both ends): samples, no warning.
  "$B/tools/feeders/lbr-feed-serial" --pty-link "$OUT/pty2" --profile "$SRC/config/profiles/live-6axis.toml" \
    --max-samples 1500 >feed2.log 2>&1 &
  for _ in $(seq 50); do [ -e pty2 ] && break; sleep 0.1; done
  timeout -s INT 20 "$LBRSIM" run --source serial:"$OUT/pty2" --profile "$SRC/config/profiles/live-6axis.toml" \
    --no-window --quiet --out y >log2 2>&1
  results_ok y
  grep -q "frames carry" log2 && fail "warning with matching profiles"
  echo "warning after $dt ms"
  ;;
record_emulator)  # item 4: --record with the emulator writes a replayable log, same volume
  printf 'lbr-moves 1\nstart 50 40 50\ntool 1\nfeed 1500\nrapid 10 10 5\nline 10 10 -2\nline 60 10 -2\nline 60 30 -2\n' >p.moves
  "$LBRSIM" run --source emulator:p.moves --speed 0 --record rec.log --no-window --quiet --out a >a.log 2>&1 || fail "record run: $(cat a.log)"
  lines=$(wc -l <rec.log)
  [ "$lines" -gt 1000 ] || fail "rec.log holds $lines lines"
  [ "$lines" -eq "$(json_num a/metrics.json samples_received)" ] || fail "rec.log $lines lines vs samples_received"
  "$LBRSIM" run --source replay:rec.log --speed 0 --no-window --quiet --out b >b.log 2>&1 || fail "replay: $(cat b.log)"
  results_ok b
  awk -v a="$(json_num a/metrics.json removed_volume_mm3)" -v b="$(json_num b/metrics.json removed_volume_mm3)" \
    'BEGIN { d = a - b; if (d < 0) d = -d; exit !(a > 1000 && d < 1e-3 * a) }' || fail "volumes differ: $(json_num a/metrics.json removed_volume_mm3) vs $(json_num b/metrics.json removed_volume_mm3)"
  ;;
png_tool)  # item 5: a finished-part picture has no tool unless asked for
  xvfb-run -a "$LBRSIM" batch --quiet --png part.png --view top --out o >log 2>&1 || fail "batch --png: $(cat log)"
  xvfb-run -a "$LBRSIM" batch --quiet --png tool.png --view top --show-tool --out o >>log 2>&1 || fail "--show-tool: $(cat log)"
  xvfb-run -a "$LBRSIM" batch --quiet --png none.png --view top --no-tool --out o >>log 2>&1 || fail "--no-tool: $(cat log)"
  [ "$("$PROBE" part.png)" = "1024 768" ] || fail "part.png size $("$PROBE" part.png)"
  [ "$("$PROBE" part.png hue)" -eq 0 ] || fail "tool pixels in the default picture: $("$PROBE" part.png hue)"
  [ "$("$PROBE" none.png diff part.png)" -eq 0 ] || fail "--no-tool differs from the default picture"
  # From the top the tool is its holder's disc: a tenth of the picture at least.
  [ "$("$PROBE" tool.png diff part.png)" -gt 70000 ] || fail "--show-tool changed only $("$PROBE" tool.png diff part.png) pixels"
  ;;
help)  # item 6: every executable the README names answers --help with usage, exit 0, and writes nothing
  for exe in app/lbrsim bench/lbr_bench_subtract bench/lbr_bench_fig4 bench/lbr_bench_table2 bench/lbr_bench_scaling \
             bench/lbr_mesh_bench bench/lbr_bench_ring bench/lbr_gfx_frame_bench tools/genbench/lbr-genbench \
             tools/feeders/lbr-feed-serial tools/feeders/lbr-feed-can; do
    [ -x "$B/$exe" ] || { echo "not built: $exe"; continue; }
    timeout 10 "$B/$exe" --help >h.txt 2>&1; rc=$?
    [ $rc -eq 0 ] || fail "$exe --help: rc $rc"
    grep -qi "usage\|options\|--benchmark_filter" h.txt || fail "$exe --help: no usage"
  done
  for s in tools/demo.sh tools/test.sh tools/bench-live.sh tools/hil/hil-bench.sh tools/build.sh tools/setup-debian.sh; do
    timeout 10 "$SRC/$s" --help >h.txt 2>&1 || fail "$s --help: rc $?"
    [ "$(wc -l <h.txt)" -ge 1 ] || fail "$s --help printed nothing"
  done
  [ -z "$(ls -A | grep -v '^h.txt$')" ] || fail "--help left files: $(ls -A)"
  ;;
can_hint)  # item 7: a CAN interface that cannot be opened says what to do
  "$LBRSIM" run --source can:lbrnocan0 --no-window --out x >log 2>&1; rc=$?
  [ $rc -eq 1 ] || fail "rc $rc"
  grep -q "ip link" log || fail "no 'ip link' hint: $(cat log)"
  if grep -q "socket(PF_CAN)" log; then grep -q "modprobe can can_raw" log || fail "no modprobe hint: $(cat log)"; fi
  ;;
small)  # item 8
  "$LBRSIM" batch --quiet --out q/ >log 2>&1 || fail "batch: $(cat log)"
  grep -q "\[info\]" log && fail "--quiet printed info lines: $(grep info log)"
  grep -q "wrote q/metrics.json, q/levels.lbrs and q/events.csv" log || fail "paths: $(grep wrote log)"
  grep -q "//" log && fail "double slash: $(grep // log)"
  cd "$SRC" && for p in bench-out/fig4.csv lbrsim-frame-000001.png lbrsim-out/metrics.json; do
    git check-ignore -q "$p" 2>/dev/null || [ ! -d .git ] || fail "$p not ignored by .gitignore"
  done
  grep -q "3\.1 s sampled" "$SRC/docs/nc-frontend.md" && fail "stale kernel times in docs/nc-frontend.md"
  if [ -x "$B/bench/lbr_mesh_bench" ]; then
    "$B/bench/lbr_mesh_bench" --benchmark_filter='BM_FullBuild/low' >"$OUT/mb.txt" 2>&1 || fail "lbr_mesh_bench"
    grep -Eq "ms_per_region=[0-9.]+[a-zµ]* " "$OUT/mb.txt" && ! grep -Eq "ms_per_region=[0-9.]+[mu]?s" "$OUT/mb.txt" \
      || fail "ms_per_region unit: $(grep -o 'ms_per_region=[^ ]*' "$OUT/mb.txt")"
  fi
  ;;
*) fail "unknown case" ;;
esac
echo "ok [$CASE]"
