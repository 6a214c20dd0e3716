#!/usr/bin/python3
"""CalculiX (calculix-ccx, NLGEOM) on the cross-flexure pivot of make_variant.py: the full leaf's
mesh from a one-body superelement file (/visualization, HEX20 -> C3D20) placed twice as the scene
places the leaves, the lower end faces clamped, the upper end faces tied to the rotor by *RIGID
BODY (reference node at the rotor's centre of mass), the moment about y on the rotation node in
STEPS increments. Writes OUTDIR/ccx.csv: moment,rotation,x,z (rotor rotation about y, rotor
centre displacement).

usage: ccx_reference.py LEAF.h5 OUTDIR MOMENT STEPS
"""
import math
import os
import re
import subprocess
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "leaf_spring"))
from ccx_reference import C3D20_FROM_GMSH  # noqa: E402  (gmsh HEX20 -> C3D20 node order)


def main():
    leaf, out, moment, steps = sys.argv[1], sys.argv[2], float(sys.argv[3]), int(sys.argv[4])
    os.makedirs(out, exist_ok=True)
    f = h5py.File(leaf, "r")
    X = f["/visualization/nodes"][:]
    cells = f["/visualization/cells"][:]
    L, width = X[:, 0].max(), X[:, 1].max()
    a = L / (2 * math.sqrt(2))
    gap = 0.0005
    placements = [((-a, 0.0, -a), -math.pi / 4), ((a, width + gap, -a), -3 * math.pi / 4)]  # as make_variant.py
    nodes, elements, clamp, tips = [], [], [], []
    for p, angle in placements:
        c, s = math.cos(angle), math.sin(angle)
        R = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
        first = len(nodes)
        for x in X:
            nodes.append(np.array(p) + R @ x)
        for cell in cells:
            elements.append([first + cell[k] for k in C3D20_FROM_GMSH])
        clamp += [first + i for i in range(len(X)) if abs(X[i, 0]) < 1e-9]
        tips += [first + i for i in range(len(X)) if abs(X[i, 0] - L) < 1e-9]
    ref, rot = len(nodes), len(nodes) + 1
    com = (0.0, width + gap / 2, a)
    deck = os.path.join(out, "pivot.inp")
    with open(deck, "w") as d:
        d.write("*NODE, NSET=NALL\n")
        for i, x in enumerate(nodes):
            d.write(f"{i + 1}, {x[0]:.15g}, {x[1]:.15g}, {x[2]:.15g}\n")
        d.write(f"{ref + 1}, {com[0]!r}, {com[1]!r}, {com[2]!r}\n{rot + 1}, {com[0]!r}, {com[1]!r}, {com[2]!r}\n")
        d.write("*ELEMENT, TYPE=C3D20, ELSET=EALL\n")
        for e, c in enumerate(elements):
            d.write(f"{e + 1}, " + ", ".join(str(k + 1) for k in c[:15]) + ",\n" + ", ".join(str(k + 1) for k in c[15:]) + "\n")
        for name, ids in (("CLAMP", clamp), ("TIPS", tips), ("REF", [ref]), ("ROT", [rot])):
            d.write(f"*NSET, NSET={name}\n")
            for k in range(0, len(ids), 8):
                d.write(", ".join(str(i + 1) for i in ids[k:k + 8]) + "\n")
        d.write(f"*RIGID BODY, NSET=TIPS, REF NODE={ref + 1}, ROT NODE={rot + 1}\n")
        d.write("*MATERIAL, NAME=STEEL\n*ELASTIC\n2.1e11, 0.3\n*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL\n")
        d.write("*BOUNDARY\nCLAMP, 1, 3\n")
        d.write(f"*STEP, NLGEOM, INC=1000\n*STATIC\n{1.0 / steps!r}, 1.0, 1e-6, {1.0 / steps!r}\n*CLOAD\n{rot + 1}, 2, {moment!r}\n")
        d.write("*NODE PRINT, NSET=REF\nU\n*NODE PRINT, NSET=ROT\nU\n*END STEP\n")
    r = subprocess.run(["ccx", "pivot"], cwd=out, capture_output=True, text=True)
    if r.returncode != 0 or "ERROR" in r.stdout:
        sys.exit("ccx failed:\n" + r.stdout[-2000:])
    text = open(os.path.join(out, "pivot.dat")).read()
    pattern = r"displacements \(vx,vy,vz\) for set {} and time\s+(\S+)\s*\n\s*\n?\s*(\d+)\s+(\S+)\s+(\S+)\s+(\S+)"
    refs = {float(m.group(1)): (float(m.group(3)), float(m.group(5))) for m in re.finditer(pattern.format("REF"), text)}
    rots = {float(m.group(1)): float(m.group(4)) for m in re.finditer(pattern.format("ROT"), text)}
    times = sorted(set(refs) & set(rots))
    if not times:
        sys.exit(f"{out}/pivot.dat: no rotor displacements found")
    with open(os.path.join(out, "ccx.csv"), "w") as c:
        c.write("moment,rotation,x,z\n")
        for t in times:
            c.write(f"{t * moment!r},{rots[t]!r},{refs[t][0]!r},{refs[t][1]!r}\n")
    print(f"ccx: {len(times)} increments, {len(nodes)} nodes, {len(elements)} C3D20; at {times[-1] * moment:g} N m "
          f"rotation {rots[times[-1]]:.5f} rad, rotor centre moved ({refs[times[-1]][0] * 1e3:.4f}, {refs[times[-1]][1] * 1e3:.4f}) mm")


if __name__ == "__main__":
    main()
