#!/usr/bin/python3
"""What stress output costs: the solid cantilever (examples/solid_bar's steel bar, TET10, clamped
at its root, a step force at its tip; 0.2 s at 1 ms: 201 output steps and animation frames) solved
with outputs.stresses off, on (the von Mises field), and on with outputs.principal_stresses, the
animation written each time. Prints femb-solve's own figures (solving, writing, total; best of
REPEATS runs on one thread) and the animation's size.
With --base-bin, the same runs with another build's femb-solve (e.g. an earlier commit's, built by
`git worktree add /tmp/base <commit>`): the ratios are the point on a noisy machine.

usage: stress_output.py BIN_DIR [--mesh-size 0.0125] [--repeats 3] [--base-bin DIR]
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

SCENE = """name: solid_cantilever
units: SI
bodies:
  - {name: bar, superelement: bar.h5, nodes: {root: A, tip: B}}
joints:
  - {type: clamp, node: A}
functions:
  on: {type: step, value: 1, t_start: 0}
loads:
  - {type: force, node: B, force: [0, 0, -1000], function: on}
analysis: {type: dynamic, end_time: 0.2, step: 1.0e-3}
outputs:
  stresses: false
  probes:
    - {name: tip, node: B, quantities: [position]}
"""


# The settings compared: label, outputs.stresses, outputs.principal_stresses.
SETTINGS = [("off", "false", "false"), ("on", "true", "false"), ("on, principal", "true", "true")]


def run(solve, work, stresses, principal, repeats):
    """Best of `repeats`: (solving, writing, total) seconds from femb-solve's summary line, and
    the animation's size in bytes."""
    best = None
    out = os.path.join(work, "out_%s_%s" % (stresses, principal))
    for _ in range(repeats):
        text = subprocess.run([solve, os.path.join(work, "scene.yaml"), "-o", out, "--threads", "1",
                               "--set", "outputs.stresses=%s" % stresses] +
                              (["--set", "outputs.principal_stresses=%s" % principal] if principal else []),
                              check=True, capture_output=True, text=True).stdout
        m = re.search(r"done in ([0-9.]+) s \(reading [0-9.]+ s, solving ([0-9.]+) s, writing ([0-9.]+) s\)", text)
        times = (float(m.group(2)), float(m.group(3)), float(m.group(1)))
        best = times if best is None or times[2] < best[2] else best
    return best, os.path.getsize(os.path.join(out, "animation.h5"))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("bin")
    ap.add_argument("--mesh-size", default="0.0125")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--base-bin", default="")
    a = ap.parse_args()
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    os.environ.update(env)
    with tempfile.TemporaryDirectory() as work:
        subprocess.run([os.path.join(a.bin, "femb-reduce"), os.path.join(ROOT, "examples/solid_bar/part.yaml"), "-o",
                        os.path.join(work, "bar.h5"), "-q", "--set", "mesh.size=" + a.mesh_size], check=True)
        with open(os.path.join(work, "scene.yaml"), "w") as f:
            f.write(SCENE)
        import h5py
        n_nodes = h5py.File(os.path.join(work, "bar.h5"), "r")["visualization/nodes"].shape[0]
        print("Stress output on the solid cantilever: %d mesh nodes (TET10, mesh size %s m), 200 steps, "
              "201 output steps and frames; best of %d, one thread" % (n_nodes, a.mesh_size, a.repeats))
        print()
        print("| femb-solve | stress output | solving [s] | writing [s] | total [s] | animation [MB] | bytes / node / frame |")
        print("|---|---|---:|---:|---:|---:|---:|")
        builds = [("this build", a.bin)] + ([("base", a.base_bin)] if a.base_bin else [])
        results = {}
        for label, bin_dir in builds:
            # (a base build without outputs.principal_stresses writes them with every stress run)
            settings = SETTINGS if label == "this build" else SETTINGS[:2]
            for setting, stresses, principal in settings:
                (solving, writing, total), size = run(os.path.join(bin_dir, "femb-solve"), work, stresses,
                                                      principal if label == "this build" else None, a.repeats)
                results[(label, setting)] = (solving, writing, total, size)
                print("| %s | %s | %.3f | %.3f | %.3f | %.1f | %.1f |" % (label, setting, solving, writing, total,
                                                                     size / 1e6, size / (n_nodes * 201.0)))
        print()
        for label, _ in builds:
            off = results[(label, "off")]
            for setting in ("on", "on, principal"):
                if (label, setting) in results:
                    on = results[(label, setting)]
                    print("%s: stresses %s / off: solving %.2fx, total %.2fx" % (label, setting, on[0] / off[0],
                                                                               on[2] / off[2]))
        if a.base_bin:
            b, t = results[("base", "on")], results[("this build", "on, principal")]
            print("this build with principal stresses / base: animation %.2fx the size (%.1f / %.1f MB), total "
                  "time %.2fx" % (t[3] / b[3], t[3] / 1e6, b[3] / 1e6, t[2] / b[2]))


if __name__ == "__main__":
    sys.exit(main())
