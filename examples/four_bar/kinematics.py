#!/usr/bin/python3
"""The rigid four-bar against its closed-form kinematics: the coupler point C and the crank
point B from the crank angle (make_scenes.coupler_point: the intersection of |C - B| = b and
|C - D| = c). Prints the largest position error; exit 1 above TOL (metres).

Then the ground reactions against the momentum balance: with no other load, the forces of the
ground at A (the driven tree joint's support reaction) and at D (the cut joint's, from its
multipliers) add up to the rate of the links' linear momentum, d/dt of results.h5's
/energy/linear_momentum by central differences between equally spaced outputs, from the second
output on (the reactions come from each output state's consistent accelerations and multipliers,
not index-3 generalized-alpha's, which start with an oscillation damped by rho_inf). Exit 1 above
5e-5 of the largest reaction.

usage: kinematics.py RUN_DIR [TOL]
"""
import csv
import math
import os
import sys

import h5py
import numpy as np

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
    with h5py.File(f"{run}/results.h5", "r") as f:
        t = f["/time"][:]
        p = f["/energy/linear_momentum"][:]
        cut = f["/loops/reaction"][:]
    ground = np.array([[float(r[f"ground_{n}.reaction.f{c}"]) for n in "ad" for c in "xy"] for r in rows])
    peak = np.max(np.abs(ground))
    force = ground[:, 0:2] + ground[:, 2:4]
    rate = (p[2:, 0:2] - p[:-2, 0:2]) / (t[2:] - t[:-2])[:, None]
    gap = np.max(np.abs(force[1:-1] - rate), axis=1) / peak
    dt = np.diff(t)
    uniform = np.abs(dt[1:] - dt[:-1]) < 1e-9 * dt[1:]
    early = t[1:-1] < 2e-3
    balance, start = np.max(gap[uniform]), np.max(gap[uniform & early])
    same = np.max(np.abs(cut[:, 0:2] - ground[:, 2:4])) / peak  # the probes.csv round-off
    print(f"ground reactions at A (tree) and D (cut joint): peak {peak:.4g} N; their sum against the rate of the linear "
          f"momentum {balance:.2e} of the peak from the second output on (tolerance 5e-5; {start:.1e} in the first 2 ms); "
          f"/loops/reaction against the D probe {same:.1e}")
    sys.exit(0 if max(error, angle_error) <= tol and balance <= 5e-5 and same <= 1e-9 else 1)


if __name__ == "__main__":
    main()
