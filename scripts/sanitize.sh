#!/usr/bin/env bash
# Builds everything with AddressSanitizer + UndefinedBehaviorSanitizer into build-asan/ and runs
# the unit tests (CTest). Any sanitizer report fails the test that triggered it.
#   scripts/sanitize.sh                 all tests
#   scripts/sanitize.sh -R BadInput     extra arguments go to ctest
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-asan -DLODREFINE_SANITIZE=ON -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build-asan -j "$(nproc)"
# halt_on_error: a UBSan report aborts the process (the build also uses -fno-sanitize-recover).
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$PWD/tests/lsan.supp}
cd build-asan
ctest --output-on-failure -j "$(nproc)" --timeout 1800 "$@"
