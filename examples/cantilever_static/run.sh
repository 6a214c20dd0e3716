#!/usr/bin/env bash
# Reduces the tube segment and runs the static cantilever. Outputs in out/cantilever_static/.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
bin=${FEMB_BIN:-$here/../../build/bin}
"$bin/femb-reduce" "$here/segment.yaml" -o "$here/segment.h5"
"$bin/femb-solve" "$here/scene.yaml" -o "${1:-out/cantilever_static}"
