#!/usr/bin/env bash
# Builds with AddressSanitizer + UndefinedBehaviorSanitizer into build-asan/ and runs the tests
# (CTest) under them. Any sanitizer report fails the run: the process that triggered it aborts
# (a test binary: its test fails; a lodrefine a test runs: it dies by a signal). ASan and LSan
# reports also go to build-asan/sanitizer-logs/, printed at the end and turned into exit 1 even if
# the test running that lodrefine only checked for a non-zero exit. UBSan's go to stderr: with
# GCC its runtime is separate and ignores log_path next to ASan.
#   scripts/sanitize.sh                 all tests
#   scripts/sanitize.sh --unit          the unit tests only (labels core, io, eval, synth), building
#                                       only their binaries and the app (the io tests run it)
#   scripts/sanitize.sh -R BadInput     extra arguments go to ctest (after --unit too)
# CI (.ci/run) runs every label but the suites that drive the same refine through make, Slurm or
# GNU Parallel and the sweeps over real data, seeds and types (.ci/run says which and why; they
# run unsanitized in scripts/test.sh).
# Optimisation: -O1 -g1 (LODREFINE_SANITIZE_OPT in CMakeLists.txt, which has the figures).
set -euo pipefail
cd "$(dirname "$0")/.."
targets=()
labels=()
if [ "${1:-}" = --unit ]; then
  shift
  targets=(--target lodrefine_core_tests lodrefine_io_tests lodrefine_eval_tests lodrefine_synth_tests)
  labels=(-L '^(core|io|eval|synth)$')
fi
cmake -S . -B build-asan -DLODREFINE_SANITIZE=ON -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build-asan -j "$(nproc)" "${targets[@]}"

logs=$PWD/build-asan/sanitizer-logs
rm -rf "$logs"
mkdir -p "$logs"
# Defaults first, the caller's options override them; the log path always wins.
# halt_on_error + abort_on_error: the first report aborts the process (SIGABRT, never a plain
# exit 1 that a test of a failing command would take for the expected error; the build also uses
# -fno-sanitize-recover=undefined). Leaks: LSan, minus tests/lsan.supp (libcitygml/xerces).
export ASAN_OPTIONS="detect_leaks=1:halt_on_error=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1:${ASAN_OPTIONS:-}:log_path=$logs/asan"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:abort_on_error=1:${UBSAN_OPTIONS:-}"
export LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp:print_suppressions=0:${LSAN_OPTIONS:-}"
status=0
(cd build-asan && ctest --output-on-failure -j "$(nproc)" --timeout 1800 "${labels[@]}" "$@") || status=$?
if [ -n "$(ls -A "$logs")" ]; then
  for f in "$logs"/*; do
    echo "==== sanitizer report: $f"
    cat "$f"
  done
  echo "sanitize.sh: $(ls "$logs" | wc -l) sanitizer report(s), see above" >&2
  status=1
fi
exit "$status"
