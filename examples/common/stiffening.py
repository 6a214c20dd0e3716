"""The generators' --stiffening flag: the segment part files get reduction.geometric_stiffening
(issue 13: the geometric stiffness inside each body and the exact inertia of the reduced field)."""


def take_flag(argv):
    """Removes --stiffening from argv (in place); True when it was there."""
    present = "--stiffening" in argv
    argv[:] = [a for a in argv if a != "--stiffening"]
    return present


def apply(part_path):
    """Switches the stiffening on in a generated part file (its reduction flow map)."""
    with open(part_path) as f:
        text = f.read()
    if "reduction: {" not in text:
        raise SystemExit(f"{part_path}: no 'reduction: {{' flow map to add geometric_stiffening to")
    with open(part_path, "w") as f:
        f.write(text.replace("reduction: {", "reduction: {geometric_stiffening: true, ", 1))
