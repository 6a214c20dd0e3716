#!/usr/bin/python3
"""What writing the results during the run costs: the planar slider-crank with its rod in 10
linear superelements (examples/slider_crank_2d's make_variant.py, 10 us steps, every step an
output step), run for REVOLUTIONS crank revolutions with outputs.flush_every at its default
(10 s), at 1 s, and without writes during the run (flush_every 1e9: only the one after the
initial state and the final one). Prints femb-solve's own figures, best of REPEATS interleaved
runs on one thread: wall time, writes during the run and their time, and each setting's wall
time against the run without writes.

usage: flush_cost.py BIN_DIR [--revolutions 30] [--repeats 2]
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def run(solve, scene, out, end_time, flush_every):
    """(wall seconds, writes during the run, their seconds) from femb-solve's summary lines."""
    text = subprocess.run([solve, scene, "-o", out, "--threads", "1", "--set", "analysis.end_time=%g" % end_time,
                           "--set", "outputs.flush_every=%g" % flush_every],
                          check=True, capture_output=True, text=True).stdout
    wall = float(re.search(r"done in ([0-9.]+) s", text).group(1))
    m = re.search(r"results written (once|[0-9]+ times) during the run .*, ([0-9.]+) s in all", text)
    writes = 0 if not m else (1 if m.group(1) == "once" else int(m.group(1).split()[0]))
    return wall, writes, float(m.group(2)) if m else 0.0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("bin")
    ap.add_argument("--revolutions", type=float, default=30)
    ap.add_argument("--repeats", type=int, default=2)
    a = ap.parse_args()
    os.environ.update(OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    solve = os.path.join(a.bin, "femb-solve")
    end_time = a.revolutions * 2 * 3.141592653589793 / 150.0
    with tempfile.TemporaryDirectory() as work:
        here = os.path.join(ROOT, "examples", "slider_crank_2d")
        model = os.path.join(work, "model")
        subprocess.run(["/usr/bin/python3", os.path.join(here, "make_variant.py"), "10", model, "1e-5", "2"],
                       check=True, capture_output=True)
        for part in ("crank", "slider"):
            subprocess.run([os.path.join(a.bin, "femb-reduce"), "-q", os.path.join(here, part + ".yaml"), "-o",
                            os.path.join(model, part + ".h5")], check=True)
        subprocess.run([os.path.join(a.bin, "femb-reduce"), "-q", os.path.join(model, "rod_10.yaml"), "-o",
                        os.path.join(model, "rod_10.h5")], check=True)
        scene = os.path.join(model, "scene.yaml")
        settings = [("1e9 (none during the run)", 1e9), ("10 (default)", 10.0), ("1", 1.0)]
        best = {}
        for _ in range(a.repeats):
            for label, every in settings:
                r = run(solve, scene, os.path.join(work, "out"), end_time, every)
                if label not in best or r[0] < best[label][0]:
                    best[label] = r
        size = os.path.getsize(os.path.join(work, "out", "results.h5"))
        print("Writing results during the run: slider-crank, rod in 10 linear bodies, %g revolutions at 10 us "
              "(%d output steps; results.h5 %.0f MB at the end), best of %d interleaved runs, one thread"
              % (a.revolutions, round(end_time / 1e-5) + 1, size / 1e6, a.repeats))
        print()
        print("| outputs.flush_every [s] | wall [s] | writes during the run | their time [s] | wall / without |")
        print("|---|---:|---:|---:|---:|")
        base = best[settings[0][0]][0]
        for label, _ in settings:
            wall, writes, seconds = best[label]
            print("| %s | %.2f | %d | %.3f | %.3f |" % (label, wall, writes, seconds, wall / base))


if __name__ == "__main__":
    sys.exit(main())
