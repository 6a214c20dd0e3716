#!/usr/bin/env bash
# Second CI stage: the unit tests built with AddressSanitizer and UndefinedBehaviorSanitizer
# (build-asan/, gcc), run under ctest. The command-line and example checks are left to the
# optimized build (scripts/test.sh): here the point is memory and UB errors in the library code.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DFEMB_SANITIZE=ON >/dev/null
cmake --build build-asan -j "$(nproc)" -- --no-print-directory -s 2>&1 | grep -v "^\[" || true
test -x build-asan/tests/superelement_checks_test || { echo "sanitize: build failed"; exit 1; }
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
# Leaks: gmsh and OpenBLAS keep global buffers until exit; only errors are fatal here.
export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
cd build-asan && ctest --output-on-failure -j 2 -E '^(cli_|example_)'
