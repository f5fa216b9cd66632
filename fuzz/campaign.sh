#!/usr/bin/env bash
# Fuzz campaign: runs every libFuzzer target in turn (nice 19: idle CPU only; slowest first) for RUNS
# executions or SECONDS, whichever comes first, from its committed seed corpus; prints one
# line per target (executions, execs/s, coverage, features, corpus size, crashes) and keeps
# new corpus entries and crash inputs in OUT/NAME/. Figures: docs/reliability.md.
# Usage: fuzz/campaign.sh BUILD_FUZZ_DIR OUT_DIR [RUNS] [SECONDS] [TARGET...]
set -euo pipefail
if [ "${1:-}" = --help ] || [ "${1:-}" = -h ] || [ $# -lt 2 ]; then  # usage: the comment above
  sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0
fi
SRC="$(cd "$(dirname "$0")" && pwd)"
BUILD="$(cd "$1" && pwd)"
OUT="$2"
RUNS="${3:-10000000}"
SECONDS_MAX="${4:-600}"
shift $(( $# < 4 ? $# : 4 ))
TARGETS=("$@")
[ ${#TARGETS[@]} -gt 0 ] || TARGETS=(gcode profile lbrs rs274_canon movelist stl canopen serial candump)
declare -A MAXLEN=([serial]=512 [candump]=128 [canopen]=1024 [gcode]=512 [rs274_canon]=512 [movelist]=512 [profile]=2048 [lbrs]=8192 [stl]=1024)
mkdir -p "$OUT"
printf "%-12s %12s %9s %7s %8s %7s %7s %s\n" target execs execs/s cov ft corpus crashes seconds
for t in "${TARGETS[@]}"; do
  d="$OUT/$t"
  mkdir -p "$d/corpus" "$d/artifacts"
  t0=$(date +%s)
  rc=0
  # malloc_context_size=0: ASan records no stack per allocation (StackDepot::Put was 10-18 % of
  # fuzz_lbrs' time); reports still show where the bad access is, and a crash input rerun
  # without it shows the allocation's stack too.
  UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 ASAN_OPTIONS="${ASAN_OPTIONS:-malloc_context_size=0}" nice -n 19 "$BUILD/fuzz/fuzz_$t" -runs="$RUNS" \
    -max_total_time="$SECONDS_MAX" -max_len="${MAXLEN[$t]}" -rss_limit_mb=2048 -print_final_stats=1 \
    -artifact_prefix="$d/artifacts/" "$d/corpus" "$SRC/corpus/$t" > "$d/log.txt" 2>&1 || rc=$?
  secs=$(( $(date +%s) - t0 ))
  execs=$(awk '/stat::number_of_executed_units/ {print $2}' "$d/log.txt" | tail -1)
  rate=$(awk '/stat::average_exec_per_sec/ {print $2}' "$d/log.txt" | tail -1)
  last=$(grep -E '^#[0-9]+' "$d/log.txt" | tail -1)
  cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<<"$last")
  ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<<"$last")
  corp=$(sed -n 's/.* corp: \([0-9]*\).*/\1/p' <<<"$last")
  # Findings: crash-, leak-, timeout- and oom- files; slow-unit- files (inputs over libFuzzer's
  # -report_slow_units seconds) are counted apart: they are not failures.
  crashes=$(find "$d/artifacts" -type f ! -name 'slow-unit-*' | wc -l)
  slow=$(find "$d/artifacts" -type f -name 'slow-unit-*' | wc -l)
  printf "%-12s %12s %9s %7s %8s %7s %7s %s%s%s\n" "$t" "${execs:-?}" "${rate:-?}" "${cov:-?}" "${ft:-?}" "${corp:-?}" \
    "$crashes" "$secs" "$([ "$rc" = 0 ] || echo " (exit $rc)")" "$([ "$slow" = 0 ] || echo " ($slow slow units)")"
done
