#!/usr/bin/env bash
# The momentum-conserving midpoint scheme against an earlier commit of femb, same machine, same
# run: builds BASE in a git worktree (kept in $BASE_DIR for the next run), then runs
# seven scenes with `analysis.integrator: midpoint` on one thread, interleaved, three times each
# (the lowest solving time counts, femb-solve's own split of its time): the tumbling tee
# (free flexible body), the planar and the spatial slider-crank (chains of joints, stiffened rod
# bodies), the spinning beam, the flexible pendulum (gravity), and the four-bar with rigid links
# and with a flexible coupler (closed loops, cut joints). Prints the times, their ratio and the
# largest difference between the two commits' probes, relative to the largest value of its
# column (columns whose values are all below 1e-12 are round-off and skipped).
# Usage: bash benchmarks/midpoint_vs_base.sh [BASE]    (default ab9796a, before the midpoint
# scheme's allocation-free rewrite)
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
base=${1:-ab9796a}
base_dir=${BASE_DIR:-/tmp/femb_base_$base}
out=${OUT:-/tmp/femb_midpoint}
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
# shellcheck source=benchmarks/base_tree.sh
source "$here/benchmarks/base_tree.sh"
build_trees femb-reduce femb-solve
# Each tree's scenes with its own reducer (file formats may differ between commits).
prepare() {  # tree, dir
  local tree=$1 dir=$2 ex=$1/examples reduce=$1/build/bin/femb-reduce
  mkdir -p "$dir/four_bar"
  "$reduce" -q "$ex/tumbling_body/tee.yaml" -o "$ex/tumbling_body/tee.h5"
  for part in crank slider rod_2; do "$reduce" -q "$ex/slider_crank_2d/$part.yaml" -o "$ex/slider_crank_2d/$part.h5"; done
  for part in crank slider; do "$reduce" -q "$ex/slider_crank_2d/$part.yaml" -o "$ex/slider_crank_3d/$part.h5"; done
  "$reduce" -q "$ex/slider_crank_3d/rod_2.yaml" -o "$ex/slider_crank_3d/rod_2.h5"
  "$reduce" -q "$ex/spinning_beam/seg_2.yaml" -o "$ex/spinning_beam/seg_2.h5"
  "$reduce" -q "$ex/pendulum/rod.yaml" -o "$ex/pendulum/rod.h5"
  /usr/bin/python3 "$tree/examples/four_bar/make_scenes.py" "$dir/four_bar" > /dev/null
  for part in coupler_2 crank rocker; do
    "$tree/build/bin/femb-reduce" -q "$dir/four_bar/$part.yaml" -o "$dir/four_bar/$part.h5"
  done
}
prepare "$base_dir" "$out/base"
prepare "$here" "$out/new"
scene() {  # tree, dir, name -> the scene file and its settings
  local ex=$1/examples
  case $3 in
    tumbling) echo "$ex/tumbling_body/scene.yaml --set analysis.end_time=2" ;;
    slider_crank_2d) echo "$ex/slider_crank_2d/scene.yaml --set analysis.end_time=0.02 --set analysis.step=2e-5" ;;
    slider_crank_3d) echo "$ex/slider_crank_3d/scene.yaml --set analysis.end_time=0.02" ;;
    spinning_beam) echo "$ex/spinning_beam/scene.yaml" ;;
    pendulum) echo "$ex/pendulum/scene.yaml --set analysis.end_time=0.5" ;;
    four_bar_rigid) echo "$2/four_bar/rigid.yaml --set analysis.end_time=0.3" ;;
    four_bar_flexible) echo "$2/four_bar/flexible.yaml --set analysis.end_time=0.05" ;;
  esac
}
names="tumbling slider_crank_2d slider_crank_3d spinning_beam pendulum four_bar_rigid four_bar_flexible"
declare -A best
for round in 1 2 3; do
  for name in $names; do
    for which in base new; do
      tree=$here
      [ $which = base ] && tree=$base_dir
      # shellcheck disable=SC2046
      text=$("$tree/build/bin/femb-solve" $(scene "$tree" "$out/$which" $name) --set analysis.integrator=midpoint \
             --threads 1 -o "$out/$which/$name" | tail -1)
      t=$(echo "$text" | sed -n 's/.*solving \([0-9.]*\) s.*/\1/p')
      key=$which$name
      if [ -z "${best[$key]:-}" ] || /usr/bin/python3 -c "import sys; sys.exit(not $t < ${best[$key]})"; then
        best[$key]=$t
      fi
      [ $which = new ] && best[steps$name]=$(echo "$text" | sed -n 's/.*: \([0-9]*\) steps, \([0-9.]*\) Newton.*/\1 steps, \2 its/p')
    done
  done
done
echo "midpoint scheme, one thread, lowest of 3 solving times (base $base, new $(git -C "$here" rev-parse --short HEAD))"
printf "%-18s %-20s %10s %10s %7s  %s\n" scene "steps" "base [s]" "new [s]" ratio "largest probe difference"
for name in $names; do
  diff=$(/usr/bin/python3 - "$out/base/$name/probes.csv" "$out/new/$name/probes.csv" <<'EOF'
import sys
import numpy as np
names = open(sys.argv[1]).readline().strip().split(",")
a = np.genfromtxt(sys.argv[1], delimiter=",", skip_header=1)
b = np.genfromtxt(sys.argv[2], delimiter=",", skip_header=1)
if a.shape != b.shape:
    print("different lengths")
else:
    scale = np.abs(a).max(axis=0)
    rel = np.where(scale > 1e-12, np.abs(a - b).max(axis=0) / np.maximum(scale, 1e-300), 0.0)
    j = int(np.argmax(rel))
    print(f"{rel[j]:.1e} of its largest value ({names[j]})")
EOF
)
  printf "%-18s %-20s %10s %10s %7.2f  %s\n" $name "${best[steps$name]}" "${best[base$name]}" "${best[new$name]}" \
    "$(/usr/bin/python3 -c "print(${best[base$name]} / ${best[new$name]})")" "$diff"
done
