#!/usr/bin/env bash
# The route into Exudyn: reduces the bar (part.yaml), exports its full mesh matrices, and writes
# with to_exudyn.py what Exudyn's ObjectFFRFreducedOrder takes (mesh, mode basis, full K and M,
# reduced matrices) as out/bar_exudyn.npz; checks the arrays against femb's superelement and, when
# Exudyn is installed, builds the body in Exudyn and compares its frequencies and static
# deflection with femb's.
# Usage: bash examples/exudyn_route/run.sh [OUTDIR]     (default out/exudyn_route)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
bin=${FEMB_BIN:-$here/../../build/bin}
run=${1:-out/exudyn_route}
mkdir -p "$run"
"$bin/femb-reduce" -q "$here/part.yaml" -o "$run/bar.h5"
"$bin/femb-reduce" -q "$here/part.yaml" --export-matrices "$run/full" --matrix-format matrix_market
/usr/bin/python3 "$here/to_exudyn.py" "$run/bar.h5" "$run/full" "$run/bar_exudyn.npz"
