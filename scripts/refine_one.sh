#!/usr/bin/env bash
# Refines one building of a run folder; the single per-building command of every dispatcher
# (scripts/batch.mk, scripts/parallel_batch.sh, scripts/slurm_batch.sh).
#
#   scripts/refine_one.sh RUN ID      (env: LODREFINE = binary, ARGS = extra refine options)
#
# Reads RUN/ID/{coarse.obj,cloud.ply}; writes refined.obj, report.json and log.txt, or, when
# refine exits non-zero, FAILED with its one-line reason (and no refined.obj). Paths inside the
# report are relative to the building folder, so runs in different folders or on different
# hosts give identical files. Safe to kill at any point: FAILED is removed first, every file is
# renamed into place (temp names carry the pid), so an interrupted building is either complete
# or has a missing/older output, which batch.mk redoes. Exits 0 once the outcome is recorded.
set -uo pipefail
if [[ $# -ne 2 ]]; then
  echo "usage: $0 RUN ID" >&2
  exit 2
fi
run=$1 id=$2
bin=${LODREFINE:-}
[[ -z $bin && -x $(dirname "$0")/../build/lodrefine ]] && bin=$(dirname "$0")/../build/lodrefine
bin=${bin:-lodrefine}
[[ $bin == */* ]] && bin=$(realpath "$bin")
cd "$run/$id" || { echo "lodrefine: error: $run/$id: no such building folder" >&2; exit 2; }

# Leftovers of a killed earlier run of this building, then the old outcome.
rm -f ./*.tmp.* FAILED
log=log.txt.tmp.$$
# shellcheck disable=SC2086  # ARGS is a list of options
if "$bin" refine --model coarse.obj --cloud cloud.ply --out refined.obj --report report.json ${ARGS:-} > "$log" 2>&1; then
  mv -f "$log" log.txt
  echo "ok $id: $(tail -n 1 log.txt)"
else
  rc=$?
  reason=$(grep 'lodrefine: error' "$log" | tail -n 1)
  [[ -z $reason ]] && reason=$(tail -n 1 "$log")
  ((rc > 128)) && reason="lodrefine: error: refine killed by signal $((rc - 128))${reason:+ ($reason)}"
  [[ -z $reason ]] && reason="lodrefine: error: refine exited with status $rc"
  rm -f refined.obj
  mv -f "$log" log.txt
  printf '%s\n' "$reason" > "FAILED.tmp.$$" && mv -f "FAILED.tmp.$$" FAILED
  echo "FAILED $id: $reason"
fi
