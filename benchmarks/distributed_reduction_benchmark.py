#!/usr/bin/python3
"""femb-reduce on MPI ranks against the one-process path: the crank of meshes/crank.geo in TET10 at
about 1e5 and 3e5 DOFs (1e6 with --sizes), two RBE2 bores, 20 fixed-interface modes, the
Craig-Bampton reduction alone (as solid_reduction_benchmark.py). Per size it reduces the same
mesh with CHOLMOD (reduction.solver: cholmod, 2 BLAS threads), and with MUMPS and SLEPc
(reduction.solver: petsc) on 1 rank (2 BLAS threads) and on 2 ranks (mpirun -np 2, a BLAS thread
each; at the first size also on 4 ranks, for the file only), and prints what this run measured: the time of every stage, the peak memory of the
largest rank and of all ranks, the factor's size and flops (MUMPS' own figures), and how far the
MPI files are from CHOLMOD's (compare_superelements.py: frequencies, reduced K and M), and the
share of the columns and of the elements rank 0 of 2 assembles.

At the first size (below 5e5 DOFs) it also compares the files of 4 ranks and of a variant with two RBE3 bores,
times the stages that loop over the elements (geometric stiffening with its inertia load cases, modal stresses on the
kept mesh: the part's defaults) on one process and on 2 ranks, each rank taking a share of the elements, and
shows the per-rank memory limit: a limit under which the one-process
path refuses the part (exit 4) while 2 ranks, each within it, reduce it to the file the one-process
path writes without a limit. Last, a projection of the factor's size and flops to 1e7 and 3e7 DOFs
from MUMPS' figures of the sizes run (a power law fitted through them).

usage: distributed_reduction_benchmark.py BIN_DIR [--sizes 1e5,3e5] [--work DIR]
"""
import argparse
import math
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
GEO = os.path.join(ROOT, "meshes", "crank.geo")
COMPARE = os.path.join(ROOT, "tests", "reducer", "distributed", "compare_superelements.py")
SIZES = {"1e5": 0.0028, "3e5": 0.00185, "1e6": 0.00118}  # element sizes (solid_reduction_benchmark.py)
MODES = 20
STAGE = re.compile(r"femb-reduce: \[\s*([\d.]+) s\] (\S+(?: \S+)?)\s+([\d.]+) s  (.*)")
MPIRUN = ["mpirun", "--allow-run-as-root", "--oversubscribe"]


def run(cmd, env=None):
    return subprocess.run(cmd, env=env, capture_output=True, text=True)


def part_file(work, msh, extra="", coupling="rbe2", name="part",
              options="keep_mesh: false, full_modes: 0, geometric_stiffening: false"):
    path = os.path.join(work, f"{name}.yaml")
    with open(path, "w") as f:
        f.write(f"""name: crank_mpi
type: solid
units: SI
material: {{E: 2.1e11, nu: 0.3, rho: 7850}}
geometry: {{file: {msh}}}
interfaces:
  - {{name: big_bore, group: big_bore, coupling: {coupling}}}
  - {{name: small_bore, group: small_bore, coupling: {coupling}}}
reduction: {{internal_modes: {MODES}, {options}{extra}}}
""")
    return path


def reduce(bin_dir, part, out, ranks, extra_args=()):
    """ranks 0: CHOLMOD without mpirun; else MUMPS and SLEPc on that many ranks."""
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="2")
    cmd = [os.path.join(bin_dir, "femb-reduce"), part, "-o", out, *extra_args]
    if ranks > 0:
        cmd = MPIRUN + ["-np", str(ranks)] + cmd + ["--set", "reduction.solver=petsc"]
    r = run(cmd, env=env)
    stages, detail = {}, {}
    for line in r.stdout.splitlines():
        m = STAGE.match(line)
        if m:
            stages[m.group(2)] = float(m.group(3))
            detail[m.group(2)] = m.group(4)
    peaks = re.findall(r"peak memory ([\d.e+]+) GB(?: on the largest rank, ([\d.e+]+) GB in all)?", r.stdout)
    peak = peaks[-1] if peaks else None  # the run's last line
    return {"code": r.returncode, "stdout": r.stdout, "stderr": r.stderr, "stages": stages, "detail": detail,
            "largest_gb": float(peak[0]) if peak else None, "all_gb": float(peak[1] or peak[0]) if peak else None}


def factor_figures(detail):
    f = detail.get("factorize K_ii", "")
    mb = float(re.search(r"factor ([\d.e+]+) MB", f).group(1))
    gflop = float(re.search(r"([\d.e+]+) GFLOP,", f).group(1))
    n_i = int(re.search(r"(\d+) interior DOFs", f).group(1))
    estimate = re.search(r"estimated ([\d.e+]+) GB on the largest", f)
    return {"factor_gb": mb / 1e3, "gflop": gflop, "n_i": n_i,
            "estimate_gb": float(estimate.group(1)) if estimate else None}


def limit_case(bin_dir, work, part, serial, two):
    """A limit between the one-process factor and 2 ranks' largest share."""
    n = two["n_i"] + 12
    dense_gb = 8.0 * n * (2.0 * (12 + MODES) + 2.0 * MODES + 20.0) / 1e9  # reduce_part.cpp's dense blocks
    if not two["estimate_gb"] < serial["factor_gb"]:
        print(f"  per-rank limit: not shown at this size (2 ranks' largest share {two['estimate_gb']:.3f} GB is "
              f"not below the one-process factor {serial['factor_gb']:.3f} GB)")
        return
    limit = dense_gb + 0.5 * (serial["factor_gb"] + two["estimate_gb"])
    one = reduce(bin_dir, part, os.path.join(work, "limited_one.h5"), 0,
                 ["--set", f"reduction.memory_limit_gb={limit:.4f}"])
    mpi = reduce(bin_dir, part, os.path.join(work, "limited_np2.h5"), 2,
                 ["--set", f"reduction.memory_limit_gb={limit:.4f}"])
    cmp = run(["/usr/bin/python3", COMPARE, os.path.join(work, "cholmod.h5"), os.path.join(work, "limited_np2.h5")])
    print(f"  per-rank limit {limit:.3f} GB: one process exit {one['code']} "
          f"({(one['stderr'].strip().splitlines() or [''])[-1][:110]}...); "
          f"2 ranks exit {mpi['code']}, against the unlimited one-process file: {cmp.stdout.strip().split(': ', 1)[-1]}")


def element_stages(bin_dir, work, msh):
    """The stages that loop over the elements, with the part's defaults (stiffening, stresses)."""
    full = part_file(work, msh, name="defaults", options="keep_mesh: true, full_modes: 0")
    one = reduce(bin_dir, full, os.path.join(work, "defaults_0.h5"), 0)
    two = reduce(bin_dir, full, os.path.join(work, "defaults_2.h5"), 2)
    for label, r in (("one process", one), ("2 ranks", two)):
        if r["code"] != 0:
            sys.exit(f"defaults on {label} failed: {r['stderr'][-400:]}")
    c = run(["/usr/bin/python3", COMPARE, os.path.join(work, "defaults_0.h5"), os.path.join(work, "defaults_2.h5")])
    times = ", ".join(f"{stage} {one['stages'].get(stage, 0.0):.2f} s -> {two['stages'].get(stage, 0.0):.2f} s"
                      for stage in ("inertia loads", "stiffening", "stresses"))
    print(f"  with the part's defaults (stiffening, stresses), one process -> 2 ranks: {times}; total "
          f"{sum(one['stages'].values()):.2f} s -> {sum(two['stages'].values()):.2f} s, peak largest rank "
          f"{one['largest_gb']:.3f} -> {two['largest_gb']:.3f} GB; 2 ranks against one process: "
          f"{c.stdout.strip().split(': ', 1)[-1]}{'' if c.returncode == 0 else '  EXCEEDS'}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("bin_dir")
    ap.add_argument("--sizes", default="1e5,3e5")
    ap.add_argument("--work", default="/tmp/femb_distributed_benchmark")
    a = ap.parse_args()
    print(f"distributed reduction benchmark: crank (meshes/crank.geo), TET10, 2 RBE2 bores, {MODES} internal modes; "
          f"{os.cpu_count()} cores")
    fits = []
    for index, name in enumerate(a.sizes.split(",")):
        work = os.path.join(a.work, name)
        os.makedirs(work, exist_ok=True)
        msh = os.path.join(work, "crank.msh")
        h = SIZES[name]
        r = run(["gmsh", GEO, "-3", "-order", "2", "-clmax", repr(h), "-clmin", repr(h / 2), "-nt", "1", "-o", msh])
        if r.returncode != 0:
            sys.exit(f"gmsh failed: {r.stderr[-300:]}")
        part = part_file(work, msh)
        runs = {"CHOLMOD, 1 process": reduce(a.bin_dir, part, os.path.join(work, "cholmod.h5"), 0),
                "MUMPS+SLEPc, np 1": reduce(a.bin_dir, part, os.path.join(work, "np1.h5"), 1),
                "MUMPS+SLEPc, np 2": reduce(a.bin_dir, part, os.path.join(work, "np2.h5"), 2)}
        for label, r in runs.items():
            if r["code"] != 0:
                sys.exit(f"[{name}] {label} failed: {r['stderr'][-400:]}")
        figures = {label: factor_figures(r["detail"]) for label, r in runs.items()}
        n = figures["CHOLMOD, 1 process"]["n_i"] + 12
        print(f"\n[{name}] {n} DOFs (h = {h * 1e3:.2f} mm)")
        print(f"  {'stage [s]':<16}" + "".join(f"{label:>22}" for label in runs))
        for stage in ("mesh", "couplings", "assembly", "factorize K_ii", "static modes", "eigen solve", "projection",
                      "write"):
            print(f"  {stage:<16}" + "".join(f"{r['stages'].get(stage, 0.0):22.2f}" for r in runs.values()))
        total = {label: sum(r["stages"].values()) for label, r in runs.items()}
        print(f"  {'total':<16}" + "".join(f"{total[label]:22.2f}" for label in runs))
        print(f"  {'peak largest GB':<16}" + "".join(f"{r['largest_gb']:22.3f}" for r in runs.values()))
        print(f"  {'peak all GB':<16}" + "".join(f"{r['all_gb']:22.3f}" for r in runs.values()))
        print(f"  {'factor GB':<16}" + "".join(f"{f['factor_gb']:22.3f}" for f in figures.values()))
        print(f"  {'factor GFLOP':<16}" + "".join(f"{f['gflop']:22.1f}" for f in figures.values()))
        share = re.match(r"(\d+) of (\d+) elements, .* in the (\d+) of (\d+) columns",
                         runs["MUMPS+SLEPc, np 2"]["detail"].get("assembly", ""))
        if share:
            cells, all_cells, columns, all_columns = (int(g) for g in share.groups())
            print(f"  np 2: rank 0 holds {columns} of {all_columns} columns ({100 * columns / all_columns:.1f}%), "
                  f"assembled from {cells} of {all_cells} elements ({100 * cells / all_cells:.1f}%; METIS' cut)")
        for label in ("MUMPS+SLEPc, np 1", "MUMPS+SLEPc, np 2"):
            out = "np1.h5" if label.endswith("1") else "np2.h5"
            c = run(["/usr/bin/python3", COMPARE, os.path.join(work, "cholmod.h5"), os.path.join(work, out)])
            print(f"  {label} against CHOLMOD: {c.stdout.strip().split(': ', 1)[-1]}"
                  f"{'' if c.returncode == 0 else '  EXCEEDS 1e-9 / 1e-8'}")
        two = figures["MUMPS+SLEPc, np 2"]
        fits.append((n, two["factor_gb"], two["gflop"], two["gflop"] / runs["MUMPS+SLEPc, np 2"]["stages"]["factorize K_ii"]))
        if index == 0 and n < 5e5:  # (4 ranks on 2 cores: the extra runs at the small size only)
            four = reduce(a.bin_dir, part, os.path.join(work, "np4.h5"), 4)
            c = run(["/usr/bin/python3", COMPARE, os.path.join(work, "cholmod.h5"), os.path.join(work, "np4.h5")])
            print(f"  MUMPS+SLEPc, np 4 (oversubscribed: its times mean nothing here) exit {four['code']}, against "
                  f"CHOLMOD: {c.stdout.strip().split(': ', 1)[-1]}{'' if c.returncode == 0 else '  EXCEEDS 1e-9 / 1e-8'}")
            limit_case(a.bin_dir, work, part, figures["CHOLMOD, 1 process"], two)
            element_stages(a.bin_dir, work, msh)
            # Both bores distributing (RBE3): the constrained shift-invert, the augmented factor.
            seats = part_file(work, msh, coupling="rbe3", name="seats")
            for ranks in (0, 2, 4):
                r = reduce(a.bin_dir, seats, os.path.join(work, f"seats_{ranks}.h5"), ranks)
                if r["code"] != 0:
                    sys.exit(f"[{name}] RBE3 bores on {ranks} ranks failed: {r['stderr'][-400:]}")
            for ranks in (2, 4):
                c = run(["/usr/bin/python3", COMPARE, os.path.join(work, "seats_0.h5"),
                         os.path.join(work, f"seats_{ranks}.h5")])
                print(f"  RBE3 bores, np {ranks} against CHOLMOD: {c.stdout.strip().split(': ', 1)[-1]}"
                      f"{'' if c.returncode == 0 else '  EXCEEDS 1e-9 / 1e-8'}")
    if len(fits) >= 2:
        (n0, g0, f0, _), (n1, g1, f1, rate) = fits[0], fits[-1]
        a_mem, a_flop = math.log(g1 / g0) / math.log(n1 / n0), math.log(f1 / f0) / math.log(n1 / n0)
        print(f"\nprojection (MUMPS' factor entries and flops, power law through {n0} and {n1} DOFs): "
              f"factor ~ n^{a_mem:.2f}, flops ~ n^{a_flop:.2f}; this machine's 2 ranks factor at {rate:.1f} GFLOP/s "
              f"(factorization stage)")
        for target in (1e7, 3e7):
            mem, flop = g1 * (target / n1) ** a_mem, f1 * (target / n1) ** a_flop
            print(f"  {target:.0e} DOFs: factor {mem:.0f} GB, {flop / 1e3:.0f} TFLOP; at this machine's rate "
                  f"{flop / rate / 3600:.1f} h")


if __name__ == "__main__":
    main()
