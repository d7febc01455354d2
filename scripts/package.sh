#!/usr/bin/env bash
# Builds the Debian package of the tree scripts/build.sh built (CPack, CMakeLists.txt: the
# program and its CityGML module under /usr, dependencies by Debian's package names), installs
# it and runs `lodrefine --version` from it: with dpkg -i when run as root (CI), else unpacked
# into a fresh prefix. Fails unless the installed program says the version CMake declares.
# Usage: scripts/package.sh [build dir, default build]
set -euo pipefail
cd "$(dirname "$0")/.."
build="${1:-build}"
version=$(sed -n 's/^project(lodrefine VERSION \([0-9.]*\) .*/\1/p' CMakeLists.txt)
rm -f "$build"/lodrefine_*.deb
(cd "$build" && cpack -G DEB >/dev/null)
deb=$(ls "$build"/lodrefine_"$version"_*.deb)
dpkg-deb --field "$deb" Package Version Depends
if [ "$(id -u)" -eq 0 ] && [ "${LODREFINE_PACKAGE_EXTRACT:-0}" != 1 ]; then
  dpkg -i "$deb" >/dev/null
  bin=/usr/bin/lodrefine
else
  prefix=$(mktemp -d)
  trap 'rm -rf "$prefix"' EXIT
  dpkg-deb -x "$deb" "$prefix"
  bin="$prefix/usr/bin/lodrefine"
fi
said=$("$bin" --version)
echo "package.sh: $deb installed: $said"
[ "$said" = "lodrefine $version" ] || { echo "package.sh: expected 'lodrefine $version'" >&2; exit 1; }
