#!/usr/bin/python3
"""Deformation shapes for bending.yaml from the rod's matrices as femb-reduce exported them (Matrix
Market, rows listed in rod_dofs.csv as node, component 1..6; node coordinates in rod.inp): the
Craig-Bampton shapes of the bending alone -- the static modes of the 8 bending coordinates of the
end nodes (u_y, u_z, theta_y, theta_z) and the 4 lowest fixed-interface modes (bending) -- without
the static modes that stretch or twist the rod. Written as /shapes of an HDF5 file.
Usage: make_shapes.py MESH_DIR OUT.h5"""
import csv
import sys
import h5py
import numpy as np
import scipy.io
import scipy.linalg

mesh, out = sys.argv[1], sys.argv[2]
K = scipy.io.mmread(mesh + "/rod_K.mtx").toarray()
M = scipy.io.mmread(mesh + "/rod_M.mtx").toarray()
rows = [(int(r["node"]), int(r["component"])) for r in csv.DictReader(open(mesh + "/rod_dofs.csv"))]
x = {}
lines = open(mesh + "/rod.inp").read().splitlines()
at = next(i for i, l in enumerate(lines) if l.strip().upper().startswith("*NODE"))
for l in lines[at + 1:]:
    if l.startswith("*"):
        break
    f = [float(v) for v in l.split(",")]
    x[int(f[0])] = f[1:4]
ends = [min(x, key=lambda k: x[k][0]), max(x, key=lambda k: x[k][0])]  # A (x = 0) and B (x = L)
boundary = [i for i, (n, c) in enumerate(rows) if n in ends]
bending = [i for i in boundary if rows[i][1] in (2, 3, 5, 6)]
interior = [i for i in range(len(rows)) if i not in boundary]
Kii, Mii = K[np.ix_(interior, interior)], M[np.ix_(interior, interior)]
V = np.zeros((len(rows), len(bending) + 4))
for j, b in enumerate(bending):  # unit motion of one bending coordinate, the others held
    V[b, j] = 1.0
    V[interior, j] = -np.linalg.solve(Kii, K[interior, b])
w, phi = scipy.linalg.eigh(Kii, Mii)
V[interior, len(bending):] = phi[:, :4]
print("make_shapes: %d static bending modes + fixed-interface modes at %s Hz; no stretch or twist"
      % (len(bending), ", ".join("%.0f" % f for f in np.sqrt(w[:4]) / (2 * np.pi))))
with h5py.File(out, "w") as h:
    h["shapes"] = V
