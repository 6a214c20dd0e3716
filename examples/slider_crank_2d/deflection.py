#!/usr/bin/python3
"""Rod midpoint deflection of the slider-crank: the distance of probe rod_mid from the line
through rod_a and rod_b (positive to the left of a -> b, in the x-y plane), against the crank
angle. Compares runs with a reference run, prints extremes and RMS errors, writes a PNG.

usage: deflection.py REFERENCE_DIR [LABEL=RUN_DIR[@TOL] ...] [--png FILE]
Exit 1 when a run's RMS error over the whole history exceeds its TOL (a fraction of the
reference's peak deflection).
"""
import argparse
import csv
import math
import sys


def load(run_dir):
    with open(f"{run_dir}/probes.csv") as f:
        rows = list(csv.DictReader(f))
    angle, w = [], []
    for r in rows:
        a = [float(r[f"rod_a.position.{c}"]) for c in "xy"]
        b = [float(r[f"rod_b.position.{c}"]) for c in "xy"]
        m = [float(r[f"rod_mid.position.{c}"]) for c in "xy"]
        d = [b[0] - a[0], b[1] - a[1]]
        length = math.hypot(*d)
        # signed distance: (m - a) . n, n = ez x d / |d|
        w.append(((m[0] - a[0]) * -d[1] + (m[1] - a[1]) * d[0]) / length)
        angle.append(float(r["crank.joint.0"]))
    return angle, w


def interpolate(xs, ys, x):
    lo, hi = 0, len(xs) - 1
    if x <= xs[0]:
        return ys[0]
    if x >= xs[-1]:
        return ys[-1]
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if xs[mid] <= x:
            lo = mid
        else:
            hi = mid
    t = (x - xs[lo]) / (xs[hi] - xs[lo])
    return ys[lo] + t * (ys[hi] - ys[lo])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("reference")
    ap.add_argument("runs", nargs="*")
    ap.add_argument("--png")
    a = ap.parse_args()
    ref_angle, ref_w = load(a.reference)
    peak = max(abs(v) for v in ref_w)
    print(f"reference {a.reference}: midpoint deflection {min(ref_w) * 1e3:+.4f} .. {max(ref_w) * 1e3:+.4f} mm")
    curves = [("reference", ref_angle, ref_w)]
    bad = False
    for item in a.runs:
        label, run = item.split("=", 1)
        tol = None
        if "@" in run:
            run, tol = run.rsplit("@", 1)
            tol = float(tol)
        angle, w = load(run)
        err = [wi - interpolate(ref_angle, ref_w, ai) for ai, wi in zip(angle, w)]
        rms = math.sqrt(sum(e * e for e in err) / len(err))
        print(f"{label:>12}: {min(w) * 1e3:+.4f} .. {max(w) * 1e3:+.4f} mm, RMS error {rms * 1e3:.4f} mm "
              f"= {rms / peak:.2%} of the reference peak" + (f" (tolerance {tol:.1%})" if tol else ""))
        if tol is not None and rms > tol * peak:
            print(f"{label}: RMS error above the tolerance {tol:.1%} of the peak", file=sys.stderr)
            bad = True
        curves.append((label, angle, w))
    if a.png:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(7, 4))
        for label, angle, w in curves:
            ax.plot(angle, [v * 1e3 for v in w], label=label, lw=2.5 if label == "reference" else 1.2,
                    ls="-" if label == "reference" else "--")
        ax.set_xlabel("crank angle [rad]")
        ax.set_ylabel("rod midpoint deflection [mm]")
        ax.set_title("2D slider-crank, flexible rod (thesis 5.2)")
        ax.grid(True, alpha=0.3)
        ax.legend()
        fig.tight_layout()
        fig.savefig(a.png, dpi=120)
        print(f"plot: {a.png}")
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
