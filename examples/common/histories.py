"""Shared by the seed examples' checks: runs named LABEL=RUN_DIR[@TOL], an RMS error against a
reference with a stated tolerance (fraction of the reference's peak), and a PNG of the curves."""
import math
import sys


def parse_run(item):
    """'LABEL=RUN_DIR[@TOL]' -> (label, run_dir, tol or None)."""
    label, run = item.split("=", 1)
    tol = None
    if "@" in run:
        run, tol = run.rsplit("@", 1)
        tol = float(tol)
    return label, run, tol


def check(label, errors, peak, tol, unit_scale=1e3, unit="mm", detail=""):
    """Prints the RMS of `errors` against `peak` (and the tolerance); returns False above it."""
    rms = math.sqrt(sum(e * e for e in errors) / len(errors))
    line = f"{label:>28}: {detail}RMS error {rms * unit_scale:.3f} {unit} = {rms / peak:.2%} of the reference peak"
    ok = True
    if tol is not None:
        line += f" (tolerance {tol:.1%})"
        if rms > tol * peak:
            line += "  FAIL"
            ok = False
    print(line)
    if not ok:
        print(f"{label}: RMS error above the tolerance {tol:.1%} of the peak", file=sys.stderr)
    return ok


def plot(curves, png, xlabel, ylabel, title, y_scale=1e3):
    """curves: [(label, xs, ys)], the first one the reference (drawn solid and thick)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4))
    for k, (label, xs, ys) in enumerate(curves):
        ax.plot(list(xs), [v * y_scale for v in ys], label=label, lw=2.5 if k == 0 else 1.2, ls="-" if k == 0 else "--")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(png, dpi=120)
    print(f"plot: {png}")


def load_columns(run_dir, *columns):
    """Columns of RUN_DIR/probes.csv as lists of floats, in the order asked."""
    import csv
    with open(f"{run_dir}/probes.csv") as f:
        rows = list(csv.DictReader(f))
    missing = [c for c in columns if rows and c not in rows[0]]
    if missing:
        sys.exit(f"{run_dir}/probes.csv: no column {missing[0]}")
    return [[float(r[c]) for r in rows] for c in columns]


def interpolate(xs, ys, x):
    """Piecewise linear y(x) on ascending xs; clamped to the ends."""
    if x <= xs[0]:
        return ys[0]
    if x >= xs[-1]:
        return ys[-1]
    lo, hi = 0, len(xs) - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if xs[mid] <= x:
            lo = mid
        else:
            hi = mid
    t = (x - xs[lo]) / (xs[hi] - xs[lo])
    return ys[lo] + t * (ys[hi] - ys[lo])
