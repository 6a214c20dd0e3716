#!/usr/bin/env bash
# A rod on bending modes alone (thesis 8.2, case 4): exports the rod's matrices,
# computes its four lowest free-free bending modes (make_shapes.py), reduces the rod on them
# (bending.yaml: its stretch and twist become the superelement's interface constraint) and with
# Craig-Bampton modes (rod.yaml), spins both up in one scene and compares (compare.py).
# Usage: bash examples/bending_rod/run.sh [OUTDIR]     (default out/bending_rod)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
bin=${FEMB_BIN:-$here/../../build/bin}
run=${1:-out/bending_rod}
mkdir -p "$here/out" "$run"
"$bin/femb-reduce" -q "$here/rod.yaml" --export-matrices "$here/out/mesh" --matrix-format matrix_market
/usr/bin/python3 "$here/make_shapes.py" "$here/out/mesh" "$here/out/bending.h5"
# Linear like the bending-only rod (a general basis has no geometric stiffening): like with like.
"$bin/femb-reduce" -q "$here/rod.yaml" -o "$here/out/rod.h5" --set reduction.internal_modes=4
"$bin/femb-reduce" "$here/bending.yaml" -o "$here/out/rod_bending.h5" | grep "general basis"
"$bin/femb-solve" -q "$here/scene.yaml" -o "$run"
/usr/bin/python3 "$here/compare.py" "$run"
