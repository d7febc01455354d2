#!/usr/bin/env bash
# Behaviour snapshot for refactors: refines every building of data/samples and of the dev tiles
# (../shared/devtiles, when present) into OUT, one OBJ and one report each, generates one
# building of each synth type and evaluates the refined samples; then
#   scripts/snapshot.sh --compare BEFORE AFTER
# says whether two snapshots agree: OBJ files byte for byte, reports as JSON without timings.
#   scripts/snapshot.sh OUT        (LODREFINE=path/to/lodrefine to use another binary)
set -uo pipefail
cd "$(dirname "$0")/.."
if [ "${1:-}" = "--compare" ]; then
  exec /usr/bin/python3 - "$2" "$3" <<'PY'
import json, os, sys
a, b = sys.argv[1], sys.argv[2]
def strip(x):
    if isinstance(x, dict):
        return {k: strip(v) for k, v in x.items() if k not in ("seconds", "written") and not k.endswith("_seconds")}
    if isinstance(x, list):
        return [strip(v) for v in x]
    return x
def files(root):
    return {os.path.relpath(os.path.join(d, f), root) for d, _, fs in os.walk(root) for f in fs}
def timed_out(report_path):
    # GLPK stopped by --mip-time-limit: its selection depends on the machine's speed and load.
    try:
        r = json.load(open(report_path))
    except (OSError, ValueError):
        return False
    if "time limit" in (r.get("selection") or {}).get("status", ""):
        return True  # the whole building's selection (select_shell)
    return any("time limit" in s.get("mip", {}).get("status", "") for s in r.get("replacements") or [])
names = sorted(files(a) | files(b))
bad = timing = 0
for n in names:
    pa, pb = os.path.join(a, n), os.path.join(b, n)
    if not (os.path.exists(pa) and os.path.exists(pb)):
        print("only in one snapshot:", n); bad += 1; continue
    if n.endswith(".json"):
        same = strip(json.load(open(pa))) == strip(json.load(open(pb)))
    else:
        same = open(pa, "rb").read() == open(pb, "rb").read()
    if same:
        continue
    stem = os.path.splitext(n)[0] + ".json"
    if stem.startswith("eval_"):
        stem = "sample_" + stem[len("eval_"):]  # the evaluation of that refined sample
    if timed_out(os.path.join(a, stem)) or timed_out(os.path.join(b, stem)):
        print("differs, GLPK time limit reached (load-dependent; rerun unloaded):", n); timing += 1
    else:
        print("differs:", n); bad += 1
print(f"{len(names)} files compared, {bad} differ" + (f", {timing} at the GLPK time limit" if timing else ""))
sys.exit(1 if bad or timing else 0)
PY
fi
OUT=${1:?usage: scripts/snapshot.sh OUT | --compare A B}
BIN=${LODREFINE:-build/lodrefine}
mkdir -p "$OUT"
jobs=()
for d in data/samples/*/; do
  jobs+=("$d/coarse.obj $d/cloud.ply sample_$(basename "$d")")
done
for tile in synth real; do
  T=../shared/devtiles/$tile
  [ -d "$T" ] || continue
  for m in "$T"/models/*.obj; do
    id=$(basename "$m" .obj)
    jobs+=("$m $T/clouds/$id.ply ${tile}_$id")
  done
done
# Each building with the defaults (the selection decides every refined building).
printf '%s\n' "${jobs[@]}" | xargs -P "$(nproc)" -L1 sh -c \
  '"$0" refine --model "$1" --cloud "$2" --out "'"$OUT"'/$3.obj" --report "'"$OUT"'/$3.json" > /dev/null 2>&1 || echo "refine failed: $3"' "$BIN"
# The generator and the evaluation, on the samples just refined.
"$BIN" synth --type all --seed 1 --count 1 --out "$OUT/synth" > /dev/null
for d in data/samples/*/; do
  id=$(basename "$d")
  "$BIN" eval --original "$d/coarse.obj" --refined "$OUT/sample_$id.obj" --cloud "$d/cloud.ply" \
    --truth "$d/truth.obj" --meta "$d/meta.json" --json "$OUT/eval_$id.json" > /dev/null
done
echo "$(find "$OUT" -type f | wc -l) files in $OUT"
