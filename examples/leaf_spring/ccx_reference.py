#!/usr/bin/python3
"""CalculiX (calculix-ccx, NLGEOM) on the leaf spring's own mesh, the outside reference: the mesh
of the superelement file (/visualization, HEX20 in gmsh order -> C3D20), face x = 0 clamped, face
x = L moving as a rigid translation (*EQUATION on x and z to one node, y held), a force across the
leaf on that node, ten increments of 1/10 to 10 N. Writes OUTDIR/ccx.csv: force,deflection,shortening.

usage: ccx_reference.py LEAF.h5 OUTDIR [FORCE]
"""
import os
import re
import subprocess
import sys

import h5py

# gmsh HEX20 edge nodes (0,1),(0,3),(0,4),(1,2),(1,5),(2,3),(2,6),(3,7),(4,5),(4,7),(5,6),(6,7) are
# nodes 8..19; Abaqus/CalculiX C3D20 wants (0,1),(1,2),(2,3),(3,0),(4,5),(5,6),(6,7),(7,4),(0,4),
# (1,5),(2,6),(3,7).
C3D20_FROM_GMSH = [0, 1, 2, 3, 4, 5, 6, 7, 8, 11, 13, 9, 16, 18, 19, 17, 10, 12, 14, 15]


def main():
    leaf, out = sys.argv[1], sys.argv[2]
    force = float(sys.argv[3]) if len(sys.argv) > 3 else 10.0
    os.makedirs(out, exist_ok=True)
    f = h5py.File(leaf, "r")
    X = f["/visualization/nodes"][:]
    cells = f["/visualization/cells"][:]
    if cells.shape[1] != 20:
        sys.exit(f"{leaf}: expected HEX20 cells, got {cells.shape[1]} nodes per cell")
    L = X[:, 0].max()
    fixed = [i for i in range(len(X)) if abs(X[i, 0]) < 1e-9]
    guided = [i for i in range(len(X)) if abs(X[i, 0] - L) < 1e-9]
    ref = guided[0]
    deck = os.path.join(out, "leaf.inp")
    with open(deck, "w") as d:
        d.write("*NODE, NSET=NALL\n")
        for i, p in enumerate(X):
            d.write(f"{i + 1}, {p[0]:.15g}, {p[1]:.15g}, {p[2]:.15g}\n")
        d.write("*ELEMENT, TYPE=C3D20, ELSET=EALL\n")
        for e, c in enumerate(cells):
            d.write(f"{e + 1}, " + ", ".join(str(c[k] + 1) for k in C3D20_FROM_GMSH[:15]) + ",\n")
            d.write(", ".join(str(c[k] + 1) for k in C3D20_FROM_GMSH[15:]) + "\n")
        for name, ids in (("FIX", fixed), ("GUIDED", guided), ("REF", [ref])):
            d.write(f"*NSET, NSET={name}\n")
            for k in range(0, len(ids), 8):
                d.write(", ".join(str(i + 1) for i in ids[k:k + 8]) + "\n")
        d.write("*EQUATION\n")
        for i in guided:
            if i == ref:
                continue
            for dof in (1, 3):
                d.write(f"2\n{i + 1}, {dof}, 1., {ref + 1}, {dof}, -1.\n")
        d.write("*MATERIAL, NAME=STEEL\n*ELASTIC\n2.1e11, 0.3\n*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL\n")
        d.write("*BOUNDARY\nFIX, 1, 3\nGUIDED, 2, 2\n")
        d.write(f"*STEP, NLGEOM, INC=100\n*STATIC, DIRECT\n0.1, 1.0\n*CLOAD\nREF, 3, {force!r}\n")
        d.write("*NODE PRINT, NSET=REF\nU\n*END STEP\n")
    r = subprocess.run(["ccx", "leaf"], cwd=out, capture_output=True, text=True)
    if r.returncode != 0 or "ERROR" in r.stdout:
        sys.exit("ccx failed:\n" + r.stdout[-2000:])
    # .dat: "displacements (vx,vy,vz) for set REF and time  0.1000000E+00" then "node ux uy uz".
    rows = []
    text = open(os.path.join(out, "leaf.dat")).read()
    for m in re.finditer(r"displacements \(vx,vy,vz\) for set REF and time\s+(\S+)\s*\n\s*\n?\s*(\d+)\s+(\S+)\s+(\S+)\s+(\S+)", text):
        t, ux, uz = float(m.group(1)), float(m.group(3)), float(m.group(5))
        rows.append((t * force, uz, -ux))
    if not rows:
        sys.exit(f"{out}/leaf.dat: no displacements of REF found")
    with open(os.path.join(out, "ccx.csv"), "w") as c:
        c.write("force,deflection,shortening\n")
        for F, w, s in rows:
            c.write(f"{F!r},{w!r},{s!r}\n")
    print(f"ccx: {len(rows)} increments, {len(X)} nodes, {len(cells)} C3D20; at {rows[-1][0]:g} N deflection "
          f"{rows[-1][1] * 1e3:.4f} mm, shortening {rows[-1][2] * 1e3:.5f} mm")


if __name__ == "__main__":
    main()
