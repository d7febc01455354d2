#!/usr/bin/env bash
# Peak memory of `lodrefine eval --dir` as a run grows: one run of synthetic buildings
# (`synth --type all`, every type, refined by scripts/batch.mk), evaluated whole and in its
# first 100 and 200 buildings. The peak must stay flat (the pooled figures are bins, and only
# the buildings in flight hold their distances); it printed 80 MB for 200 buildings after issue
# 18 and 1,235 MB for 275 before issue 47's fix.
#
#   scripts/eval_memory_bench.sh DIR [JOBS=2] [SIZES="100 200 400"]   (env: LODREFINE)
#
# DIR/all is generated and refined once (resumable: rerunning reuses it, and only adds
# buildings); each size is DIR/run_<n>, hard links to the first n building folders of DIR/all.
# Prints one line per size: buildings, wall seconds, peak resident memory (MB).
set -euo pipefail
usage() {
  sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//'
  exit 2
}
(($# >= 1)) || usage
jobs=${2:-2} sizes=${3:-100 200 400}
root=$(cd "$(dirname "$0")/.." && pwd)
bin=$(realpath "${LODREFINE:-$root/build/lodrefine}")
dir=$(mkdir -p "$1" && realpath "$1")
largest=0
for n in $sizes; do ((n > largest)) && largest=$n; done
# synth --type all makes 11 types x count buildings.
count=$(((largest + 10) / 11))
if (($(find "$dir/all" -mindepth 2 -maxdepth 2 -name coarse.obj 2> /dev/null | wc -l) < largest)); then
  echo "generating $((count * 11)) buildings into $dir/all ..."
  rm -rf "$dir/all"
  "$bin" synth --type all --count "$count" --out "$dir/all" > "$dir/synth.log"
fi
echo "refining $dir/all with $jobs jobs (only what is missing) ..."
nice make -s -f "$root/scripts/batch.mk" RUN="$dir/all" LODREFINE="$bin" -j"$jobs" refined > "$dir/refine.log"

printf "%-10s %9s %10s\n" "buildings" "wall (s)" "peak (MB)"
mapfile -t ids < <(find "$dir/all" -mindepth 2 -maxdepth 2 -name coarse.obj -printf '%h\n' | xargs -n1 basename | sort)
for n in $sizes; do
  run=$dir/run_$n
  rm -rf "$run"
  mkdir -p "$run"
  for id in "${ids[@]:0:n}"; do cp -al "$dir/all/$id" "$run/$id"; done
  /usr/bin/time -f "%e %M" -o "$dir/time.$n" "$bin" eval --quiet --dir "$run" --jobs "$jobs" \
    --json "$dir/eval_$n.json" > "$dir/eval_$n.txt"
  read -r wall kb < "$dir/time.$n"
  printf "%-10d %9.1f %10d\n" "$n" "$wall" $((kb / 1024))
done
