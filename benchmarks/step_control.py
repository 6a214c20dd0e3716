#!/usr/bin/python3
"""Run time against error with fixed and error-controlled steps (`step: auto`) on every
dynamic seed case, each with its recommended model (and the few-body stiffened model where the
example has one): the example's fixed step, then `analysis.step=auto` at three step tolerances.
The error is the example's own measure against the example's own reference (RMS over the
history, fraction of the reference's peak), computed by the example's comparison script.

The references come from the examples' run.sh outputs: pass the folder they wrote to (the test
suite's build/example_out, or run `bash examples/<case>/run.sh DIR/<case>`); a case whose
reference is missing is run here first (minutes each).

Wall time: femb-solve on one thread (--threads 1: ratios between the rows are the point), the
median of REPEATS runs; the reduction is not counted.

With --integrator radau every run (the fixed one at the example's step too) takes the Radau IIA
integrator (analysis.integrator=radau), with its own error estimate under step: auto.

usage: step_control.py BIN_DIR [--examples-out DIR] [--tolerances 1e-3,3e-4,1e-4] [--repeats 1]
                       [--cases slider_crank_2d,...] [--integrator radau]
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EX = os.path.join(ROOT, "examples")

# case, model label, scene (EX: example folder, OUT: the example's output folder), --set
# overrides, reference folder (in OUT), comparison script (in EX), its extra arguments.
CASES = [
    ("cantilever_transient", "10 bodies, CoM frames", "EX/scene.yaml", [], "reference_20_bodies",
     "cantilever_transient/compare.py", []),
    ("rotating_beam", "10 bodies", "EX/scene.yaml", [], "reference_20_bodies", "rotating_beam/deflection.py", []),
    ("rotating_beam", "1 body, stiffened", "OUT/1_body_stiffened/scene.yaml", [], "reference_20_bodies",
     "rotating_beam/deflection.py", []),
    ("slider_crank_2d", "10 bodies", "OUT/10_bodies/scene.yaml", [], "reference_20_bodies",
     "slider_crank_2d/deflection.py", []),
    ("slider_crank_2d", "2 bodies, stiffened", "EX/scene.yaml", [], "reference_20_bodies",
     "slider_crank_2d/deflection.py", []),
    ("slider_crank_3d", "10 bodies", "OUT/10_bodies/scene.yaml", [], "reference_20_bodies",
     "slider_crank_2d/deflection.py", []),
    ("spinning_beam", "2 bodies, option B", "EX/scene.yaml", [], "reference_10_bodies", "spinning_beam/compare.py",
     ["--smooth", "0.002"]),
    ("spin_up_beam", "10 bodies, 6 rad/s", "EX/scene.yaml", ["functions.spin.omega=6"], "reference_w6",
     "spin_up_beam/lag.py", []),
    ("spin_up_beam", "1 body, 6 rad/s, stiffened", "OUT/1_body_w6_stiffened/scene.yaml", [], "reference_w6",
     "spin_up_beam/lag.py", []),
]


def solve(bin_dir, scene, out, sets, repeats):
    """Median wall time, steps taken, steps rejected; or None and the failure's last line."""
    times, steps, rejected = [], 0, 0
    for _ in range(repeats):
        start = time.time()
        r = subprocess.run([os.path.join(bin_dir, "femb-solve"), scene, "-o", out, "--threads", "1"] +
                           [a for s in sets for a in ("--set", s)], capture_output=True, text=True)
        times.append(time.time() - start)
        if r.returncode != 0:
            lines = r.stderr.strip().splitlines()
            return None, lines[-1] if lines else f"exit {r.returncode}"
        m = re.search(r"done in [0-9.]+ s[^:]*: (\d+) steps", r.stdout)
        steps = int(m.group(1)) if m else 0
        m = re.search(r"(\d+) steps rejected", r.stdout)
        rejected = int(m.group(1)) if m else 0
    return (statistics.median(times), steps, rejected), None


def error(script, extra, ref, run_dir):
    r = subprocess.run(["/usr/bin/python3", os.path.join(EX, script), ref, f"run={run_dir}"] + extra,
                       capture_output=True, text=True)
    m = re.search(r"= ([0-9.]+)% of the reference peak", r.stdout)
    return float(m.group(1)) if m else float("nan")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("bin_dir")
    ap.add_argument("--examples-out", default=os.path.join(ROOT, "build", "example_out"))
    ap.add_argument("--tolerances", default="1e-3,3e-4,1e-4")
    ap.add_argument("--repeats", type=int, default=1)
    ap.add_argument("--cases", default="")
    ap.add_argument("--work", default="/tmp/femb_step_control")
    ap.add_argument("--integrator", default="", help="analysis.integrator for every run (default: the scene's)")
    a = ap.parse_args()
    wanted = set(a.cases.split(",")) if a.cases else None
    tolerances = [t for t in a.tolerances.split(",") if t]
    print(f"{'case':<21} {'model':<27} {'steps':<16} {'taken':>7} {'rejected':>8} {'time [s]':>9} {'RMS error':>9}")
    for case, label, scene, sets, ref, script, extra in CASES:
        if wanted and case not in wanted:
            continue
        out = os.path.join(a.examples_out, case)
        if not os.path.isdir(os.path.join(out, ref)):
            print(f"({case}: running examples/{case}/run.sh for its reference)", flush=True)
            subprocess.run(["bash", os.path.join(EX, case, "run.sh"), out], check=True, capture_output=True,
                           env=dict(os.environ, FEMB_BIN=a.bin_dir))
        scene_path = scene.replace("EX/", os.path.join(EX, case) + "/").replace("OUT/", out + "/")
        for tol in [None] + tolerances:
            name = "fixed" if tol is None else f"auto_{tol}"
            run_dir = os.path.join(a.work, a.integrator or "scene", case,
                                   label.replace(" ", "_").replace(",", "").replace("/", ""), name)
            os.makedirs(run_dir, exist_ok=True)
            run_sets = sets + ([] if tol is None else ["analysis.step=auto", f"analysis.step_tolerance={tol}"])
            if a.integrator:
                run_sets = run_sets + [f"analysis.integrator={a.integrator}"]
            measured, failure = solve(a.bin_dir, scene_path, run_dir, run_sets, a.repeats)
            setting = "fixed (example)" if tol is None else f"auto, tol {tol}"
            if failure:
                print(f"{case:<21} {label:<27} {setting:<16} failed: {failure}", flush=True)
                continue
            wall, steps, rejected = measured
            err = error(script, extra, os.path.join(out, ref), run_dir)
            print(f"{case:<21} {label:<27} {setting:<16} {steps:>7} {rejected:>8} {wall:9.2f} {err:8.2f}%", flush=True)


if __name__ == "__main__":
    sys.exit(main())
