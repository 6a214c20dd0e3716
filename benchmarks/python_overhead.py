#!/usr/bin/python3
"""What the Python route costs: the 10-body slider-crank (examples/slider_crank_2d with its rod
in 10 superelements, 10 us steps, 0.126 s) run by femb-solve, by femb.Scene.run and stepped by
Simulation.step_to (reading a node at each pause), best of 3 interleaved runs, one thread; and a
force written in Python, its cost per call.

usage: PYTHONPATH=build/python /usr/bin/python3 benchmarks/python_overhead.py [BIN] [--repeat N]
Prints what it measured on this run.
"""

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time


HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("bin", nargs="?", default=os.path.join(ROOT, "build", "bin"))
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    import femb
    binary = os.path.abspath(args.bin)
    work = tempfile.mkdtemp(prefix="femb_python_overhead_")
    try:
        sc = os.path.join(ROOT, "examples", "slider_crank_2d")
        for part in ("crank", "slider"):
            subprocess.run([os.path.join(binary, "femb-reduce"), "-q", os.path.join(sc, part + ".yaml"), "-o",
                            os.path.join(sc, part + ".h5")], check=True)
        variant = os.path.join(work, "ten")
        subprocess.run(["/usr/bin/python3", os.path.join(sc, "make_variant.py"), "10", variant], check=True,
                       stdout=subprocess.DEVNULL)
        subprocess.run([os.path.join(binary, "femb-reduce"), "-q", os.path.join(variant, "rod_10.yaml"), "-o",
                        os.path.join(variant, "rod_10.h5")], check=True)
        scene_file = os.path.join(variant, "scene.yaml")
        times = {"femb-solve -o DIR": [], "Scene.run(output=DIR)": [], "Scene.run() in memory": [],
                 "Scene.start(), step_to every 1 ms, in memory": [], "Scene.start(), step_to every step, in memory": []}
        for _ in range(args.repeat):
            start = time.perf_counter()
            subprocess.run([os.path.join(binary, "femb-solve"), "-q", scene_file, "-o", os.path.join(work, "cli"),
                            "--threads", "1"], check=True)
            times["femb-solve -o DIR"].append(time.perf_counter() - start)
            start = time.perf_counter()
            femb.Scene.load(scene_file).run(output=os.path.join(work, "py"))
            times["Scene.run(output=DIR)"].append(time.perf_counter() - start)
            start = time.perf_counter()
            results = femb.Scene.load(scene_file).run()
            times["Scene.run() in memory"].append(time.perf_counter() - start)
            for every, route in ((1e-3, "Scene.start(), step_to every 1 ms, in memory"),
                                 (1e-5, "Scene.start(), step_to every step, in memory")):
                start = time.perf_counter()
                with femb.Scene.load(scene_file).start() as sim:
                    for k in range(1, int(round(0.126 / every)) + 1):
                        sim.step_to(k * every)
                        sim.node("rod_mid")
                    sim.finish()
                times[route].append(time.perf_counter() - start)
        steps = results.step_count
        base = min(times["femb-solve -o DIR"])
        print(f"python_overhead: 10-body slider-crank, {steps} steps, one thread, best of {args.repeat} (this run)")
        print("| route | wall [s] | / femb-solve |")
        print("|---|---:|---:|")
        for route, t in times.items():
            print(f"| {route} | {min(t):.3f} | {min(t) / base:.3f} |")
        # A force written in Python: the sprung bar of python/tests/test_user_force.py with the
        # built-in spring and with the same spring as a Python function (Jacobian given), the
        # difference in wall time over the calls made.
        sys.path.insert(0, os.path.join(ROOT, "python", "tests"))
        import test_user_force as bar
        calls = [0]

        def counted(*a):
            calls[0] += 1
            return bar.spring_with_jacobian(*a)

        analysis = {"type": "dynamic", "end_time": 5.0, "step": 1e-4, "rho_inf": 0.9}
        builtin, python = [], []
        for _ in range(args.repeat):
            scene = femb.Scene(bar.bar(True, analysis))
            start = time.perf_counter()
            scene.run()
            builtin.append(time.perf_counter() - start)
            calls[0] = 0
            scene = femb.Scene(bar.bar(False, analysis)).add_force("tip", counted, jacobian=True)
            start = time.perf_counter()
            scene.run()
            python.append(time.perf_counter() - start)
        per_call = (min(python) - min(builtin)) / calls[0]
        print(f"python_overhead: a Python force (spring-damper with its Jacobian, numpy): {calls[0]} calls in "
              f"{min(python):.3f} s against {min(builtin):.3f} s with the built-in spring: {per_call * 1e6:.1f} us "
              f"per call")
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
