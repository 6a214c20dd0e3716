#!/usr/bin/env bash
# Second CI stage: the unit tests built with AddressSanitizer and UndefinedBehaviorSanitizer
# (build-asan/, clang -O1: scripts/sanitizer_tree.sh), run under ctest. The command-line and example checks
# are left to the optimized build (scripts/test.sh), and so are the longest runs (a 1e5-step energy
# history, the rigid four-bar's 1e5 steps, 200 s under the sanitizers, the spin-up beam, the full
# nonlinear leaf; the midpoint scheme's rigid four-bar under gravity and its step-control
# convergence, 40 s each, whose paths the triple pendulum and the generalized-alpha step control
# take too): the point here is memory and UB errors in the library code, which the other tests
# exercise on the same paths. Also left out: the tilted four-bar's error-controlled runs against a
# fixed 5 us run (both integrators, 1e-3 of the reactions' peak): 20-60 s each here for paths
# that the resumed-run tests take too, and a step sequence that follows the round-off (clang -O1
# without -march=native takes another one than the release build), so that the bound would test
# the compiler's rounding, not memory.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/sanitizer_tree.sh
targets=$(grep -o '^femb_add_test([^)]*)' tests/CMakeLists.txt | sed 's|.*/||; s|\.cpp)||')
# One goal (femb_unit_tests: every test executable), so that make compiles nproc sources at once.
cmake --build build-asan -j "$(nproc)" --target femb_unit_tests -- --no-print-directory -s 2>&1 | grep -v "^\[" || true
for t in $targets; do test -x "build-asan/tests/$t" || { echo "sanitize: $t did not build"; exit 1; }; done
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
# Leaks: gmsh and OpenBLAS keep global buffers until exit; only errors are fatal here.
export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
cd build-asan && ctest --output-on-failure -j 2 \
  -E '^(cli_|example_)|Over1e5Steps|FollowsItsClosedFormKinematics|SpinUpBeam|OneBodyWithModalDerivativesMatchesTheFullNonlinearModel|RigidFourBarUnderGravityKeepsItsEnergyWithTheMidpointScheme|MidpointErrorFallsWithTheTolerance|RestartAtTheBreakpointLeavesASmoothRun'
