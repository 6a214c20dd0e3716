#!/usr/bin/python3
"""Writes the four-bar example's scenes and parts into OUTDIR (examples/four_bar/README.md).

A crank-rocker four-bar in the x-y plane: ground pivots A (origin) and D (0.4 m, 0), crank AB
0.1 m driven at 100 rad/s, coupler BC 0.35 m (a 6 mm steel rod), rocker DC 0.3 m. Three models
of the same mechanism:
  rigid.yaml          every link rigid: one loop, closed by a cut joint (femb picks the
                      rocker's ground pivot D) with 2 constraint equations (3 more are the
                      plane's and are dropped);
  flexible.yaml       the coupler flexible in 2 superelements, crank and rocker rigid: the same
                      cut joint closes the loop;
  superelements.yaml  every link a superelement (crank and rocker stiff, E = 2e14 Pa): the loop
                      closes through the rocker's own nodes, a tree without multipliers.
usage: make_scenes.py OUTDIR [END_TIME] [STEP]
"""
import math
import sys

d, a, b, c = 0.4, 0.1, 0.35, 0.3
omega = 100.0
rho, diameter = 7870.0, 0.006
area = math.pi * diameter ** 2 / 4


def coupler_point(theta):
    """C for the crank angle theta: |C - B| = b, |C - D| = c, the branch above the ground line."""
    B = (a * math.cos(theta), a * math.sin(theta))
    e = math.hypot(B[0] - d, B[1])
    x = (c * c - b * b + e * e) / (2 * e)
    y = math.sqrt(c * c - x * x)
    u = ((B[0] - d) / e, B[1] / e)
    v = (u[1], -u[0])
    return B, (d + x * u[0] + y * v[0], x * u[1] + y * v[1])


def p(v):
    return f"[{v[0]:.17g}, {v[1]:.17g}, 0]"


def rigid(name, P, Q, nP, nQ):
    """A uniform 6 mm steel rod as a rigid body (the stiff superelement's mass and inertia)."""
    L = math.hypot(Q[0] - P[0], Q[1] - P[1])
    m = rho * area * L
    I = m * L * L / 12
    Ia = m * diameter ** 2 / 8
    phi = math.atan2(Q[1] - P[1], Q[0] - P[0])
    return (f"  - {{name: {name}, type: rigid, mass: {m:.17g}, inertia: [{Ia:.17g}, {I:.17g}, {I:.17g}], "
            f"center_of_mass: [{L / 2:.17g}, 0, 0], points: {{P: [0, 0, 0], Q: [{L:.17g}, 0, 0]}}, "
            f"placement: {{position: {p(P)}, rotation: [0, 0, {phi:.17g}]}}, nodes: {{P: {nP}, Q: {nQ}}}}}\n")


def part(name, length, E, modes, comment):
    return (f"# {comment}\nname: {name}\ntype: beam\nunits: SI\nmaterial: {{E: {E:g}, nu: 0.3, rho: {rho:g}}}\n"
            f"section: {{shape: circle, diameter: {diameter:g}}}\nbeam:\n  theory: euler_bernoulli\n"
            f"  points: {{A: [0, 0, 0], B: [{length:.17g}, 0, 0]}}\n  segments: [{{from: A, to: B, elements: 10}}]\n"
            f"interfaces: [{{name: A}}, {{name: B}}]\nreduction: {{internal_modes: {modes}, floating_frame: center_of_mass}}\n")


def superelement(name, file, P, Q, nP, nQ):
    phi = math.atan2(Q[1] - P[1], Q[0] - P[0])
    return (f"  - {{name: {name}, superelement: {file}, placement: {{position: {p(P)}, rotation: [0, 0, {phi:.17g}]}}, "
            f"nodes: {{A: {nP}, B: {nQ}}}}}\n")


def main():
    out = sys.argv[1]
    end_time = float(sys.argv[2]) if len(sys.argv) > 2 else 3 * 2 * math.pi / omega
    step = float(sys.argv[3]) if len(sys.argv) > 3 else 2e-5
    theta0 = 0.0
    B, C = coupler_point(theta0)
    M = ((B[0] + C[0]) / 2, (B[1] + C[1]) / 2)
    joints = ("joints:\n"
              "  - {type: revolute, node: A, axis: [0, 0, 1], prescribed: crank_angle}\n"
              "  - {type: revolute, node: B2, parent: B1, axis: [0, 0, 1]}\n"
              "  - {type: revolute, node: C2, parent: C1, axis: [0, 0, 1]}\n"
              "  - {type: revolute, node: D, axis: [0, 0, 1]}\n"
              f"functions:\n  crank_angle: {{type: linear, slope: {omega:g}}}\n"
              f"analysis: {{type: dynamic, end_time: {end_time:.17g}, step: {step:g}, rho_inf: 0.8}}\n"
              "outputs:\n  probes:\n"
              "    - {name: crank, node: A, quantities: [joint]}\n"
              "    - {name: rod_a, node: B2, quantities: [position]}\n"
              "    - {name: rod_b, node: C1, quantities: [position]}\n")
    mid_probe = "    - {name: rod_mid, node: M, quantities: [position]}\n"
    # The rocker's angle: the joint at D is the one cut to close the loop; its probe shows the
    # angle from the placements.
    rocker_probe = "    - {name: rocker, node: D, quantities: [joint]}\n"
    # The ground's reactions: at A the driven tree joint's, at D the cut joint's (its multipliers).
    reaction_probes = ("    - {name: ground_a, node: A, quantities: [reaction]}\n"
                       "    - {name: ground_d, node: D, quantities: [reaction]}\n")
    with open(f"{out}/coupler_2.yaml", "w") as f:
        f.write(part("coupler_2", b / 2, 2e11, 4, "One half of the four-bar's coupler (0.35 m, 6 mm steel rod)."))
    with open(f"{out}/crank.yaml", "w") as f:
        f.write(part("crank", a, 2e14, 0, "The crank as a stiff superelement (E = 2e14 Pa)."))
    with open(f"{out}/rocker.yaml", "w") as f:
        f.write(part("rocker", c, 2e14, 0, "The rocker as a stiff superelement (E = 2e14 Pa)."))
    head = "units: SI\nbodies:\n"
    crank_rigid = rigid("crank", (0.0, 0.0), B, "A", "B1")
    rocker_rigid = rigid("rocker", (d, 0.0), C, "D", "C2")
    coupler_flexible = superelement("coupler0", "coupler_2.h5", B, M, "B2", "M") + superelement("coupler1", "coupler_2.h5", M, C, "M", "C1")
    with open(f"{out}/rigid.yaml", "w") as f:
        f.write("# The four-bar with every link rigid (make_scenes.py).\nname: four_bar_rigid\n" + head + crank_rigid +
                rigid("coupler", B, C, "B2", "C1") + rocker_rigid + joints + rocker_probe + reaction_probes)
    with open(f"{out}/flexible.yaml", "w") as f:
        f.write("# The four-bar with a flexible coupler in 2 superelements, rigid crank and rocker (make_scenes.py).\n"
                "name: four_bar_flexible\n" + head + crank_rigid + coupler_flexible + rocker_rigid + joints + mid_probe)
    with open(f"{out}/superelements.yaml", "w") as f:
        f.write("# The four-bar with every link a superelement (make_scenes.py).\nname: four_bar_superelements\n" + head +
                superelement("crank", "crank.h5", (0.0, 0.0), B, "A", "B1") + coupler_flexible +
                superelement("rocker", "rocker.h5", (d, 0.0), C, "D", "C2") + joints + mid_probe)


if __name__ == "__main__":
    main()
