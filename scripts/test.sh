#!/usr/bin/env bash
# Sets up, builds and runs every test (unit, integration, command-line).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
cd build && ctest --output-on-failure -j 2
