#!/usr/bin/env bash
# Refines every building of the dev tiles (../shared/devtiles) and scores them with the
# project's judge (score.py). Prints per tile the score table and the per-building rows.
#   scripts/devtiles.sh [OUT_DIR=devtiles-out] [extra refine args...]
set -uo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-devtiles-out}; shift || true
TILES=${DEVTILES:-../shared/devtiles}
BIN=${LODREFINE:-build/lodrefine}
for tile in synth real; do
  [ -d "$TILES/$tile" ] || { echo "no $TILES/$tile"; continue; }
  mkdir -p "$OUT/$tile"
  ls "$TILES/$tile/models" | sed 's/\.obj$//' | \
    xargs -P "$(nproc)" -I{} sh -c '
      s=$(date +%s.%N)
      '"$BIN"' refine --model '"$TILES/$tile"'/models/{}.obj --cloud '"$TILES/$tile"'/clouds/{}.ply \
        --out '"$OUT/$tile"'/{}.obj --report '"$OUT/$tile"'/{}.json "$@" > '"$OUT/$tile"'/{}.log 2>&1
      rc=$?; e=$(date +%s.%N)
      echo "{} rc=$rc $(echo "$e - $s" | bc) s" > '"$OUT/$tile"'/{}.time' _ "$@"
  echo "== $tile"
  /usr/bin/python3 "$TILES/score.py" "$TILES/$tile" "$OUT/$tile" --json "$OUT/$tile/score.json"
  /usr/bin/python3 - "$OUT/$tile" <<'PY'
import json, sys, os, glob
d = sys.argv[1]
s = json.load(open(os.path.join(d, "score.json")))
worse = 0
slow = 0.0
for r in s["rows"]:
    t = open(os.path.join(d, r["id"] + ".time")).read().split()
    sec = float(t[2]); slow = max(slow, sec)
    outc = ""
    try:
        rep = json.load(open(os.path.join(d, r["id"] + ".json")))
        outc = rep.get("outcome", "")
    except Exception:
        outc = open(os.path.join(d, r["id"] + ".log")).read().strip()[-90:]
    tfo, tfr = r["truth_facade_orig"], r["truth_facade_ref"]
    w = tfr == tfr and tfr > tfo + 1e-3
    worse += w
    print(f'{r["id"]:18s} {r["kind"]:8s} {t[1]:5s} {sec:6.2f}s  facade {tfo:.3f}->{tfr:.3f}  roof ->{r["roof_ref"]:.3f} wt={int(bool(r["watertight"]))} {"WORSE " if w else ""}{outc}')
print(f"made worse: {worse}; slowest: {slow:.2f} s")
PY
done
