#!/usr/bin/python3
"""Rod midpoint deflection of the slider-crank: the distance of probe rod_mid from the line
through rod_a and rod_b along the rod's y axis, y = z x (b - a) / |z x (b - a)| (the horizontal
normal of the rod: in the planar mechanism, to the left of a -> b in the x-y plane; in the
spatial one, the rod's local y axis, which its universal joint keeps horizontal), against the
crank angle. Compares runs with a reference run, prints extremes and RMS errors, writes a PNG.

usage: deflection.py REFERENCE_DIR [LABEL=RUN_DIR[@TOL] ...] [--png FILE]
Exit 1 when a run's RMS error over the whole history exceeds its TOL (a fraction of the
reference's peak deflection).
"""
import argparse
import csv
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
import histories  # noqa: E402


def load(run_dir):
    with open(f"{run_dir}/probes.csv") as f:
        rows = list(csv.DictReader(f))
    angle, w = [], []
    for r in rows:
        a = [float(r[f"rod_a.position.{c}"]) for c in "xy"]
        b = [float(r[f"rod_b.position.{c}"]) for c in "xy"]
        m = [float(r[f"rod_mid.position.{c}"]) for c in "xy"]
        d = [b[0] - a[0], b[1] - a[1]]
        # signed distance: (m - a) . y, y = ez x d / |ez x d| (no z component)
        w.append(((m[0] - a[0]) * -d[1] + (m[1] - a[1]) * d[0]) / math.hypot(*d))
        angle.append(float(r["crank.joint.0"]))
    return angle, w


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("reference")
    ap.add_argument("runs", nargs="*")
    ap.add_argument("--png")
    ap.add_argument("--title", default="2D slider-crank, flexible rod (thesis 5.2)")
    a = ap.parse_args()
    ref_angle, ref_w = load(a.reference)
    peak = max(abs(v) for v in ref_w)
    print(f"reference {a.reference}: midpoint deflection {min(ref_w) * 1e3:+.4f} .. {max(ref_w) * 1e3:+.4f} mm")
    curves = [("reference", ref_angle, ref_w)]
    ok = True
    for item in a.runs:
        label, run, tol = histories.parse_run(item)
        angle, w = load(run)
        err = [wi - histories.interpolate(ref_angle, ref_w, ai) for ai, wi in zip(angle, w)]
        ok &= histories.check(label, err, peak, tol, detail=f"{min(w) * 1e3:+.4f} .. {max(w) * 1e3:+.4f} mm, ")
        curves.append((label, angle, w))
    if a.png:
        histories.plot(curves, a.png, "crank angle [rad]", "rod midpoint deflection [mm]",
                       a.title)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
