"""The slider-cranks' flexible rod (0.3 m, 6 mm diameter, E = 0.2e12 Pa, rho = 7870) in N equal
superelements: the segment's part file and the rod's scene node names (shared by the planar and
the spatial slider-crank generators)."""
import os

LENGTH = 0.3


def write_segment(out, n, modes):
    """Writes OUT/rod_N.yaml (one segment of length 0.3/N); returns the segment length."""
    L = LENGTH / n
    elements = max(4, 20 // n)
    with open(os.path.join(out, f"rod_{n}.yaml"), "w") as f:
        f.write(f"""# One of {n} segments of the slider-crank's rod (L = 0.3 m, d = 6 mm, E = 0.2e12 Pa, rho = 7870).
name: rod_{n}
type: beam
units: SI
material: {{E: 2.0e11, nu: 0.3, rho: 7870}}
section: {{shape: circle, diameter: 0.006}}
beam:
  theory: euler_bernoulli
  points: {{A: [0, 0, 0], B: [{L!r}, 0, 0]}}
  segments: [{{from: A, to: B, elements: {elements}}}]
interfaces: [{{name: A}}, {{name: B}}]
reduction: {{internal_modes: {modes}, floating_frame: center_of_mass}}
""")
    return L


def node_names(n):
    """rod_a, rod_1, ..., rod_b with the middle node (N even) named rod_mid."""
    names = ["rod_a"] + [f"rod_{i}" for i in range(1, n)] + ["rod_b"]
    names[n // 2] = "rod_mid"
    return names


def parse_args(argv):
    """make_variant.py N OUTDIR [STEP] [MODES] [OPTIONS] -> (n, out, step, modes, options text);
    creates OUTDIR. N must be even (the rod midpoint is then a node). MODES defaults to 4 per body
    for 2 bodies, 2 above; OPTIONS is a YAML flow map of the rod bodies' options."""
    import sys
    n, out = int(argv[1]), argv[2]
    step = float(argv[3]) if len(argv) > 3 else 1.0e-5
    modes = int(argv[4]) if len(argv) > 4 and argv[4] else (4 if n <= 2 else 2)
    options = f", options: {argv[5]}" if len(argv) > 5 and argv[5] else ""
    if n < 2 or n % 2:
        sys.exit("make_variant.py: N must be even and >= 2")
    os.makedirs(out, exist_ok=True)
    return n, out, step, modes, options
