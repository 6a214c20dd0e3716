#!/usr/bin/env bash
# Regenerates the validation page's evidence (docs/validation.md): runs every self-checking example
# (the same run.sh the test suite runs, so the same figures), keeps each one's check output as
# docs/results/<case>/check.log and its plots as docs/results/<case>/*.png. Runs in out/validation.
# About 10 minutes on 2 cores. Usage: bash scripts/validation.sh [CASE...]   (default: all)
set -uo pipefail
cd "$(dirname "$0")/.."
export FEMB_BIN=${FEMB_BIN:-$PWD/build/bin} OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
cases=("$@")
[ ${#cases[@]} -gt 0 ] || cases=(cantilever_static cantilever_transient rotating_beam slider_crank_2d slider_crank_3d
  spinning_beam spin_up_beam cantilever_plate leaf_spring cross_flexure four_bar tumbling_body imported_matrices
  bending_rod)
status=0
for c in "${cases[@]}"; do
  [ -f "examples/$c/run.sh" ] || { echo "validation: no example $c" >&2; exit 2; }
  out=out/validation/$c
  rm -rf "$out" && mkdir -p "$out" "docs/results/$c"
  start=$SECONDS
  if bash "examples/$c/run.sh" "$out" > "$out/check.log" 2>&1; then verdict=passed; else verdict=FAILED; status=1; fi
  # The log as the page shows it: the run's own lines, without the scratch folder's name.
  sed "s|$out/|OUTDIR/|g; s|$PWD/||g" "$out/check.log" > "docs/results/$c/check.log"
  rm -f docs/results/"$c"/*.png
  find "$out" -maxdepth 1 -name '*.png' -exec cp {} "docs/results/$c/" \;
  echo "validation: $c $verdict in $((SECONDS - start)) s ($(ls docs/results/"$c"/*.png 2>/dev/null | wc -l) plots)"
done
exit $status
