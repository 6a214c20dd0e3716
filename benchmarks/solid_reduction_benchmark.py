#!/usr/bin/python3
"""Solid reduction benchmark: the crank of meshes/crank.geo in TET10 at about 1e5, 3e5 and 1e6 DOFs,
two RBE2 interfaces (the bores), 20 fixed-interface modes. Per size it prints what this run
measured: DOFs, the time of every stage, peak memory, the factorization's GFLOP/s against this
machine's DGEMM rate, linear solves per eigenmode, total time against factorization + solves,
the relative error of the first 10 nonzero free-free frequencies of the reduced model against
the full model, and CalculiX (calculix-ccx) on the same mesh: its wall time for the same
fixed-interface frequency step and the largest relative difference of its 20 frequencies from
femb's fixed-interface ones.

usage: solid_reduction_benchmark.py BIN_DIR [--sizes 1e5,3e5,1e6] [--no-ccx] [--no-compact] [--ccx-timeout S]

It also prints the factorization rate on a compact part (a cube at ~1e5 and ~2.6e5 DOFs), where
supernodes are larger than in the slender crank. The 1e6 size needs ~18 GB (femb) and ~22 GB
(CalculiX) and about 30 minutes in all on 2 cores.
"""
import argparse
import json
import os
import re
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
GEO = os.path.join(ROOT, "meshes", "crank.geo")
# Element sizes that give about the named numbers of DOFs (measured: h = 3 mm -> 8.8e4).
SIZES = {"1e5": 0.0028, "3e5": 0.00185, "1e6": 0.00118}
E, NU, RHO, MODES = 2.1e11, 0.3, 7850.0, 20
STAGE = re.compile(r"femb-reduce: \[\s*([\d.]+) s\] (\S+(?: \S+)?)\s+([\d.]+) s  (.*)")


def run(cmd, env=None, timeout=None):
    return subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=timeout)


def mesh(h, path):
    start = time.time()
    r = run(["gmsh", GEO, "-3", "-order", "2", "-clmax", repr(h), "-clmin", repr(h / 2), "-nt", "1", "-o", path])
    if r.returncode != 0 or not os.path.exists(path):
        sys.exit(f"gmsh failed on {GEO}: {r.stdout[-500:]}{r.stderr[-500:]}")
    return time.time() - start


def femb(bin_dir, msh, work):
    # Craig-Bampton alone, as CalculiX computes it: geometric_stiffening (femb-reduce's default
    # since 2026-11-27) off; it adds about 60-90% to a solid's reduction (README).
    part = os.path.join(work, "part.yaml")
    with open(part, "w") as f:
        f.write(f"""name: crank_benchmark
type: solid
units: SI
material: {{E: {E}, nu: {NU}, rho: {RHO}}}
geometry: {{file: {msh}}}
interfaces:
  - {{name: big_bore, group: big_bore, coupling: rbe2}}
  - {{name: small_bore, group: small_bore, coupling: rbe2}}
reduction: {{internal_modes: {MODES}, floating_frame: center_of_mass, keep_mesh: false, full_modes: 10, geometric_stiffening: false}}
""")
    out = os.path.join(work, "crank.h5")
    env = dict(os.environ, OPENBLAS_NUM_THREADS="2", OMP_NUM_THREADS="1")
    r = run(["/usr/bin/time", "-f", "PEAK_KB %M", os.path.join(bin_dir, "femb-reduce"), part, "-o", out], env=env)
    if r.returncode != 0:
        return {"ok": False, "error": r.stderr.strip().splitlines()[-2:] if r.stderr.strip() else ["exit %d" % r.returncode],
                "log": r.stdout}
    stages = {}
    detail = {}
    for line in r.stdout.splitlines():
        m = STAGE.match(line)
        if m:
            stages[m.group(2)] = float(m.group(3))
            detail[m.group(2)] = m.group(4)
    j = json.loads(run([os.path.join(bin_dir, "femb-inspect"), out, "--json"]).stdout)
    peak = int(re.search(r"PEAK_KB (\d+)", r.stderr).group(1))
    return {"ok": True, "stages": stages, "detail": detail, "json": j, "peak_kb": peak}


def dgemm_rate(bin_dir):
    env = dict(os.environ, OPENBLAS_NUM_THREADS="2")
    r = run([os.path.join(bin_dir, "dgemm_rate")], env=env)
    return float(r.stdout.split()[0])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("bin_dir")
    ap.add_argument("--sizes", default="1e5,3e5,1e6")
    ap.add_argument("--no-ccx", action="store_true")
    ap.add_argument("--no-compact", action="store_true", help="skip the compact-part factorization rates")
    ap.add_argument("--ccx-timeout", type=float, default=3600)
    ap.add_argument("--work", default="/tmp/femb_solid_benchmark")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    peak_gemm = dgemm_rate(a.bin_dir)
    print(f"solid reduction benchmark: crank (meshes/crank.geo), TET10, 2 RBE2 interfaces, {MODES} internal modes")
    print(f"machine: {os.cpu_count()} cores, DGEMM (OpenBLAS, 2 threads, n = 2000) {peak_gemm:.1f} GFLOP/s\n")
    rows = []
    for name in a.sizes.split(","):
        h = SIZES[name]
        work = os.path.join(a.work, name)
        os.makedirs(work, exist_ok=True)
        msh = os.path.join(work, "crank.msh")
        t_mesh = mesh(h, msh)
        r = femb(a.bin_dir, msh, work)
        if not r["ok"]:
            print(f"[{name}] femb-reduce failed: {' '.join(r['error'])}")
            continue
        s, d, j = r["stages"], r["detail"], r["json"]
        n = j["n_full_dofs"]
        flop = float(re.search(r"([\d.e+]+) GFLOP,", d["factorize K_ii"]).group(1))
        factor_mb = float(re.search(r"factor ([\d.e+]+) MB", d["factorize K_ii"]).group(1))
        solves = int(re.search(r"(\d+) linear solves", d["eigen solve"]).group(1))
        passes_m = re.search(r"(\d+) passes over the factor", d["eigen solve"])
        passes = int(passes_m.group(1)) if passes_m else solves
        numeric = float(re.search(r"numeric ([\d.e+-]+) s", d["factorize K_ii"]).group(1))
        rate = flop / numeric
        reduction = t_mesh + sum(v for k, v in s.items() if k not in ("full modes", "mesh"))
        core = s["factorize K_ii"] + s["static modes"] + s["eigen solve"]
        red, full = j["free_free_frequencies_hz"][6:16], j["full_free_free_frequencies_hz"][6:16]
        err = max(abs(x - y) / y for x, y in zip(red, full))
        print(f"[{name}] {n} DOFs (h = {h * 1e3:.2f} mm)")
        print(f"  mesh (gmsh)       {t_mesh:8.2f} s")
        for k in ("mesh", "couplings", "assembly", "factorize K_ii", "static modes", "eigen solve", "projection",
                  "frame+mass", "write"):
            extra = ""
            if k == "mesh":
                k_label = "read mesh"
            else:
                k_label = k
            if k == "factorize K_ii":
                extra = (f"   factor {factor_mb / 1e3:.2f} GB, {flop:.1f} GFLOP, {rate:.1f} GFLOP/s = "
                         f"{100 * rate / peak_gemm:.0f}% of DGEMM (goal >= 40%)")
            if k == "eigen solve":
                extra = (f"   {solves} right-hand sides in {passes} block passes over the factor for {MODES} modes = "
                         f"{solves / MODES:.1f} solves, {passes / MODES:.2f} passes per mode (goal <= 4)")
            print(f"  {k_label:<17} {s.get(k, 0.0):8.2f} s{extra}")
        print(f"  total             {reduction:8.2f} s   = {reduction / core:.2f} x (factorization + solves) (goal <= 1.25)")
        print(f"  peak memory       {r['peak_kb'] / 1e6:8.2f} GB (whole run incl. the full-model reference)")
        print(f"  reduced vs full   max rel. error of free-free modes 7-16: {err:.2e} "
              f"(full model: {s.get('full modes', 0):.1f} s, not counted)")
        row = {"name": name, "dofs": n, "femb": reduction, "peak_gb": r["peak_kb"] / 1e6, "gflops": rate,
               "pct": 100 * rate / peak_gemm, "spm": solves / MODES, "ppm": passes / MODES, "ratio": reduction / core, "err": err}
        if not a.no_ccx:
            try:
                c = run(["/usr/bin/python3", os.path.join(HERE, "ccx_frequency.py"), msh, os.path.join(work, "ccx"),
                         str(MODES), str(E), str(NU), str(RHO), "big_bore", "small_bore"], timeout=a.ccx_timeout)
                cj = json.loads(c.stdout.strip().splitlines()[-1])
                if cj["ok"]:
                    ours = j["internal_frequencies_hz"]
                    diff = max(abs(x - y) / y for x, y in zip(ours, cj["frequencies_hz"]))
                    row.update(ccx=cj["seconds"], ccx_gb=cj["peak_kb"] / 1e6, diff=diff)
                    print(f"  CalculiX 2.20     {cj['seconds']:8.2f} s   peak {cj['peak_kb'] / 1e6:.2f} GB; "
                          f"femb is {cj['seconds'] / reduction:.1f}x faster (goal >= 3x); "
                          f"fixed-interface frequencies agree within {diff:.1e}")
                else:
                    print(f"  CalculiX failed: {cj.get('error')}")
            except subprocess.TimeoutExpired:
                print(f"  CalculiX did not finish in {a.ccx_timeout:.0f} s")
                row.update(ccx=None)
        print(flush=True)
        rows.append(row)
    if not a.no_compact:
        # The factorization's rate depends on the part's shape (supernode sizes): a compact
        # part, the 0.1 m cube of built-in shape box, TET10, RBE2 on two faces.
        print("compact part (cube 0.1 m, TET10), factorization only:")
        for h in (0.006, 0.0043):
            work = os.path.join(a.work, f"cube_{h}")
            os.makedirs(work, exist_ok=True)
            part = os.path.join(work, "cube.yaml")
            with open(part, "w") as f:
                f.write(f"name: cube\ntype: solid\nmaterial: {{E: {E}, nu: {NU}, rho: {RHO}}}\n"
                        f"geometry: {{shape: box, size: [0.1, 0.1, 0.1]}}\nmesh: {{size: {h}, order: 2}}\n"
                        f"interfaces: [{{name: a, group: xmin}}, {{name: b, group: xmax}}]\n"
                        f"reduction: {{internal_modes: {MODES}, keep_mesh: false, geometric_stiffening: false}}\n")
            env = dict(os.environ, OPENBLAS_NUM_THREADS="2", OMP_NUM_THREADS="1")
            r = run([os.path.join(a.bin_dir, "femb-reduce"), part, "-o", os.path.join(work, "cube.h5")], env=env)
            d = {m.group(2): m.group(4) for m in map(STAGE.match, r.stdout.splitlines()) if m}
            f = d.get("factorize K_ii", "")
            flop = float(re.search(r"([\d.e+]+) GFLOP,", f).group(1))
            numeric = float(re.search(r"numeric ([\d.e+-]+) s", f).group(1))
            n_i = int(re.search(r"(\d+) interior DOFs", f).group(1))
            print(f"  {n_i} interior DOFs: {flop:.0f} GFLOP in {numeric:.2f} s = {flop / numeric:.1f} GFLOP/s "
                  f"= {100 * flop / numeric / peak_gemm:.0f}% of DGEMM (goal >= 40%)")
        print()
    print("| DOFs | femb reduce [s] | peak mem [GB] | factor GFLOP/s (% DGEMM) | solves (passes) per mode | total/(factor+solves) "
          "| max rel. err modes 7-16 | CalculiX [s] | speed-up |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        ccx = r.get("ccx")
        ccx_s = f"{ccx:.1f}" if ccx else "-"
        sp = f"{ccx / r['femb']:.1f}x" if ccx else "-"
        print(f"| {r['dofs']} | {r['femb']:.1f} | {r['peak_gb']:.2f} | {r['gflops']:.1f} ({r['pct']:.0f}%) | "
              f"{r['spm']:.1f} ({r['ppm']:.2f}) | {r['ratio']:.2f} | {r['err']:.1e} | {ccx_s} | {sp} |")


if __name__ == "__main__":
    main()
