#!/usr/bin/env python3
"""femb's meshio bridge: reads any mesh format meshio knows (Abaqus .inp, Nastran .bdf,
VTK/VTU, MED, ...) and writes femb's plain-text mesh:

    femb-mesh 1
    nodes N            then N lines "x y z"
    ids N              then one line of N node ids (the file's node labels)
    cells TYPE M K     then M lines of K 0-based node indices (gmsh node order)
    set NAME C         then one line of C 0-based node indices   (repeated per named set)

TYPE is tet4, tet10, hex8 or hex20; with --any-cells (imported matrices: the mesh only draws the
part and places its nodes) the cells of the highest dimension the file has: volume cells, else
surface cells (tri3, tri6, quad4, quad8; a mix of them is drawn as tri3 through the corners),
else line2. Node ids: the labels of Abaqus/CalculiX .inp files (*NODE) and Nastran .bdf GRID
cards; 1..N in file order for other formats. Named sets are meshio's point sets, and the nodes
of its named cell sets. Usage: meshio_bridge.py [--any-cells] IN OUT. Exit code 2 and one line
on stderr on failure; 3 when meshio is missing.
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
SURFACE = {"triangle": "tri3", "triangle6": "tri6", "quad": "quad4", "quad8": "quad8"}
LINE = {"line": "line2"}


def node_ids(src, n):
    """The node labels in the order meshio lists the points, or None (then 1..n)."""
    lower = src.lower()
    ids = []
    if lower.endswith(".inp"):
        in_node = False
        with open(src, errors="replace") as f:
            for line in f:
                s = line.strip()
                if not s or s.startswith("**"):
                    continue
                if s.startswith("*"):
                    in_node = s.split(",")[0].strip().upper() == "*NODE"
                    continue
                if in_node:
                    ids.append(int(s.split(",")[0]))
    elif lower.endswith((".bdf", ".nas", ".fem")):
        with open(src, errors="replace") as f:
            for line in f:
                if line.startswith("GRID*"):
                    ids.append(int(line[8:24]))
                elif line.startswith("GRID"):
                    field = line[8:16] if "," not in line else line.split(",")[1]
                    ids.append(int(field))
    else:
        return None
    if len(ids) != n:
        raise ValueError("found %d node labels but meshio read %d nodes (several *NODE blocks or GRID formats "
                         "meshio reads differently)" % (len(ids), n))
    if len(set(ids)) != n:
        raise ValueError("node labels are not unique")
    return ids


def pick_cells(mesh, any_cells):
    """(femb type, cells in gmsh order, None) of the cells femb uses, or (None, None, message)."""
    volume = [c for c in mesh.cells if c.type in NAMES]
    if volume:
        if len({c.type for c in volume}) > 1:
            return None, None, "mixed volume element types are not supported yet"
        kind = volume[0].type
        data = np.vstack([c.data for c in volume])
        if kind in TO_GMSH:
            data = data[:, TO_GMSH[kind]]
        return NAMES[kind], data, None
    if not any_cells:
        return None, None, "the mesh has no volume elements (tetra, tetra10, hexahedron, hexahedron20)"
    surface = [c for c in mesh.cells if c.type in SURFACE]
    if surface:
        if len({c.type for c in surface}) == 1:
            return SURFACE[surface[0].type], np.vstack([c.data for c in surface]), None
        tris = []
        for c in surface:
            if c.type.startswith("triangle"):
                tris.append(c.data[:, :3])
            else:
                tris.append(c.data[:, [0, 1, 2]])
                tris.append(c.data[:, [0, 2, 3]])
        return "tri3", np.vstack(tris), None
    lines = [c for c in mesh.cells if c.type in LINE]
    if lines:
        return "line2", np.vstack([c.data for c in lines]), None
    return None, None, "the mesh has no cells to draw (volume, surface or line cells)"


def main(src, dst, any_cells=False):
    try:
        mesh = meshio.read(src)
    except (Exception, SystemExit) as e:  # meshio raises many kinds, and sometimes exits
        reason = "not a mesh meshio can read" if isinstance(e, SystemExit) else str(e)
        sys.stderr.write("%s: cannot read with meshio: %s\n" % (src, reason))
        return 2
    kind, data, error = pick_cells(mesh, any_cells)
    if error:
        sys.stderr.write("%s: %s\n" % (src, error))
        return 2
    try:
        labels = node_ids(src, len(mesh.points))
    except (ValueError, OSError) as e:
        sys.stderr.write("%s: node labels: %s\n" % (src, e))
        return 2
    if labels is None:
        labels = range(1, len(mesh.points) + 1)
    sets = {name: np.asarray(idx, dtype=int) for name, idx in (mesh.point_sets or {}).items()}
    for name, per_block in (mesh.cell_sets or {}).items():
        nodes = [mesh.cells[b].data[np.asarray(cells, dtype=int)].ravel() for b, cells in enumerate(per_block)
                 if cells is not None and len(cells) > 0]
        if nodes:
            sets.setdefault(name, np.unique(np.concatenate(nodes)))
    points = mesh.points if mesh.points.shape[1] == 3 else np.hstack([mesh.points, np.zeros((len(mesh.points), 1))])
    with open(dst, "w") as out:
        out.write("femb-mesh 1\nnodes %d\n" % len(points))
        np.savetxt(out, points, fmt="%.17g")
        out.write("ids %d\n" % len(points))
        out.write(" ".join(str(i) for i in labels) + "\n")
        out.write("cells %s %d %d\n" % (kind, data.shape[0], data.shape[1]))
        np.savetxt(out, data, fmt="%d")
        for name, idx in sets.items():
            out.write("set %s %d\n" % (name.replace(" ", "_"), len(idx)))
            out.write(" ".join(str(i) for i in idx) + "\n")
    return 0


if __name__ == "__main__":
    args = sys.argv[1:]
    any_cells = "--any-cells" in args
    args = [a for a in args if a != "--any-cells"]
    if len(args) != 2:
        sys.stderr.write("usage: meshio_bridge.py [--any-cells] IN OUT\n")
        sys.exit(2)
    sys.exit(main(args[0], args[1], any_cells))
