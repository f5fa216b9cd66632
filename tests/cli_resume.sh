#!/usr/bin/env bash
# Power-loss resume (docs/snapshot.md): `lbrsim run` is killed with SIGKILL at three random
# points, restarted with --resume each time, and the final part must be the part of an
# uninterrupted run (removed volume within 0.1 %: sweeps merged differently around the
# resume points, each within [live] merge_tolerance_mm, and their sections' polygons within
# the chord tolerance: 0.01 % was the bound at a 1 µm tolerance, up to 0.022 % measured at
# the built-in 0.01 mm). Two sources (about 5 s each): the
# emulator paced at 40x real time, and a replay of the emulator run's --record file. Then the
# catch-up from the recording: the killed replay runs record (--record) too, and the restarts
# must apply the recorded samples after their snapshot's offset first (samples_caught_up > 0
# over the restarts: the log lines of the killed ones, metrics.json of the last) — still the
# uninterrupted run's part. (The emulator is not caught up: it computes those samples again.)
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
volume() { sed -n 's/.*"removed_volume_mm3": *\([0-9.e+-]*\).*/\1/p' "$1"; }
run() {  # SOURCE OPTIONS...
  local source=$1; shift
  "$lbrsim" run --no-window --quiet --source "$source" --speed "${SPEED:-40}" --profile "$profile" "$@"
}

caught_up() {  # LOG...: samples the restarts caught up, from their log lines
  sed -n 's/.*resume: caught up \([0-9]*\) samples.*/\1/p' "$@" | awk '{ n += $1 } END { print n + 0 }'
}

resume_case() {  # NAME SOURCE CUT_RECORD(- for none) [OPTIONS of the uninterrupted run]
  local name=$1 source=$2 cut_record=$3; shift 3
  local dir=$out/$name t0 ref_ms kills=0 delay_ms pid a b rec=() n
  [ "$cut_record" = - ] || rec=(--record "$cut_record")
  t0=$(date +%s%N)
  run "$source" --out "$dir/ref" "$@" >/dev/null
  ref_ms=$(( ($(date +%s%N) - t0) / 1000000 ))
  echo "$name uninterrupted: $(volume "$dir/ref/metrics.json") mm3 in $ref_ms ms"
  for i in 1 2 3; do
    delay_ms=$(( ref_ms / 5 + RANDOM % (ref_ms / 2 + 1) ))
    # exec: $! must be lbrsim itself (a backgrounded shell function is a subshell: killing it
    # left lbrsim running, beside the next restart).
    (exec "$lbrsim" run --no-window --quiet --source "$source" --speed "${SPEED:-40}" --profile "$profile" \
      --out "$dir/cut" --resume "${rec[@]}") >"$dir/log$i" 2>&1 &
    pid=$!
    sleep "$(printf '%d.%03d' $((delay_ms / 1000)) $((delay_ms % 1000)))"
    if kill -9 "$pid" 2>/dev/null; then kills=$((kills + 1)); echo "  kill -9 after $delay_ms ms"; fi
    wait "$pid" 2>/dev/null || true
  done
  run "$source" --out "$dir/cut" --resume "${rec[@]}" >"$dir/log-final" 2>&1
  a=$(volume "$dir/ref/metrics.json") b=$(volume "$dir/cut/metrics.json")
  echo "  resumed after $kills kills: $b mm3 ($(grep -o '"resumed_generation": *[0-9]*' "$dir/cut/metrics.json"))"
  [ "$kills" -ge 1 ] || { echo "FAIL: no $name run was killed (it ran too fast)"; exit 1; }
  awk -v a="$a" -v b="$b" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(a > 0 && d <= 1e-3 * a) }' ||
    { echo "FAIL: $name volumes differ by more than 0.1 %"; exit 1; }
  if [ "$cut_record" != - ]; then
    n=$(caught_up "$dir"/log*)
    echo "  caught up from the recording: $n samples ($(grep -o '"samples_caught_up": *[0-9]*' "$dir/cut/metrics.json"))"
    [ "$n" -gt 0 ] || { echo "FAIL: $name: no restart caught up from its recording"; exit 1; }
  fi
}

resume_case emulator "emulator:$src/config/programs/cam-pocket.ngc" - --record "$out/in.log"
# The log was written at 40x: replayed at its own pace it takes as long as the emulator run.
SPEED=1 resume_case replay "replay:$out/in.log" -
SPEED=1 resume_case replay-catch-up "replay:$out/in.log" "$out/cut-replay.log"
