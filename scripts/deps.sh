#!/usr/bin/env bash
# Installs lodrefine's build and test dependencies from Debian's packages (Debian 12).
# Usage: scripts/deps.sh [--with-cloudcompare] [--with-browser] [--with-cluster] [--with-lazperf]
#   --with-cloudcompare  CloudCompare, for the independent C2M cross-check test
#   --with-lazperf       node and the npm package laz-perf (LASzip as WASM) in /tmp/lazjs, the
#                        independent decoder tests/laz/test_laz.cpp compares ours with
#   --with-browser       Chromium, for the headless test of the HTML report
#   --with-cluster       Slurm, munge and GNU Parallel, for the cluster dispatch tests
set -euo pipefail
SUDO=""
LAZPERF=0
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
PKGS="build-essential cmake ccache pkgconf clang-format-14 libcgal-dev libeigen3-dev libglpk-dev libtinyobjloader-dev
      libcli11-dev nlohmann-json3-dev libtbb-dev libjemalloc-dev libgtest-dev libboost-dev zlib1g-dev libcitygml-dev
      python3-jsonschema python3-numpy python3-scipy"
for flag in "$@"; do
  case "$flag" in
    --with-cloudcompare) PKGS="$PKGS cloudcompare" ;;
    --with-browser) PKGS="$PKGS chromium" ;;
    --with-cluster) PKGS="$PKGS slurm-wlm munge parallel" ;;
    --with-lazperf) LAZPERF=1; command -v npm >/dev/null || PKGS="$PKGS nodejs npm" ;;
    *) echo "deps.sh: unknown option $flag" >&2; exit 2 ;;
  esac
done
missing=""
for p in $PKGS; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
  echo "installing:$missing"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get -o DPkg::Lock::Timeout=600 install -y -qq --no-install-recommends $missing
fi
if [ "$LAZPERF" = 1 ] && [ ! -d /tmp/lazjs/node_modules/laz-perf ]; then
  # Best effort: without it the cross-check tests skip.
  mkdir -p /tmp/lazjs && npm install --prefix /tmp/lazjs --no-audit --no-fund laz-perf@0.0.7 >/dev/null 2>&1 ||
    echo "deps.sh: npm install laz-perf failed; the LAZ cross-check tests will skip" >&2
fi
