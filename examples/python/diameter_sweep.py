"""A design sweep on Dask: the slider-crank's rod diameter over 16 values, each design reduced
and simulated on a worker of a dask.distributed LocalCluster (2 workers), the peak rod midpoint
deflection gathered and plotted against the diameter.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/diameter_sweep.py [OUTDIR]
        [--end-time T] [--workers N] [--check] [--broken]

--check also runs the 16 designs one after another in this process and says whether the peaks
are the same; --broken adds a 17th design whose rod cannot be reduced (a negative diameter): its
error comes back in its place while the others finish. Against a cluster, pass its scheduler's
address as FEMB_DASK_SCHEDULER (every worker must see femb and OUTDIR at the same paths; the
model's module, slider_crank.py, is sent to the workers).
"""

import argparse
import functools
import os
import sys
import time

import numpy as np

import femb

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
# The workers import the model too: they start with this environment.
os.environ["PYTHONPATH"] = os.pathsep.join(p for p in (HERE, os.environ.get("PYTHONPATH")) if p)
import slider_crank  # noqa: E402  (the model, beside this file)


def peak_deflection(diameter, crank, slider, out, end_time, parts):
    """One design: its rod reduced, the slider-crank run in memory, the peak deflection [m]."""
    rod = slider_crank.reduce_rod(out, diameter, parts=parts)
    results = slider_crank.scene(crank, slider, rod, end_time=end_time).run()
    return float(np.abs(slider_crank.midpoint_deflection(results)).max())


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", nargs="?", default="out/python_diameter_sweep")
    parser.add_argument("--end-time", type=float, default=0.126, help="simulated time [s] (three revolutions)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--check", action="store_true", help="also run the designs serially and compare")
    parser.add_argument("--broken", action="store_true", help="add a design that fails")
    args = parser.parse_args()
    out = os.path.abspath(args.out)
    files = slider_crank.reduce_parts(out)
    diameters = list(np.linspace(0.004, 0.010, 16))
    if args.broken:
        diameters.append(-0.006)
    jobs = [functools.partial(peak_deflection, d, files["crank"], files["slider"], out, args.end_time,
                              slider_crank.PARTS) for d in diameters]

    from dask.distributed import Client, LocalCluster
    start = time.perf_counter()
    scheduler = os.environ.get("FEMB_DASK_SCHEDULER")
    if scheduler:
        client, cluster = Client(scheduler), None
        # A cluster's workers started elsewhere do not have this folder on their path: send them
        # the model's module (a LocalCluster's workers start with this environment).
        client.upload_file(os.path.join(HERE, "slider_crank.py"))
    else:
        cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
    try:
        peaks = femb.sweep(jobs, client=client)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    seconds = time.perf_counter() - start
    failed = [(d, p) for d, p in zip(diameters, peaks) if isinstance(p, Exception)]
    for d, p in zip(diameters, peaks):
        if isinstance(p, Exception):
            print(f"diameter_sweep.py: d = {d * 1e3:7.3f} mm: {type(p).__name__}: {p}")
        else:
            print(f"diameter_sweep.py: d = {d * 1e3:7.3f} mm: peak deflection {p * 1e3:.5f} mm")
    where = "the cluster's workers" if scheduler else f"{args.workers} local workers"
    print(f"diameter_sweep.py: {len(diameters)} designs on {where} in {seconds:.1f} s, {len(failed)} failed")
    if args.check:
        start = time.perf_counter()
        serial = femb.sweep(jobs)
        same = all((isinstance(a, Exception) and type(a) is type(b) and str(a) == str(b)) or a == b
                   for a, b in zip(peaks, serial))
        print(f"diameter_sweep.py: serial runs in {time.perf_counter() - start:.1f} s: "
              f"{'the same peaks' if same else 'DIFFERENT peaks'}")
        if not same:
            return 1
    good = [(d, p) for d, p in zip(diameters, peaks) if not isinstance(p, Exception)]
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.semilogy([d * 1e3 for d, _ in good], [p * 1e3 for _, p in good], "o-")
    ax.set_xlabel("rod diameter [mm]")
    ax.set_ylabel("peak midpoint deflection [mm]")
    ax.set_title("Slider-crank rod: a sweep on Dask (femb from Python)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "peak_deflection.png"), dpi=120)
    print(f"diameter_sweep.py: plot in {os.path.join(out, 'peak_deflection.png')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
