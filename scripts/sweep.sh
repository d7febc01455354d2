#!/usr/bin/env bash
# Sweep over FRESH generated tiles: K tiles per kind (synth, real, topo) with new seeds, every
# building refined, each tile scored with ../shared/devtiles/score.py; for real tiles also the
# city path (gen/city_check.py, plain and --truth-city). Prints per kind the pooled truth facade
# and roof RMSE before -> after, per-seed figures, watertight rate, buildings made worse,
# outcomes, correct city buildings changed, the ten worst buildings and refine wall times.
# Not for CI.
#
#   scripts/sweep.sh [--k K=3] [--n N=30] [--first-seed S=1000] [--kinds "synth real topo"]
#                    [--out DIR=/tmp/lodrefine-sweep] [--tiles DIR=/tmp/lodrefine-sweep-tiles]
#                    [--jobs J=nproc] [--timeout SEC=120] [-- extra refine args...]
#   env: LODREFINE = binary (default build/lodrefine), DEVTILES = ../shared/devtiles
#
# Time (2 cores, K=3, N=30): generation ~2 min, once (cached in --tiles: same kind/seed/N = same
# tile; ~1 min per real tile, seconds for synth/topo); the sweep proper ~10-12 min (refine
# 20-45 s, score.py 5.5-7 min, city_check ~4 min). Both are printed and kept in sweep.json.
# Outputs: DIR/sweep.json, DIR/sweep.md, DIR/summary.txt (the printed summary), and per tile
# DIR/runs/<kind>-s<seed>-n<N>/ (<id>.obj/.json/.log/.time, score.json, score.txt; real tiles:
# city/ and city_truth/ = the city_check.py work folders, city.txt / city_truth.txt = their output).
# Tiles and outputs are never written inside the repository.
set -uo pipefail

usage() { sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//'; exit "${1:-2}"; }

ROOT=$(cd "$(dirname "$0")/.." && pwd)
K=3 N=30 FIRST=1000 KINDS="synth real topo" OUT=/tmp/lodrefine-sweep TILES_DIR=/tmp/lodrefine-sweep-tiles
JOBS=$(nproc) TMO=120 CITY_TMO=${SWEEP_CITY_TIMEOUT:-1200}
EXTRA=()
is_uint() { [[ $1 =~ ^[0-9]+$ ]]; }
while [ $# -gt 0 ]; do
  case $1 in
    --k) K=${2:?}; shift 2 ;;
    --n) N=${2:?}; shift 2 ;;
    --first-seed) FIRST=${2:?}; shift 2 ;;
    --kinds) KINDS=${2:?}; shift 2 ;;
    --out) OUT=${2:?}; shift 2 ;;
    --tiles) TILES_DIR=${2:?}; shift 2 ;;
    --jobs) JOBS=${2:?}; shift 2 ;;
    --timeout) TMO=${2:?}; shift 2 ;;
    -h|--help) usage 0 ;;
    --) shift; EXTRA=("$@"); break ;;
    *) echo "sweep.sh: unknown argument '$1'" >&2; usage 2 ;;
  esac
done
for v in "$K" "$N" "$FIRST" "$JOBS" "$TMO"; do
  is_uint "$v" || { echo "sweep.sh: '$v' is not a non-negative integer" >&2; exit 2; }
done
[ "$K" -ge 1 ] && [ "$N" -ge 1 ] && [ "$JOBS" -ge 1 ] || { echo "sweep.sh: K, N, J must be >= 1" >&2; exit 2; }
for kind in $KINDS; do
  case $kind in synth|real|topo) ;; *) echo "sweep.sh: unknown kind '$kind' (synth real topo)" >&2; exit 2 ;; esac
done

DEVTILES=${DEVTILES:-$ROOT/../shared/devtiles}
DEVTILES=$(cd "$DEVTILES" && pwd) || { echo "sweep.sh: no devtiles folder" >&2; exit 2; }
GEN=$DEVTILES/gen
PY=/usr/bin/python3
BIN=${LODREFINE:-$ROOT/build/lodrefine}
case $BIN in /*) ;; *) BIN=$(cd "$(dirname "$BIN")" && pwd)/$(basename "$BIN") ;; esac
[ -x "$BIN" ] || { echo "sweep.sh: no executable $BIN (set LODREFINE)" >&2; exit 2; }
REPORT_PY=$ROOT/scripts/sweep_report.py

mkdir -p "$OUT" "$TILES_DIR" || exit 2
OUT=$(cd "$OUT" && pwd); TILES_DIR=$(cd "$TILES_DIR" && pwd)
for d in "$OUT" "$TILES_DIR"; do
  case "$d/" in "$ROOT"/*) echo "sweep.sh: $d is inside the repository; use /tmp" >&2; exit 2 ;; esac
done
now() { date +%s.%N; }
secs() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.1f", b - a }'; }

# ---------------------------------------------------------------- 1. tiles (cached)
# A tile folder is complete when the generator exited 0 and every building of meta.json has its
# model, cloud and truth: then .sweep-complete holds "kind seed N". Generation goes to a
# .partial folder renamed into place, so an interrupted generation is redone.
tile_dir() { printf '%s/%s-s%s-n%s' "$TILES_DIR" "$1" "$2" "$3"; }
tile_complete() {
  local d=$1
  [ -f "$d/.sweep-complete" ] && [ "$(cat "$d/.sweep-complete")" = "$2 $3 $4" ] || return 1
  "$PY" - "$d" <<'PY' 2>/dev/null
import json, os, sys
d = sys.argv[1]
m = json.load(open(os.path.join(d, "meta.json")))
ok = bool(m["buildings"]) and os.path.exists(os.path.join(d, "tile.ply")) and all(
    os.path.exists(os.path.join(d, sub, b["id"] + ext))
    for b in m["buildings"] for sub, ext in (("models", ".obj"), ("clouds", ".ply"), ("truth", ".obj")))
sys.exit(0 if ok else 1)
PY
}
gen_one() {   # kind seed n dir: runs in an xargs worker
  local kind=$1 seed=$2 n=$3 d=$4 part s rc
  part="$d.partial"
  rm -rf -- "$part"; mkdir -p -- "$part"
  s=$(date +%s.%N)
  "$PY" "$GEN/${kind}_tile.py" "$part" "$seed" "$n" > "$part/gen.log" 2>&1
  rc=$?
  echo "gen $kind seed $seed: exit $rc, $(awk -v a="$s" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }') s" >> "$part/gen.log"
  if [ $rc -ne 0 ]; then echo "generation of $kind seed $seed FAILED (exit $rc), see $part/gen.log" >&2; return 0; fi
  printf '%s %s %s' "$kind" "$seed" "$n" > "$part/.sweep-complete"
  rm -rf -- "$d"; mv -- "$part" "$d"
  tail -n 1 "$d/gen.log"
}
export -f gen_one; export PY GEN

T_GEN0=$(now)
todo=()
for kind in $KINDS; do
  for ((i = 0; i < K; i++)); do
    seed=$((FIRST + i)); d=$(tile_dir "$kind" "$seed" "$N")
    if tile_complete "$d" "$kind" "$seed" "$N"; then echo "tile $kind seed $seed N=$N: cached ($d)"
    else todo+=("$kind" "$seed" "$N" "$d"); fi
  done
done
if [ ${#todo[@]} -gt 0 ]; then
  echo "generating $(( ${#todo[@]} / 4 )) tile(s) into $TILES_DIR ($JOBS at once)"
  printf '%s\0' "${todo[@]}" | xargs -0 -n 4 -P "$JOBS" bash -c 'gen_one "$@"' _
fi
T_GEN=$(secs "$T_GEN0" "$(now)")
echo "generation: $T_GEN s"

# ---------------------------------------------------------------- 2. refine every building
# what is measured: recorded now, checked again at the end (the binary may be rebuilt meanwhile)
VERSION=$("$BIN" --version 2>&1 | head -n 1)
HEAD=$(git -C "$ROOT" rev-parse --short HEAD 2>/dev/null || echo unknown)
DIRTY=$(git -C "$ROOT" status --porcelain --untracked-files=no 2>/dev/null | wc -l)
BIN_SUM=$(sha256sum "$BIN" | cut -c1-16)
T0=$(now)
MANIFEST=$OUT/manifest.tsv
: > "$MANIFEST"
: > "$OUT/jobs.bin"
for kind in $KINDS; do
  for ((i = 0; i < K; i++)); do
    seed=$((FIRST + i)); d=$(tile_dir "$kind" "$seed" "$N")
    if ! tile_complete "$d" "$kind" "$seed" "$N"; then
      echo "tile $kind seed $seed missing: left out of the sweep" >&2; continue
    fi
    run=$OUT/runs/$kind-s$seed-n$N
    rm -rf -- "$run"; mkdir -p -- "$run"
    printf '%s\t%s\t%s\t%s\t%s\n' "$kind" "$seed" "$N" "$d" "$run" >> "$MANIFEST"
    # ids come from meta.json (the generator's own list); only safe file names are run
    "$PY" - "$d" <<'PY' | while IFS= read -r id; do printf '%s\0%s\0%s\0%s\0' "$d/models/$id.obj" "$d/clouds/$id.ply" "$run" "$id" >> "$OUT/jobs.bin"; done
import json, re, sys
for b in json.load(open(sys.argv[1] + "/meta.json"))["buildings"]:
    if re.fullmatch(r"[A-Za-z0-9_][A-Za-z0-9._-]*", b["id"]): print(b["id"])
    else: print("unsafe building id skipped: %r" % b["id"], file=sys.stderr)
PY
  done
done
[ -s "$MANIFEST" ] || { echo "sweep.sh: no tile to sweep" >&2; exit 1; }
# extra refine args travel as a NUL-separated file (no eval, any characters)
EXTRA_FILE=$OUT/extra-args.bin
: > "$EXTRA_FILE"
[ ${#EXTRA[@]} -gt 0 ] && printf '%s\0' "${EXTRA[@]}" > "$EXTRA_FILE"
refine_one() {   # model cloud run id; never fails the pool
  local m=$1 c=$2 run=$3 id=$4 s e rc extra=()
  [ -s "$SWEEP_EXTRA" ] && mapfile -d '' -t extra < "$SWEEP_EXTRA"
  s=$(date +%s.%N)
  timeout -k 10 "$SWEEP_TIMEOUT" "$SWEEP_BIN" refine --model "$m" --cloud "$c" --out "$run/$id.obj" \
    --report "$run/$id.json" "${extra[@]}" > "$run/$id.log" 2>&1
  rc=$?; e=$(date +%s.%N)
  # a failed or timed-out refine is a lost building: no .obj for score.py
  if [ $rc -ne 0 ] && [ -e "$run/$id.obj" ]; then mv -f -- "$run/$id.obj" "$run/$id.obj.failed"; fi
  printf '%s rc=%s %s s\n' "$id" "$rc" "$(awk -v a="$s" -v b="$e" 'BEGIN { printf "%.3f", b - a }')" > "$run/$id.time"
  return 0
}
export -f refine_one
export SWEEP_BIN="$BIN" SWEEP_TIMEOUT="$TMO" SWEEP_EXTRA="$EXTRA_FILE"
nb=$(tr -cd '\0' < "$OUT/jobs.bin" | wc -c); nb=$((nb / 4))
echo "refining $nb building(s) of $(wc -l < "$MANIFEST") tile(s), $JOBS at once, timeout $TMO s: $BIN ${EXTRA[*]}"
xargs -0 -n 4 -P "$JOBS" bash -c 'refine_one "$@"' _ < "$OUT/jobs.bin"
T_REF=$(secs "$T0" "$(now)")
echo "refine: $T_REF s"

# ---------------------------------------------------------------- 3. score every tile
T1=$(now)
score_one() {   # tile run
  "$PY" "$SWEEP_DEVTILES/score.py" "$1" "$2" --json "$2/score.json" > "$2/score.txt" 2>&1
  echo "score $(basename "$2"): exit $? ($(grep -m1 '^produced' "$2/score.txt"))"
  return 0
}
export -f score_one; export SWEEP_DEVTILES="$DEVTILES"
cut -f4,5 "$MANIFEST" | tr '\t\n' '\0\0' | xargs -0 -n 2 -P "$JOBS" bash -c 'score_one "$@"' _
# per-building truth sample counts, to pool RMSE over samples across tiles (cached per tile)
cut -f4 "$MANIFEST" | tr '\n' '\0' | xargs -0 -n 1 -P "$JOBS" "$PY" "$REPORT_PY" counts
T_SCORE=$(secs "$T1" "$(now)")
echo "score: $T_SCORE s"

# ---------------------------------------------------------------- 4. city path (real tiles)
T2=$(now)
while IFS=$'\t' read -r kind seed n d run; do
  [ "$kind" = real ] || continue
  for mode in city city_truth; do
    flag=(); [ "$mode" = city_truth ] && flag=(--truth-city)
    s=$(now)
    timeout -k 10 "$CITY_TMO" "$PY" "$GEN/city_check.py" "$d" "$run/$mode" "$BIN" "${flag[@]}" > "$run/$mode.txt" 2>&1
    rc=$?
    echo "$rc $(secs "$s" "$(now)")" > "$run/$mode.rc"
    echo "city_check $(basename "$run") ${flag[*]:-(plain)}: exit $rc, $(secs "$s" "$(now)") s; $(grep -m1 '^correct buildings' "$run/$mode.txt" | cut -c1-160)"
  done
done < "$MANIFEST"
T_CITY=$(secs "$T2" "$(now)")
echo "city_check: $T_CITY s"
T_SWEEP=$(secs "$T0" "$(now)")
echo "sweep proper (refine + score + city_check): $T_SWEEP s; generation: $T_GEN s"

# ---------------------------------------------------------------- 5. summary
BIN_SUM_END=$(sha256sum "$BIN" | cut -c1-16)
[ "$BIN_SUM" = "$BIN_SUM_END" ] || echo "WARNING: $BIN changed during the sweep ($BIN_SUM -> $BIN_SUM_END): results mix two builds" >&2
"$PY" "$REPORT_PY" report "$OUT" --version "$VERSION" --head "$HEAD" --dirty "$DIRTY" --bin "$BIN" \
  --bin-sha256 "$BIN_SUM" --bin-sha256-end "$BIN_SUM_END" \
  --k "$K" --n "$N" --first-seed "$FIRST" --jobs "$JOBS" --timeout "$TMO" --extra-file "$EXTRA_FILE" \
  --t-gen "$T_GEN" --t-refine "$T_REF" --t-score "$T_SCORE" --t-city "$T_CITY" --t-sweep "$T_SWEEP" \
  | tee "$OUT/summary.txt"
echo "wrote $OUT/sweep.json $OUT/sweep.md $OUT/summary.txt"
