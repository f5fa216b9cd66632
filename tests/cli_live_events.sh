#!/usr/bin/env bash
# Live collision checks end to end (issue 16, docs/verification.md#live):
#   tests/cli_live_events.sh BUILD_DIR OUT_DIR
# `lbrsim run --source emulator:PROGRAM` of a program that forgets G43 (the tip one tool
# length, 60 mm, below the programmed Z) under xvfb: the screenshot's bottom edge is the red
# alarm band, metrics.json and events.csv hold the shank event at the program line of the
# first move down (line 3) with its sample number. The same program with G43: no event, no band.
set -uo pipefail
. "$(dirname "$0")/cli_lib.sh"
B=$1 OUT=$2
LBRSIM=$B/app/lbrsim PROBE=$B/tests/png_probe
rm -rf "$OUT" && mkdir -p "$OUT" && cd "$OUT" || exit 1
fail() { echo "FAIL: $*" >&2; exit 1; }
body='G0 X20 Y20 Z5\nG1 Z-3 F1000\nG1 X80 F3000\nG1 Y60\nG0 Z20\nM2\n'
printf "G21 G90 G17\nT1 M6\n$body" >bad.ngc
printf "G21 G90 G17\nT1 M6 G43 H1\n$body" >good.ngc

run() {  # NAME: the emulated run under xvfb, a screenshot every 10 frames
  xvfb-run -a "$LBRSIM" run --source emulator:"$1".ngc --speed 1 --hidden --screenshot-every 10 \
    --screenshot-prefix "$1"- --size 320x240 --quiet --out "$1" >"$1".log 2>&1 || fail "$1 run: $(tail -5 "$1".log)"
  last=$(ls "$1"-*.png 2>/dev/null | tail -1)
  [ -n "$last" ] || fail "$1: no screenshot"
  read -r r g b < <("$PROBE" "$last" at -3 -3)
}

run bad
[ "${r:-0}" -gt 110 ] && [ "${g:-255}" -lt 40 ] && [ "${b:-255}" -lt 40 ] || fail "bad: $last corner is $r $g $b, not the red alarm band"
[ "$(json_num bad/metrics.json event_errors)" -ge 2 ] || fail "bad: event_errors $(json_num bad/metrics.json event_errors)"
# metrics.json sorts an event's keys: kind, last_line, last_move, line, ...
grep -A3 '"kind": "shank-in-material"' bad/metrics.json | grep -q '"line": 3,' || fail "bad: no shank event at line 3 in metrics.json"
grep -q '^shank-in-material,error,[0-9.]*,bad.ngc,3,7,' bad/events.csv || fail "bad: events.csv: $(cat bad/events.csv)"
move=$(awk -F, '$1 == "shank-in-material" { print $8 }' bad/events.csv)
[ "${move:-0}" -gt 0 ] || fail "bad: no sample number in events.csv"
grep -q "error: shank-in-material.*sample $move, raised" bad.log || fail "bad: the log lacks the event: $(cat bad.log)"
[ "$(json_num bad/metrics.json event_latency_count)" -gt 0 ] || fail "bad: no latency measured"

run good
[ "${r:-255}" -lt 80 ] || fail "good: $last corner is $r $g $b (an alarm band without a collision?)"
[ "$(json_num good/metrics.json event_errors)" = 0 ] || fail "good: event_errors $(json_num good/metrics.json event_errors)"
[ "$(wc -l <good/events.csv)" -eq 1 ] || fail "good: events.csv: $(cat good/events.csv)"
echo "bad: shank event at sample $move, latency p99 $(json_num bad/metrics.json event_latency_p99_ms) ms"
