#!/usr/bin/env bash
# The main job on the default example: set up, build, reduce the example beam parts and inspect
# the superelement files. Outputs land in out/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh
mkdir -p out
for ex in beam_rod tube_cantilever; do
  build/bin/femb-reduce "examples/$ex/part.yaml" -o "out/$ex.h5" --full-modes 10
done
build/bin/femb-inspect out/beam_rod.h5 --check
echo
echo "run_example: superelement files in $(pwd)/out/: beam_rod.h5, tube_cantilever.h5"
echo "run_example: inspect one with: build/bin/femb-inspect out/tube_cantilever.h5 [--json]"
