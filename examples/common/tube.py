"""The seeds' tube (L = 1 m, outer radius 0.01 m, wall 0.001 m, E = 70 GPa, rho = 2700 kg/m^3)
as beam part files of its segments: shared by the cantilever_static, cantilever_transient and
rotating_beam generators."""
import os


def write_part(path, name, length, elements, modes, frame, comment):
    """Writes the part file of a tube segment of the given length (Euler-Bernoulli elements,
    interfaces A at x = 0 and B at x = length)."""
    with open(path, "w") as g:
        g.write(f"""# {comment}
name: {name}
type: beam
units: SI
material: {{E: 70.0e9, nu: 0.3, rho: 2700}}
section: {{shape: tube, outer_radius: 0.01, wall: 0.001}}
beam:
  theory: euler_bernoulli
  points: {{A: [0, 0, 0], B: [{length!r}, 0, 0]}}
  segments: [{{from: A, to: B, elements: {elements}}}]
interfaces: [{{name: A}}, {{name: B}}]
reduction: {{internal_modes: {modes}, floating_frame: '{frame}'}}
""")


def write_segment(out, n, frame="center_of_mass"):
    """Writes OUT/seg.yaml: a segment of length 1/n, 4 internal modes below 3 bodies, else 2."""
    length = 1.0 / n
    write_part(os.path.join(out, "seg.yaml"), "seg", length, max(4, 40 // n), 4 if n < 3 else 2, frame,
               f"1/{n} of the seeds' tube: outer radius 0.01 m, wall 0.001 m, E = 70 GPa, rho = 2700 kg/m^3.")
    return length
