#!/usr/bin/env python3
"""femb's meshio bridge: reads any mesh format meshio knows (Abaqus .inp, Nastran .bdf,
VTK/VTU, MED, ...) and writes femb's plain-text mesh:

    femb-mesh 1
    nodes N            then N lines "x y z"
    cells TYPE M K     then M lines of K 0-based node indices (gmsh node order)
    set NAME C         then one line of C 0-based node indices   (repeated per named set)

TYPE is tet4, tet10, hex8 or hex20. Named sets are meshio's point sets, and the nodes of its
named cell sets of surface or volume cells. Usage: meshio_bridge.py IN OUT. Exit code 2 and one
line on stderr on failure; 3 when meshio is missing.
"""
import sys

try:
    import meshio
    import numpy as np
except ImportError:
    sys.stderr.write("meshio is not installed: apt-get install python3-meshio\n")
    sys.exit(3)

# meshio (VTK) node order -> gmsh node order for the quadratic cells.
TO_GMSH = {"tetra10": [0, 1, 2, 3, 4, 5, 6, 7, 9, 8],
           "hexahedron20": [0, 1, 2, 3, 4, 5, 6, 7, 8, 11, 16, 9, 17, 10, 18, 19, 12, 15, 13, 14]}
NAMES = {"tetra": "tet4", "tetra10": "tet10", "hexahedron": "hex8", "hexahedron20": "hex20"}


def main(src, dst):
    try:
        mesh = meshio.read(src)
    except (Exception, SystemExit) as e:  # meshio raises many kinds, and sometimes exits
        reason = "not a mesh meshio can read" if isinstance(e, SystemExit) else str(e)
        sys.stderr.write("%s: cannot read with meshio: %s\n" % (src, reason))
        return 2
    volume = [c for c in mesh.cells if c.type in NAMES]
    if not volume:
        sys.stderr.write("%s: the mesh has no volume elements (tetra, tetra10, hexahedron, hexahedron20)\n" % src)
        return 2
    if len({c.type for c in volume}) > 1:
        sys.stderr.write("%s: mixed volume element types are not supported yet\n" % src)
        return 2
    kind = volume[0].type
    data = np.vstack([c.data for c in volume])
    if kind in TO_GMSH:
        data = data[:, TO_GMSH[kind]]
    sets = {name: np.asarray(idx, dtype=int) for name, idx in (mesh.point_sets or {}).items()}
    for name, per_block in (mesh.cell_sets or {}).items():
        nodes = [mesh.cells[b].data[np.asarray(ids, dtype=int)].ravel() for b, ids in enumerate(per_block)
                 if ids is not None and len(ids) > 0]
        if nodes:
            sets.setdefault(name, np.unique(np.concatenate(nodes)))
    points = mesh.points if mesh.points.shape[1] == 3 else np.hstack([mesh.points, np.zeros((len(mesh.points), 1))])
    with open(dst, "w") as out:
        out.write("femb-mesh 1\nnodes %d\n" % len(points))
        np.savetxt(out, points, fmt="%.17g")
        out.write("cells %s %d %d\n" % (NAMES[kind], data.shape[0], data.shape[1]))
        np.savetxt(out, data, fmt="%d")
        for name, idx in sets.items():
            out.write("set %s %d\n" % (name.replace(" ", "_"), len(idx)))
            out.write(" ".join(str(i) for i in idx) + "\n")
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.stderr.write("usage: meshio_bridge.py IN OUT\n")
        sys.exit(2)
    sys.exit(main(sys.argv[1], sys.argv[2]))
