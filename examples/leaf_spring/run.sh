#!/usr/bin/env bash
# Clamped-guided leaf spring: one solid superelement with modal derivatives (the
# Green-Lagrange polynomial internal force) vs the same body linear inside, against CalculiX
# NLGEOM on the same mesh (ccx_reference.py; femb's own full Newton agrees with it, see
# tests/solver/analysis/leaf_spring_test.cpp). Prints the errors over the stroke, plots them.
# Usage: bash examples/leaf_spring/run.sh [OUTDIR]     (default out/leaf_spring)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
bin=${FEMB_BIN:-$here/../../build/bin}
out=${1:-out/leaf_spring}
mkdir -p "$out"
start=$SECONDS
"$bin/femb-reduce" -q "$here/part.yaml" -o "$here/leaf.h5"
echo "leaf_spring: reduced in $((SECONDS - start)) s"
start=$SECONDS
"$bin/femb-solve" -q "$here/scene.yaml" -o "$out/modal_derivatives"
echo "leaf_spring: one body with modal derivatives solved in $((SECONDS - start)) s"
sed 's|nodes: {A: a, B: b}}|nodes: {A: a, B: b}, options: {internal_force: linear}}|; s|superelement: leaf.h5|superelement: '"$here"'/leaf.h5|' \
  "$here/scene.yaml" > "$out/scene_linear.yaml"
"$bin/femb-solve" -q "$out/scene_linear.yaml" -o "$out/linear"
if ! command -v ccx > /dev/null; then
  echo "leaf_spring: CalculiX (ccx) not found: apt-get install calculix-ccx, or bash scripts/setup.sh" >&2
  exit 2
fi
start=$SECONDS
/usr/bin/python3 "$here/ccx_reference.py" "$here/leaf.h5" "$out/ccx"
echo "leaf_spring: CalculiX reference in $((SECONDS - start)) s"
# Tolerance: 2% over the stroke for the body with modal derivatives (measured 0.06%);
# the linear body is shown, with no tolerance: it has no shortening at all.
/usr/bin/python3 "$here/compare.py" "$out/ccx/ccx.csv" "1 body, modal derivatives=$out/modal_derivatives@0.02" \
  "1 body, linear inside=$out/linear" --png "$out/leaf_spring.png"
