#!/usr/bin/python3
"""Tip displacement history of runs against a reference run: RMS over time of the distance
between the tips, relative to the reference's largest tip displacement; exit 1 above a run's
tolerance. Optional PNG of the tip deflection against time.

usage: compare.py REFERENCE_DIR LABEL=RUN_DIR[@TOL] ... [--png FILE]
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
    return [(float(r["time"]), float(r["tip.position.x"]), float(r["tip.position.y"])) for r in rows]


def at(history, t):
    lo, hi = 0, len(history) - 1
    if t <= history[0][0]:
        return history[0]
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if history[mid][0] <= t:
            lo = mid
        else:
            hi = mid
    (t0, x0, y0), (t1, x1, y1) = history[lo], history[hi]
    s = (t - t0) / (t1 - t0) if t1 > t0 else 0.0
    return t, x0 + s * (x1 - x0), y0 + s * (y1 - y0)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("reference")
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--png")
    a = ap.parse_args()
    ref = load(a.reference)
    x_free = ref[0][1]
    peak = max(math.hypot(x - x_free, y) for _, x, y in ref)
    print(f"reference {a.reference}: largest tip displacement {peak:.4f} m")
    ok, curves = True, [("reference", [p[0] for p in ref], [p[2] for p in ref])]
    for item in a.runs:
        label, run, tol = histories.parse_run(item)
        hist = load(run)
        err = [math.hypot(x - at(ref, t)[1], y - at(ref, t)[2]) for t, x, y in hist]
        ok &= histories.check(label, err, peak, tol, detail="tip ")
        curves.append((label, [p[0] for p in hist], [p[2] for p in hist]))
    if a.png:
        histories.plot(curves, a.png, "time [s]", "tip y [m]", "transient cantilever, tip force 0 -> 2500 N in 0.05 s",
                       y_scale=1.0)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
