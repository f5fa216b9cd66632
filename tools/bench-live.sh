#!/usr/bin/env bash
# Live benchmark over a pseudo-terminal: lbr-feed-serial streams PROGRAM at 1 kHz × 6 axes
# (config/profiles/live-6axis.toml) into `lbrsim run --source serial:PTY`; prints the
# metrics that docs/performance.md reports. Usage: tools/bench-live.sh [BUILD] [SAMPLES] [PROGRAM]
set -euo pipefail
if [ "${1:-}" = --help ] || [ "${1:-}" = -h ]; then  # usage: the comment above
  sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0
fi
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD="${1:-$ROOT/build}"
SAMPLES="${2:-30000}"
PROGRAM="${3:-$ROOT/bench/programs/pocket-t1.moves}"
PROFILE="$ROOT/config/profiles/live-6axis.toml"
OUT="$(mktemp -d)"
PTY="$OUT/pty"
"$BUILD/tools/feeders/lbr-feed-serial" --profile "$PROFILE" --program "$PROGRAM" --pty-link "$PTY" \
  --max-samples "$SAMPLES" > "$OUT/feed.json" &
for _ in $(seq 200); do [ -e "$PTY" ] && break; sleep 0.05; done
"$BUILD/app/lbrsim" --log-level warn run --profile "$PROFILE" --source "serial:$PTY" --out "$OUT/live" --quiet
wait
echo "machine: $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg), $(uname -r)"
python3 - "$OUT/live/metrics.json" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
keys = ["samples_received", "samples_applied", "samples_lost", "ring_overruns", "ring_high_water",
        "lag_p50_ms", "lag_p99_ms", "lag_max_ms", "sweeps", "batches", "rt_mode"]
for k in keys: print(f"{k:18} {m[k]}")
print("decode_errors     ", {k: v for k, v in m["decode_errors"].items() if v} or "none")
PY
rm -rf "$OUT"
