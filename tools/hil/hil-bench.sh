#!/usr/bin/env bash
# HIL bench with vcan (docs/performance.md, DESIGN "HIL bench"): this development kernel has
# no AF_CAN, so Debian's linux-image-amd64 kernel boots under qemu (TCG) with a busybox
# initramfs holding lbrsim, lbr-feed-can, their shared libraries and the can, can-raw,
# can-dev, vcan modules. In the VM: vcan0, `lbr-feed-can` (with injected faults) →
# `lbrsim run --source can:vcan0 --record`, then a replay of the recorded candump log.
# Debian's can-utils interoperate: `candump -l` records the feeder's frames during the live
# run and its file is replayed (replay:); `canplayer` plays lbrsim's recording onto vcan0
# for a second live run; both logs must agree line for line (candump's format).
# The interface is taken down for 0.4 s mid-run (bus-off / interface-down detection and
# reconnection). Checks: every injected fault counted, replay = live (samples, faults, volume).
# Usage: tools/hil/hil-bench.sh [BUILD_DIR] [WORK_DIR]   (needs qemu-system-x86,
# busybox-static, cpio, can-utils; downloads the kernel package once into WORK_DIR with apt-get).
set -euo pipefail
if [ "${1:-}" = --help ] || [ "${1:-}" = -h ]; then  # usage: the comment above
  sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0
fi
ROOT="$(cd "$(dirname "$0")/../.." && pwd)"
BUILD="$(cd "${1:-$ROOT/build}" && pwd)"
WORK="${2:-$BUILD/hil}"
mkdir -p "$WORK"
WORK="$(cd "$WORK" && pwd)"

PKG="$(apt-cache depends linux-image-amd64 | awk '/Depends: linux-image-/{print $2; exit}')"
KVER="${PKG#linux-image-}"
KDIR="$WORK/kernel-$KVER"
if [ ! -f "$KDIR/boot/vmlinuz-$KVER" ]; then
  (cd "$WORK" && apt-get download "$PKG" && dpkg-deb -x "$PKG"_*.deb "$KDIR" && rm -f "$PKG"_*.deb)
fi

R="$WORK/root"
rm -rf "$R"
mkdir -p "$R"/{bin,sbin,proc,sys,dev,tmp,mods,data}
cp "$(command -v busybox)" "$R/bin/busybox"
for a in sh mount insmod ip poweroff cat sleep kill tr echo grep ls head mkdir gzip base64 sed; do ln -sf busybox "$R/bin/$a"; done
for b in "$BUILD/app/lbrsim" "$BUILD/tools/feeders/lbr-feed-can" "$(command -v candump)" "$(command -v canplayer)"; do
  cp "$b" "$R/bin/"
  for lib in $(ldd "$b" | awk '/=>/ {print $3} /^[ \t]*\// {print $1}'); do
    mkdir -p "$R$(dirname "$lib")"
    cp -L "$lib" "$R$lib"
  done
done
for m in net/can/can net/can/can-raw drivers/net/can/dev/can-dev drivers/net/can/vcan; do
  cp "$KDIR/lib/modules/$KVER/kernel/$m.ko" "$R/mods/"
done
cp "$ROOT/tools/hil/hil-profile.toml" "$R/data/profile.toml"
cp "$ROOT/tests/data/live-short.moves" "$R/data/program.moves"
echo "--drop-every 101 --duplicate-every 151 --corrupt-every 199 --statusword" > "$R/data/faults"
cp "$ROOT/tools/hil/init.sh" "$R/init"
chmod +x "$R/init"
(cd "$R" && find . | cpio -o -H newc --quiet | gzip -1) > "$WORK/initrd.gz"

timeout 600 qemu-system-x86_64 -accel tcg -m 1024 -smp 2 -nographic -no-reboot \
  -kernel "$KDIR/boot/vmlinuz-$KVER" -initrd "$WORK/initrd.gz" \
  -append "console=ttyS0 panic=-1 quiet loglevel=3" > "$WORK/console.log" 2>&1 || true
grep -a "HIL-" "$WORK/console.log" | cut -c1-200

python3 - "$WORK/console.log" <<'PY'
import json, sys
lines = open(sys.argv[1], encoding="utf-8", errors="replace").read().splitlines()
def get(tag):
    for l in lines:  # the first line may carry terminal escapes from the boot
        i = l.find(tag + " ")
        if i >= 0:
            return l[i + len(tag) + 1:].strip()
    sys.exit(f"HIL: no {tag} line in the console log")
if any("HIL-ERROR" in l for l in lines): sys.exit("HIL: setup error in the VM")
feed, live, rep, rep_cd, play = (json.loads(get(t)) for t in ("HIL-FEED", "HIL-LIVE", "HIL-REPLAY", "HIL-CANDUMP-REPLAY", "HIL-PLAY"))
errs = live["decode_errors"]
fail = []
def expect(cond, what):
    if not cond: fail.append(what)
expect(all(get(t) == "0" for t in ("HIL-LIVE-RC", "HIL-REPLAY-RC", "HIL-CANDUMP-REPLAY-RC", "HIL-CANPLAYER-RC", "HIL-PLAY-RC")),
       "exit codes")
# The corrupted TPDOs are length errors; every SYNC yields a sample or a lost cycle
# (the last cycle may stay open). Under TCG on a loaded host the VM can stall between a SYNC
# and its TPDOs, so late TPDOs (counted, cycle lost) are possible: lost cycles are at least
# the injected faults' cycles and at most those plus the late TPDOs.
# Frames injected while the interface is down (below) never arrive: allow a few.
expect(feed["corrupted"] - 3 <= errs["length"] <= feed["corrupted"], f"length {errs['length']} vs corrupted {feed['corrupted']}")
# (a repeated late TPDO counts as late again, not as a duplicate)
expect(feed["duplicated"] - 3 <= errs["duplicate_tpdo"] + errs["late_tpdo"], f"duplicate_tpdo {errs['duplicate_tpdo']}")
expect(0 <= feed["syncs"] - (live["samples_received"] + live["samples_lost"]) <= 1, "syncs = samples + lost cycles")
# The interface goes down for 0.4 s mid-run: detected (bus_off), reconnected, and the SYNCs
# missed meanwhile are counted through the SYNC counter.
expect(errs["bus_off"] >= 1 and errs["reconnect"] >= 1, f"bus_off {errs['bus_off']} reconnect {errs['reconnect']}")
expect(feed["send_errors"] > 0, "the feeder saw no send errors while the interface was down")
down = errs["sequence_gap"]
expect(50 <= down <= 200, f"SYNCs missed while down: {down} (0.4 s at 250 Hz ~ 100)")
injected = feed["dropped"] + feed["corrupted"]
expect(injected - 8 <= live["samples_lost"] - down <= injected + errs["late_tpdo"] + 2,
       f"samples_lost {live['samples_lost']} (down {down})")
expect(live["ring_overruns"] == 0, "ring overruns")
for k in ("samples_received", "samples_applied", "samples_lost"):
    expect(live[k] == rep[k], f"replay {k} {rep[k]} != live {live[k]}")
for k, v in errs.items():
    if k not in ("reconnect", "bus_off", "read_error"):
        expect(rep["decode_errors"][k] == v, f"replay decode_errors.{k}")
a, b = live["removed_volume_mm3"], rep["removed_volume_mm3"]
expect(abs(a - b) <= 5e-5 * abs(a) and a > 1000, f"volume live {a} replay {b}")
# can-utils. The two logs: every line matches candump -l's layout, and lbrsim's recording
# (timestamps aside) is candump's file in order, less what lbrsim missed while reconnecting.
import base64, gzip, re
logs = {t: gzip.decompress(base64.b64decode(get(t))).decode().splitlines() for t in ("HIL-LOG-LBRSIM", "HIL-LOG-CANDUMP")}
shape = re.compile(r"^\(\d{10}\.\d{6}\) vcan0 ([0-9A-F]{3}|[0-9A-F]{8})#([0-9A-F]{2}){0,8}$")
for t, ls in logs.items():
    bad = [l for l in ls if not shape.match(l)]
    expect(not bad and ls, f"{t}: {len(bad)} of {len(ls)} lines not in candump -l layout, e.g. {bad[:2]}")
ours, theirs = ([l.split(" ", 1)[1] for l in ls] for ls in (logs["HIL-LOG-LBRSIM"], logs["HIL-LOG-CANDUMP"]))
j = 0
for l in ours:
    while j < len(theirs) and theirs[j] != l: j += 1
    j += 1
expect(j <= len(theirs), "lbrsim's recording is not candump's file in order")
missed = len(theirs) - len(ours)
expect(missed >= 0, f"lbrsim recorded {-missed} frames more than candump")
# candump's file holds what the feeder sent (less the frames sent while the interface was
# down, which the SYNC counter counts): the same accounting as the live run, and the volume.
cd_err = rep_cd["decode_errors"]
expect(feed["corrupted"] - 3 <= cd_err["length"] <= feed["corrupted"], f"candump replay length {cd_err['length']}")
expect(0 <= feed["syncs"] - (rep_cd["samples_received"] + rep_cd["samples_lost"]) <= 1, "candump replay: syncs = samples + lost")
# Volume: candump keeps listening while lbrsim reconnects after the interface comes back,
# so its file can hold cycles lbrsim never saw (one whole cycle is 4 frames: "missed <= 4"
# was not enough). When the replay decodes the samples the live run received, the volumes
# agree; with more samples it removes at least as much.
c = rep_cd["removed_volume_mm3"]
if rep_cd["samples_received"] == live["samples_received"]:
    expect(abs(c - a) <= 5e-5 * abs(a), f"volume candump replay {c} live {a}")
else:
    expect(rep_cd["samples_received"] > live["samples_received"] and c >= a * (1 - 5e-5),
           f"candump replay {rep_cd['samples_received']} samples, {c} mm3; live {live['samples_received']}, {a} mm3")
# canplayer → lbrsim: the recorded samples again. canplayer sends what is due every 1 ms
# (-g), so the play run's profile allows TPDOs 50 ms after their SYNC (init.sh).
p = play["removed_volume_mm3"]
expect(abs(p - a) <= 1e-3 * abs(a), f"volume canplayer {p} live {a}")
late = play["decode_errors"]["late_tpdo"] + errs["late_tpdo"]
expect(abs(play["samples_received"] - live["samples_received"]) <= late + 2, f"canplayer samples {play['samples_received']} live {live['samples_received']}")
print(f"HIL can-utils: candump -l {len(theirs)} frames (lbrsim recorded {len(ours)}), replay {rep_cd['samples_received']} "
      f"samples + {rep_cd['samples_lost']} lost, volume {c:.3f}; canplayer -> lbrsim {play['samples_received']} samples "
      f"({play['decode_errors']['late_tpdo']} late TPDOs), volume {p:.3f}")
print(f"HIL: {feed['samples']} samples over vcan0, lost {live['samples_lost']} (injected "
      f"{feed['dropped']} dropped + {feed['corrupted']} corrupted, {errs['late_tpdo']} late TPDOs, {down} SYNCs while "
      f"down, bus_off {errs['bus_off']}, reconnect {errs['reconnect']}), duplicates {errs['duplicate_tpdo']}, "
      f"lag p50/p99/max {live['lag_p50_ms']:.2f}/{live['lag_p99_ms']:.2f}/{live['lag_max_ms']:.2f} ms (TCG), "
      f"volume live {a:.3f} replay {b:.3f}, rt {live['rt_mode']}")
if fail: sys.exit("HIL FAILED: " + "; ".join(fail))
print("HIL: ok")
PY
