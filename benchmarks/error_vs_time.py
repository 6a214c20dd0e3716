#!/usr/bin/python3
"""Error against run time on two seed cases, one setting changed at a time from a base model:

- slider_crank_2d (examples/slider_crank_2d; planar): base 4 bodies, 2 internal modes each,
  h = 10 us, rho_inf = 0.8. Error: RMS over the three revolutions of the rod midpoint deflection
  against a 20-body reference at h = 5 us, relative to the reference's peak.
- spinning_beam (examples/spinning_beam; spatial, spin + tumbling): base 2 bodies, 4 modes,
  h = 20 us, rho_inf = 0.5, Cardona's option B. Error: RMS of the 2 ms moving average of the base
  angular velocity about z against a 10-body reference at h = 2.5 us, relative to its peak.

The other settings: exact transformations, full tangent, Newton matrix every iteration,
quadratic velocity terms. Time: median wall time of femb-solve over REPEATS runs (reduction not
counted). Prints one table per case and writes a Pareto-style PNG per case.

usage: error_vs_time.py BIN_DIR [--cases slider_crank_2d,spinning_beam] [--repeats 3]
                        [--work DIR] [--png-prefix PREFIX]     (PNG: PREFIX<case>.png)
"""
import argparse
import os
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXAMPLES = os.path.join(ROOT, "examples")
sys.path.insert(0, os.path.join(EXAMPLES, "common"))
sys.path.insert(0, os.path.join(EXAMPLES, "slider_crank_2d"))
sys.path.insert(0, os.path.join(EXAMPLES, "spinning_beam"))
import compare as spinning  # noqa: E402  (the examples' own measures)
import deflection  # noqa: E402
import histories  # noqa: E402


def run(cmd):
    subprocess.run(cmd, check=True, capture_output=True)


class SliderCrank:
    name, title = "slider_crank_2d", "2D slider-crank"
    ylabel = "RMS error of the midpoint deflection [% of peak]"
    ex = os.path.join(EXAMPLES, "slider_crank_2d")
    base = dict(n=4, step=1e-5, modes=2, options="")
    reference = dict(n=20, step=5e-6, modes=2, options="")

    def setup(self, bin_dir):
        for part in ("crank", "slider"):
            run([os.path.join(bin_dir, "femb-reduce"), "-q", os.path.join(self.ex, f"{part}.yaml"), "-o",
                 os.path.join(self.ex, f"{part}.h5")])

    def prepare(self, bin_dir, out, n, step, modes, options):
        run(["/usr/bin/python3", os.path.join(self.ex, "make_variant.py"), str(n), out, repr(step), str(modes), options])
        run([os.path.join(bin_dir, "femb-reduce"), "-q", os.path.join(out, f"rod_{n}.yaml"), "-o",
             os.path.join(out, f"rod_{n}.h5")])

    def settings(self):
        s = [("bodies", f"{n} bodies", dict(n=n, modes=4 if n == 2 else 2), []) for n in (2, 4, 6, 10)]
        s += [("modes", f"{m} modes", dict(modes=m), []) for m in (0, 1, 4)]
        s += [("step", f"h = {h * 1e6:g} us", dict(step=h), []) for h in (4e-5, 2e-5, 5e-6)]
        s += [("rho_inf", f"rho_inf = {r}", {}, [f"analysis.rho_inf={r}"]) for r in (0.5, 1.0)]
        return s + common_settings()

    def error(self, run_dir, ref_dir):
        ref_angle, ref_w = deflection.load(ref_dir)
        angle, w = deflection.load(run_dir)
        err = [wi - histories.interpolate(ref_angle, ref_w, ai) for ai, wi in zip(angle, w)]
        return (sum(e * e for e in err) / len(err)) ** 0.5 / max(abs(v) for v in ref_w)


class SpinningBeam:
    name, title = "spinning_beam", "beam on a spherical joint"
    ylabel = "RMS error of the base angular velocity (2 ms average) [% of peak]"
    ex = os.path.join(EXAMPLES, "spinning_beam")
    base = dict(n=2, step=2e-5, modes=4, options="")
    reference = dict(n=10, step=2.5e-6, modes=2, options="")

    def setup(self, bin_dir):
        pass

    def prepare(self, bin_dir, out, n, step, modes, options):
        run(["/usr/bin/python3", os.path.join(self.ex, "make_variant.py"), out, str(n), repr(step), str(modes), options])
        run([os.path.join(bin_dir, "femb-reduce"), "-q", os.path.join(out, f"seg_{n}.yaml"), "-o",
             os.path.join(out, f"seg_{n}.h5")])

    def settings(self):
        s = [("bodies", f"{n} bodies", dict(n=n, modes=4 if n == 2 else 2), []) for n in (2, 4, 10)]
        s += [("modes", f"{m} modes", dict(modes=m), []) for m in (0, 2, 8)]
        s += [("step", f"h = {h * 1e6:g} us", dict(step=h), []) for h in (4e-5, 1e-5)]
        s += [("rho_inf", f"rho_inf = {r}", {}, [f"analysis.rho_inf={r}"]) for r in (0.2, 0.8)]
        s += [("inertia", f"corotational, option {o}", dict(options=f"{{inertia: corotational, inertia_option: {o}}}"), [])
              for o in "BA"]
        return s + [(g, label, dict(options=o or self.base["options"]), sets)
                    for g, label, o, sets in common_settings(raw=True)]

    def error(self, run_dir, ref_dir):
        def smooth(d):
            t, w = histories.load_columns(d, "time", spinning.COLUMN)
            return t, spinning.moving_average(t, w, 0.002)
        rt, rw = smooth(ref_dir)
        t, w = smooth(run_dir)
        inside = [k for k, tk in enumerate(t) if 0.001 <= tk <= t[-1] - 0.001]   # full 2 ms windows
        err = [w[k] - histories.interpolate(rt, rw, t[k]) for k in inside]
        peak = max(abs(v) for tk, v in zip(rt, rw) if 0.001 <= tk <= rt[-1] - 0.001)
        return (sum(e * e for e in err) / len(err)) ** 0.5 / peak


def common_settings(raw=False):
    """Formulation switches shared by both cases: (group, label, variant changes or options, --set)."""
    s = [("transformations", "approximated", "{transformations: approximated}", []),
         ("tangent", "K1-only tangent", "{tangent: K1}", []),
         ("tangent", "Jacobian reuse", "", ["analysis.jacobian_reuse=steps"]),
         ("velocity terms", "no quadratic velocity terms", "{quadratic_velocity_terms: false}", [])]
    return s if raw else [(g, label, dict(options=o) if o else {}, sets) for g, label, o, sets in s]


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


def measure(case, a):
    work = os.path.join(a.work, case.name)
    os.makedirs(work, exist_ok=True)
    case.setup(a.bin_dir)
    ref = os.path.join(work, "reference")
    case.prepare(a.bin_dir, ref, **case.reference)
    t_ref, failure = solve(a.bin_dir, ref, [], 1)
    if failure:
        sys.exit(f"{case.name}: the reference failed: {failure}")
    print(f"{case.title} error vs time; reference {case.reference} ({t_ref:.1f} s)")
    print(f"base {case.base}; median of {a.repeats} runs\n")
    print(f"{'group':<16} {'setting':<28} {'time [s]':>9} {'RMS error':>10}")
    rows = []
    for group, label, changes, sets in [("base", "base", {}, [])] + case.settings():
        variant = dict(case.base, **changes)
        out = os.path.join(work, label.replace(" ", "_").replace("=", "").replace("/", ""))
        case.prepare(a.bin_dir, out, **variant)
        t, failure = solve(a.bin_dir, out, sets, a.repeats)
        if failure:
            print(f"{group:<16} {label:<28} {'-':>9} {'failed':>10}  ({failure})")
            continue
        rms = case.error(out, ref)
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
    ax.set_ylabel(case.ylabel)
    ax.set_title(f"{case.title}: error vs time, one setting changed from the base")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    png = f"{a.png_prefix}{case.name}.png"
    fig.savefig(png, dpi=120)
    print(f"\nplot: {png}\n")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("bin_dir")
    ap.add_argument("--cases", default="slider_crank_2d,spinning_beam")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--work", default="/tmp/femb_error_vs_time")
    ap.add_argument("--png-prefix", default="error_vs_time_")
    a = ap.parse_args()
    a.bin_dir = os.path.abspath(a.bin_dir)
    cases = {c.name: c for c in (SliderCrank(), SpinningBeam())}
    for name in a.cases.split(","):
        if name not in cases:
            sys.exit(f"error_vs_time.py: unknown case {name} (have {', '.join(cases)})")
        measure(cases[name], a)


if __name__ == "__main__":
    main()
