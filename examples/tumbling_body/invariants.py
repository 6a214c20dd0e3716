#!/usr/bin/python3
"""Energy and angular momentum of tumbling runs (results.h5), their largest relative drift, the
body-frame spin component about the intermediate axis (y) and its flips; checks each run's
drift against a stated bound and writes a PNG.

usage: invariants.py LABEL=RUN_DIR[@BOUND] ... [--png FILE] [--same-flips LABEL,LABEL,...]
BOUND: largest allowed relative drift of both the total energy and the angular momentum.
--same-flips: the listed runs must flip as often as the first of them, at times within 2% of
the spin period."""
import argparse
import math
import os
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from histories import parse_run  # noqa: E402


def rotation(q):
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def load(run):
    with h5py.File(f"{run}/results.h5", "r") as f:
        t = f["time"][:]
        energy = f["energy/kinetic"][:] + f["energy/elastic"][:]
        H = f["energy/angular_momentum"][:]
        omega = f["nodes/angular_velocity"][:, 0:3]
        frame = f["bodies/tee/floating_frame"][:]
    # Spin in the body's frame (its floating frame), component along the part's y axis.
    spin_y = np.array([rotation(frame[i, 3:7]).T.dot(omega[i])[1] for i in range(len(t))])
    dE = np.abs(energy - energy[0]) / energy[0]
    dH = np.linalg.norm(H - H[0], axis=1) / np.linalg.norm(H[0])
    return t, dE, dH, spin_y


def flips(t, spin):
    """Times where the spin about the intermediate axis changes sign (linear interpolation)."""
    out = []
    for i in range(1, len(t)):
        if spin[i - 1] * spin[i] < 0:
            out.append(t[i - 1] + (t[i] - t[i - 1]) * spin[i - 1] / (spin[i - 1] - spin[i]))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--png")
    ap.add_argument("--same-flips")
    args = ap.parse_args()
    data, ok = {}, True
    for item in args.runs:
        label, run, bound = parse_run(item)
        t, dE, dH, spin = load(run)
        data[label] = (t, dE, dH, spin)
        f = flips(t, spin)
        line = (f"{label:>34}: energy drift {dE.max():.2e}, angular momentum drift {dH.max():.2e} "
                f"(largest over {len(t) - 1} steps); spin flips at " + ", ".join(f"{x:.3f}" for x in f) + " s")
        if bound is not None:
            line += f" (bound {bound:.0e})"
            if max(dE.max(), dH.max()) > bound:
                line += "  FAIL"
                print(f"{label}: drift above {bound:.0e}", file=sys.stderr)
                ok = False
        print(line)
    if args.same_flips:
        labels = args.same_flips.split(",")
        t, _, _, spin = data[labels[0]]
        ref = flips(t, spin)
        period = 2 * math.pi / abs(spin[0])
        for label in labels[1:]:
            t, _, _, s = data[label]
            f = flips(t, s)
            worst = max((abs(a - b) for a, b in zip(f, ref)), default=0.0)
            print(f"{label:>34}: flip times within {worst / period:.2%} of the spin period of {labels[0]}'s")
            if len(f) != len(ref) or worst > 0.02 * period:
                print(f"{label}: spin flips {f} differ from {labels[0]}'s {ref}", file=sys.stderr)
                ok = False
    if args.png:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, (a1, a2) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
        for k, (label, (t, dE, dH, spin)) in enumerate(data.items()):
            a1.plot(t, spin, label=label, lw=2.0 if k == 0 else 1.0, ls="-" if k == 0 else "--")
            a2.semilogy(t[1:], np.maximum(dE[1:], 1e-17), label=f"{label}: energy", lw=1.0)
            a2.semilogy(t[1:], np.maximum(dH[1:], 1e-17), label=f"{label}: angular momentum", lw=1.0, ls=":")
        a1.set_ylabel("spin about the intermediate axis [rad/s]")
        a1.set_title("flexible T-handle tumbling in free flight")
        a1.grid(True, alpha=0.3)
        a1.legend(fontsize=7)
        a2.set_xlabel("time [s]")
        a2.set_ylabel("relative drift")
        a2.grid(True, alpha=0.3)
        a2.legend(fontsize=6, ncol=2)
        fig.tight_layout()
        fig.savefig(args.png, dpi=120)
        print(f"plot: {args.png}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
