#!/usr/bin/env bash
# Called by batch.mk through $(shell): checks RUN's building folder names, then takes
# RUN/.batch.lock (flock) for as long as the calling make lives, so two batch runs on one folder
# cannot interleave. Prints "ok", or the one-line reason the run must not start (batch.mk stops
# with it, exit 2).
set -u
export LC_ALL=C
run=$1
if [[ ! -d $run ]]; then
  printf 'lodrefine: error: %s: no such run folder\n' "$run"
  exit 0
fi
# Folder names become make targets and shell words: only safe names (what crop and convert
# make) are run; anything else is refused before any building runs, not quoted and hoped for.
for model in "$run"/*/coarse.obj; do
  [[ -e $model ]] || continue
  name=${model%/coarse.obj}
  name=${name##*/}
  if [[ ! $name =~ ^[A-Za-z0-9_][A-Za-z0-9._-]*$ ]]; then
    printf 'lodrefine: error: %s: building folder %q is not a safe name ([A-Za-z0-9._-], not starting with - or .); rename it\n' "$run" "$name"
    exit 0
  fi
  # A planted link (Y -> /elsewhere) would take the building's outputs, and the cleaning of
  # temporaries, outside the run folder.
  if [[ -L $run/$name ]]; then
    printf 'lodrefine: error: %s: building folder %q is a symbolic link; the batch writes only inside the run folder\n' "$run" "$name"
    exit 0
  fi
done
# A dispatcher (parallel_batch.sh) that holds the lock itself runs make for the summary.
if [[ -n ${LODREFINE_BATCH_LOCKED:-} ]]; then
  echo ok
  exit 0
fi
# make may start us through sh: the lock belongs to make itself.
owner=$PPID
[[ $(cat "/proc/$owner/comm" 2>/dev/null) == sh ]] && owner=$(awk '{print $4}' "/proc/$owner/stat")
exec 9>> "$run/.batch.lock"
# A short wait: the holder of a run that just ended needs up to 0.05 s to notice.
if ! flock -w 1 9; then
  echo "lodrefine: error: $run is in use by another batch run (make pid $(cat "$run/.batch.pid" 2>/dev/null)); wait for it to end"
  exit 0
fi
echo "$owner" > "$run/.batch.pid"
# Temporaries of writers killed in an earlier run: only lodrefine's own (.lodrefine-tmp-*), in
# RUN, its building folders and plots/ (nobody else writes here while we hold the lock).
find "$run" -maxdepth 2 -name '.lodrefine-tmp-*' -type f -delete 2> /dev/null
# The holder keeps fd 9 (the lock) open until make exits, however it exits (SIGKILL included).
tail --pid="$owner" -s 0.05 -f /dev/null < /dev/null > /dev/null 2>&1 &
echo ok
