#!/usr/bin/env bash
# Soak bench: lbr-feed-serial streams 1 kHz × 6 axes (config/profiles/live-6axis.toml, the
# program played forwards and backwards) for DURATION seconds into
# `lbrsim run --source serial:PTY` over a pseudo-terminal, injecting faults: flipped bits,
# garbage, truncated, dropped and duplicated frames, bursts, and a hang-up + new pty every
# DISCONNECT_EVERY seconds (lbrsim reopens it: live.serial.reconnect_ms). Checks: lbrsim
# exits 0 and writes its results; every sample the feeder generated is either received or
# counted lost (sequence_gap); RSS after warm-up grows by less than MAX_SLOPE KiB/min, or by
# no more than MAX_GROWTH KiB in all (the allocator takes memory from the system in steps of
# a MiB or more, and a short run sees one or two of them: docs/reliability.md).
# Prints the RSS slope and the lag p99 of every WINDOW-second window; writes soak.json
# (figures) to OUT. Usage:
#   tools/soak.sh [--duration S] [--window S] [--disconnect-every S] [--max-slope KIB_PER_MIN] [--max-growth KIB]
#                 [--build DIR] [--out DIR] [--program FILE]
set -euo pipefail
if [ "${1:-}" = --help ] || [ "${1:-}" = -h ]; then  # usage: the comment above
  sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0
fi
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
DURATION=120 WINDOW=30 DISCONNECT_EVERY=30 MAX_SLOPE=256 MAX_GROWTH=4096 BUILD="$ROOT/build" OUT="" PROGRAM="$ROOT/bench/programs/pocket-t1.moves"
while [ $# -gt 0 ]; do
  case "$1" in
    --duration) DURATION=$2 ;;
    --window) WINDOW=$2 ;;
    --disconnect-every) DISCONNECT_EVERY=$2 ;;
    --max-slope) MAX_SLOPE=$2 ;;
    --max-growth) MAX_GROWTH=$2 ;;
    --build) BUILD=$2 ;;
    --out) OUT=$2 ;;
    --program) PROGRAM=$2 ;;
    *) echo "soak.sh: unknown argument $1 (see --help)" >&2; exit 2 ;;
  esac
  shift 2
done
[ -n "$OUT" ] || OUT="$(mktemp -d)"
mkdir -p "$OUT"
PTY="$OUT/pty"
# The bench profile, reopening the pty 100 ms after a hang-up.
sed 's/^baud = 4000000$/baud = 4000000\nreconnect_ms = 100.0/' "$ROOT/config/profiles/live-6axis.toml" > "$OUT/soak.toml"
grep -q '^reconnect_ms = 100.0$' "$OUT/soak.toml" || { echo "soak.sh: could not set live.serial.reconnect_ms" >&2; exit 1; }

"$BUILD/tools/feeders/lbr-feed-serial" --profile "$OUT/soak.toml" --program "$PROGRAM" --pty-link "$PTY" \
  --duration-s "$DURATION" --corrupt-every 997 --garbage-every 1499 --truncate-every 2003 --drop-every 2999 \
  --duplicate-every 3001 --burst-every 10007 --burst-len 200 --disconnect-every-s "$DISCONNECT_EVERY" \
  --disconnect-ms 500 --seed 7 > "$OUT/feed.json" 2> "$OUT/feed.err" &
FEED=$!
for _ in $(seq 200); do [ -e "$PTY" ] && break; sleep 0.05; done
"$BUILD/app/lbrsim" --log-level info run --profile "$OUT/soak.toml" --source "serial:$PTY" --out "$OUT/live" \
  --no-window --status-every "$WINDOW" > "$OUT/lbrsim.out" 2> "$OUT/lbrsim.err" &
SIM=$!
# RSS of lbrsim every 5 s (t [s], VmRSS [KiB]) while the feeder runs.
: > "$OUT/rss.csv"
T0=$(date +%s.%N)
while kill -0 "$FEED" 2>/dev/null; do
  rss=$(awk '/^VmRSS:/ {print $2}' "/proc/$SIM/status" 2>/dev/null || true)
  [ -n "$rss" ] || break  # lbrsim is gone: a crash, reported below
  awk -v a="$(date +%s.%N)" -v b="$T0" -v r="$rss" 'BEGIN { printf "%.1f %s\n", a - b, r }' >> "$OUT/rss.csv"
  sleep 5
done
FEED_RC=0; wait "$FEED" || FEED_RC=$?
sleep 1
kill -INT "$SIM" 2>/dev/null || true
SIM_RC=0; wait "$SIM" || SIM_RC=$?
[ "$FEED_RC" = 0 ] || { echo "soak: feeder exit status $FEED_RC: $(cat "$OUT/feed.err")" >&2; exit 1; }
[ "$SIM_RC" = 0 ] || { echo "soak: lbrsim exit status $SIM_RC (crash?): $(tail -5 "$OUT/lbrsim.err")" >&2; exit 1; }

python3 - "$OUT" "$DURATION" "$MAX_SLOPE" "$MAX_GROWTH" <<'PY'
import json, os, re, sys
out, duration, max_slope, max_growth = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
feed = json.load(open(os.path.join(out, "feed.json")))
m = json.load(open(os.path.join(out, "live", "metrics.json")))
err = m["decode_errors"]
gaps = err.get("sequence_gap", 0)
received = m["samples_received"]
# RSS slope after warm-up (the first fifth of the run, at least 20 s): least squares.
rss = [tuple(map(float, l.split())) for l in open(os.path.join(out, "rss.csv")) if l.strip()]
warm = max(20.0, duration / 5)
pts = [(t, r) for t, r in rss if t >= warm]
slope = 0.0
if len(pts) >= 3:
    n = len(pts); mt = sum(t for t, _ in pts) / n; mr = sum(r for _, r in pts) / n
    slope = sum((t - mt) * (r - mr) for t, r in pts) / sum((t - mt) ** 2 for t, _ in pts) * 60.0
windows = [float(x) for x in re.findall(r"p99 since last line ([0-9.]+) ms", open(os.path.join(out, "lbrsim.out")).read())]
figures = {
    "duration_s": duration, "generated": feed["samples"], "frames_sent_intact_or_damaged": feed["frames_sent"],
    "received": received, "sequence_gap": gaps, "accounted": received + gaps,
    "faults_injected": {k: feed[k] for k in ("corrupted", "garbage", "truncated", "dropped", "duplicated", "disconnects",
                                             "not_sent_disconnected", "bursts")},
    "decode_errors": {k: v for k, v in err.items() if v},
    "samples_rejected": m["samples_rejected"], "ring_overruns": m["ring_overruns"],
    "rss_kib_after_warmup": pts[0][1] if pts else 0, "rss_kib_last": rss[-1][1] if rss else 0,
    "rss_slope_kib_per_min": round(slope, 2),
    "rss_growth_kib_after_warmup": (rss[-1][1] - pts[0][1]) if pts else 0, "lag_p99_ms_per_window": windows,
    "lag_p99_ms": m["lag_p99_ms"], "lag_max_ms": m["lag_max_ms"],
    "load": open("/proc/loadavg").read().split()[:3], "cores": os.cpu_count(),
}
json.dump(figures, open(os.path.join(out, "soak.json"), "w"), indent=1)
print(json.dumps(figures, indent=1))
ok = True
if received + gaps != feed["samples"]:
    print(f"soak: FAIL generated {feed['samples']} != received {received} + sequence_gap {gaps}"); ok = False
if err.get("reconnect", 0) != feed["disconnects"]:
    print(f"soak: FAIL {feed['disconnects']} hang-ups but {err.get('reconnect', 0)} reconnects"); ok = False
growth = figures["rss_growth_kib_after_warmup"]
if slope > max_slope and growth > max_growth:
    print(f"soak: FAIL RSS grows {slope:.1f} KiB/min after warm-up (limit {max_slope}), "
          f"{growth:.0f} KiB in all (limit {max_growth:.0f})"); ok = False
sys.exit(0 if ok else 1)
PY
