"""The generators' --stiffening flag: the segment part files say reduction.geometric_stiffening
(issue 13: the geometric stiffness inside each body and the exact inertia of the reduced field)
explicitly, true with the flag and false without it: femb-reduce's default is on, and the
examples' linear variants and 20-body references stay linear (the tables' numbers)."""


def take_flag(argv):
    """Removes --stiffening from argv (in place); True when it was there."""
    present = "--stiffening" in argv
    argv[:] = [a for a in argv if a != "--stiffening"]
    return present


def apply(part_path, on=True):
    """Sets the stiffening on or off in a generated part file (its reduction flow map)."""
    with open(part_path) as f:
        text = f.read()
    if "reduction: {" not in text:
        raise SystemExit(f"{part_path}: no 'reduction: {{' flow map to add geometric_stiffening to")
    with open(part_path, "w") as f:
        f.write(text.replace("reduction: {", f"reduction: {{geometric_stiffening: {'true' if on else 'false'}, ", 1))
