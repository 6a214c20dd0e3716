#!/usr/bin/python3
"""Cross-flexure pivot: rotor rotation about y against the moment (probe rotor, pseudo-time k =
moment k M/STEPS) of femb runs, against the full nonlinear reference (cross_flexure_reference:
moment at prescribed angles, interpolated), and the rotor centre's shift. Exit 1 when a run's
largest relative rotation error exceeds its tolerance. Optional PNG.

usage: compare.py REFERENCE_CSV MOMENT STEPS LABEL=RUN_DIR[@TOL] ... [--png FILE]
"""
import argparse
import csv
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
import histories  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("reference")
    ap.add_argument("moment", type=float)
    ap.add_argument("steps", type=int)
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--png")
    a = ap.parse_args()
    with open(a.reference) as f:
        ref = [(float(r["theta"]), float(r["moment"]), float(r["shift_x"]), float(r["shift_z"])) for r in csv.DictReader(f)]
    ref = [(0.0, 0.0, 0.0, 0.0)] + ref
    moments = [r[1] for r in ref]
    theta_of = lambda M: histories.interpolate(moments, [r[0] for r in ref], M)  # noqa: E731
    shift_of = lambda M: histories.interpolate(moments, [r[2] for r in ref], M)  # noqa: E731
    print(f"reference {a.reference} (full Green-Lagrange model, Newton): {ref[-1][1]:.4f} N m at {ref[-1][0]:.3f} rad")
    ok, curves = True, []
    for item in a.runs:
        label, run, tol = histories.parse_run(item)
        t, qw, qy, x = histories.load_columns(run, "time", "rotor.rotation.w", "rotor.rotation.y", "rotor.position.x")
        rows = [(ti * a.moment / a.steps, 2 * math.atan2(qyi, qwi), xi - x[0]) for ti, qwi, qyi, xi in zip(t, qw, qy, x) if ti > 0]
        if rows[-1][0] > moments[-1] + 1e-12:
            sys.exit(f"{a.reference}: reaches {moments[-1]:.4f} N m only; the runs go to {rows[-1][0]:.4f}")
        err = max(abs(th - theta_of(M)) / theta_of(M) for M, th, _ in rows)
        shift = max(abs(s - shift_of(M)) for M, _, s in rows) / max(abs(shift_of(M)) for M, _, _ in rows)
        line = (f"{label:>28}: at {rows[-1][0]:.2f} N m {rows[-1][1]:.4f} rad (reference {theta_of(rows[-1][0]):.4f}); "
                f"largest rotation error {err:.2%}, centre shift error {shift:.2%} of its largest")
        if tol is not None:
            line += f" (tolerance {tol:.0%})"
            if err > tol:
                line += "  FAIL"
                ok = False
        if len(rows) < a.steps:
            line += f"  stopped after {len(rows)} of {a.steps} steps"
            ok = False
        print(line)
        curves.append((label, [r[0] for r in rows], [r[1] for r in rows]))
    if a.png:
        curves.insert(0, ("full model (reference)", [r[1] for r in ref], [r[0] for r in ref]))
        histories.plot(curves, a.png, "moment [N m]", "rotor rotation [rad]",
                       "cross-flexure pivot, two 50 x 10 x 0.5 mm steel leaves", y_scale=1.0)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
