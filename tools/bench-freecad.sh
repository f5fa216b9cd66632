#!/usr/bin/env bash
# FreeCAD's PathSimulator (voxel Z-map) side by side with `lbrsim batch --threads 1` on the
# finish3d workload (bench/programs/finish3d.ngc, default profile: 100 x 80 x 30 stock, top at
# Z0; T2 ball Ø6, T5 bull Ø12 R2). Benchmark only: needs `freecadcmd` (Debian package
# `freecad`), which is never a build or test dependency. Runs alternate FreeCAD / lbrsim,
# REPEAT times, and prints each time, the medians and the ratio.
#
#   tools/bench-freecad.sh [BUILD_DIR] [PROGRAM] [REPEAT] [RESOLUTION_MM]
#   defaults:              build        bench/programs/finish3d.ngc  3  0.1
#
# FreeCAD time: the PathSim.ApplyCommand loop only (like lbrsim's kernel time: no parsing, no
# meshing), stock at RESOLUTION_MM (the GUI's 0.1 % accuracy on a 100 mm stock), tool profile
# at 0.005 mm (the GUI's 0.05 x accuracy). lbrsim time: "simulated in" of lbrsim batch (kernel
# wall time, collision checks off: FreeCAD has none), Δ 0.1 mm, auto grid, one kernel thread. Removed volumes: FreeCAD from its result
# mesh, lbrsim from its summary line.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
PROGRAM=${2:-bench/programs/finish3d.ngc}
REPEAT=${3:-3}
RES=${4:-0.1}
LBRSIM="$BUILD/app/lbrsim"
if ! command -v freecadcmd >/dev/null 2>&1; then
  echo "bench-freecad: freecadcmd not installed (Debian package freecad); skipped"
  exit 0
fi
[[ -x "$LBRSIM" ]] || { echo "bench-freecad: $LBRSIM not built" >&2; exit 1; }
[[ -f "$PROGRAM" ]] || { echo "bench-freecad: $PROGRAM not found" >&2; exit 1; }
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT

cat >"$TMP/fc_sim.py" <<'EOF'
import math, os, re, sys, time
import FreeCAD, Part, Path, PathSimulator, Mesh
from FreeCAD import Vector

program = os.environ["LBR_FC_PROGRAM"]
res = float(os.environ["LBR_FC_RES"])
out = os.environ["LBR_FC_OUT"]

def ball(d, length=40.0):
    r = d / 2
    return Part.makeSphere(r, Vector(0, 0, r)).fuse(Part.makeCylinder(r, length - r, Vector(0, 0, r))).removeSplitter()

def bull(d, rc, length=40.0):
    r = d / 2
    core = Part.makeCylinder(r - rc, rc, Vector(0, 0, 0))
    torus = Part.makeTorus(r - rc, rc, Vector(0, 0, rc))
    top = Part.makeCylinder(r, length - rc, Vector(0, 0, rc))
    return core.fuse(torus).fuse(top).removeSplitter()

def flat(d, length=40.0):
    return Part.makeCylinder(d / 2, length)

# Tools of the default profile (config/profiles/default-mill3.toml) used by the workloads.
tools = {1: flat(10.0), 2: ball(6.0), 5: bull(12.0, 2.0)}

# Parse the program (G0/G1 with modal axes, G2/G3 in XY chorded like FreeCAD's GUI, T n M6).
word = re.compile(r"([A-Z])\s*([-+]?[0-9]*\.?[0-9]+)")
ops = []  # ("tool", n) or ("move", name, x, y, z)
pos = [0.0, 0.0, 0.0]
motion = None
tool = None
with open(program) as f:
    for line in f:
        line = re.sub(r"\(.*?\)", "", line).strip().upper()
        if not line or line.startswith("%"):
            continue
        w = {}
        gs = []
        for k, v in word.findall(line):
            if k == "G":
                gs.append(v)
            else:
                w[k] = float(v)
        for g in gs:
            if g in ("0", "00", "1", "01", "2", "02", "3", "03"):
                motion = "G" + str(int(g))
        if "T" in w:
            tool = int(w["T"])
        if "M" in w and int(w["M"]) == 6 and tool is not None:
            ops.append(("tool", tool))
        if not any(a in w for a in "XYZ") or motion is None:
            continue
        if "53" in gs:  # G53: machine coordinates (the retract before a tool change), not the part's
            continue
        nxt = [w.get("X", pos[0]), w.get("Y", pos[1]), w.get("Z", pos[2])]
        if motion in ("G2", "G3"):
            cx, cy = pos[0] + w.get("I", 0.0), pos[1] + w.get("J", 0.0)
            a0 = math.atan2(pos[1] - cy, pos[0] - cx)
            a1 = math.atan2(nxt[1] - cy, nxt[0] - cx)
            da = a1 - a0
            da = da % (2 * math.pi) if motion == "G3" else -((-da) % (2 * math.pi))
            if abs(da) < 1e-12:
                da = 2 * math.pi if motion == "G3" else -2 * math.pi
            r = math.hypot(pos[0] - cx, pos[1] - cy)
            n = max(1, math.ceil(math.sqrt(r / res * da * da)))
            for i in range(1, n + 1):
                a = a0 + da * i / n
                ops.append(("move", "G1", cx + r * math.cos(a), cy + r * math.sin(a), pos[2] + (nxt[2] - pos[2]) * i / n))
        else:
            ops.append(("move", motion, nxt[0], nxt[1], nxt[2]))
        pos = nxt

cmds = []
for op in ops:
    if op[0] == "tool":
        cmds.append(op)
    else:
        cmds.append(Path.Command(op[1], {"X": op[2], "Y": op[3], "Z": op[4]}))

stock = Part.makeBox(100, 80, 30, Vector(0, 0, -30))
sim = PathSimulator.PathSim()
sim.BeginSimulation(stock, res)
cur = FreeCAD.Placement(Vector(0, 0, 0), FreeCAD.Rotation())
moves = 0
t0 = time.perf_counter()
for c in cmds:
    if isinstance(c, tuple):
        sim.SetToolShape(tools[c[1]], 0.005)
        continue
    cur = sim.ApplyCommand(cur, c)
    moves += 1
t = time.perf_counter() - t0
vol = None
try:
    m = sim.GetResultMesh()[0]
    v = 100 * 80 * 30 - m.Volume
    vol = v if 0 < v < 100 * 80 * 30 else None  # the result mesh is not always closed
except Exception as e:  # the mesh is a bonus; the time is the figure
    sys.stderr.write("volume: %s\n" % e)
with open(out, "w") as f:
    f.write("%.4f %d %s\n" % (t, moves, "%.3f" % vol if vol is not None else "nan"))
EOF

median() { sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
fc_times=() lbr_times=()
for i in $(seq 1 "$REPEAT"); do
  LBR_FC_PROGRAM="$PWD/$PROGRAM" LBR_FC_RES="$RES" LBR_FC_OUT="$TMP/fc.txt" freecadcmd "$TMP/fc_sim.py" >"$TMP/fc.log" 2>&1 || true
  if [[ ! -s "$TMP/fc.txt" ]]; then
    echo "bench-freecad: FreeCAD run failed:" >&2
    tail -20 "$TMP/fc.log" >&2
    exit 1
  fi
  read -r fc_t fc_moves fc_vol <"$TMP/fc.txt"
  rm -f "$TMP/fc.txt"
  line=$("$LBRSIM" batch --quiet --no-checks --threads 1 --program "$PROGRAM" --out "$TMP/lbr" | grep 'simulated in')
  lbr_t=$(sed -E 's/.*simulated in ([0-9.]+) s.*/\1/' <<<"$line")
  lbr_vol=$(sed -E 's/^removed ([0-9.]+) mm3.*/\1/' <<<"$line")
  printf 'run %d: FreeCAD PathSimulator %.3f s (%d moves, removed %s mm3) | lbrsim %.3f s (removed %s mm3)\n' \
    "$i" "$fc_t" "$fc_moves" "$fc_vol" "$lbr_t" "$lbr_vol"
  fc_times+=("$fc_t")
  lbr_times+=("$lbr_t")
done
fc_med=$(printf '%s\n' "${fc_times[@]}" | median)
lbr_med=$(printf '%s\n' "${lbr_times[@]}" | median)
printf '%s, Z-map %s mm, medians of %d: FreeCAD %.3f s, lbrsim (1 thread) %.3f s, lbrsim / FreeCAD = %.2f\n' \
  "$PROGRAM" "$RES" "$REPEAT" "$fc_med" "$lbr_med" "$(awk -v a="$lbr_med" -v b="$fc_med" 'BEGIN {print a / b}')"
