#!/usr/bin/python3
"""Stress in the slider-crank's rod: how the recovered stress converges with the
number of bodies, beside the midpoint deflection. For the rod in 2, 4 and 10 linear bodies, 2
bodies with geometric stiffening (whose files add the inertia load cases' stresses) and the
20-body reference, all at h = 10 us, three crank revolutions with outputs.stresses and a stress
probe on the rod's top fibre at its midpoint; and the reference again at 5 us. Prints per model:
the peak von Mises stress in the rod over the run (results.h5 bodies/<rod i>/max_von_mises) and
its error against the reference's, the RMS error of the midpoint fibre's axial stress history and
of the midpoint deflection history (both as fractions of the reference's peak), and the solve
time. The reference is at the models' step: the stress history carries high-frequency vibration
of the rod whose phase the step changes (the 5 us row shows by how much), which would otherwise
hide the convergence in the number of bodies.

usage: stress_convergence.py [OUTDIR]     (default out/slider_crank_2d_stress; ~2 min)
"""
import csv
import os
import subprocess
import sys
import time

import h5py

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, "..", "common"))
import histories  # noqa: E402
from deflection import load as load_deflection  # noqa: E402

bin_dir = os.environ.get("FEMB_BIN", os.path.join(here, "..", "..", "build", "bin"))
out = sys.argv[1] if len(sys.argv) > 1 else "out/slider_crank_2d_stress"


def run(label, n, step, stiffened=False):
    d = os.path.join(out, label)
    args = [sys.executable, os.path.join(here, "make_variant.py"), str(n), d, repr(step)]
    subprocess.run(args + (["--stiffening"] if stiffened else []), check=True, stdout=subprocess.DEVNULL)
    subprocess.run([os.path.join(bin_dir, "femb-reduce"), "-q", f"rod_{n}.yaml", "-o", f"rod_{n}.h5"], cwd=d, check=True)
    scene = os.path.join(d, "scene.yaml")
    text = open(scene).read()
    # The midpoint is the B end of body n/2 - 1 at x = 0.3; its top fibre is 3 mm above the axis.
    text = text.replace("outputs:\n  probes:\n",
                        "outputs:\n  stresses: true\n  animation: false\n  probes:\n"
                        f"    - {{name: mid_top, body: rod{n // 2 - 1}, point: [0.3, 0.003, 0], quantities: [stress]}}\n")
    open(scene, "w").write(text)
    start = time.time()
    subprocess.run([os.path.join(bin_dir, "femb-solve"), "-q", scene, "-o", os.path.join(d, "out")], check=True)
    seconds = time.time() - start
    with h5py.File(os.path.join(d, "out", "results.h5"), "r") as f:
        peak = max(f[f"bodies/rod{i}/max_von_mises"][()].max() for i in range(n))
    with open(os.path.join(d, "out", "probes.csv")) as f:
        rows = list(csv.DictReader(f))
    angle = [float(r["crank.joint.0"]) for r in rows]
    sigma = [float(r["mid_top.stress.xx"]) for r in rows]
    return {"label": label, "peak": peak, "angle": angle, "sigma": sigma, "seconds": seconds,
            "deflection": load_deflection(os.path.join(d, "out"))}


def rms_error(model, reference, key):
    ref_angle, ref_values = (reference["angle"], reference[key]) if key == "sigma" else reference["deflection"]
    angle, values = (model["angle"], model[key]) if key == "sigma" else model["deflection"]
    err = [v - histories.interpolate(ref_angle, ref_values, a) for a, v in zip(angle, values)]
    peak = max(abs(v) for v in ref_values)
    return (sum(e * e for e in err) / len(err)) ** 0.5 / peak


def main():
    os.makedirs(out, exist_ok=True)
    reference = run("reference_20_bodies", 20, 1e-5)
    models = [run("2_bodies", 2, 1e-5), run("4_bodies", 4, 1e-5), run("10_bodies", 10, 1e-5),
              run("2_bodies_stiffened", 2, 1e-5, stiffened=True), run("20_bodies_at_5_us", 20, 5e-6)]
    print(f"reference (20 bodies, h = 10 us): peak von Mises in the rod {reference['peak'] / 1e6:.2f} MPa, "
          f"midpoint top fibre {min(reference['sigma']) / 1e6:+.2f} .. {max(reference['sigma']) / 1e6:+.2f} MPa, "
          f"{reference['seconds']:.1f} s")
    print("| model | peak von Mises [MPa] | its error | RMS error, midpoint stress | RMS error, midpoint deflection | solve [s] |")
    print("|---|---|---|---|---|---|")
    for m in models:
        print(f"| {m['label'].replace('_', ' ')} | {m['peak'] / 1e6:.2f} | {100 * (m['peak'] / reference['peak'] - 1):+.1f}% | "
              f"{100 * rms_error(m, reference, 'sigma'):.2f}% | {100 * rms_error(m, reference, 'deflection'):.2f}% | "
              f"{m['seconds']:.1f} |")


if __name__ == "__main__":
    main()
