#!/usr/bin/python3
"""Writes a CalculiX deck for the fixed-interface eigenproblem of a femb solid part and runs it.

The deck is the same mesh (a gmsh .msh read with meshio), the same material, the node sets of the
named surfaces clamped (what Craig-Bampton's fixed-interface modes solve when the interfaces are
RBE2 couplings), and a *FREQUENCY step with the same number of modes.

usage: ccx_frequency.py MESH.msh WORKDIR MODES E NU RHO SET [SET...]
prints one JSON line: {"seconds": wall time of ccx, "peak_kb": max RSS, "frequencies_hz": [...]}
"""
import json
import os
import re
import subprocess
import sys
import time

import meshio


def write_deck(mesh_path, deck, modes, E, nu, rho, sets):
    m = meshio.read(mesh_path)
    tets = [c.data for c in m.cells if c.type == "tetra10"]
    if not tets:
        sys.exit(f"{mesh_path}: no tetra10 cells")
    with open(deck, "w") as f:
        f.write("*NODE, NSET=NALL\n")
        for i, p in enumerate(m.points):
            f.write(f"{i + 1}, {p[0]:.13g}, {p[1]:.13g}, {p[2]:.13g}\n")
        f.write("*ELEMENT, TYPE=C3D10, ELSET=EALL\n")
        e = 0
        for block in tets:
            for c in block:
                e += 1
                # meshio holds VTK order, edges (01, 12, 20, 03, 13, 23): Abaqus/CalculiX C3D10 order too.
                f.write(f"{e}, " + ", ".join(str(k + 1) for k in c) + "\n")
        fixed = set()
        for name in sets:
            if name not in m.cell_sets:
                sys.exit(f"{mesh_path}: no physical group '{name}'")
            for block, idx in zip(m.cells, m.cell_sets[name]):
                if len(idx):
                    fixed.update(int(k) for k in block.data[idx].ravel())
        f.write("*NSET, NSET=FIX\n")
        ids = sorted(fixed)
        for i in range(0, len(ids), 8):
            f.write(", ".join(str(k + 1) for k in ids[i:i + 8]) + "\n")
        f.write(f"*MATERIAL, NAME=MAT\n*ELASTIC\n{E:.13g}, {nu:.13g}\n*DENSITY\n{rho:.13g}\n")
        f.write("*SOLID SECTION, ELSET=EALL, MATERIAL=MAT\n")
        f.write("*BOUNDARY\nFIX, 1, 3\n")
        f.write(f"*STEP\n*FREQUENCY\n{modes}\n*END STEP\n")
    return len(m.points)


def main():
    mesh_path, work, modes = sys.argv[1], sys.argv[2], int(sys.argv[3])
    E, nu, rho = map(float, sys.argv[4:7])
    sets = sys.argv[7:]
    os.makedirs(work, exist_ok=True)
    deck = os.path.join(work, "deck")
    write_deck(mesh_path, deck + ".inp", modes, E, nu, rho, sets)
    env = dict(os.environ, OMP_NUM_THREADS=os.environ.get("OMP_NUM_THREADS", "2"))
    start = time.time()
    run = subprocess.run(["/usr/bin/time", "-f", "PEAK_KB %M", "ccx", "-i", "deck"], cwd=work, env=env,
                         capture_output=True, text=True)
    seconds = time.time() - start
    peak = re.search(r"PEAK_KB (\d+)", run.stderr)
    result = {"seconds": seconds, "peak_kb": int(peak.group(1)) if peak else None, "frequencies_hz": [],
              "ok": run.returncode == 0}
    if run.returncode != 0:
        result["error"] = (run.stdout + run.stderr).strip().splitlines()[-3:]
    else:
        text = open(deck + ".dat").read()
        block = text.split("E I G E N V A L U E   O U T P U T")[1]
        for line in block.splitlines():
            f = line.split()
            if len(f) == 5 and f[0].isdigit():
                result["frequencies_hz"].append(float(f[3]))
    print(json.dumps(result))


if __name__ == "__main__":
    main()
