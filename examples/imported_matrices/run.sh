#!/usr/bin/env bash
# Imported matrices: exports the crank's TET10 mesh with femb-reduce --export-matrices,
# has CalculiX 2.20 assemble it (job.inp: *FREQUENCY, SOLVER=MATRIXSTORAGE), reduces CalculiX's
# matrices with the bores picked by geometry (part.yaml) and femb's own assembly of the same mesh
# (native.yaml), spins both up in one scene and compares (compare.py).
# Usage: bash examples/imported_matrices/run.sh [OUTDIR]     (default out/imported_matrices)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
bin=${FEMB_BIN:-$here/../../build/bin}
run=${1:-out/imported_matrices}
command -v ccx > /dev/null || { echo "imported_matrices: needs CalculiX: apt-get install calculix-ccx" >&2; exit 2; }
mkdir -p "$here/out/ccx" "$run"
"$bin/femb-reduce" -q "$here/native.yaml" --export-matrices "$here/out/mesh"
cp "$here/job.inp" "$here/out/ccx/job.inp"
(cd "$here/out/ccx" && ccx job > ccx.log 2>&1) || { echo "imported_matrices: ccx failed: see $here/out/ccx/ccx.log" >&2; exit 3; }
"$bin/femb-reduce" "$here/part.yaml" -o "$here/out/crank_imported.h5"
"$bin/femb-reduce" -q "$here/native.yaml" -o "$here/out/crank_native.h5"
"$bin/femb-solve" -q "$here/scene.yaml" -o "$run"
/usr/bin/python3 "$here/compare.py" "$here/out" "$run"
