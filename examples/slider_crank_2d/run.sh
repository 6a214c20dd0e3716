#!/usr/bin/env bash
# Reduces crank, rod and slider and runs three crank revolutions. Outputs in out/slider_crank_2d/.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
bin=${FEMB_BIN:-$here/../../build/bin}
for part in crank rod slider; do
  "$bin/femb-reduce" -q "$here/$part.yaml" -o "$here/$part.h5"
done
"$bin/femb-solve" "$here/scene.yaml" -o "${1:-out/slider_crank_2d}" "${@:2}"
