#!/usr/bin/python3
"""The cantilever plate's normalized tip displacements w/L and -u/L (mean of probes tip_1 and
tip_2) against the load parameter P L^2 / EI (P = both tip forces together, 2 kN per unit
pseudo-time), compared with the elastica (../cantilever_static/elastica.py) for the beam
bending stiffness EI = E b t^3 / 12 and the plate's E b t^3 / (12 (1 - nu^2)): a 1 m wide plate
bends between the two (rigid cross-sections restrain the anticlastic curvature, a free edge
does not). Prints where in that band the run's deflection lies (0 = beam, 1 = plate). Exit 1
when the run does not reach the full load or its deflection w lies outside the band by more
than TOL (a fraction of the tip displacement). Optional PNG.

usage: check.py RUN_DIR [TOL] [--png FILE]
"""
import argparse
import math
import os
import sys

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, "..", "cantilever_static"))
sys.path.insert(0, os.path.join(here, "..", "common"))
import elastica  # noqa: E402
import histories  # noqa: E402

L, E, NU, B, T = 10.0, 1.2e10, 0.3, 1.0, 0.1
EI_BEAM = E * B * T**3 / 12
EI_PLATE = EI_BEAM / (1 - NU**2)
P_PER_TIME = 2000.0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("run")
    ap.add_argument("tol", nargs="?", type=float)
    ap.add_argument("--png")
    a = ap.parse_args()
    cols = histories.load_columns(a.run, "time", "tip_1.position.x", "tip_1.position.z",
                                  "tip_2.position.x", "tip_2.position.z")
    loads = [t * P_PER_TIME for t in cols[0] if t > 0]
    u = [-(L - 0.5 * (x1 + x2)) for t, x1, x2 in zip(cols[0], cols[1], cols[3]) if t > 0]
    w = [0.5 * (z1 + z2) for t, z1, z2 in zip(cols[0], cols[2], cols[4]) if t > 0]
    beam = elastica.tips(loads, EI_BEAM, L)
    plate = elastica.tips(loads, EI_PLATE, L)
    outside, where = 0.0, []
    print(f"{'P L^2/EI':>9} {'w/L':>8} {'-u/L':>8} {'beam w/L':>9} {'beam -u/L':>9} {'plate w/L':>9}  in the band")
    for k, P in enumerate(loads):
        size = math.hypot(u[k], w[k])
        # the band between the two curves' deflections (the elastica's y is downward)
        wb, wp = -beam[P][1], -plate[P][1]
        lo, hi = sorted((wb, wp))
        outside = max(outside, max(0.0, lo - w[k], w[k] - hi) / size)
        where.append((wb - w[k]) / (wb - wp))
        if k % 5 == 4 or k == 0:
            print(f"{P * L**2 / EI_BEAM:9.2f} {w[k] / L:8.4f} {-u[k] / L:8.4f} {wb / L:9.4f} "
                  f"{(L - beam[P][0]) / L:9.4f} {wp / L:9.4f}  {where[-1]:.2f}")
    reached = loads[-1] if loads else 0.0
    line = (f"{a.run}: up to P = {reached / 1e3:.0f} kN (P L^2/EI = {reached * L**2 / EI_BEAM:.1f}); w between the beam "
            f"and the plate elastica at {min(where):.2f} .. {max(where):.2f} of the band, outside it by {outside:.2%}")
    ok = True
    if a.tol is not None:
        line += f" (tolerance {a.tol:.1%})"
        if outside > a.tol or reached < 50 * P_PER_TIME:
            line += "  FAIL"
            ok = False
    print(line)
    if a.png:
        ks = [P * L**2 / EI_BEAM for P in loads]
        curves = [("elastica, EI (beam): w/L", ks, [-beam[P][1] / L for P in loads]),
                  ("elastica, EI/(1-nu^2) (plate): w/L", ks, [-plate[P][1] / L for P in loads]),
                  ("10 solid bodies: w/L", ks, [v / L for v in w]),
                  ("elastica, EI: -u/L", ks, [(L - beam[P][0]) / L for P in loads]),
                  ("10 solid bodies: -u/L", ks, [-v / L for v in u])]
        histories.plot(curves, a.png, "P L^2 / EI", "normalized tip displacement",
                       "cantilever plate 10 m x 1 m x 0.1 m (thesis 8.4)", y_scale=1.0)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
