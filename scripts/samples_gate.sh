#!/usr/bin/env bash
# The project's own regression gate (.ci/run): refines the sample buildings of data/samples with
# the current build (scripts/batch.mk) and compares the run with the committed baseline
# data/samples/baseline.json and the absolute gates of tests/regression_thresholds.json
# (`lodrefine eval --baseline --gates --junit`). A sample that got worse fails with one line
# naming the building, the figure and its old and new value.
#
#   scripts/samples_gate.sh [check]   compare (exit 1 on a regression or breach)
#   scripts/samples_gate.sh --write   rewrite data/samples/baseline.json from the current build
#                                     (after a change that is meant to move the figures; commit it)
#
# env: LODREFINE (default build/lodrefine), JUNIT (JUnit XML out, default build/samples-gate.xml),
# TOLERANCE (m, default 0.005). The run folder is removed unless the gate fails.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
mode=${1:-check}
case $mode in
  check | --write) ;;
  *) echo "usage: $0 [check | --write]" >&2; exit 2 ;;
esac
bin=$(realpath "${LODREFINE:-$root/build/lodrefine}")
[[ -x $bin ]] || { echo "lodrefine: error: $bin: no lodrefine binary (scripts/build.sh)" >&2; exit 2; }
baseline=$root/data/samples/baseline.json
gates=$root/tests/regression_thresholds.json
junit=${JUNIT:-$root/build/samples-gate.xml}

run=$(mktemp -d "${TMPDIR:-/tmp}/lodrefine-samples-gate.XXXXXX")
for d in "$root"/data/samples/*/; do
  [[ -f $d/coarse.obj ]] && cp -a "$d" "$run/"
done
make -s -f "$root/scripts/batch.mk" RUN="$run" LODREFINE="$bin" refined -j "$(nproc)" > "$run/batch.log" 2>&1 ||
  { cat "$run/batch.log" >&2; echo "lodrefine: error: the batch over the samples failed ($run)" >&2; exit 2; }

if [[ $mode == --write ]]; then
  "$bin" eval --dir "$run" --write-baseline "$baseline"
  echo "samples gate: wrote $baseline"
  rm -rf "$run"
  exit 0
fi
mkdir -p "$(dirname "$junit")"
if "$bin" eval --dir "$run" --baseline "$baseline" --gates "$gates" --tolerance "${TOLERANCE:-0.005}" --junit "$junit"; then
  rm -rf "$run"
  echo "samples gate: passed (JUnit: $junit)"
else
  rc=$?
  echo "samples gate: FAILED with exit $rc (run kept in $run, JUnit: $junit); if the change is meant to" \
       "move the figures, rewrite the baseline: scripts/samples_gate.sh --write" >&2
  exit "$rc"
fi
