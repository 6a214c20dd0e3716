#!/usr/bin/env bash
# Second CI stage: the unit tests built with AddressSanitizer and UndefinedBehaviorSanitizer and
# run under ctest. One clang tree, build-san/ (-O1 -g1, assertions on: Eigen's index checks
# too), serves this stage and the fuzzing stage (scripts/fuzz.sh): the library is compiled once
# with the fuzzers' coverage instrumentation (-fsanitize=fuzzer-no-link), which the tests carry
# but do not use. Until issue 14's session 12 these were two trees, gcc for the tests and clang
# for the fuzzers: the library was compiled twice, and CI took 44 minutes.
# The command-line and example checks are left to the optimized build (scripts/test.sh), and so
# are the longest runs (a 1e5-step energy history, the rigid four-bar's 1e5 steps, the spin-up
# beam, the full nonlinear leaf, and the midpoint-scheme runs of a loop and of step control):
# the point here is memory and UB errors in the library code, which the other tests exercise
# on the same paths.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/sanitizer_tree.sh
targets=$(grep -o '^femb_add_test([^)]*)' tests/CMakeLists.txt | sed 's|.*/||; s|\.cpp)||')
# shellcheck disable=SC2086
cmake --build build-san -j "$(nproc)" --target $targets -- --no-print-directory -s 2>&1 | grep -v "^\[" || true
for t in $targets; do test -x "build-san/tests/$t" || { echo "sanitize: $t did not build"; exit 1; }; done
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
# Leaks: gmsh and OpenBLAS keep global buffers until exit; only errors are fatal here.
export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
cd build-san && ctest --output-on-failure -j 2 \
  -E '^(cli_|example_)|Over1e5Steps|FollowsItsClosedFormKinematics|SpinUpBeam|OneBodyWithModalDerivativesMatchesTheFullNonlinearModel|RigidFourBarUnderGravityKeepsItsEnergyWithTheMidpointScheme|MidpointErrorFallsWithTheTolerance'
