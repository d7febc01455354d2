# Sourced by parallel_batch.sh and slurm_batch.sh (with their arguments): usage from the caller's
# header comment, RUN as an absolute path, the binary (LODREFINE, absolute, exported with ARGS to
# the jobs) and batch.mk as `batch` (its `todo` list and the summary).
if [[ $# -lt 1 ]]; then
  sed -n '2,/^set /p' "$0" | grep '^#' | sed 's/^# \{0,1\}//'
  exit 2
fi
run=$(realpath "$1")
scripts=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
LODREFINE=$(realpath "${LODREFINE:-$scripts/../build/lodrefine}")
ARGS=${ARGS:-}
# Both reach make's command line, where "$" is make syntax: a folder named "r$(shell cmd)" ran cmd.
for path in "$run" "$LODREFINE"; do
  if [[ $path == *'$'* ]]; then
    printf 'lodrefine: error: %s: a path holding "$" is not taken (make would expand it); rename it\n' "$path" >&2
    exit 2
  fi
done
export LODREFINE ARGS
batch=(make -s -f "$scripts/batch.mk" RUN="$run" LODREFINE="$LODREFINE")
