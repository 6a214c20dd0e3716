#!/usr/bin/env bash
# Cardona's beam on a spherical joint (Cardona 2000 sec. 8.2, thesis 5.1), in SI with the thesis's
# times read in milliseconds (make_variant.py states the unit system): torque about the vertical
# during the first 10.2 ms, vertical tip kick at 25.2 ms, 50 ms. The beam in 2 superelements
# (scene.yaml), in 10 at h = 10 us, against a reference of 10
# superelements at h = 2.5 us. Compares the base angular velocity about z (raw up to the kick,
# 2 ms moving average over the whole run) and the tip positions; plot. The 2-body model also with
# the corotational inertia, in Cardona's options B and A.
# Usage: bash examples/spinning_beam/run.sh [OUTDIR]     (default out/spinning_beam)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
bin=${FEMB_BIN:-$here/../../build/bin}
out=${1:-out/spinning_beam}
mkdir -p "$out"
"$bin/femb-reduce" -q "$here/seg_2.yaml" -o "$here/seg_2.h5"
run() {  # name, scene
  local start=$SECONDS
  "$bin/femb-solve" -q "$2" -o "$out/$1"
  echo "spinning_beam: $1 done in $((SECONDS - start)) s"
}
variant() {  # name, bodies, step, modes, options
  /usr/bin/python3 "$here/make_variant.py" "$out/$1" "$2" "$3" "$4" "$5" > /dev/null
  "$bin/femb-reduce" -q "$out/$1/seg_$2.yaml" -o "$out/$1/seg_$2.h5"
  run "$1" "$out/$1/scene.yaml"
}
run 2_bodies "$here/scene.yaml"
variant 2_bodies_corotational_B 2 2e-5 4 "{inertia: corotational, inertia_option: B}"
variant 2_bodies_corotational_A 2 2e-5 4 "{inertia: corotational, inertia_option: A}"
variant 10_bodies 10 1e-5 2 ""
variant reference_10_bodies 10 2.5e-6 2 ""
# Tolerances: about 1.5 times what was measured (README.md). The exact inertia (scene.yaml,
# femb-solve's default) has no option; Cardona's options A and B are variants of the corotational
# inertia. Before the kick the motion is planar and they coincide; after it, option A's base
# rotation oscillates with a large spurious amplitude (as Cardona 2000 reports for this very
# case), while the tip follows the reference: its bound only catches regressions.
ref="$out/reference_10_bodies"
/usr/bin/python3 "$here/compare.py" "$ref" "2 bodies=$out/2_bodies@0.04" \
  "2 bodies, corotational B=$out/2_bodies_corotational_B@0.04" \
  "2 bodies, corotational A=$out/2_bodies_corotational_A@0.04" "10 bodies, h 10 us=$out/10_bodies@0.03" --until 0.0252
/usr/bin/python3 "$here/compare.py" "$ref" "2 bodies=$out/2_bodies@0.025" \
  "2 bodies, corotational B=$out/2_bodies_corotational_B@0.04" \
  "2 bodies, corotational A=$out/2_bodies_corotational_A@0.80" "10 bodies, h 10 us=$out/10_bodies@0.025" --smooth 0.002 --png "$out/base_angular_velocity.png"
echo "results: $out/<model>/{results.h5,probes.csv,animation.xdmf}; plot $out/base_angular_velocity.png"
