#!/usr/bin/python3
"""Compares the two rods of scene.yaml: the tip's distance from the hub (the Craig-Bampton rod
stretches under the centrifugal force, the bending-only rod does not: its constraint holds to the
Newton tolerance) and the tip's lag behind the rigid rotation (bending under the angular
acceleration: the same in both bases). Exits 1 when a check fails. Usage: compare.py RUN_DIR"""
import csv
import math
import sys

rows = list(csv.DictReader(open(sys.argv[1] + "/probes.csv")))
L, E, rho, omega = 0.3, 2.0e11, 7870, 300.0
stretch_cb, stretch_b, lag_cb, lag_b = [], [], [], []
for r in rows:
    x1, y1 = float(r["tip1.position.x"]), float(r["tip1.position.y"])
    x2, y2 = float(r["tip2.position.x"]), float(r["tip2.position.y"])
    phi = float(r["hub1.joint.0"])
    stretch_cb.append(math.hypot(x1, y1) - L)
    stretch_b.append(math.hypot(x2, y2) - L)
    # Lag: the tip's angle behind the hub's (bending), as an arc length; angles wrapped to +-pi.
    wrap = lambda a: math.atan2(math.sin(a), math.cos(a))
    lag_cb.append(L * wrap(phi - math.atan2(y1, x1)))
    lag_b.append(L * wrap(phi - math.atan2(y2, x2)))
# A uniform bar spinning at omega stretches by rho omega^2 L^3 / (3 E) (closed form, quasi-static).
# Measured over the last 50 ms at speed (mean for the Craig-Bampton rod, largest for the other).
closed = rho * omega ** 2 * L ** 3 / (3 * E)
t = [float(r["time"]) for r in rows]
hold = [i for i, x in enumerate(t) if x >= t[-1] - 0.05]
stretch = sum(stretch_cb[i] for i in hold) / len(hold)
kept = max(abs(stretch_b[i]) for i in hold)
peak_lag = max(abs(x) for x in lag_cb)
lag_diff = max(abs(a - b) for a, b in zip(lag_cb, lag_b))
print("compare: at %.0f rad/s the Craig-Bampton rod stretches by %.3e m (closed form rho omega^2 L^3 / 3E = %.3e m, "
      "%+.1f%%); the bending-only rod's length changes by at most %.1e m" % (omega, stretch, closed,
                                                                         100 * (stretch / closed - 1), kept))
print("compare: tip lag behind the hub during the spin-up, peak %.3e m; the two bases differ by %.2e m (%.2f%% of "
      "the peak)" % (peak_lag, lag_diff, 100 * lag_diff / peak_lag))
ok = abs(stretch / closed - 1) < 0.1 and kept < 1e-3 * closed and lag_diff < 0.01 * peak_lag
sys.exit(0 if ok else 1)
