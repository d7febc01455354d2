#!/usr/bin/env bash
# Refreshes third_party/three/ from the npm registry (`npm pack`, cache outside the repo).
# Usage: scripts/vendor_three.sh [VERSION=0.160.0]  (needs a self-contained build/three.module.min.js)
set -euo pipefail
version=${1:-0.160.0}
root=$(cd "$(dirname "$0")/.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
(cd "$tmp" && npm pack "three@$version" --cache "$tmp/cache" > /dev/null && tar xzf "three-$version.tgz")
if grep -q "^import\|from\"\./" "$tmp/package/build/three.module.min.js"; then
  echo "three@$version: build/three.module.min.js imports other files; pick a version <= 0.160.0" >&2
  exit 1
fi
cp "$tmp/package/build/three.module.min.js" "$tmp/package/LICENSE" "$root/third_party/three/"
echo "third_party/three: three@$version"
