#!/usr/bin/env bash
# Reduces the stiff rod and swings both pendulums for 3 s. Outputs in out/pendulum/ (or $1).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
bin=${FEMB_BIN:-$here/../../build/bin}
"$bin/femb-reduce" -q "$here/rod.yaml" -o "$here/rod.h5"
"$bin/femb-solve" "$here/scene.yaml" -o "${1:-out/pendulum}" "${@:2}"
