#!/usr/bin/env bash
# Refines every building of the dev tiles (../shared/devtiles) and scores them with the
# project's judges: score.py for synth, real and topo (per tile the score table and the
# per-building rows), score_city.py for the city file (correct buildings changed).
#   scripts/devtiles.sh [OUT_DIR=devtiles-out] [extra refine args...]
#   TILES_ONLY="topo city" scripts/devtiles.sh OUT   runs only those tiles
set -uo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-devtiles-out}; shift || true
TILES=${DEVTILES:-../shared/devtiles}
BIN=${LODREFINE:-build/lodrefine}
for tile in ${TILES_ONLY:-synth real topo city}; do
  [ "$tile" = city ] && continue
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

case " ${TILES_ONLY:-city} " in
  *" city "*)
    if [ -f "$TILES/city/coarse.city.json" ]; then
      echo "== city"
      mkdir -p "$OUT/city"
      s=$(date +%s.%N)
      "$BIN" refine --model "$TILES/city/coarse.city.json" --cloud "$TILES/city/tile.ply" \
        --out "$OUT/city/refined.city.json" --report "$OUT/city/report.json" "$@" > "$OUT/city/log.txt" 2>&1
      echo "city refine rc=$? $(echo "$(date +%s.%N) - $s" | bc) s; $(tail -n 1 "$OUT/city/log.txt")"
      /usr/bin/python3 "$TILES/score_city.py" "$OUT/city/refined.city.json" "$OUT/city" --json "$OUT/city/score.json"
    fi ;;
esac
