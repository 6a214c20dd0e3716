#!/usr/bin/python3
"""Modal derivatives: error against run time on the cross-flexure pivot (examples/cross_flexure):
each leaf in 1 or 3 bodies with modal derivatives, or 1, 3 or 10 linear bodies. Error: the largest
relative error of the rotor rotation over the 12 load steps (to 0.6 N m, 0.63 rad) against the
full Green-Lagrange model (build/bin/cross_flexure_reference). Time: median wall time of
femb-solve over REPEATS runs (reduction not counted; it is printed). Prints the table, writes a PNG.

usage: flexure_error_vs_time.py BIN_DIR [--repeats 3] [--work DIR] [--png FILE]
"""
import argparse
import math
import os
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EX = os.path.join(ROOT, "examples", "cross_flexure")
sys.path.insert(0, os.path.join(ROOT, "examples", "common"))
import histories  # noqa: E402

MOMENT, STEPS = 0.6, 12


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("bin_dir")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--work", default="/tmp/femb_flexure_error_vs_time")
    ap.add_argument("--png", default="flexure_error_vs_time.png")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    rows = []
    reference = os.path.join(a.work, "reference.csv")
    for n, kind in ((1, "derivatives"), (3, "derivatives"), (1, "linear"), (3, "linear"), (10, "linear")):
        out = os.path.join(a.work, f"{n}_{kind}")
        subprocess.run(["/usr/bin/python3", os.path.join(EX, "make_variant.py"), out, str(n), kind, repr(MOMENT), str(STEPS)],
                       check=True, capture_output=True)
        start = time.time()
        subprocess.run([os.path.join(a.bin_dir, "femb-reduce"), "-q", os.path.join(out, "seg.yaml"), "-o",
                        os.path.join(out, "seg.h5")], check=True)
        reduce_time = time.time() - start
        if not os.path.exists(reference):
            thetas = ",".join(f"{0.05 * k:.2f}" for k in range(1, 16))
            subprocess.run([os.path.join(a.bin_dir, "cross_flexure_reference"), os.path.join(out, "seg.yaml"), reference,
                            thetas, "0.05"], check=True, capture_output=True)
        times = []
        for _ in range(a.repeats):
            start = time.time()
            subprocess.run([os.path.join(a.bin_dir, "femb-solve"), "-q", os.path.join(out, "scene.yaml"), "-o", out], check=True)
            times.append(time.time() - start)
        ref = [(0.0, 0.0)] + [tuple(map(float, line.split(",")[:2])) for line in open(reference).read().split("\n")[1:] if line]
        t, qw, qy = histories.load_columns(out, "time", "rotor.rotation.w", "rotor.rotation.y")
        err = 0.0
        for ti, w, y in zip(t, qw, qy):
            if ti <= 0:
                continue
            M = ti * MOMENT / STEPS
            expected = histories.interpolate([r[1] for r in ref], [r[0] for r in ref], M)
            err = max(err, abs(2 * math.atan2(y, w) - expected) / expected)
        label = f"{n} bod{'y' if n == 1 else 'ies'}, {'modal derivatives' if kind == 'derivatives' else 'linear'}"
        rows.append((label, statistics.median(times), err, reduce_time))
        print(f"{label:<32} femb-solve {rows[-1][1]:6.2f} s (median of {a.repeats})  rotation error {err:7.2%}"
              f"   (reduction {reduce_time:.1f} s)", flush=True)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for label, t, e, _ in rows:
        ax.scatter([t], [e * 100], label=label)
        ax.annotate(label, (t, e * 100), fontsize=7, xytext=(3, 3), textcoords="offset points")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time of femb-solve [s] (median)")
    ax.set_ylabel("largest rotation error [%]")
    ax.set_title("cross-flexure pivot to 0.63 rad: error vs time per leaf model")
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(a.png, dpi=120)
    print(f"plot: {a.png}")


if __name__ == "__main__":
    main()
