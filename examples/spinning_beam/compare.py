#!/usr/bin/python3
"""Angular velocity about the vertical axis at the base of Cardona's beam (probe base), runs
against a reference run: RMS over time of the difference, relative to the reference's largest
value; exit 1 above a run's tolerance. Also prints the RMS distance between the tip positions
(the beam's overall motion). Optional PNG of the histories.

usage: compare.py REFERENCE_DIR LABEL=RUN_DIR[@TOL] ... [--until T] [--png FILE]
--until T: only the history up to time T (e.g. before the tip impulse).
--smooth W: compare centred moving averages over W seconds (after a hammer blow the base's own
rotation rate carries every bending mode the model and the step resolve, so its pointwise value
does not converge; its average over a bending period does).
"""
import argparse
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
import histories  # noqa: E402

COLUMN = "base.angular_velocity.z"
LENGTH = 0.14142


def moving_average(t, w, width):
    """Centred moving average over `width` (trapezoidal rule, window clipped at the ends)."""
    area = [0.0]
    for k in range(1, len(t)):
        area.append(area[-1] + 0.5 * (w[k] + w[k - 1]) * (t[k] - t[k - 1]))

    def integral(x):
        return histories.interpolate(t, area, x)

    out = []
    for tk in t:
        lo, hi = max(t[0], tk - width / 2), min(t[-1], tk + width / 2)
        out.append((integral(hi) - integral(lo)) / (hi - lo) if hi > lo else 0.0)
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("reference")
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--png")
    ap.add_argument("--until", type=float, default=float("inf"))
    ap.add_argument("--smooth", type=float, default=0.0)
    a = ap.parse_args()

    def load(run):
        t, w = histories.load_columns(run, "time", COLUMN)
        if a.smooth > 0:
            w = moving_average(t, w, a.smooth)
        # a clipped window at either end is no average over W: leave those times out
        lo, hi = (t[0] + a.smooth / 2, t[-1] - a.smooth / 2) if a.smooth > 0 else (t[0], t[-1])
        keep = [k for k, tk in enumerate(t) if lo <= tk <= min(hi, a.until)]
        return [t[k] for k in keep], [w[k] for k in keep]

    ref_t, ref_w = load(a.reference)
    if a.until != float("inf") or a.smooth > 0:
        print(("" if a.until == float("inf") else f"up to t = {a.until} s") +
              ("" if a.smooth == 0 else f" moving average over {a.smooth * 1e3:g} ms") + ":")
    peak = max(abs(w) for w in ref_w)
    print(f"reference {a.reference}: base angular velocity about z {min(ref_w):+.2f} .. {max(ref_w):+.2f} rad/s, "
          f"{ref_w[-1]:+.2f} at the end")
    ok, curves, tip_errors = True, [("reference", ref_t, ref_w)], []

    def tip_error(run):
        cols = [f"tip.position.{c}" for c in "xyz"]
        rt, *rx = histories.load_columns(a.reference, "time", *cols)
        t, *x = histories.load_columns(run, "time", *cols)
        sq = [sum((x[c][k] - histories.interpolate(rt, rx[c], tk))**2 for c in range(3))
              for k, tk in enumerate(t) if tk <= a.until]
        return math.sqrt(sum(sq) / len(sq))

    for item in a.runs:
        label, run, tol = histories.parse_run(item)
        t, w = load(run)
        err = [wi - histories.interpolate(ref_t, ref_w, ti) for ti, wi in zip(t, w)]
        ok &= histories.check(label, err, peak, tol, unit_scale=1.0, unit="rad/s",
                              detail=f"{min(w):+.2f} .. {max(w):+.2f} rad/s, ")
        tip_errors.append((label, tip_error(run)))
        curves.append((label, t, w))
    for label, e in tip_errors:
        print(f"{label:>28}: tip position RMS difference {e * 1e3:.3f} mm ({e / LENGTH:.3%} of the beam length)")
    if a.png:
        histories.plot(curves, a.png, "time [s]", "base angular velocity about z [rad/s]",
                       "beam on a spherical joint (Cardona 2000, thesis 5.1)", y_scale=1.0)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
