#!/usr/bin/env bash
# `lbrsim view --design` end to end (issue 16, docs/verification.md#live-design):
#   tests/cli_view_design.sh BUILD_DIR OUT_DIR
# The default stock as the design (nothing should be cut from it) against a slot 10 wide,
# 2 deep, through the stock along X (2000 mm3): the view prints the batch comparison's gouge
# (batch's design_gouge_mm3 to the mm3, 2000 within 1 %), and with --color deviation its
# screenshot shows the slot's faces red; with --color plain none. Levels 0.5 mm apart keep
# the mesh small for llvmpipe; 640x480 leaves the slot clear of the colour legend (right edge,
# whose deep-red swatch is ~200 of the red pixels counted).
set -uo pipefail
. "$(dirname "$0")/cli_lib.sh"
B=$1 OUT=$2
LBRSIM=$B/app/lbrsim PROBE=$B/tests/png_probe
rm -rf "$OUT" && mkdir -p "$OUT" && cd "$OUT" || exit 1
fail() { echo "FAIL: $*" >&2; exit 1; }
# The default stock X0..100 Y0..80 Z-30..0, 12 outward triangles.
v() { case $1 in 0) echo "0 0 -30" ;; 1) echo "100 0 -30" ;; 2) echo "0 80 -30" ;; 3) echo "100 80 -30" ;;
                 4) echo "0 0 0" ;; 5) echo "100 0 0" ;; 6) echo "0 80 0" ;; 7) echo "100 80 0" ;; esac; }
{
  echo "solid stock"
  for t in "0 2 3" "0 3 1" "4 5 7" "4 7 6" "0 1 5" "0 5 4" "2 6 7" "2 7 3" "0 4 6" "0 6 2" "1 3 7" "1 7 5"; do
    echo "facet normal 0 0 0"; echo "outer loop"
    for k in $t; do echo "vertex $(v "$k")"; done
    echo "endloop"; echo "endfacet"
  done
  echo "endsolid stock"
} >stock.stl
printf 'G21 G90 G17\nT1 M6 S1000 M3\nG43 H1\nG0 X-10 Y40 Z5\nG1 Z-2 F1000\nG1 X110\nG0 Z5\nM2\n' >slot.ngc
args=(--program slot.ngc --level-spacing 0.5 --design stock.stl)
"$LBRSIM" batch --quiet --out batch "${args[@]}" >batch.log 2>&1 || fail "batch: $(tail -3 batch.log)"
batch_gouge=$(json_num batch/metrics.json design_gouge_mm3)

view() {  # COLOUR: a static view under xvfb, one screenshot
  xvfb-run -a "$LBRSIM" view --hidden --no-ui --frames 3 --screenshot-every 2 --screenshot-prefix "$1"- \
    --size 640x480 --quiet "${args[@]}" --color "$1" >"$1".log 2>&1 || fail "view $1: $(tail -5 "$1".log)"
  shot=$(ls "$1"-*.png 2>/dev/null | tail -1)
  [ -n "$shot" ] || fail "view $1: no screenshot"
  red=$("$PROBE" "$shot" count 219 31 26 60)
}
view deviation
view_gouge=$(sed -n 's/^design: gouge \([0-9.]*\) mm3.*/\1/p' deviation.log)
[ -n "$view_gouge" ] || fail "view: no design line: $(cat deviation.log)"
[ "${view_gouge%.*}" = "${batch_gouge%.*}" ] || fail "view gouge $view_gouge mm3, batch $batch_gouge mm3"
[ "${view_gouge%.*}" -ge 1980 ] && [ "${view_gouge%.*}" -le 2020 ] || fail "view gouge $view_gouge mm3, not 2000 within 1 %"
[ "${red:-0}" -gt 1500 ] || fail "view --color deviation: $red red pixels in $shot"
view plain
[ "${red:-9999}" -lt 50 ] || fail "view --color plain: $red red pixels in $shot"
echo "view --design: gouge $view_gouge mm3 (batch $batch_gouge), red pixels with deviation colours"
