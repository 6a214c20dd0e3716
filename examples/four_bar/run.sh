#!/usr/bin/env bash
# Closed loops end to end: a crank-rocker four-bar with every link rigid (one loop,
# closed by a cut joint with constraint equations), the same with the coupler flexible in 2
# superelements and rigid crank and rocker, and the same with every link a superelement (a
# tree: no cut joint); then the slider-crank of examples/slider_crank_2d with a rigid crank and
# a rigid slider block whose joint to the rod is cut, against slider_crank_2d's tree model.
# Usage: bash examples/four_bar/run.sh [OUTDIR]     (default out/four_bar)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
bin=${FEMB_BIN:-$here/../../build/bin}
out=${1:-out/four_bar}
mkdir -p "$out"
/usr/bin/python3 "$here/make_scenes.py" "$out"
for part in coupler_2 crank rocker; do
  "$bin/femb-reduce" -q "$out/$part.yaml" -o "$out/$part.h5"
done
run() {  # name, scene
  local start=$SECONDS
  "$bin/femb-solve" "$2" -o "$out/$1" > "$out/$1.log"
  grep -E "closes a loop|done in" "$out/$1.log" | sed "s|^femb-solve: |four_bar: $1: |"
}
run rigid "$out/rigid.yaml"
run flexible "$out/flexible.yaml"
run superelements "$out/superelements.yaml"
# The rigid four-bar follows the closed form to the Newton tolerance (1e-9 of its size).
/usr/bin/python3 "$here/kinematics.py" "$out/rigid" 1e-8
# The flexible coupler between rigid links (cut joint) against every link a superelement
# (tree; crank and rocker stiff, E = 2e14 Pa): measured 0.17% RMS of the peak midpoint
# deflection (0.08% with E = 1e15 Pa: the rigid links are their stiff limit).
/usr/bin/python3 "$here/../slider_crank_2d/deflection.py" "$out/superelements" "cut joint, rigid crank and rocker=$out/flexible@0.005" \
  --title "four-bar, flexible coupler in 2 superelements" --png "$out/coupler_deflection.png"
# The slider-crank closed by a cut joint against slider_crank_2d's tree model: measured 0.05%.
mkdir -p "$out/slider_crank"
cp "$here/slider_crank_loop.yaml" "$here"/../slider_crank_2d/{scene.yaml,rod_2.yaml,crank.yaml,slider.yaml} "$out/slider_crank/"
for part in rod_2 crank slider; do
  "$bin/femb-reduce" -q "$out/slider_crank/$part.yaml" -o "$out/slider_crank/$part.h5"
done
run slider_crank/loop "$out/slider_crank/slider_crank_loop.yaml"
run slider_crank/tree "$out/slider_crank/scene.yaml"
/usr/bin/python3 "$here/../slider_crank_2d/deflection.py" "$out/slider_crank/tree" "cut joint, rigid crank and block=$out/slider_crank/loop@0.002"
echo "results: $out/<model>/{results.h5,probes.csv,animation.xdmf}; plot $out/coupler_deflection.png"
