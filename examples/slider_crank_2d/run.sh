#!/usr/bin/env bash
# The seeds' 2D slider-crank (thesis 5.2) end to end: reduce the crank, the slider and the rod
# segments, simulate three crank revolutions with the rod in 2 superelements (scene.yaml) and,
# as the reference, in 10 superelements at half the step, then print the rod midpoint
# deflection extremes and the error, and plot the deflection against the crank angle.
# Usage: bash examples/slider_crank_2d/run.sh [OUTDIR]     (default out/slider_crank_2d)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
bin=${FEMB_BIN:-$here/../../build/bin}
out=${1:-out/slider_crank_2d}
mkdir -p "$out"
for part in crank slider rod_2; do
  "$bin/femb-reduce" -q "$here/$part.yaml" -o "$here/$part.h5"
done
echo "slider_crank_2d: rod in 2 superelements (scene.yaml), h = 10 us"
"$bin/femb-solve" "$here/scene.yaml" -o "$out/2_bodies"
echo "slider_crank_2d: reference, rod in 10 superelements, h = 5 us"
/usr/bin/python3 "$here/make_variant.py" 10 "$out/ref_10_bodies" 5e-6 > /dev/null
"$bin/femb-reduce" -q "$out/ref_10_bodies/rod_10.yaml" -o "$out/ref_10_bodies/rod_10.h5"
"$bin/femb-solve" "$out/ref_10_bodies/scene.yaml" -o "$out/ref_10_bodies"
# The 2-body model against the 10-body reference: RMS error over the whole history within 5%
# of the peak deflection (measured: see README.md).
/usr/bin/python3 "$here/deflection.py" "$out/ref_10_bodies" "2 bodies=$out/2_bodies" \
  --png "$out/midpoint_deflection.png" --tol 0.05
echo "results: $out/2_bodies/{results.h5,probes.csv}, $out/ref_10_bodies/, plot $out/midpoint_deflection.png"
