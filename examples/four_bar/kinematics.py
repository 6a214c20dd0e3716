#!/usr/bin/python3
"""The rigid four-bar against its closed-form kinematics: the coupler point C and the crank
point B from the crank angle (make_scenes.coupler_point: the intersection of |C - B| = b and
|C - D| = c). Prints the largest position error; exit 1 above TOL (metres).

usage: kinematics.py RUN_DIR [TOL]
"""
import csv
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_scenes  # noqa: E402


def main():
    run = sys.argv[1]
    tol = float(sys.argv[2]) if len(sys.argv) > 2 else 1e-8
    with open(f"{run}/probes.csv") as f:
        rows = list(csv.DictReader(f))
    error = angle_error = 0.0
    _, C0 = make_scenes.coupler_point(0.0)
    psi0 = math.atan2(C0[1], C0[0] - make_scenes.d)
    for r in rows:
        B, C = make_scenes.coupler_point(float(r["crank.joint.0"]))
        for name, point in (("rod_a", B), ("rod_b", C)):
            x, y = float(r[f"{name}.position.x"]), float(r[f"{name}.position.y"])
            error = max(error, math.hypot(x - point[0], y - point[1]))
        # The rocker's angle from t = 0 (the probe of the cut joint at D) against the closed form.
        psi = math.atan2(C[1], C[0] - make_scenes.d) - psi0
        angle_error = max(angle_error, abs(float(r["rocker.joint.0"]) - psi))
    turns = float(rows[-1]["crank.joint.0"]) / (2 * math.pi)
    print(f"rigid four-bar, {turns:.2f} crank turns, {len(rows)} outputs: largest error of B and C against the closed "
          f"form {error:.2e} m, of the rocker angle {angle_error:.2e} rad (tolerance {tol:g} m, rad)")
    sys.exit(0 if max(error, angle_error) <= tol else 1)


if __name__ == "__main__":
    main()
