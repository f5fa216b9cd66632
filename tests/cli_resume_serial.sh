#!/usr/bin/env bash
# Power-loss resume with a real serial source (docs/snapshot.md): lbr-feed-serial streams
# 1 kHz frames over a pseudo-terminal into `lbrsim run --source serial:PTY --record LOG
# --resume`, which is killed with SIGKILL twice, each time 0.2–0.6 s (random) after one of its
# snapshots, and restarted on the same pty and recording. While lbrsim is down the feeder is
# stopped (SIGSTOP before the kill, SIGCONT once the restart has caught up), so no frame goes
# out with nobody listening: what the part lacks after a kill is only what came after the
# snapshot, and the recording holds it. Checks: every restart catches up from the recording
# (samples_caught_up > 0 each; the last one's in its metrics.json) and the final part is
# the uninterrupted run's (removed volume within 0.1 %: sweeps merged differently around the
# kills, each within [live] merge_tolerance_mm, and their polygons within the chord tolerance;
# 0.01 % at 1 µm, up to 0.022 % measured at 0.01 mm), with no sample lost on the wire.
# usage: cli_resume_serial.sh LBRSIM FEEDER OUT_DIR SRC_DIR [SEED]
set -euo pipefail
lbrsim=$1 feeder=$2 out=$3 src=$4 seed=${5:-$RANDOM}
RANDOM=$seed
echo "seed $seed (rerun: cli_resume_serial.sh LBRSIM FEEDER OUT SRC $seed)"
rm -rf "$out" && mkdir -p "$out"
program=$src/tests/data/live-short.moves  # ~3 s of cutting; the feeder plays it on and back
profile=$out/profile.toml
cat "$src/config/profiles/default-mill3.toml" > "$profile"
printf '\n[live]\nsnapshot_s = 1.0\n' >> "$profile"
grep -c '^\[live\]' "$profile" | grep -qx 1 || { echo "the default profile has its own [live] table; update this test"; exit 1; }
json() { sed -n "s/.*\"$2\": *\([0-9.e+-]*\).*/\1/p" "$1" | head -1; }
feeder_pid=
cleanup() { [ -z "$feeder_pid" ] || { kill -CONT "$feeder_pid" 2>/dev/null; kill "$feeder_pid" 2>/dev/null; } || true; }
trap cleanup EXIT

start_feeder() {  # DIR: the feeder in the background on DIR/pty; waits for the link
  rm -f "$1/pty"
  "$feeder" --program "$program" --profile "$profile" --duration-s 7 --pty-link "$1/pty" >"$1/feed.json" &
  feeder_pid=$!
  local i=0
  while [ ! -e "$1/pty" ] && [ $i -lt 400 ]; do sleep 0.05; i=$((i + 1)); done
  [ -e "$1/pty" ] || { echo "FAIL: the feeder made no pty"; exit 1; }
}
lbrsim_cmd() {  # DIR OPTIONS...
  local d=$1; shift
  exec "$lbrsim" run --no-window --quiet --source "serial:$d/pty" --profile "$profile" --out "$d/run" \
    --record "$d/serial.log" "$@"
}
snapshot_mtime() {  # DIR: newest snapshot's modification time [ns], 0 without one
  local t=0 f m
  for f in "$1"/run/snapshot-a.lbrsnap "$1"/run/snapshot-b.lbrsnap; do
    [ -e "$f" ] || continue
    m=$(stat -c %.9Y "$f" | tr -d .)
    [ "$m" -le "$t" ] || t=$m
  done
  echo "$t"
}

# Uninterrupted.
ref=$out/ref
mkdir -p "$ref"
start_feeder "$ref"
(lbrsim_cmd "$ref") >"$ref/log" 2>&1
wait "$feeder_pid"
feeder_pid=
a=$(json "$ref/run/metrics.json" removed_volume_mm3)
echo "uninterrupted: $a mm3, $(json "$ref/run/metrics.json" samples_applied) samples applied"

# Killed twice, resumed from its snapshot and recording each time.
cut=$out/cut
mkdir -p "$cut"
start_feeder "$cut"
total=0
for i in 1 2 3; do
  (lbrsim_cmd "$cut" --resume) >"$cut/log$i" 2>&1 &
  pid=$!
  if [ "$i" -gt 1 ]; then
    # Let the restart catch up and open the pty before the feeder goes on.
    n=0
    while ! grep -q 'resume: caught up' "$cut/log$i" && [ $n -lt 200 ]; do sleep 0.05; n=$((n + 1)); done
    sleep 0.3
    kill -CONT "$feeder_pid"
  fi
  [ "$i" -lt 3 ] || break
  before=$(snapshot_mtime "$cut") n=0
  while [ "$(snapshot_mtime "$cut")" = "$before" ] && [ $n -lt 250 ]; do sleep 0.02; n=$((n + 1)); done
  [ $n -lt 250 ] || { echo "FAIL: no snapshot within 5 s"; exit 1; }
  delay_ms=$((200 + RANDOM % 400))
  sleep "0.$(printf '%03d' $delay_ms)"
  kill -STOP "$feeder_pid"
  sleep 0.05  # lbrsim reads and records what the feeder wrote before it stopped
  kill -9 "$pid"
  wait "$pid" 2>/dev/null || true
  echo "  kill -9 $delay_ms ms after a snapshot"
done
wait "$pid"
wait "$feeder_pid"
feeder_pid=
for i in 2 3; do
  n=$(sed -n 's/.*resume: caught up \([0-9]*\) samples.*/\1/p' "$cut/log$i")
  echo "  restart $((i - 1)): caught up ${n:-0} samples from the recording"
  [ "${n:-0}" -gt 0 ] || { echo "FAIL: restart $((i - 1)) caught up nothing"; cat "$cut/log$i"; exit 1; }
  total=$((total + n))
done
m=$cut/run/metrics.json
b=$(json "$m" removed_volume_mm3)
echo "resumed: $b mm3; samples_caught_up $(json "$m" samples_caught_up) (last restart), $total over both"
[ "$(json "$m" samples_caught_up)" -gt 0 ] || { echo "FAIL: metrics.json: samples_caught_up is 0"; exit 1; }
for f in "$ref/run/metrics.json" "$m"; do
  for k in samples_lost ring_overruns; do
    [ "$(json "$f" $k)" = 0 ] || { echo "FAIL: $f: $k $(json "$f" $k)"; exit 1; }
  done
done
awk -v a="$a" -v b="$b" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(a > 0 && d <= 1e-3 * a) }' ||
  { echo "FAIL: volumes differ by more than 0.1 % ($a vs $b)"; exit 1; }
