#!/usr/bin/python3
"""Error against run time on the seeds' 2D slider-crank (examples/slider_crank_2d): one setting
changed at a time from the base model (4 bodies, 2 internal modes each, h = 10 us, rho_inf = 0.8,
exact transformations, full tangent, Newton matrix every iteration, quadratic velocity terms).
Error: RMS over the three revolutions of the rod midpoint deflection against a 20-body reference
at h = 5 us, relative to the reference's peak. Time: median wall time of femb-solve over REPEATS
runs (reduction not counted). Prints the table and writes a Pareto-style PNG.

usage: error_vs_time.py BIN_DIR [--repeats 3] [--work DIR] [--png FILE]
"""
import argparse
import os
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EX = os.path.join(ROOT, "examples", "slider_crank_2d")
sys.path.insert(0, EX)
import deflection  # noqa: E402  (the example's own measure)


def prepare(bin_dir, work, name, n, step, modes, options=""):
    out = os.path.join(work, name)
    subprocess.run(["/usr/bin/python3", os.path.join(EX, "make_variant.py"), str(n), out, repr(step), str(modes), options],
                   check=True, capture_output=True)
    subprocess.run([os.path.join(bin_dir, "femb-reduce"), "-q", os.path.join(out, f"rod_{n}.yaml"), "-o",
                    os.path.join(out, f"rod_{n}.h5")], check=True)
    return out


def solve(bin_dir, out, sets, repeats):
    times = []
    for _ in range(repeats):
        start = time.time()
        r = subprocess.run([os.path.join(bin_dir, "femb-solve"), "-q", os.path.join(out, "scene.yaml"), "-o", out] +
                           [a for s in sets for a in ("--set", s)], capture_output=True, text=True)
        times.append(time.time() - start)
        if r.returncode != 0:
            return None, r.stderr.strip().splitlines()[-1] if r.stderr.strip() else f"exit {r.returncode}"
    return statistics.median(times), None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("bin_dir")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--work", default="/tmp/femb_error_vs_time")
    ap.add_argument("--png", default="error_vs_time.png")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    for part in ("crank", "slider"):
        subprocess.run([os.path.join(a.bin_dir, "femb-reduce"), "-q", os.path.join(EX, f"{part}.yaml"), "-o",
                        os.path.join(EX, f"{part}.h5")], check=True)
    ref = prepare(a.bin_dir, a.work, "reference", 20, 5e-6, 2)
    t_ref, _ = solve(a.bin_dir, ref, [], 1)
    ref_angle, ref_w = deflection.load(ref)
    peak = max(abs(v) for v in ref_w)
    print(f"slider-crank error vs time; reference: 20 bodies, h = 5 us ({t_ref:.1f} s), peak deflection {peak * 1e3:.3f} mm")
    print(f"base: 4 bodies, 2 modes, h = 10 us, rho_inf = 0.8, exact, full tangent; median of {a.repeats} runs\n")
    # (group, label, bodies, step, modes, options, --set overrides)
    settings = [("bodies", f"{n} bodies", n, 1e-5, 4 if n == 2 else 2, "", []) for n in (2, 4, 6, 10)]
    settings += [("modes", f"{m} modes", 4, 1e-5, m, "", []) for m in (0, 1, 4)]
    settings += [("step", f"h = {h * 1e6:g} us", 4, h, 2, "", []) for h in (4e-5, 2e-5, 5e-6)]
    settings += [("rho_inf", f"rho_inf = {r}", 4, 1e-5, 2, "", [f"analysis.rho_inf={r}"]) for r in (0.5, 1.0)]
    settings += [("transformations", "approximated", 4, 1e-5, 2, "{transformations: approximated}", [])]
    settings += [("tangent", "K1-only tangent", 4, 1e-5, 2, "{tangent: K1}", []),
                 ("tangent", "Jacobian reuse", 4, 1e-5, 2, "", ["analysis.jacobian_reuse=true"])]
    settings += [("velocity terms", "no quadratic velocity terms", 4, 1e-5, 2, "{quadratic_velocity_terms: false}", [])]
    rows = []
    print(f"{'group':<16} {'setting':<28} {'time [s]':>9} {'RMS error':>10}")
    for group, label, n, step, modes, options, sets in settings:
        name = label.replace(" ", "_").replace("=", "").replace("/", "")
        out = prepare(a.bin_dir, a.work, name, n, step, modes, options)
        t, failure = solve(a.bin_dir, out, sets, a.repeats)
        if failure:
            print(f"{group:<16} {label:<28} {'-':>9} {'failed':>10}  ({failure})")
            continue
        angle, w = deflection.load(out)
        err = [wi - deflection.interpolate(ref_angle, ref_w, ai) for ai, wi in zip(angle, w)]
        rms = (sum(e * e for e in err) / len(err)) ** 0.5 / peak
        rows.append((group, label, t, rms))
        print(f"{group:<16} {label:<28} {t:9.2f} {rms:10.2%}", flush=True)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7.5, 5))
    for g in dict.fromkeys(r[0] for r in rows):
        pts = [r for r in rows if r[0] == g]
        ax.scatter([r[2] for r in pts], [r[3] * 100 for r in pts], label=g)
        for r in pts:
            ax.annotate(r[1], (r[2], r[3] * 100), fontsize=7, xytext=(3, 3), textcoords="offset points")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time of femb-solve [s] (median)")
    ax.set_ylabel("RMS error of the midpoint deflection [% of peak]")
    ax.set_title("2D slider-crank: error vs time, one setting changed from the base")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(a.png, dpi=120)
    print(f"\nplot: {a.png}")


if __name__ == "__main__":
    main()
