#!/usr/bin/env bash
# The solver's hot path against an earlier commit of femb, same machine, same run:
# builds BASE in a git worktree (kept in $BASE_DIR for the next run), then, interleaved and
# twice each (the lower time counts):
#   - the 10-body 2D slider-crank (examples/slider_crank_2d, 10 linear rod bodies, h = 10 us,
#     12 600 steps) with each commit's femb-reduce and femb-solve, on 1 thread and on 2;
#     prints wall times, ratios and the largest difference of the rod midpoint's position;
#   - each commit's solver_scaling_benchmark (its own table: ms per body-step, allocations).
# Usage: bash benchmarks/hot_path_vs_base.sh [BASE]    (default 9db5b40, the state before the allocation-free hot path)
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
base=${1:-9db5b40}
base_dir=${BASE_DIR:-/tmp/femb_base_$base}
out=${OUT:-/tmp/femb_hot_path}
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
# shellcheck source=benchmarks/base_tree.sh
source "$here/benchmarks/base_tree.sh"
build_trees femb-reduce femb-solve solver_scaling_benchmark
mkdir -p "$out"
# Each tree's slider-crank with its own tools (file formats may differ between commits).
prepare() {  # tree, dir
  local tree=$1 dir=$2 ex=$1/examples/slider_crank_2d
  for part in crank slider; do "$tree/build/bin/femb-reduce" -q "$ex/$part.yaml" -o "$ex/$part.h5"; done
  /usr/bin/python3 "$ex/make_variant.py" 10 "$dir" 1e-5 2 > /dev/null
  "$tree/build/bin/femb-reduce" -q "$dir/rod_10.yaml" -o "$dir/rod_10.h5"
}
prepare "$base_dir" "$out/base"
prepare "$here" "$out/new"
nanoseconds() {  # tree, dir, threads -> wall time (a commit without --threads: its one way)
  local start threads=(--threads "$3")
  "$1/build/bin/femb-solve" --help | grep -q -- --threads || threads=()
  start=$(date +%s%N)
  "$1/build/bin/femb-solve" -q "$2/scene.yaml" -o "$2/run_$3" "${threads[@]}" > /dev/null || return 1
  echo $(($(date +%s%N) - start))
}
declare -A best
for round in 1 2; do
  for threads in 1 2; do
    for which in base new; do
      tree=$here
      [ $which = base ] && tree=$base_dir
      ns=$(nanoseconds "$tree" "$out/$which" $threads)
      key=$which$threads
      if [ -z "${best[$key]:-}" ] || [ "$ns" -lt "${best[$key]}" ]; then best[$key]=$ns; fi
    done
  done
done
echo "10-body slider-crank, h = 10 us, 12 600 steps (lower of 2 runs; base $base, new $(git -C "$here" rev-parse --short HEAD))"
/usr/bin/python3 - "${best[base1]}" "${best[new1]}" "${best[base2]}" "${best[new2]}" <<'EOF'
import sys
b1, n1, b2, n2 = (int(x) * 1e-9 for x in sys.argv[1:])
print(f"{'threads':10s} {'base (s)':>12s} {'new (s)':>12s} {'ratio':>8s}")
print(f"{'1':10s} {b1:12.2f} {n1:12.2f} {b1 / n1:8.2f}")
print(f"{'2':10s} {b2:12.2f} {n2:12.2f} {b2 / n2:8.2f}")
print(f"{'1 vs 2':10s} {b1:12.2f} {n2:12.2f} {b1 / n2:8.2f}  (base on 1 thread / new on 2)")
EOF
/usr/bin/python3 - "$out/base/run_1/probes.csv" "$out/new/run_1/probes.csv" "$out/new/run_2/probes.csv" <<'EOF'
import csv, sys
def load(p):
    rows = list(csv.reader(open(p)))
    return rows[0], [[float(x) for x in r] for r in rows[1:]]
h, a = load(sys.argv[1])
for other in sys.argv[2:]:
    h2, b = load(other)
    cols = [i for i, name in enumerate(h) if name.startswith("rod_mid.position")]
    d = max(abs(ra[i] - rb[h2.index(h[i])]) for ra, rb in zip(a, b) for i in cols)
    print(f"rod midpoint, base vs {other.split('/')[-2]}: largest difference {d:.3g} m over {len(a)} steps")
EOF
echo
echo "solver_scaling_benchmark of base $base:"
"$base_dir/build/bin/solver_scaling_benchmark" | tail -n +3
echo
echo "solver_scaling_benchmark of new:"
"$here/build/bin/solver_scaling_benchmark" | tail -n +3
