"""The generators' --stiffening flag: the segment part files say reduction.geometric_stiffening
(the geometric stiffness inside each body) explicitly, true with the flag and false without it:
femb-reduce's default is on, and the examples' linear variants and 20-body references stay the
thesis's linear bodies (the tables' numbers): linear inside, with the corotational inertia
(thesis 3.22; body option inertia: corotational). femb-solve's default for a body without the
stiffening is the exact inertia, whose centrifugal load on the bending then has nothing to
balance it (rotating_beam README)."""


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


def body_options(stiffened, options=""):
    """The bodies' options text (", options: {...}" or "") for a generated scene: `options` (that
    text, possibly empty) with inertia: corotational added for the linear variants."""
    if stiffened:
        return options
    if not options:
        return ", options: {inertia: corotational}"
    return options.replace("options: {", "options: {inertia: corotational, ", 1)
