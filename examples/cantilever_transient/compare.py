#!/usr/bin/python3
"""Tip displacement history of runs against a reference run: RMS over time of the distance
between the tips, relative to the reference's largest tip displacement; exit 1 above a run's
tolerance. Optional PNG of the tip deflection against time.

usage: compare.py REFERENCE_DIR LABEL=RUN_DIR[@TOL] ... [--png FILE]
"""
import argparse
import csv
import math
import sys


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
    bad, curves = False, [("reference", ref)]
    for item in a.runs:
        label, run = item.split("=", 1)
        tol = None
        if "@" in run:
            run, tol = run.rsplit("@", 1)
            tol = float(tol)
        hist = load(run)
        err = [math.hypot(x - at(ref, t)[1], y - at(ref, t)[2]) for t, x, y in hist]
        rms = math.sqrt(sum(e * e for e in err) / len(err))
        line = f"{label:>28}: RMS tip error {rms * 1e3:.2f} mm = {rms / peak:.2%} of the largest tip displacement"
        if tol is not None:
            line += f" (tolerance {tol:.1%})"
            if rms > tol * peak:
                line += "  FAIL"
                bad = True
        print(line)
        curves.append((label, hist))
    if a.png:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(7, 4))
        for label, h in curves:
            ax.plot([p[0] for p in h], [p[2] for p in h], label=label, lw=2.5 if label == "reference" else 1.2,
                    ls="-" if label == "reference" else "--")
        ax.set_xlabel("time [s]")
        ax.set_ylabel("tip y [m]")
        ax.set_title("transient cantilever, tip force 0 -> 2500 N in 0.05 s")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(a.png, dpi=120)
        print(f"plot: {a.png}")
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
