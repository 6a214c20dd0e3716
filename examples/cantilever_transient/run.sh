#!/usr/bin/env bash
# The seeds' transient cantilever (thesis 5.1): the static case's tube (rho = 2700 kg/m^3),
# clamped, tip force 0 -> 2500 N (vertical) in 0.05 s then constant, 0.25 s simulated. Floating
# frame at the centre of mass vs at the left or right interface node, 1 and 3 bodies, plus 10
# bodies (the recommended model, scene.yaml); reference: 20 bodies at a quarter of the step.
# Checks each against the reference with the tolerance stated below; plots the tip deflection.
# Usage: bash examples/cantilever_transient/run.sh [OUTDIR]   (default out/cantilever_transient)
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
bin=${FEMB_BIN:-$here/../../build/bin}
out=${1:-out/cantilever_transient}
mkdir -p "$out"
variant() {  # name, bodies, frame, [step]
  /usr/bin/python3 "$here/make_variant.py" "$out/$1" "$2" "$3" ${4:-5e-4} || exit 2
  "$bin/femb-reduce" -q "$out/$1/seg.yaml" -o "$out/$1/seg.h5" || exit 2
  local start=$SECONDS
  "$bin/femb-solve" -q "$out/$1/scene.yaml" -o "$out/$1" 2> "$out/$1.err"
  local code=$?
  echo "cantilever_transient: $1 exit $code in $((SECONDS - start)) s $(tail -n 1 "$out/$1.err")"
  echo $code > "$out/$1.code"
}
variant reference_20_bodies 20 center_of_mass 1.25e-4
"$bin/femb-reduce" -q "$here/segment.yaml" -o "$here/segment.h5" || exit 2
start=$SECONDS
"$bin/femb-solve" -q "$here/scene.yaml" -o "$out/10_bodies_com" || exit 3
echo "cantilever_transient: 10_bodies_com (scene.yaml) in $((SECONDS - start)) s"
for n in 1 3; do
  variant ${n}_bodies_com $n center_of_mass
  variant ${n}_bodies_left $n interface:A
  variant ${n}_bodies_right $n interface:B
done
status=0
# RMS over the history of the tip distance from the reference, relative to the reference's
# largest tip displacement (1.29 m); tolerances at or above what was measured (README.md).
/usr/bin/python3 "$here/compare.py" "$out/reference_20_bodies" "10 bodies, CoM frame=$out/10_bodies_com@0.015" \
  "3 bodies, CoM frame=$out/3_bodies_com@0.09" "3 bodies, left-node frame=$out/3_bodies_left@0.30" \
  "3 bodies, right-node frame=$out/3_bodies_right@0.33" --png "$out/tip_deflection.png" || status=1
# One body cannot follow this motion (the whole beam folds past 60 degrees inside one linear
# body): femb-solve must stop with a message and exit 3, keeping the results up to there.
for f in com left right; do
  [ "$(cat "$out/1_bodies_$f.code")" = 3 ] || { echo "1 body ($f): expected exit 3"; status=1; }
done
exit $status
