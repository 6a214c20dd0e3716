#!/usr/bin/python3
"""Time to accuracy on the planar slider-crank as it was compared with its open peer (Exudyn
1.11, ANCF cables: 1% RMS in 0.04-0.08 s of solve time, 0.3% in 0.09-0.37 s; the peer's numbers
as measured side by side, not rerun here).

The model as a multibody user would build it for that comparison: a rigid crank (0.15 m, 0.371 kg,
driven at 150 rad/s) and a rigid slider (0.0334 kg), the flexible rod (0.3 m, d = 6 mm, steel) in 2
superelements of the example's rod_2.yaml (4 internal modes, geometric stiffening, exact inertia).
The example's scene.yaml models the crank and the slider as very stiff superelements (E = 2e14)
instead; it is run too. Error: RMS of the rod-midpoint deflection over three revolutions against the
example's reference (20 linear bodies, h = 5 us), as a fraction of its peak (deflection.py).

Per row: femb-solve's own split of its time (its last line: reading, solving, writing), the best of
REPEATS runs on one thread; wall = the whole process. Settings varied: the step, Newton's tolerance
(analysis.tolerance; the scene default 1e-8) and analysis.body_matrices_every (1: default; the kept
steps turn all of a body's matrices, analysis.body_matrices_kept: all).

With --png FILE: error against solve time, femb's rows at tolerance 1e-3 and every 8th step (the
step varied) and the defaults, with the peer's two reported ranges.

usage: peer_slider_crank.py BIN_DIR [--out DIR] [--repeats 3] [--png FILE]
"""
import argparse
import os
import re
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EX = os.path.join(ROOT, "examples", "slider_crank_2d")

RIGID = """name: slider_crank_2d_rigid
units: SI
bodies:
  - {name: crank, type: rigid, mass: 0.37086501, center_of_mass: [0.075, 0, 0],
     inertia: [1.8543251e-05, 0.00070464352, 0.00070464352], points: {O: [0, 0, 0], A: [0.15, 0, 0]}, nodes: {O: O, A: A}}
  - {name: rod0, superelement: rod_2.h5, placement: {position: [0.15, 0, 0]}, nodes: {A: rod_a, B: rod_mid}}
  - {name: rod1, superelement: rod_2.h5, placement: {position: [0.3, 0, 0]}, nodes: {A: rod_mid, B: rod_b}}
  - {name: slider, type: rigid, mass: 0.033379031, center_of_mass: [0, 0, 0], inertia: [1.0e-12, 1.0e-12, 1.0e-12],
     points: {S: [0, 0, 0]}, placement: {position: [0.45, 0, 0]}, nodes: {S: slider}}
joints:
  - {type: revolute, node: O, axis: [0, 0, 1], prescribed: crank_angle}
  - {type: revolute, node: rod_a, parent: A, axis: [0, 0, 1]}
  - {type: prismatic, node: slider, axis: [1, 0, 0]}
  - {type: revolute, node: rod_b, parent: slider, axis: [0, 0, 1]}
functions:
  crank_angle: {type: linear, slope: 150}
analysis: {type: dynamic, end_time: 0.126, step: 1.0e-5, rho_inf: 0.8}
outputs:
  animation: false
  probes:
    - {name: crank, node: O, quantities: [joint]}
    - {name: rod_a, node: rod_a, quantities: [position]}
    - {name: rod_mid, node: rod_mid, quantities: [position]}
    - {name: rod_b, node: rod_b, quantities: [position]}
    - {name: slider, node: slider, quantities: [position, joint]}
"""


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"peer_slider_crank: {' '.join(cmd)} failed: {r.stderr.strip()}")
    return r.stdout


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("bin")
    ap.add_argument("--out", default="out/peer_slider_crank")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--png", default="")
    a = ap.parse_args()
    os.environ["OMP_NUM_THREADS"] = os.environ["OPENBLAS_NUM_THREADS"] = "1"
    solve, reduce = os.path.join(a.bin, "femb-solve"), os.path.join(a.bin, "femb-reduce")
    os.makedirs(a.out, exist_ok=True)
    for part in ("crank", "slider", "rod_2"):
        run([reduce, "-q", os.path.join(EX, part + ".yaml"), "-o", os.path.join(a.out, part + ".h5")])
    with open(os.path.join(a.out, "rigid.yaml"), "w") as f:
        f.write(RIGID)
    with open(os.path.join(EX, "scene.yaml")) as f:
        stiff = f.read().replace("outputs:\n", "outputs:\n  animation: false\n")
    with open(os.path.join(a.out, "stiff.yaml"), "w") as f:
        f.write(stiff)
    ref = os.path.join(a.out, "reference_20_bodies")
    if not os.path.exists(os.path.join(ref, "probes.csv")):
        print("peer_slider_crank: the 20-body reference (about 10 s)", flush=True)
        run(["/usr/bin/python3", os.path.join(EX, "make_variant.py"), "20", ref, "5e-6", "2"])
        run([reduce, "-q", os.path.join(ref, "rod_20.yaml"), "-o", os.path.join(ref, "rod_20.h5")])
        run([solve, "-q", os.path.join(ref, "scene.yaml"), "-o", ref, "--threads", "1"])
    print("model                              step     tolerance  every  steps  its/step  solving [s]  wall [s]  RMS error")
    # The defaults (Newton tolerance 1e-8, every body matrix every step), the settings of the
    # earlier rounds (1e-4, every 4th step) and the fastest found (1e-3, every 8th step: the
    # error does not change with either, see the README) along the step.
    rigid = "rigid crank and slider"
    rows = [(rigid, "rigid.yaml", h, "1e-8", "1") for h in ("1e-4", "1.5e-4")]
    rows += [(rigid, "rigid.yaml", h, "1e-4", "4") for h in ("1e-4", "1.5e-4")]
    rows += [(rigid, "rigid.yaml", h, "1e-3", "8") for h in ("5e-5", "7.5e-5", "1e-4", "1.25e-4", "1.4e-4", "1.5e-4",
                                                             "2e-4")]
    rows += [("stiff crank and slider (example)", "stiff.yaml", "1.5e-4", tol, every)
             for tol, every in (("1e-8", "1"), ("1e-3", "8"))]
    measured = []
    for label, scene, h, tol, every in rows:
        out = os.path.join(a.out, f"{scene[:-5]}_{h}_{tol}_{every}")
        best_solve = best_wall = float("inf")
        for _ in range(a.repeats):
            start = time.time()
            text = run([solve, os.path.join(a.out, scene), "-o", out, "--threads", "1", "--set", f"analysis.step={h}",
                        "--set", f"analysis.tolerance={tol}", "--set", f"analysis.body_matrices_every={every}"])
            best_wall = min(best_wall, time.time() - start)
            m = re.search(r"solving ([0-9.]+) s.*: (\d+) steps, ([0-9.]+) Newton", text)
            best_solve = min(best_solve, float(m.group(1)))
        cmp = run(["/usr/bin/python3", os.path.join(EX, "deflection.py"), ref, f"run={out}"])
        err = re.search(r"= ([0-9.]+)% of the reference peak", cmp).group(1)
        print(f"{label:34s} {float(h) * 1e6:5.1f} us  {tol:>9s}  {every:>5s}  {m.group(2):>5s}  {m.group(3):>8s}"
              f"  {best_solve:11.3f}  {best_wall:8.3f}  {err}%", flush=True)
        measured.append((label, h, tol, every, best_solve, float(err)))
    if a.png:
        plot(measured, a.png)


def plot(measured, png):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for (tol, every), style, name in ((("1e-3", "8"), "o-", "femb, tolerance 1e-3, body_matrices_every 8"),
                                      (("1e-8", "1"), "s--", "femb, defaults")):
        pts = sorted(((t, e, h) for label, h, tl, ev, t, e in measured
                      if label.startswith("rigid") and (tl, ev) == (tol, every)), key=lambda p: -float(p[2]))
        if not pts:
            continue
        ax.plot([p[0] for p in pts], [p[1] for p in pts], style, label=name)
        for t, e, h in pts:
            ax.annotate(f"{float(h) * 1e6:.0f} us", (t, e), textcoords="offset points", xytext=(4, 4), fontsize=7)
    for err, lo, hi in ((1.0, 0.04, 0.08), (0.3, 0.09, 0.37)):
        ax.plot([lo, hi], [err, err], color="tab:red", lw=4, alpha=0.6,
                label="peer (Exudyn 1.11, ANCF), as reported side by side" if err == 1.0 else None)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("solve time [s], one thread")
    ax.set_ylabel("RMS error of the rod midpoint deflection [% of peak]")
    ax.set_title("planar slider-crank, 3 revolutions: error against run time")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(png, dpi=120)
    print(f"peer_slider_crank: plot {png}")


if __name__ == "__main__":
    main()
