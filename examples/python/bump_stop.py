"""A force femb does not ship, written in Python: the pendulum example's rigid bar released
horizontal swings down and strikes a bump stop, a wall at x = -0.1 m that pushes back on the
bar's tip with a Hunt-Crossley contact force f = k p^1.5 (1 + 1.5 alpha pdot) (p the tip's
penetration, pdot its rate; nothing while the tip is clear).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/bump_stop.py [OUTDIR] [--end-time T]

Prints the largest penetration and contact force and the rebound; plots the tip's x and the
contact force (OUTDIR/bump_stop.png, default out/python_bump_stop).
"""

import argparse
import os

import numpy as np

import femb

WALL = -0.1    # m: the wall's plane x = WALL, the bar's side x > WALL
STIFF = 2e7    # N/m^1.5
ALPHA = 0.2    # s/m: Hunt-Crossley damping (coefficient of restitution about 1 - 2/3 alpha v)


def contact(t, x, R, v, w):
    """The wall's force on the tip (world axes) and no moment."""
    p = WALL - x[0]
    if p <= 0:
        return np.zeros(6)
    force = max(STIFF * p**1.5 * (1 + 1.5 * ALPHA * -v[0]), 0.0)
    return np.array([force, 0, 0, 0, 0, 0])


def scene(end_time):
    return femb.Scene({
        "name": "bump_stop", "units": "SI",
        "bodies": [{"name": "bar", "type": "rigid", "mass": 0.0667557023, "center_of_mass": [0.15, 0, 0],
                    "inertia": [3.004006603e-07, 0.0005008179676, 0.0005008179676],
                    "points": {"P": [0, 0, 0], "T": [0.3, 0, 0]}, "nodes": {"P": "pivot", "T": "tip"}}],
        "joints": [{"type": "revolute", "node": "pivot", "axis": [0, 0, 1]}],
        "loads": [{"type": "gravity", "g": [0, -9.81, 0]}],
        "analysis": {"type": "dynamic", "end_time": end_time, "step": "auto", "step_tolerance": 1e-6,
                     "output_step": 2e-4, "max_step": 1e-3},
        "outputs": {"probes": [{"name": "tip", "node": "tip", "quantities": ["position", "velocity"]}]},
    }).add_force("tip", contact, name="bump_stop")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", nargs="?", default="out/python_bump_stop")
    parser.add_argument("--end-time", type=float, default=1.0)
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    r = scene(args.end_time).run()
    x, vx = r.probes["tip.position.x"], r.probes["tip.velocity.x"]
    force = np.array([contact(t, [xi, 0, 0], None, [vi, 0, 0], None)[0] for t, xi, vi in zip(r.time, x, vx)])
    hit = np.argmax(force > 0)
    print(f"bump_stop.py: {r.step_count} steps, {r.newton_iterations} Newton iterations; "
          f"first contact at t = {r.time[hit]:.4f} s, {-vx[hit]:.3f} m/s")
    leave = vx[np.argmax((force == 0) & (np.arange(len(x)) > hit))]
    print(f"bump_stop.py: largest penetration {max(WALL - x.min(), 0) * 1e6:.2f} um, largest contact force "
          f"{force.max():.1f} N; the tip leaves the wall at {leave:.3f} m/s: restitution {leave / -vx[hit]:.3f} "
          f"(Hunt and Crossley's estimate 1 - 2/3 alpha v = {1 - 2 / 3 * ALPHA * -vx[hit]:.3f})")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a, b) = plt.subplots(2, 1, sharex=True, figsize=(7, 5))
    a.plot(r.time, x)
    a.axhline(WALL, color="k", lw=0.8)
    a.set_ylabel("tip x [m]")
    b.plot(r.time, force)
    b.set_ylabel("contact force [N]")
    b.set_xlabel("time [s]")
    fig.suptitle("Pendulum on a bump stop: a force written in Python")
    fig.tight_layout()
    path = os.path.join(args.out, "bump_stop.png")
    fig.savefig(path, dpi=120)
    print(f"bump_stop.py: plot in {path}")


if __name__ == "__main__":
    main()
