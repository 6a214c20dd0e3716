#!/usr/bin/python3
"""Tip deflection of the spin-up beam in the hub frame (y_hub = -sin(theta) x + cos(theta) y,
theta the hub angle), runs against a reference: RMS over time relative to the reference's
largest |deflection|; exit 1 above a run's tolerance; optional PNG.

usage: lag.py REFERENCE_DIR LABEL=RUN_DIR[@TOL] ... [--png FILE]
"""
import argparse
import csv
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
import histories  # noqa: E402


def load(run):
    with open(f"{run}/probes.csv") as f:
        rows = list(csv.DictReader(f))
    t, w = [], []
    for r in rows:
        th = float(r["hub.joint.0"])
        x, y = float(r["tip.position.x"]), float(r["tip.position.y"])
        t.append(float(r["time"]))
        w.append(-math.sin(th) * x + math.cos(th) * y)
    return t, w


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("reference")
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--png")
    a = ap.parse_args()
    t_ref, w_ref = load(a.reference)
    peak = max(abs(v) for v in w_ref)
    print(f"reference {a.reference}: tip deflection in the hub frame {min(w_ref):+.4f} .. {max(w_ref):+.4f} m, "
          f"|w| at the end {abs(w_ref[-1]) * 1e3:.2f} mm")
    ok, curves = True, [("reference", t_ref, w_ref)]
    for item in a.runs:
        label, run, tol = histories.parse_run(item)
        t, w = load(run)
        ref_at = {round(ti, 6): wi for ti, wi in zip(t_ref, w_ref)}
        err = [wi - ref_at[round(ti, 6)] for ti, wi in zip(t, w) if round(ti, 6) in ref_at]
        ok &= histories.check(label, err, peak, tol, detail=f"{min(w):+.4f} .. {max(w):+.4f} m, ")
        curves.append((label, t, w))
    if a.png:
        histories.plot(curves, a.png, "time [s]", "tip deflection in the hub frame [m]", "spin-up beam", y_scale=1.0)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
