#!/usr/bin/env bash
# Refines every building of a run folder as a Slurm job array, with the same per-building command
# (scripts/refine_one.sh) and the same outputs as scripts/batch.mk, then a dependent job writes
# batch.mk's summary (RUN/summary.*, RUN/report.html).
#
#   scripts/slurm_batch.sh RUN [--wait] [sbatch options]     (env: LODREFINE, ARGS)
#   e.g.  scripts/slurm_batch.sh /shared/run --partition=city --time=2:00:00
#
# The nodes must see RUN, this repository and the binary at the same absolute paths. Only what is
# missing or out of date is submitted. At most MAX_TASKS (default 1000, Slurm's default
# MaxArraySize is 1001) array tasks: task k refines ids k, k+tasks, ... of the list. Logs go to
# RUN/.slurm/. --wait returns when the summary is written (exit non-zero if a job failed). Do not
# start batch.mk on the same folder while the jobs run.
set -euo pipefail
source "$(dirname "$0")/dispatch_common.sh"
shift
wait=()
if [[ ${1:-} == --wait ]]; then
  wait=(--wait)
  shift
fi
command -v sbatch > /dev/null || { echo "lodrefine: error: sbatch not found (Debian: slurm-client)" >&2; exit 2; }

mkdir -p "$run/.slurm"
list=$(mktemp "$run/.slurm/todo.XXXXXXXXXX")
"${batch[@]}" todo > "$list"
n=$(wc -l < "$list")
if ((n == 0)); then
  echo "nothing to refine"
  exec "${batch[@]}"
fi
tasks=$((n < ${MAX_TASKS:-1000} ? n : ${MAX_TASKS:-1000}))
# Each task: every tasks-th id of the list (checked safe names), starting at its own index. Paths
# go into the job script %q-quoted.
task="for id in \$(awk -v k=\$SLURM_ARRAY_TASK_ID -v t=$tasks '(NR - 1) % t == k' $(printf %q "$list")); do
        $(printf %q "$scripts/refine_one.sh") $(printf %q "$run") \"\$id\"; done"
array=$(sbatch --parsable --export=ALL --array=0-$((tasks - 1)) --job-name=lodrefine \
        --output="$run/.slurm/%A_%a.out" "$@" --wrap "$task")
echo "submitted job array $array: $n buildings in $tasks tasks"
last=$(sbatch --parsable --export=ALL --dependency=afterany:"$array" --job-name=lodrefine-summary \
       --output="$run/.slurm/summary_%j.out" "${wait[@]}" "$@" \
       --wrap "$(printf '%q ' "${batch[@]}"); rm -f $(printf %q "$list")")
echo "summary job $last (after $array): $run/summary.txt"
