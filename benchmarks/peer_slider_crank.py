#!/usr/bin/python3
"""Time to accuracy on the planar slider-crank, femb's side of the comparison with its strongest open
peer, and femb's least solve time at each error level against the peer's.

The model as a multibody user would build it for that comparison: a rigid crank (0.15 m, 0.371 kg,
driven at 150 rad/s) and a rigid slider (0.0334 kg), the flexible rod (0.3 m, d = 6 mm, steel) in 1,
2 or 4 superelements: the whole rod in one body with its first bending pair (2 internal modes), or
examples/slider_crank_2d's rod segment of 0.15 m or 0.075 m (4 internal modes); each with geometric
stiffening and exact inertia. The one-body rod's midpoint is a point probe, the others' a node.
Newton tolerance 1e-3 and analysis.body_matrices_every 8 (the error does not change with either;
the defaults are run too, at 2 steps). Error: RMS of the
rod-midpoint deflection over three revolutions against femb's own converged reference (the
example's 20 linear bodies at h = 5 us), as a fraction of its peak (deflection.py). "Counted"
error: the largest error of that model at that step or at any smaller step run, so that a
cancellation of time and space error at one step does not count.

Each model runs under two integrators: generalized-alpha (second order) and the three-stage Radau
IIA scheme (fifth order, analysis.integrator: radau; its bodies' matrices computed at every
stage, body_matrices_every 1), each at its own steps.

The peer's least solve times (Exudyn 1.11, ANCF cables, index-3 generalized-alpha, its fastest
build) are the figures measured side by side on this machine against an independent reference (a
64-element geometrically exact rod; docs/performance.md): they are constants here, not rerun. This
benchmark's reference is femb's own, so its errors are not that comparison's; the ratio compares
femb's least time at a level against the peer's least time at the same level.

Per row: femb-solve's own split of its time (its last line: reading, solving, writing), the best of
REPEATS runs on one thread; wall = the whole process.

usage: peer_slider_crank.py BIN_DIR [--out DIR] [--repeats 2] [--png FILE]
"""
import argparse
import os
import re
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EX = os.path.join(ROOT, "examples", "slider_crank_2d")

sys.path.insert(0, os.path.join(ROOT, "examples", "common"))
import rod  # noqa: E402
import stiffening  # noqa: E402

# The peer's least solve time [s] reaching each counted error [%] (docs/performance.md; not reached
# at 0.1%).
PEER_LEAST = {2.0: 0.027, 1.0: 0.037, 0.5: 0.037, 0.2: 0.109, 0.1: None}
LEVELS = (2.0, 1.0, 0.5, 0.2, 0.1)
ALPHA_STEPS = ("2e-4", "1.4e-4", "1e-4", "7.5e-5", "5e-5", "2.5e-5", "1e-5")
STEPS = {1: ALPHA_STEPS, 2: ALPHA_STEPS, 4: ("2e-4", "1e-4", "5e-5", "1e-5")}
# The Radau IIA integrator (order 5): its steps, tolerance 1e-3, the bodies' matrices at every stage.
RADAU_STEPS = {1: ("2.5e-3", "2e-3", "1.5e-3", "1.25e-3", "1e-3", "7.5e-4", "5e-4", "2.5e-4"),
               2: ("2e-3", "1.5e-3", "1e-3", "7.5e-4", "5e-4", "2.5e-4"), 4: ("1.5e-3", "1e-3", "5e-4", "2.5e-4")}
MODELS = (1, 2, 4)
SHORT = {"generalized_alpha": "g-alpha", "radau": "radau"}


def rigid_scene(n):
    """The scene with a rigid crank and slider and the rod in n segments of rod_<n>.h5 (n = 1: the
    midpoint a point probe of the body)."""
    names = ["rod_a", "rod_b"] if n == 1 else rod.node_names(n)
    mid = ("{name: rod_mid, body: rod0, point: [0.3, 0, 0], quantities: [position]}" if n == 1 else
           "{name: rod_mid, node: rod_mid, quantities: [position]}")
    length = 0.3 / n
    segments = "\n".join(
        f"  - {{name: rod{i}, superelement: rod_{n}.h5, placement: {{position: [{0.15 + i * length!r}, 0, 0]}}, "
        f"nodes: {{A: {names[i]}, B: {names[i + 1]}}}}}" for i in range(n))
    return f"""name: slider_crank_2d_rigid_{n}
units: SI
bodies:
  - {{name: crank, type: rigid, mass: 0.37086501, center_of_mass: [0.075, 0, 0],
     inertia: [1.8543251e-05, 0.00070464352, 0.00070464352], points: {{O: [0, 0, 0], A: [0.15, 0, 0]}}, nodes: {{O: O, A: A}}}}
{segments}
  - {{name: slider, type: rigid, mass: 0.033379031, center_of_mass: [0, 0, 0], inertia: [1.0e-12, 1.0e-12, 1.0e-12],
     points: {{S: [0, 0, 0]}}, placement: {{position: [0.45, 0, 0]}}, nodes: {{S: slider}}}}
joints:
  - {{type: revolute, node: O, axis: [0, 0, 1], prescribed: crank_angle}}
  - {{type: revolute, node: rod_a, parent: A, axis: [0, 0, 1]}}
  - {{type: prismatic, node: slider, axis: [1, 0, 0]}}
  - {{type: revolute, node: rod_b, parent: slider, axis: [0, 0, 1]}}
functions:
  crank_angle: {{type: linear, slope: 150}}
analysis: {{type: dynamic, end_time: 0.126, step: 1.0e-5, rho_inf: 0.8}}
outputs:
  animation: false
  probes:
    - {{name: crank, node: O, quantities: [joint]}}
    - {{name: rod_a, node: rod_a, quantities: [position]}}
    - {mid}
    - {{name: rod_b, node: rod_b, quantities: [position]}}
    - {{name: slider, node: slider, quantities: [position, joint]}}
"""


def bodies(n):
    return "1 body  " if n == 1 else f"{n} bodies"


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"peer_slider_crank: {' '.join(cmd)} failed: {r.stderr.strip()}")
    return r.stdout


def prepare(a, solve, reduce):
    """The parts (the example's 2-segment rod, a 4-segment one with the same modes and stiffening),
    the scenes and femb's reference."""
    for part in ("crank", "slider", "rod_2"):
        run([reduce, "-q", os.path.join(EX, part + ".yaml"), "-o", os.path.join(a.out, part + ".h5")])
    for n, modes in ((1, 2), (4, 4)):
        rod.write_segment(a.out, n, modes)
        stiffening.apply(os.path.join(a.out, f"rod_{n}.yaml"), True)
        run([reduce, "-q", os.path.join(a.out, f"rod_{n}.yaml"), "-o", os.path.join(a.out, f"rod_{n}.h5")])
    for n in MODELS:
        with open(os.path.join(a.out, f"rigid_{n}.yaml"), "w") as f:
            f.write(rigid_scene(n))
    ref = os.path.join(a.out, "reference_20_bodies")
    if not os.path.exists(os.path.join(ref, "probes.csv")):
        print("peer_slider_crank: the 20-body reference (about 10 s)", flush=True)
        run(["/usr/bin/python3", os.path.join(EX, "make_variant.py"), "20", ref, "5e-6", "2"])
        run([reduce, "-q", os.path.join(ref, "rod_20.yaml"), "-o", os.path.join(ref, "rod_20.h5")])
        run([solve, "-q", os.path.join(ref, "scene.yaml"), "-o", ref, "--threads", "1"])
    return ref


def measure(a, solve, ref, n, h, tol, every, integrator="generalized_alpha"):
    """One row: (steps, iterations per step, best solve time, best wall time, error in %)."""
    out = os.path.join(a.out, f"rigid_{n}_{integrator}_{h}_{tol}_{every}")
    best_solve = best_wall = float("inf")
    for _ in range(a.repeats):
        start = time.time()
        text = run([solve, os.path.join(a.out, f"rigid_{n}.yaml"), "-o", out, "--threads", "1", "--set",
                    f"analysis.step={h}", "--set", f"analysis.tolerance={tol}", "--set",
                    f"analysis.body_matrices_every={every}", "--set", f"analysis.integrator={integrator}"])
        best_wall = min(best_wall, time.time() - start)
        m = re.search(r"solving ([0-9.]+) s.*: (\d+) steps, ([0-9.]+) Newton", text)
        best_solve = min(best_solve, float(m.group(1)))
    cmp = run(["/usr/bin/python3", os.path.join(EX, "deflection.py"), ref, f"run={out}"])
    err = float(re.search(r"= ([0-9.]+)% of the reference peak", cmp).group(1))
    return int(m.group(2)), float(m.group(3)), best_solve, best_wall, err


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("bin")
    ap.add_argument("--out", default="out/peer_slider_crank")
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--png", default="")
    a = ap.parse_args()
    os.environ["OMP_NUM_THREADS"] = os.environ["OPENBLAS_NUM_THREADS"] = "1"
    solve, reduce = os.path.join(a.bin, "femb-solve"), os.path.join(a.bin, "femb-reduce")
    os.makedirs(a.out, exist_ok=True)
    ref = prepare(a, solve, reduce)
    print("model     integrator     step  tolerance  every  steps  its/step  solving [s]  wall [s]  error  counted")
    measured = []  # (integrator, n, h, solve time, counted error)
    for integrator, steps, every in (("generalized_alpha", STEPS, "8"), ("radau", RADAU_STEPS, "1")):
        for n in MODELS:
            rows = [(h, "1e-3", every) + measure(a, solve, ref, n, h, "1e-3", every, integrator) for h in steps[n]]
            for i, (h, tol, ev, count, its, t_solve, wall, err) in enumerate(rows):
                counted = max(r[-1] for r in rows[i:])  # this step and every smaller one
                print(f"{bodies(n)}  {SHORT[integrator]:>9s}  {float(h) * 1e6:6.1f} us  {tol:>9s}  {ev:>5s}  "
                      f"{count:>5d}  {its:8.2f}  {t_solve:11.3f}  {wall:8.3f}  {err:.3f}%  {counted:.3f}%", flush=True)
                measured.append((integrator, n, h, t_solve, counted))
    for h in ("1e-4", "1.4e-4"):
        steps, its, t_solve, wall, err = measure(a, solve, ref, 2, h, "1e-8", "1")
        print(f"2 bodies  {'g-alpha':>9s}  {float(h) * 1e6:6.1f} us  {'1e-8':>9s}  {'1':>5s}  {steps:>5d}  {its:8.2f}"
              f"  {t_solve:11.3f}  {wall:8.3f}  {err:.3f}%  (the defaults)", flush=True)
    print("\nleast solve time reaching a counted error (femb's reference; the peer's figures against the "
          "independent one):")
    print("level   femb [s]  model, integrator, step     peer [s]  peer / femb  target (femb <= peer / 2; "
          "0.1% < 0.1 s)")
    for level in LEVELS:
        hits = [(t, n, h, i) for i, n, h, t, counted in measured if counted <= level]
        peer = PEER_LEAST[level]
        if not hits:
            print(f"{level:4.1f}%   not reached")
            continue
        t, n, h, integrator = min(hits)
        target = 0.1 if peer is None else peer / 2
        ratio = f"{peer / t:11.2f}" if peer else "   not reached"
        print(f"{level:4.1f}%   {t:8.3f}  {bodies(n)}, {SHORT[integrator]:>7s}, {float(h) * 1e6:4.0f} us  "
              f"{(f'{peer:8.3f}' if peer else '       -')}  {ratio}  {'met' if t <= target else 'not met'} "
              f"({target:.4f} s)")
    if a.png:
        plot(measured, a.png)


def plot(measured, png):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(10, 4.8))
    for integrator, n, style in (("generalized_alpha", 1, "^-"), ("generalized_alpha", 2, "o-"),
                                 ("generalized_alpha", 4, "s-"), ("radau", 1, "^--"), ("radau", 2, "o--"),
                                 ("radau", 4, "s--")):
        pts = [(t, c, h) for i, m, h, t, c in measured if m == n and i == integrator]
        ax.plot([p[0] for p in pts], [p[1] for p in pts], style,
                label=f"femb {SHORT[integrator]}, {bodies(n).strip()}")
        for t, c, h in pts:
            ax.annotate(f"{float(h) * 1e6:.0f} us", (t, c), textcoords="offset points", xytext=(4, 4), fontsize=7)
    levels = [lv for lv in LEVELS if PEER_LEAST[lv]]
    ax.plot([PEER_LEAST[lv] for lv in levels], levels, "x", color="tab:red", markersize=9,
            label="peer's least time at each level\n(side by side, independent reference)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("solve time [s], one thread")
    ax.set_ylabel("counted RMS error of the rod midpoint\ndeflection [% of peak], femb's reference")
    ax.set_title("planar slider-crank, 3 revolutions: error against solve time")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="center left", bbox_to_anchor=(1.02, 0.5))
    fig.tight_layout()
    fig.savefig(png, dpi=120)
    print(f"peer_slider_crank: plot {png}")


if __name__ == "__main__":
    main()
