#!/usr/bin/env bash
# Builds femb and runs every benchmark, printing the measured tables.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh >/dev/null
bash scripts/build.sh >/dev/null
build/bin/beam_reduction_benchmark
echo
build/bin/solver_scaling_benchmark
echo
build/bin/body_kernels_benchmark
echo
# Solid reduction vs CalculiX (calculix-ccx): about 35 minutes and 22 GB at the 1e6-DOF size;
# SOLID_SIZES=1e5,3e5 for a quick run.
command -v ccx > /dev/null || apt-get install -y -q calculix-ccx > /dev/null
/usr/bin/python3 benchmarks/solid_reduction_benchmark.py build/bin --sizes "${SOLID_SIZES:-1e5,3e5,1e6}"
echo
# femb-reduce on MPI ranks (MUMPS, SLEPc) against CHOLMOD, np 1 and 2 (about 5 minutes).
/usr/bin/python3 benchmarks/distributed_reduction_benchmark.py build/bin --sizes "${MPI_SIZES:-1e5,3e5}"
echo
# Error vs run time on the 2D slider-crank and the spinning beam (about 8 minutes): tables, PNGs.
mkdir -p out
/usr/bin/python3 benchmarks/error_vs_time.py build/bin --png-prefix out/error_vs_time_
echo
# Modal derivatives: error vs run time on the cross-flexure pivot (about 2 minutes).
/usr/bin/python3 benchmarks/flexure_error_vs_time.py build/bin --png out/flexure_error_vs_time.png
echo
# Fixed vs error-controlled steps (step: auto) on every dynamic seed case (about 10 minutes once
# the examples' references exist in build/example_out, e.g. after ctest; else they are run first).
/usr/bin/python3 benchmarks/step_control.py build/bin
echo
# Time to accuracy on the slider-crank compared with its peer: rigid crank and slider,
# the rod in 2 or 4 stiffened bodies along the step, least times against the peer's (about 15 s).
/usr/bin/python3 benchmarks/peer_slider_crank.py build/bin --out out/peer_slider_crank
echo
# The solver's hot path against the commit before the allocation-free hot path (9db5b40; builds it once in
# /tmp, about 10 minutes, then about 2 minutes): not run here, run it by hand:
#   bash benchmarks/hot_path_vs_base.sh [BASE]
# The midpoint scheme against its state before the allocation-free rewrite (ab9796a; builds it
# once in /tmp, about 6 minutes, then about 20 s): by hand too:
#   bash benchmarks/midpoint_vs_base.sh [BASE]
# The four-bar coupler's energy with and without geometric stiffening (about 40 s).
/usr/bin/python3 benchmarks/stiffening_energy.py build/bin out/stiffening_energy
echo
# What writing the results during the run costs (the 10-body slider-crank, about 4 minutes).
/usr/bin/python3 benchmarks/flush_cost.py build/bin
echo
# What stress output costs: the solid cantilever with outputs.stresses off and on (about 15 s).
/usr/bin/python3 benchmarks/stress_output.py build/bin
