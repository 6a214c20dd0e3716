#!/usr/bin/python3
"""Leaf spring: deflection and shortening of the guided end (probe guided_end, pseudo-time = force
in N) of femb runs against CalculiX's NLGEOM reference (ccx.csv), at every load step; exit 1 when a
run's largest relative error exceeds its tolerance. Optional PNG.

usage: compare.py CCX_CSV LABEL=RUN_DIR[@TOL] ... [--png FILE]
"""
import argparse
import csv
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
import histories  # noqa: E402


def load_run(run):
    t, x, z = histories.load_columns(run, "time", "guided_end.position.x", "guided_end.position.z")
    return {round(ti, 9): (zi - z[0], x[0] - xi) for ti, xi, zi in zip(t, x, z) if ti > 0}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("ccx")
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--png")
    a = ap.parse_args()
    with open(a.ccx) as f:
        ref = [(float(r["force"]), float(r["deflection"]), float(r["shortening"])) for r in csv.DictReader(f)]
    print(f"reference {a.ccx} (CalculiX NLGEOM): at {ref[-1][0]:g} N deflection {ref[-1][1] * 1e3:.4f} mm, "
          f"shortening {ref[-1][2] * 1e3:.5f} mm")
    ok, curves = True, []
    for item in a.runs:
        label, run, tol = histories.parse_run(item)
        got = load_run(run)
        worst_w = worst_s = 0.0
        for F, w, s in ref:
            if round(F, 9) not in got:
                print(f"{label}: no result at {F:g} N", file=sys.stderr)
                ok = False
                continue
            gw, gs = got[round(F, 9)]
            worst_w = max(worst_w, abs(gw - w) / abs(w))
            worst_s = max(worst_s, abs(gs - s) / abs(s))
        line = f"{label:>34}: largest error over the stroke: deflection {worst_w:.3%}, shortening {worst_s:.3%}"
        if tol is not None:
            line += f" (tolerance {tol:.1%})"
            if max(worst_w, worst_s) > tol:
                line += "  FAIL"
                ok = False
        print(line)
        forces = sorted(got)
        curves.append((label, forces, [got[F] for F in forces]))
    if a.png:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
        F = [r[0] for r in ref]
        left.plot(F, [r[1] * 1e3 for r in ref], "k-", lw=2.5, label="CalculiX NLGEOM (reference)")
        right.plot(F, [r[2] * 1e3 for r in ref], "k-", lw=2.5, label="CalculiX NLGEOM (reference)")
        for label, forces, values in curves:
            left.plot(forces, [v[0] * 1e3 for v in values], "o--", ms=4, label=label)
            right.plot(forces, [v[1] * 1e3 for v in values], "o--", ms=4, label=label)
        left.set(xlabel="force [N]", ylabel="deflection [mm]", title="guided end across the leaf")
        right.set(xlabel="force [N]", ylabel="shortening [mm]", title="guided end along the leaf")
        for ax in (left, right):
            ax.grid(True, alpha=0.3)
            ax.legend(fontsize=8)
        fig.suptitle("clamped-guided leaf spring 50 x 10 x 0.5 mm, one superelement")
        fig.tight_layout()
        fig.savefig(a.png, dpi=120)
        print(f"plot: {a.png}")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
