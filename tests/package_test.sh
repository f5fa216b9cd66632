#!/usr/bin/env bash
# The Debian package in a clean Debian 12 (ctest label package; docs/deployment.md#tests):
# builds it (cmake --build BUILD --target package), installs it with apt-get into a minbase
# root made by debootstrap (so its Depends: are resolved from the archive), and runs the
# installed lbrsim there: `batch` and `run --source emulator:demo --speed 0` must exit 0 and
# remove the same volume as the build tree's binary; profiles and programs must be found in
# /etc/lbrsim and /usr/share/lbrsim from any folder.
# usage: package_test.sh BUILD_DIR
# Needs root and debootstrap; exits 77 (ctest: skipped) with the reason otherwise. The Debian
# root after `apt-get update` and the downloaded .debs are cached in BUILD_DIR/package-test,
# so a rerun needs no download. Mirror: LBR_DEBIAN_MIRROR, else the host's apt sources.
set -euo pipefail
build=$(cd "$1" && pwd)
work=$build/package-test
skip() { echo "SKIPPED: $*"; exit 77; }
[ "$(id -u)" -eq 0 ] || skip "needs root (debootstrap, chroot); run ctest -L package as root"
command -v debootstrap >/dev/null || skip "debootstrap is not installed (tools/setup-debian.sh installs it)"
command -v chroot >/dev/null || skip "chroot is not available"

host_sources() { cat /etc/apt/sources.list.d/*.sources /etc/apt/sources.list 2>/dev/null || true; }
mirror=${LBR_DEBIAN_MIRROR:-$(host_sources | sed -n 's/^URIs: *\([^ ]*\/debian\)$/\1/p; s/^deb \([^ ]*\/debian\) bookworm .*/\1/p' | head -n1)}
[ -n "$mirror" ] || skip "no Debian mirror: set LBR_DEBIAN_MIRROR"

t0=$(date +%s)
cmake --build "$build" --target package >/dev/null
deb=$(ls "$build"/lbrsim_*_amd64.deb | head -n1)
echo "package: $deb"

mkdir -p "$work/archives"
base=$work/bookworm-minbase.tar
if [ ! -f "$base" ]; then  # once: debootstrap, the host's apt sources, apt-get update
  rm -rf "$work/base"
  debootstrap --variant=minbase bookworm "$work/base" "$mirror" >"$work/debootstrap.log" 2>&1 ||
    { tail -n 20 "$work/debootstrap.log"; exit 1; }
  if ls /etc/apt/sources.list.d/debian.sources >/dev/null 2>&1; then
    rm -f "$work/base/etc/apt/sources.list"; cp /etc/apt/sources.list.d/debian.sources "$work/base/etc/apt/sources.list.d/"
  fi
  chroot "$work/base" apt-get update -q >/dev/null
  tar -C "$work/base" -cf "$base.tmp" . && mv "$base.tmp" "$base"
  rm -rf "$work/base"
fi

root=$work/root
cleanup() { umount "$root/proc" 2>/dev/null || true; rm -rf "$root"; }
trap cleanup EXIT
rm -rf "$root" && mkdir -p "$root"
tar -C "$root" -xf "$base"
mount -t proc proc "$root/proc"
cp "$work"/archives/*.deb "$root/var/cache/apt/archives/" 2>/dev/null || true
cp "$deb" "$root/tmp/lbrsim.deb"
DEBIAN_FRONTEND=noninteractive chroot "$root" apt-get install -y -q --no-install-recommends /tmp/lbrsim.deb \
  >"$work/install.log" 2>&1 || { tail -n 30 "$work/install.log"; exit 1; }
cp "$root"/var/cache/apt/archives/*.deb "$work/archives/" 2>/dev/null || true

fail() { echo "FAIL: $*"; exit 1; }
volume() { sed -n 's/.*"removed_volume_mm3": *\([0-9.e+-]*\).*/\1/p' "$1"; }
in_root() { chroot "$root" /bin/sh -c "cd /tmp && $*"; }

version=$(in_root lbrsim --version)
[ "$version" = "lbrsim $(basename "$deb" | cut -d_ -f2)" ] || fail "lbrsim --version says '$version'"
in_root lbrsim profile live-6axis | grep -q "ok" || fail "/etc/lbrsim/live-6axis.toml not found by name"
[ "$(in_root lbrsim profile live-6axis --can-bitrate)" = 500000 ] || fail "lbrsim profile live-6axis --can-bitrate"
in_root test -f /lib/systemd/system/lbrsim@.service || fail "no lbrsim@.service"
in_root test -f /usr/share/man/man1/lbrsim.1.gz || fail "no man page"
in_root dpkg-query -W -f='\${Conffiles}' lbrsim | grep -q /etc/lbrsim/live-6axis.toml || fail "profiles are not conffiles"

in_root lbrsim batch --quiet --out /tmp/batch >/dev/null || fail "lbrsim batch exited $?"
"$build/app/lbrsim" batch --quiet --out "$work/ref-batch" >/dev/null
[ "$(volume "$root/tmp/batch/metrics.json")" = "$(volume "$work/ref-batch/metrics.json")" ] ||
  fail "batch removed $(volume "$root/tmp/batch/metrics.json") mm3, the build tree $(volume "$work/ref-batch/metrics.json")"

in_root lbrsim run --source emulator:demo --speed 0 --no-window --quiet --out /tmp/run >/dev/null || fail "lbrsim run exited $?"
"$build/app/lbrsim" run --source emulator:demo --speed 0 --no-window --quiet --out "$work/ref-run" >/dev/null
[ "$(volume "$root/tmp/run/metrics.json")" = "$(volume "$work/ref-run/metrics.json")" ] ||
  fail "run removed $(volume "$root/tmp/run/metrics.json") mm3, the build tree $(volume "$work/ref-run/metrics.json")"

# A bundled program through a profile's name, from another folder.
in_root lbrsim batch --quiet --profile lathe --program lathe-shaft.ngc --out /tmp/lathe >/dev/null ||
  fail "installed lathe profile + bundled program not found"
echo "package test passed: batch $(volume "$root/tmp/batch/metrics.json") mm3, run $(volume "$root/tmp/run/metrics.json") mm3," \
     "$(( $(date +%s) - t0 )) s"
