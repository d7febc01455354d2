#!/usr/bin/env bash
# Generates a "tile" of N synthetic buildings of mixed types (cycling flat, gable, hip, shed,
# stepped, lshape, tshape, polygon, recess, bay, setback) with consecutive seeds into OUT_DIR/<id>/.
# Each building lands at its own random offset within +-300 m of the origin (85000, 447000).
# Usage: scripts/make_tile.sh OUT_DIR [N=16] [FIRST_SEED=1] [extra `lodrefine synth` options...]
# The binary is $LODREFINE, else build/lodrefine, else `lodrefine` on PATH.
set -euo pipefail

if [[ $# -lt 1 ]]; then
  sed -n '2,6p' "$0" | sed 's/^# \{0,1\}//'
  exit 2
fi
out=$1
n=${2:-16}
seed=${3:-1}
shift $(($# < 3 ? $# : 3))

root=$(cd "$(dirname "$0")/.." && pwd)
bin=${LODREFINE:-}
[[ -z $bin && -x $root/build/lodrefine ]] && bin=$root/build/lodrefine
bin=${bin:-lodrefine}

types=(flat gable hip shed stepped lshape tshape polygon recess bay setback)
mkdir -p "$out"
for ((i = 0; i < n; i++)); do
  "$bin" synth --type "${types[i % ${#types[@]}]}" --seed $((seed + i)) --count 1 --out "$out" "$@"
done
