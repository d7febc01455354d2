#!/usr/bin/env bash
# City-scale bench on one machine: generates a tile of BUILDINGS buildings whose clouds (about
# POINTS points in all) are streamed into one PLY, crops it in one streaming pass, refines every
# building in parallel (scripts/batch.mk, JOBS at once) and evaluates the run. Prints wall time,
# buildings per second, peak memory of each stage (the refine figure is the largest single
# building's process) and the outcome counts; the run's report is DIR/run/report.html.
#
#   scripts/city_bench.sh DIR [BUILDINGS=2000] [POINTS=100000000] [JOBS=nproc]   (env: LODREFINE)
#
# Needs about 25 bytes per point on disk for the tile plus as much again for the crops.
# Besides the printed table, DIR keeps what scripts/benchmarks.py reads: bench.meta (date, commit,
# binary, settings), time.<stage> (wall s, peak KB), refine_rss.log, crop.log, run/summary.json.
set -euo pipefail
if [[ $# -lt 1 ]]; then
  sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'
  exit 2
fi
root=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$1"
dir=$(realpath "$1") n=${2:-2000} points=${3:-100000000} jobs=${4:-$(nproc)}
bin=$(realpath "${LODREFINE:-$root/build/lodrefine}")
run=$dir/run
# synth --points counts the scanned-facade points; clutter, ground and neighbours add about
# 9 % (measured: 32.7k points per building for 30k).
per=$((points * 100 / 109 / n))
((per >= 100)) || { echo "city_bench: too few points per building ($per)" >&2; exit 2; }

# measure NAME CMD...: wall seconds and peak resident memory (KB) of CMD and its children.
measure() {
  local name=$1
  shift
  /usr/bin/time -f "%e %M" -o "$dir/time.$name" "$@"
}
wall() { cut -d' ' -f1 "$dir/time.$1"; }
peak_mb() { echo $(($(cut -d' ' -f2 "$dir/time.$1") / 1024)); }

{
  echo "date=$(date -u +%Y-%m-%dT%H:%M:%SZ)"
  echo "head=$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)"
  echo "dirty=$(git -C "$root" status --porcelain --untracked-files=no 2>/dev/null | wc -l)"
  echo "version=$("$bin" --version 2>&1 | head -n 1)"
  echo "buildings=$n"
  echo "points=$points"
  echo "jobs=$jobs"
} > "$dir/bench.meta"
echo "generating $n buildings, about $points points ..."
measure synth "$bin" synth --tile "$dir/tile.ply" --count "$n" --points "$per" --out "$run" > "$dir/synth.log"
echo "cropping ..."
measure crop "$bin" crop --tile "$dir/tile.ply" --models "$run" --out "$run" > "$dir/crop.log"
tile_points=$(tail -n 1 "$dir/crop.log" | cut -d' ' -f1)
# Each refine under /usr/bin/time: the largest building's peak memory.
cat > "$dir/refine_rss.sh" << WRAP
#!/bin/sh
exec /usr/bin/time -f %M -a -o '$dir/refine_rss.log' '$bin' "\$@"
WRAP
chmod +x "$dir/refine_rss.sh"
rm -f "$dir/refine_rss.log"
echo "refining with $jobs jobs ..."
measure refine nice make -s -f "$root/scripts/batch.mk" RUN="$run" LODREFINE="$dir/refine_rss.sh" -j"$jobs" refined \
  > "$dir/refine.log"
echo "evaluating ..."
measure eval make -s -f "$root/scripts/batch.mk" RUN="$run" LODREFINE="$bin" > "$dir/summary.log" 2> "$dir/eval.log"

refine_peak=$(sort -n "$dir/refine_rss.log" | tail -n 1)
awk -v n="$n" -v pts="$tile_points" -v jobs="$jobs" \
    -v gs="$(wall synth)" -v gm="$(peak_mb synth)" -v cs="$(wall crop)" -v cm="$(peak_mb crop)" \
    -v rs="$(wall refine)" -v rm="$((refine_peak / 1024))" -v es="$(wall eval)" -v em="$(peak_mb eval)" 'BEGIN {
  printf "city bench: %d buildings, %d tile points (%.1f GB PLY), %d refine jobs\n", n, pts, pts * 24 / 1e9, jobs
  printf "%-10s %9s %12s %14s\n", "stage", "wall (s)", "peak (MB)", "throughput"
  printf "%-10s %9.1f %12d %10.1f b/s\n", "generate", gs, gm, n / gs
  printf "%-10s %9.1f %12d %8.1f Mpt/s\n", "crop", cs, cm, pts / cs / 1e6
  printf "%-10s %9.1f %12d %10.1f b/s   (peak: largest single building)\n", "refine", rs, rm, n / rs
  printf "%-10s %9.1f %12d %10.1f b/s\n", "eval", es, em, n / es
  printf "crop + refine: %.1f s, %.2f buildings/s\n", cs + rs, n / (cs + rs)
}'
grep "^outcomes:" "$run/summary.txt"
echo "report: $run/report.html"
