#!/usr/bin/env bash
# The main job on the default example: set up, build, reduce the example parts, inspect one,
# and simulate the static cantilever of the seeds (10 superelements, tip force up to 10 kN).
# Outputs land in out/.
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
bash examples/cantilever_static/run.sh out/cantilever_static
tip=$(tail -1 out/cantilever_static/probes.csv | cut -d, -f2,3)
echo
echo "run_example: superelement files in $(pwd)/out/: beam_rod.h5, tube_cantilever.h5"
echo "run_example: cantilever at 10 kN: tip position (x, y) = ($tip) m;"
echo "run_example:   time history in out/cantilever_static/probes.csv, all nodes in out/cantilever_static/results.h5"
