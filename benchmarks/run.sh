#!/usr/bin/env bash
# Builds femb and runs every benchmark, printing the measured tables.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh >/dev/null
bash scripts/build.sh >/dev/null
build/bin/beam_reduction_benchmark
echo
build/bin/solver_scaling_benchmark
