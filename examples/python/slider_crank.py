"""The planar slider-crank of examples/slider_crank_2d built in Python: its parts reduced with
femb.reduce, the scene made as a dict, run in memory, and the rod midpoint's deflection plotted.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/slider_crank.py [OUTDIR]

Writes OUTDIR/deflection.png (default out/python_slider_crank) and prints the peak deflection.
"""

import os
import sys

import numpy as np

import femb

HERE = os.path.dirname(os.path.abspath(__file__))
PARTS = os.path.abspath(os.path.join(HERE, "..", "slider_crank_2d"))


def reduce_parts(out, progress=None):
    """The crank and the slider (rigid-like superelements) reduced into `out`: their files."""
    os.makedirs(out, exist_ok=True)
    files = {}
    for part in ("crank", "slider"):
        files[part] = os.path.join(out, part + ".h5")
        femb.reduce(os.path.join(PARTS, part + ".yaml"), files[part], progress=progress)
    return files


def reduce_rod(out, diameter=0.006, progress=None, parts=PARTS):
    """One of the rod's two segments (0.15 m, steel, 4 internal modes) of the given diameter [m];
    parts: the folder of the part files (a sweep's workers are given the client's)."""
    path = os.path.join(out, f"rod_{diameter * 1e3:.4g}mm.h5")
    femb.reduce(os.path.join(parts, "rod_2.yaml"), path, set={"section.diameter": diameter}, progress=progress)
    return path


def scene(crank, slider, rod, end_time=0.126, step=1e-5):
    """The slider-crank (crank 0.15 m at 150 rad/s, rod 0.3 m in 2 superelements): a femb.Scene."""
    return femb.Scene({
        "name": "slider_crank_python",
        "units": "SI",
        "bodies": [
            {"name": "crank", "superelement": crank, "nodes": {"O": "O", "A": "A"}},
            {"name": "rod0", "superelement": rod, "placement": {"position": [0.15, 0, 0]},
             "nodes": {"A": "rod_a", "B": "rod_mid"}},
            {"name": "rod1", "superelement": rod, "placement": {"position": [0.3, 0, 0]},
             "nodes": {"A": "rod_mid", "B": "rod_b"}},
            {"name": "slider", "superelement": slider, "placement": {"position": [0.45, 0, 0]},
             "nodes": {"S": "slider"}},
        ],
        "joints": [
            {"type": "revolute", "node": "O", "axis": [0, 0, 1], "prescribed": "crank_angle"},
            {"type": "revolute", "node": "rod_a", "parent": "A", "axis": [0, 0, 1]},
            {"type": "prismatic", "node": "slider", "axis": [1, 0, 0]},
            {"type": "revolute", "node": "rod_b", "parent": "slider", "axis": [0, 0, 1]},
        ],
        "functions": {"crank_angle": {"type": "linear", "slope": 150}},
        "analysis": {"type": "dynamic", "end_time": end_time, "step": step, "rho_inf": 0.8},
        "outputs": {"probes": [{"name": n, "node": n, "quantities": ["position"]}
                               for n in ("rod_a", "rod_mid", "rod_b")]},
    })


def midpoint_deflection(results):
    """The rod midpoint's distance from the chord between the rod's ends, signed in the plane [m]."""
    a, m, b = (np.stack([results.probes[f"{n}.position.{c}"] for c in "xy"], axis=1)
               for n in ("rod_a", "rod_mid", "rod_b"))
    chord, d = b - a, m - a
    return (chord[:, 0] * d[:, 1] - chord[:, 1] * d[:, 0]) / np.linalg.norm(chord, axis=1)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "out/python_slider_crank"
    files = reduce_parts(out)
    rod = reduce_rod(out)
    results = scene(files["crank"], files["slider"], rod).run()
    w = midpoint_deflection(results)
    print(f"slider_crank.py: {len(results.time)} output steps, peak midpoint deflection {np.abs(w).max() * 1e3:.4f} mm")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 3.5))
    ax.plot(results.time, w * 1e3)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("rod midpoint deflection [mm]")
    ax.set_title("Planar slider-crank, rod in 2 superelements (femb from Python)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "deflection.png"), dpi=120)
    print(f"slider_crank.py: plot in {os.path.join(out, 'deflection.png')}")


if __name__ == "__main__":
    main()
