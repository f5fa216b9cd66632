#!/usr/bin/env bash
# lintian on the Debian package: no errors allowed; warnings are printed (docs/deployment.md
# lists the ones that remain and why). usage: package_lintian.sh BUILD_DIR
set -euo pipefail
command -v lintian >/dev/null || { echo "SKIPPED: lintian is not installed (tools/setup-debian.sh)"; exit 77; }
cmake --build "$1" --target package >/dev/null
deb=$(ls "$1"/lbrsim_*_amd64.deb | head -n1)
lintian --fail-on error --no-tag-display-limit "$deb"
