#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, ASan + UBSan) into build-fuzz/ and runs them.
#   scripts/fuzz.sh [TARGET|all] [SECONDS]   fuzz TARGET (fuzz_obj, fuzz_ply, fuzz_las, fuzz_laz, fuzz_citygml,
#                                           fuzz_cityjson, fuzz_refine; default all, one after the
#                                           other) for SECONDS each (default 600), with
#                                           tests/fuzz/TARGET.dict when there is one
#   scripts/fuzz.sh regress                 run every saved input of tests/fuzz/regressions/<target>/
#                                           and the seed corpus once through its target (no fuzzing)
# New corpus entries go to build-fuzz/corpus/<target>/ (the seeds in tests/fuzz/corpus/ are only
# read), crashes/timeouts/leaks to build-fuzz/artifacts/<target>/, logs to build-fuzz/logs/.
# Extra libFuzzer flags: FUZZ_FLAGS="-jobs=2 -workers=2" scripts/fuzz.sh fuzz_ply 3600
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
TARGETS=(fuzz_obj fuzz_ply fuzz_las fuzz_laz fuzz_citygml fuzz_cityjson fuzz_refine)
what=${1:-all}
seconds=${2:-600}

CC=${CC:-clang} CXX=${CXX:-clang++} cmake -S . -B build-fuzz -DLODREFINE_FUZZ=ON -DLODREFINE_TESTS=OFF \
  -DCMAKE_BUILD_TYPE=Release >/dev/null
jobs=$(( $(nproc) > 2 ? $(nproc) - 1 : 1 ))

max_len() { case $1 in fuzz_refine) echo 8192 ;; *) echo 4096 ;; esac; }
dict() { [ -f "tests/fuzz/$1.dict" ] && echo "-dict=tests/fuzz/$1.dict" || true; }
timeout_s() { case $1 in fuzz_refine) echo 60 ;; *) echo 10 ;; esac; }

export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:symbolize=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
# libcitygml leaks its partly built model when a parse fails (tests/lsan.supp): not a finding.
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$ROOT/tests/lsan.supp}

if [ "$what" = regress ]; then
  cmake --build build-fuzz -j "$jobs" --target "${TARGETS[@]}"
  status=0
  for t in "${TARGETS[@]}"; do
    files=()
    for d in "tests/fuzz/regressions/$t" "tests/fuzz/corpus/$t"; do
      [ -d "$d" ] && while IFS= read -r f; do files+=("$f"); done < <(find "$d" -type f | sort)
    done
    [ ${#files[@]} -eq 0 ] && continue
    echo "== $t: ${#files[@]} inputs"
    if ! "build-fuzz/$t" -timeout="$(timeout_s "$t")" -rss_limit_mb=4096 "${files[@]}" >"build-fuzz/$t.regress.log" 2>&1; then
      echo "FAILED: $t (see build-fuzz/$t.regress.log)"; tail -n 40 "build-fuzz/$t.regress.log"; status=1
    fi
  done
  [ $status -eq 0 ] && echo "all regression inputs pass"
  exit $status
fi

if [ "$what" = all ]; then targets=("${TARGETS[@]}"); else targets=("$what"); fi
cmake --build build-fuzz -j "$jobs" --target "${targets[@]}"
mkdir -p build-fuzz/logs
status=0
for t in "${targets[@]}"; do
  mkdir -p "build-fuzz/corpus/$t" "build-fuzz/artifacts/$t"
  log="build-fuzz/logs/$t.log"
  echo "== $t for ${seconds}s (log: $log)"
  set +e
  "build-fuzz/$t" "build-fuzz/corpus/$t" "tests/fuzz/corpus/$t" \
    -max_total_time="$seconds" -max_len="$(max_len "$t")" -timeout="$(timeout_s "$t")" -rss_limit_mb=4096 \
    -artifact_prefix="$ROOT/build-fuzz/artifacts/$t/" -print_final_stats=1 $(dict "$t") ${FUZZ_FLAGS:-} >"$log" 2>&1
  rc=$?
  set -e
  grep -E '^#[0-9]+.*(DONE|pulse|NEW)' "$log" | tail -n 1 || true
  grep -E '^stat::(number_of_executed_units|peak_rss_mb|new_units_added)' "$log" || true
  if [ $rc -ne 0 ]; then
    echo "CRASH in $t (exit $rc):"; grep -E 'ERROR|FUZZ_CHECK|Test unit written|runtime error' "$log" | head -n 5
    status=1
  fi
done
exit $status
