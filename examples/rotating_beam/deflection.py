#!/usr/bin/python3
"""Tip deflection of the rotating beam relative to the line through the hinge and the beam's
current centre of mass (the mean of its equal bodies' centres of mass, results.h5
bodies/<name>/center_of_mass; files written before it existed: the mean of the bodies'
centre-of-mass floating frames, i.e. of their midpoints, which for one body deflects 0.31 of the
tip where the centre of mass deflects 0.375), positive
ahead in the direction of rotation; runs against a reference (RMS over time, relative to the
reference's largest deflection); exit 1 above a run's tolerance; optional PNG.

usage: deflection.py REFERENCE_DIR LABEL=RUN_DIR[@TOL] ... [--png FILE]
"""
import argparse
import os
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
import histories  # noqa: E402


def load(run):
    f = h5py.File(f"{run}/results.h5", "r")
    t = f["time"][:]
    names = [n.decode() if isinstance(n, bytes) else n for n in f["nodes/names"][:]]
    pos = f["nodes/position"][:].reshape(len(t), len(names), 3)
    tip = max((n for n in names if n.startswith("n")), key=lambda n: int(n[1:]))
    hinge, end = pos[:, names.index("n0")], pos[:, names.index(tip)]
    key = "center_of_mass" if all("center_of_mass" in f[f"bodies/{b}"] for b in f["bodies"]) else "floating_frame"
    com = np.mean([f[f"bodies/{b}/{key}"][:, :3] for b in f["bodies"]], axis=0)
    u = com - hinge
    u /= np.linalg.norm(u, axis=1)[:, None]
    r = end - hinge
    return t, u[:, 0] * r[:, 1] - u[:, 1] * r[:, 0]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("reference")
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--png")
    a = ap.parse_args()
    t_ref, w_ref = load(a.reference)
    peak = np.abs(w_ref).max()
    print(f"reference {a.reference}: tip deflection {w_ref.min() * 1e3:+.3f} .. {w_ref.max() * 1e3:+.3f} mm")
    ok, curves = True, [("reference", t_ref, w_ref)]
    for item in a.runs:
        label, run, tol = histories.parse_run(item)
        t, w = load(run)
        err = list(w - np.interp(t, t_ref, w_ref))
        ok &= histories.check(label, err, peak, tol, detail=f"tip deflection {w.min() * 1e3:+.3f} .. {w.max() * 1e3:+.3f} mm, ")
        curves.append((label, t, w))
    if a.png:
        histories.plot(curves, a.png, "time [s]", "tip deflection [mm]", "rotating beam (100 rad/s), 50 N tip pulse for 0.01 s")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
