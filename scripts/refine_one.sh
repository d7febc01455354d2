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
# renamed into place (temporaries are .lodrefine-tmp-*, created exclusively, and removed by the
# next run), so an interrupted building is either complete or has a missing/older output, which
# batch.mk redoes. Exits 0 once the outcome is recorded.
set -uo pipefail
if [[ $# -ne 2 ]]; then
  echo "usage: $0 RUN ID" >&2
  exit 2
fi
run=$1 id=$2
# The id is a folder name the dispatchers checked; refuse anything else here too.
safe_name() { local LC_ALL=C; [[ $1 =~ ^[A-Za-z0-9_][A-Za-z0-9._-]*$ ]]; }
if ! safe_name "$id"; then
  printf 'lodrefine: error: %s: building folder %q is not a safe name ([A-Za-z0-9._-], not starting with - or .)\n' "$run" "$id" >&2
  exit 2
fi
if [[ -L $run/$id ]]; then
  printf 'lodrefine: error: %s: building folder %q is a symbolic link; refine writes only inside the run folder\n' "$run" "$id" >&2
  exit 2
fi
bin=${LODREFINE:-}
[[ -z $bin && -x $(dirname "$0")/../build/lodrefine ]] && bin=$(dirname "$0")/../build/lodrefine
bin=${bin:-lodrefine}
[[ $bin == */* ]] && bin=$(realpath "$bin")
cd "$run/$id" || { echo "lodrefine: error: $run/$id: no such building folder" >&2; exit 2; }

# Leftovers of a killed earlier run of this building (lodrefine's own temporaries only), then
# the old outcome.
rm -f ./.lodrefine-tmp-* FAILED
log=$(mktemp .lodrefine-tmp-XXXXXXXXXX) && chmod 644 "$log" || exit 2
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
  failed=$(mktemp .lodrefine-tmp-XXXXXXXXXX) && chmod 644 "$failed" && printf '%s\n' "$reason" > "$failed" && mv -f "$failed" FAILED
  echo "FAILED $id: $reason"
fi
