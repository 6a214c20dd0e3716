#!/usr/bin/env bash
# The thesis's cantilever plate (8.4): 10 m x 1 m x 0.1 m, E = 12 GPa, nu = 0.3, clamped, in 10
# solid superelements (TET10 from gmsh, 4 corner interfaces each, 24 Craig-Bampton modes), two
# equal tip forces that stay vertical up to P L^2/EI = 10. Compares w/L and -u/L with the
# elastica for the beam (EI) and plate (EI / (1 - nu^2)) bending stiffness; plot.
# Usage: bash examples/cantilever_plate/run.sh [OUTDIR]     (default out/cantilever_plate)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
bin=${FEMB_BIN:-$here/../../build/bin}
out=${1:-out/cantilever_plate}
mkdir -p "$out"
start=$SECONDS
"$bin/femb-reduce" -q "$here/segment.yaml" -o "$here/segment.h5"
echo "cantilever_plate: segment reduced in $((SECONDS - start)) s"
start=$SECONDS
"$bin/femb-solve" -q "$here/scene.yaml" -o "$out/10_bodies"
echo "cantilever_plate: 10 bodies solved in $((SECONDS - start)) s"
# Tolerance: the deflection may leave the band between the beam and the plate elastica by 0.5%
# of the tip displacement (measured: inside, at 0.25-0.29 of the band from the beam side).
/usr/bin/python3 "$here/check.py" "$out/10_bodies" 0.005 --png "$out/tip_displacements.png"
echo "results: $out/10_bodies/{results.h5,probes.csv,animation.xdmf}; plot $out/tip_displacements.png"
