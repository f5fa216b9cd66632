#!/usr/bin/env bash
# Power-loss resume (docs/snapshot.md): `lbrsim run` on the emulator (paced at 40x real time,
# about 5 s) is killed with SIGKILL
# at several random points, restarted with --resume each time, and the final part must be
# the part of an uninterrupted run (removed volume within 0.01 %: sweeps merged differently
# around the resume points, each within [live] merge_tolerance_mm).
# usage: cli_resume.sh LBRSIM OUT_DIR SRC_DIR [SEED]
set -euo pipefail
lbrsim=$1 out=$2 src=$3 seed=${4:-$RANDOM}
RANDOM=$seed
echo "seed $seed (rerun: cli_resume.sh LBRSIM OUT SRC $seed)"
rm -rf "$out" && mkdir -p "$out"
profile=$out/profile.toml
cat "$src/config/profiles/default-mill3.toml" > "$profile"
printf '\n[live]\nsnapshot_s = 0.1\n' >> "$profile"
grep -c '^\[live\]' "$profile" | grep -qx 1 || { echo "the default profile has its own [live] table; update this test"; exit 1; }
program=emulator:$src/config/programs/cam-pocket.ngc
run() { "$lbrsim" run --no-window --quiet --source "$program" --speed 40 --profile "$profile" "$@"; }
volume() { sed -n 's/.*"removed_volume_mm3": *\([0-9.e+-]*\).*/\1/p' "$1"; }

t0=$(date +%s%N)
run --out "$out/ref" >/dev/null
ref_ms=$(( ($(date +%s%N) - t0) / 1000000 ))
echo "uninterrupted: $(volume "$out/ref/metrics.json") mm3 in $ref_ms ms"

kills=0
for i in 1 2 3; do
  delay_ms=$(( ref_ms / 5 + RANDOM % (ref_ms / 2 + 1) ))
  run --out "$out/cut" --resume >"$out/log$i" 2>&1 &
  pid=$!
  sleep "$(printf '%d.%03d' $((delay_ms / 1000)) $((delay_ms % 1000)))"
  if kill -9 "$pid" 2>/dev/null; then kills=$((kills + 1)); echo "kill -9 after $delay_ms ms"; fi
  wait "$pid" 2>/dev/null || true
done
run --out "$out/cut" --resume >"$out/log-final" 2>&1
grep -o '"resumed_generation": *[0-9]*' "$out/cut/metrics.json" || true
a=$(volume "$out/ref/metrics.json") b=$(volume "$out/cut/metrics.json")
echo "resumed after $kills kills: $b mm3 (uninterrupted $a mm3)"
[ "$kills" -ge 1 ] || { echo "FAIL: no run was killed (the program ran too fast)"; exit 1; }
awk -v a="$a" -v b="$b" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(a > 0 && d <= 1e-4 * a) }' ||
  { echo "FAIL: volumes differ by more than 0.01 %"; exit 1; }
