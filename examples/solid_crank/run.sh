#!/usr/bin/env bash
# solid_crank: mesh meshes/crank.geo with gmsh (TET10), reduce it to a superelement with two
# interfaces, check it, and write its mode shapes as VTU files for ParaView.
# Usage: bash examples/solid_crank/run.sh [BUILD_BIN_DIR]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
bin=${1:-$here/../../build/bin}
out=$here/out
mkdir -p "$out"
"$bin/femb-reduce" "$here/part.yaml" -o "$out/solid_crank.h5"
"$bin/femb-inspect" "$out/solid_crank.h5" --check
"$bin/femb-inspect" "$out/solid_crank.h5" --vtu "$out/modes" > /dev/null
echo "solid_crank: mode shapes in $out/modes/*.vtu (open in ParaView, warp by 'displacement')"
