#!/usr/bin/env bash
# Installs lodrefine's build and test dependencies from Debian's packages (Debian 12).
# Usage: scripts/deps.sh [--with-cloudcompare]
set -euo pipefail
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
PKGS="build-essential cmake ccache libcgal-dev libeigen3-dev libglpk-dev libtinyobjloader-dev
      libcli11-dev nlohmann-json3-dev libtbb-dev libgtest-dev libboost-dev libcitygml-dev
      python3-jsonschema"
if [ "${1:-}" = "--with-cloudcompare" ]; then PKGS="$PKGS cloudcompare"; fi
missing=""
for p in $PKGS; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
  echo "installing:$missing"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends $missing
fi
