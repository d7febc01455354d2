#!/usr/bin/env bash
# Refines every building of a run folder with GNU Parallel, on this machine or over ssh, with the
# same per-building command (scripts/refine_one.sh) and the same outputs as scripts/batch.mk.
#
#   scripts/parallel_batch.sh RUN [parallel options]        (env: LODREFINE, ARGS)
#   e.g.  --sshloginfile hosts.txt        hosts as `8/user@node1` lines (`:` is this machine)
#         --sshlogin : -j2                this machine only
#
# Remote hosts must see RUN, this repository and the binary at the same absolute paths (a shared
# file system). Like batch.mk it does only what is missing or out of date, holds RUN's lock while
# it runs, and ends with batch.mk's summary (RUN/summary.*, RUN/report.html).
set -euo pipefail
source "$(dirname "$0")/dispatch_common.sh"
shift
command -v parallel > /dev/null || { echo "lodrefine: error: GNU Parallel not found (Debian: parallel)" >&2; exit 2; }

exec 9>> "$run/.batch.lock"
# A short wait, as batch_lock.sh's: the holder of a make run that just ended (`make clean-results`
# too) needs up to 0.05 s, more on a loaded machine, to let go.
flock -w 1 9 || { echo "lodrefine: error: $run is in use by another batch run; wait for it to end" >&2; exit 1; }
export LODREFINE_BATCH_LOCKED=1
todo=$(mktemp)
trap 'rm -f "$todo"' EXIT
"${batch[@]}" todo > "$todo"
echo "$(wc -l < "$todo") buildings to refine"
# --env: remote hosts get the binary and options; the ids (checked safe names) come one a line
# from the list; -q: the command's words reach the (remote) shell quoted, RUN with spaces too.
parallel --will-cite -q --env LODREFINE --env ARGS "$@" "$scripts/refine_one.sh" "$run" {} :::: "$todo"
"${batch[@]}"
