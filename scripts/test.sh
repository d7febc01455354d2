#!/usr/bin/env bash
# Builds lodrefine and runs the whole test suite (GoogleTest through CTest).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh
cd build
rm -rf test-tmp && mkdir test-tmp  # the tests' files (TEST_TMPDIR): one run's at a time
ctest --output-on-failure -j "$(nproc)" --timeout 900
