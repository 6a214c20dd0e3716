"""femb from Python: reduce a part's mesh to a superelement file, inspect it, and simulate scenes
of superelements and rigid bodies, with the same defaults, checks and messages as the programs
femb-reduce, femb-inspect and femb-solve, and the results as numpy arrays.

    import femb
    rod = femb.reduce("examples/slider_crank_2d/rod.yaml", "rod.h5")
    print(rod.frequencies)                      # fixed-interface frequencies [Hz]
    scene = femb.Scene.load("examples/slider_crank_2d/scene.yaml")
    scene.set("analysis.end_time", 0.03)        # the --set key paths
    results = scene.run()                       # in memory; run(output="out/dir") also writes files
    results.probes["rod_mid.position.y"]        # numpy, one value per output step
    scene.add_force("rod_mid", lambda t, x, R, v, w: [0, -1.0 * x[1], 0, 0, 0, 0])   # a force in Python
    with scene.start() as sim:                  # stepping under your control
        sim.step_to(0.01)
        sim.node("rod_mid")["position"]

Units are the part's and the scene's (`units:`, SI by default). Errors: a bad input raises
femb.InputError whose message is the program's line (file, line, key); a numerical failure
raises femb.NumericalError with the results up to the failure in its `results`; a part whose
factor would not fit in memory raises femb.RefusedError. Warnings go to Python's warnings
(category femb.FembWarning); progress lines go to a callable you pass (none by default).
"""

import json
import os
import shutil
import warnings

from . import _core
from ._core import FembError, InputError, NumericalError, RefusedError

from .sweep import sweep

__all__ = ["reduce", "Superelement", "Scene", "Simulation", "Results", "sweep", "FembError", "InputError", "NumericalError",
           "RefusedError", "FembWarning"]


for _error in (FembError, InputError, NumericalError, RefusedError):
    _error.__module__ = "femb"  # shown as femb.InputError in tracebacks


class FembWarning(UserWarning):
    """A warning femb-solve or femb-reduce would print (and print also with --quiet)."""


def _warn(line):
    warnings.warn(line.removeprefix("warning: "), FembWarning, stacklevel=2)


def _json_default(value):
    # numpy scalars and arrays in a scene or part dict, as plain numbers and lists.
    if hasattr(value, "tolist"):
        return value.tolist()
    raise TypeError(f"{type(value).__name__} {value!r} is not a number, string, list or dict")


def _overrides(values):
    """{"analysis.end_time": 0.03} -> ["analysis.end_time=0.03"]: each value as YAML (JSON is YAML)."""
    out = []
    for key, value in (values or {}).items():
        out.append(f"{key}={json.dumps(value, default=_json_default)}")
    return out


def _document(source, what, base_dir):
    """(text, name) of a YAML file path or of a dict with the same content. A dict's relative paths
    start from base_dir (default: the current folder); its lines are reported as <what dict>."""
    if isinstance(source, dict):
        text = json.dumps(source, indent=1, default=_json_default)
        return text, os.path.join(os.path.abspath(base_dir or "."), f"<{what} dict>")
    path = os.fspath(source)
    try:
        with open(path, encoding="utf-8") as f:
            return f.read(), path
    except OSError as e:
        raise InputError(f"{path}: cannot read {what} file ({e.strerror})") from None


class Superelement:
    """A superelement file (what femb-reduce writes; formats/SUPERELEMENT_FORMAT.md).

    K, M: the reduced stiffness and mass (numpy, n x n); labels: each reduced coordinate's name
    (interface node and direction, or mode); interfaces: {name: (position, orientation)};
    frequencies: the fixed-interface frequencies of the internal modes [Hz];
    mass_properties: {"mass", "center_of_mass", "inertia_com"} in part axes.
    """

    def __init__(self, path):
        self.path = os.fspath(path)
        self._data = _core.read_superelement(self.path)
        self._shapes = None

    def __repr__(self):
        return (f"femb.Superelement({self.path!r}: {self.name}, {self.K.shape[0]} reduced coordinates, "
                f"{len(self.interfaces)} interface nodes)")

    @property
    def name(self):
        return self._data.name

    @property
    def K(self):
        return self._data.K

    @property
    def M(self):
        return self._data.M

    @property
    def labels(self):
        return self._data.labels

    @property
    def interfaces(self):
        return {i.name: (i.position, i.orientation) for i in self._data.interfaces}

    @property
    def frequencies(self):
        return self._data.internal_frequencies_hz

    @property
    def full_frequencies(self):
        """The unreduced model's free-free frequencies [Hz] when the file holds them (else empty)."""
        return self._data.full_free_free_frequencies_hz

    @property
    def mass_properties(self):
        p = self._data.mass_properties
        return {"mass": p.mass, "center_of_mass": p.center_of_mass, "inertia_com": p.inertia_com}

    def checks(self):
        """femb-inspect's report and checks (what `femb-inspect --json` prints), as a dict."""
        return json.loads(self._data.checks_json())

    @property
    def mesh(self):
        """(nodes, cells): the file's mesh in part axes, or None when it holds none."""
        if not self._data.has_mesh:
            return None
        return self._data.mesh_nodes, self._data.mesh_cells

    def mode_shape(self, i):
        """Reduced coordinate i's shape on the mesh: (n_nodes, 3) for solids and shells' translations,
        (n_nodes, 6) for beams (translations, rotations)."""
        if not self._data.has_mesh:
            raise InputError(f"{self.path}: holds no mesh to show a mode shape on")
        if self._shapes is None:
            self._shapes = self._data.mesh_shapes
        n = self._shapes.shape[1]
        if not 0 <= i < n:
            raise IndexError(f"{self.path}: reduced coordinate {i} of {n}")
        return self._shapes[:, i].reshape(-1, self._data.mesh_dofs_per_node)

    def to_vtu(self, directory):
        """Writes the mode shapes for ParaView (what femb-inspect --vtu writes); returns the number of files."""
        return self._data.write_vtu(os.fspath(directory))


def reduce(part, output=None, set=None, progress=None, base_dir=None):
    """Reduces a part to a superelement file, as femb-reduce does, and returns it.

    part: a part file's path, or a dict of the same content (formats/PART_FORMAT.md);
    output: the file to write (default: <part name>.h5 in the current folder), written under a
    temporary name and renamed; set: {"reduction.internal_modes": 8, ...} as femb-reduce's --set;
    progress: a callable taking each stage's line (e.g. print), none by default.
    """
    text, name = _document(part, "part", base_dir)
    data = _core.reduce(text, name, _overrides(set), os.fspath(output) if output else "", progress, _warn)
    written = os.fspath(output) if output else None
    result = Superelement.__new__(Superelement)
    result.path = written or os.path.abspath(data.name + ".h5")
    result._data = data
    result._shapes = None
    return result


class Scene:
    """A scene (formats/SCENE_FORMAT.md): Scene.load(path) or Scene(dict). Checked when made and at
    every set(); run() simulates it."""

    def __init__(self, spec, base_dir=None):
        self._text, self._name = _document(spec, "scene", base_dir)
        self._set = {}
        self._forces = []
        self._modal_forces = []
        _core.check_scene(self._text, self._name, [])

    @classmethod
    def load(cls, path, set=None):
        scene = cls(os.fspath(path))
        for key, value in (set or {}).items():
            scene.set(key, value)
        return scene

    def set(self, key, value):
        """Overrides one key, as femb-solve --set key=value (e.g. "analysis.step", 5e-4 or
        "bodies[1].options.modal_damping", 0.02). Returns the scene."""
        trial = dict(self._set)
        trial[key] = value
        _core.check_scene(self._text, self._name, _overrides(trial))
        self._set = trial
        return self

    def add_force(self, node, function, jacobian=False, name=None, other=None):
        """Adds a force written in Python on a node of the scene. Returns the scene.

        function(t, position, rotation, velocity, angular_velocity) returns the force and the
        moment about the node, (fx, fy, fz, mx, my, mz), in world axes and the scene's units, of
        the time t [s] (statics: the load factor, at rest) and the node's position (3), rotation
        (3 x 3, node axes in world axes), velocity (3) and angular velocity (3, world axes). With
        jacobian=True it returns (f, K, C): K = df/d(position, theta) with theta the rotation
        increment in world axes (rotation -> exp(theta~) rotation), C = df/d(velocity,
        angular_velocity), each 6 x 6; without, femb differences the function (12 more calls
        whenever the iteration matrix is built). It enters Newton's residual and matrix like the
        built-in loads, the reactions and the energy balance's external work, with either
        integrator, statics and step: auto. An exception, a wrong shape or a value that is not
        finite stops the run with NumericalError naming the force and the time (results kept).

        other: a second node for a force between two nodes (a bushing, a spring of your own law):
        function(t, position, rotation, velocity, angular_velocity, position_other,
        rotation_other, velocity_other, angular_velocity_other) gives the force and moment on
        `node`; `other` takes the opposite force and the opposite moment about itself, so the
        pair keeps momentum. With jacobian=True it returns (f, K, C), K = df/d(position, theta,
        position_other, theta_other) and C = df/d(velocity, angular_velocity, velocity_other,
        angular_velocity_other), each 6 x 12 (femb derives the other node's from them); without,
        femb differences the function (24 more calls per matrix).
        """
        self._forces.append((str(node), str(other) if other is not None else "",
                             name or getattr(function, "__name__", "force"), function, bool(jacobian)))
        return self

    def add_modal_force(self, body, function, jacobian=False, name=None):
        """Adds a generalized force written in Python on a flexible body's modal coordinates (the
        internal coordinates of its superelement, results.body(name)["modal_coordinates"]).
        Returns the scene.

        function(t, q, qdot) returns Q, one value per modal coordinate (the virtual work Q . dq:
        units of force times the coordinate's), e.g. an actuator, a damper or a control force on
        the modes. With jacobian=True it returns (Q, K, C), K = dQ/dq, C = dQ/dqdot; without, femb
        differences it (2 n calls more per matrix). It enters the residual, the iteration matrix
        and the external work like the node forces.
        """
        self._modal_forces.append((str(body), name or getattr(function, "__name__", "modal_force"), function,
                                   bool(jacobian)))
        return self

    def start(self, output=None, threads=1, progress=None):
        """A dynamic analysis to step under your control: a Simulation (see its step_to). The
        arguments as run()'s."""
        return Simulation(_core.Simulation(self._text, self._name, _overrides(self._set),
                                           os.fspath(output) if output else "", int(threads), progress, _warn,
                                           self._forces, self._modal_forces))

    def run(self, output=None, threads=1, progress=None):
        """Runs the scene's analysis and returns its Results.

        output: a folder to write results.h5, probes.csv, the animation and checkpoint.h5 into, as
        femb-solve -o does; None (default): the results stay in memory, no file is written.
        threads: for the bodies' forces and matrices (the same bits for any number).
        progress: a callable taking femb-solve's progress lines (e.g. print); none by default.
        A numerical failure raises NumericalError with the results up to it in `.results`.
        Ctrl-C stops a dynamic run at the end of its step (within 0.1 s and 64 steps) and raises
        KeyboardInterrupt; with `output` the results up to there are in the folder.
        """
        r = _core.run(self._text, self._name, _overrides(self._set), os.fspath(output) if output else "",
                      int(threads), progress, _warn, self._forces, self._modal_forces)
        results = Results(r)
        if r.exit_code != 0:
            error = NumericalError(r.error)
            error.results = results
            raise error
        return results


def _plain(series):
    """The C++ series (RecordedResults) as a namespace of numpy copies, lists and numbers."""
    import types
    import numpy as np

    def copy(value):
        if isinstance(value, np.ndarray):
            return value.copy()
        if isinstance(value, list) and value and hasattr(value[0], "modal_coordinates"):
            return [_plain(v) for v in value]
        return value

    names = [n for n in dir(series) if not n.startswith("_")]
    return types.SimpleNamespace(**{n: copy(getattr(series, n)) for n in names})


class Simulation:
    """A dynamic run stepped under the caller's control (Scene.start): step_to(t) takes the
    scene's steps up to the first that ends at or after t; between steps the caller reads the
    state (node(name), time, results()) and may change what its forces read, for co-simulation
    and controllers. The same steps and results as run()'s. A context manager; close() (or the
    end of a with block) stops an unfinished run::

        with scene.start() as sim:
            for t in np.arange(0.001, 0.1, 0.001):
                sim.step_to(t)
                controller.update(sim.node("tip")["position"])
            results = sim.finish()
    """

    def __init__(self, core):
        self._core = core

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    @property
    def time(self):
        """The time the run has reached [s]."""
        return self._core.time

    @property
    def done(self):
        return self._core.done

    def step_to(self, t):
        """Steps to the first step end at or after t (at most to the analysis' end_time); returns
        the time reached. A numerical failure raises NumericalError with the results so far."""
        reached = self._core.step_to(float(t))
        if self._core.done:
            self._raise_if_failed()
        return reached

    def node(self, name):
        """The node's position, rotation (3 x 3), velocity and angular velocity (world axes) now."""
        return self._core.node(name)

    def results(self):
        """The results recorded so far."""
        return Results(self._core.results())

    def finish(self):
        """Runs to the analysis' end_time and returns the Results."""
        self._core.step_to(float("inf"))
        self._raise_if_failed()
        return self.results()

    def close(self):
        """Stops an unfinished run at its next step's end (the results so far are kept)."""
        self._core.close()

    def _raise_if_failed(self):
        r = self._core.results()
        if r.exit_code == 3:
            error = NumericalError(r.error)
            error.results = Results(r)
            raise error


class Results:
    """A run's results as numpy arrays, a row per output step (what results.h5 holds).

    time; probes: {column: values} with probes.csv's column names in full precision;
    energy: {"kinetic", "elastic", "external_work", "linear_momentum", "angular_momentum"};
    node(name) and body(name): their series; frequencies: a modes analysis' [Hz];
    steps: every step taken {"time", "size"}; step_count and newton_iterations over the run;
    status: "completed" or what stopped the run.
    """

    def __init__(self, run_result):
        r = run_result.results
        self._r = r
        self.status = run_result.status
        self.analysis = run_result.analysis
        self.ok = run_result.exit_code == 0
        self.step_count = run_result.steps
        self.newton_iterations = run_result.iterations
        self.time = r.time
        probes = r.probes
        self.probes = {name: probes[:, i] for i, name in enumerate(r.probe_names)}
        self.energy = {"kinetic": r.kinetic, "elastic": r.elastic, "external_work": r.external_work,
                       "linear_momentum": r.linear_momentum, "angular_momentum": r.angular_momentum}
        self.frequencies = run_result.frequencies_hz
        self.steps = {"time": r.steps_time, "size": r.steps_size}
        self.nodes = list(r.node_names)
        self.bodies = [b.name for b in r.bodies]
        self._run = run_result  # the animation's frames of a run kept in memory (write_animation)

    def __getstate__(self):
        # Sent between processes (a sweep's workers): the series as plain numpy arrays, without
        # the run (its model and animation frames stay where it ran).
        state = dict(self.__dict__)
        state["_r"] = _plain(self._r)
        state["_run"] = None
        return state

    def __setstate__(self, state):
        self.__dict__.update(state)

    def __repr__(self):
        return (f"femb.Results({self.analysis}, {len(self.time)} output steps, {len(self.probes)} probe columns, "
                f"status {self.status!r})")

    def node(self, name):
        """A node's series: position (n x 3), quaternion (n x 4: w, x, y, z), velocity,
        angular_velocity (n x 3), reaction (n x 6, with outputs.reactions), joint_coordinates."""
        try:
            k = self.nodes.index(name)
        except ValueError:
            raise KeyError(f"no node '{name}' (nodes: {', '.join(self.nodes)})") from None
        r = self._r
        out = {"position": r.position[:, 3 * k:3 * k + 3], "quaternion": r.quaternion[:, 4 * k:4 * k + 4],
               "velocity": r.velocity[:, 3 * k:3 * k + 3],
               "angular_velocity": r.angular_velocity[:, 3 * k:3 * k + 3]}
        if r.reaction.shape[0] > 0:
            out["reaction"] = r.reaction[:, 6 * k:6 * k + 6]
        columns = [i for i, label in enumerate(r.joint_coordinate_labels) if label.rsplit(".", 1)[0] == name]
        if columns:
            out["joint_coordinates"] = r.joint_coordinates[:, columns[0]:columns[-1] + 1]
        return out

    def body(self, name):
        """A body's series: modal_coordinates, floating_frame (x, quaternion), center_of_mass, nodes,
        and with stresses max_von_mises with its mesh node and point."""
        for b in self._r.bodies:
            if b.name == name:
                out = {"modal_coordinates": b.modal_coordinates, "floating_frame": b.floating_frame,
                       "center_of_mass": b.center_of_mass, "nodes": list(b.nodes)}
                if len(b.max_von_mises):
                    out.update(max_von_mises=b.max_von_mises, max_von_mises_node=b.max_von_mises_node,
                               max_von_mises_point=b.max_von_mises_point)
                return out
        raise KeyError(f"no body '{name}' (bodies: {', '.join(self.bodies)})")

    def write(self, directory):
        """Writes results.h5 and probes.csv into `directory` (created if needed), as femb-solve
        writes them; write_animation() adds the ParaView animation. Returns the two paths."""
        if not isinstance(self._r, _core.RecordedResults):
            raise FembError("results that came from another process are written where they were made "
                            "(run(output=...) there)")
        directory = os.fspath(directory)
        os.makedirs(directory, exist_ok=True)
        h5 = os.path.join(directory, "results.h5")
        csv = os.path.join(directory, "probes.csv")
        _core.write_probes_csv(self._r, csv)
        _core.write_results(self._r, self.status, h5)
        return h5, csv

    def write_animation(self, directory):
        """Writes the run's ParaView animation (animation.xdmf and animation.h5, as femb-solve
        writes them) into `directory` (created if needed) and returns the .xdmf's path. A run kept
        in memory keeps its animation frames (a few numbers per body each, about 500 frames; the
        outputs.animation* keys choose them) and makes them here; a run with an output folder
        has written its animation there, which is copied. Results sent from another process have
        neither: FembError."""
        directory = os.fspath(directory)
        xdmf = os.path.join(directory, "animation.xdmf")
        run = self._run
        if run is not None and run.write_animation(directory):
            if not os.path.exists(xdmf):
                raise FembError("the run has no animation (outputs.animation is false, or no body has a mesh or "
                                "nodes to draw)")
            return xdmf
        if run is not None and run.output:
            source = os.path.join(run.output, "animation.xdmf")
            if not os.path.exists(source):
                raise FembError(f"{source}: the run wrote no animation (outputs.animation, meshes in the files)")
            os.makedirs(directory, exist_ok=True)
            if os.path.abspath(run.output) != os.path.abspath(directory):
                for name in ("animation.h5", "animation.xdmf"):
                    shutil.copyfile(os.path.join(run.output, name), os.path.join(directory, name))
            return xdmf
        raise FembError("these results came from another process: their animation is written where they were "
                        "made (write_animation() or run(output=...) there)")

    @property
    def loops(self):
        """Closed loops: cut_joints, violation (a length per output step), reaction (6 per cut joint)."""
        r = self._r
        return {"cut_joints": list(r.cut_joints), "violation": r.loop_violation, "reaction": r.loop_reaction}
