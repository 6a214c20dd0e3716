#!/usr/bin/env bash
# Reduces the beam segment and runs the spin-up. Outputs in out/spin_up_beam/ (or $1).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
bin=${FEMB_BIN:-$here/../../build/bin}
"$bin/femb-reduce" -q "$here/segment.yaml" -o "$here/segment.h5"
"$bin/femb-solve" "$here/scene.yaml" -o "${1:-out/spin_up_beam}" "${@:2}"
