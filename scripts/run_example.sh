#!/usr/bin/env bash
# The main job: set up, build, then the seeds' 2D slider-crank end to end (reduce the crank,
# slider and rod parts, simulate three crank revolutions with the rod in 2 superelements and a
# 10-superelement reference, print the rod midpoint deflection extremes and error, and plot the
# deflection against the crank angle), plus a solid part reduced and inspected.
# Outputs land in out/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh
mkdir -p out
bash examples/slider_crank_2d/run.sh out/slider_crank_2d
echo
build/bin/femb-reduce examples/solid_crank/part.yaml -o out/solid_crank.h5 -q
build/bin/femb-inspect out/solid_crank.h5 --check | sed -n '1,4p;/Checks:/,$p'
echo
echo "run_example: slider-crank results in $(pwd)/out/slider_crank_2d/ (plot: midpoint_deflection.png);"
echo "run_example: solid crank superelement out/solid_crank.h5"
