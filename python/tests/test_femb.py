"""The Python package against the programs: the same files, the same numbers, the same errors.

Run: PYTHONPATH=build/python FEMB_BIN=build/bin /usr/bin/python3 -m pytest -q python/tests
(ctest runs it as python_package)."""

import os
import pickle
import shutil
import subprocess

import h5py
import numpy as np
import pytest

import femb

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
BIN = os.path.abspath(os.environ.get("FEMB_BIN", os.path.join(ROOT, "build", "bin")))
EXAMPLES = os.path.join(ROOT, "examples")


def program(name, *args, cwd=None):
    """Runs one of femb's programs; returns (exit code, stdout, stderr)."""
    p = subprocess.run([os.path.join(BIN, name), *args], capture_output=True, text=True, cwd=cwd,
                       env=dict(os.environ, OMP_NUM_THREADS="1"))
    return p.returncode, p.stdout, p.stderr


@pytest.fixture(scope="module")
def slider_crank(tmp_path_factory):
    """examples/slider_crank_2d's parts reduced by femb-reduce into a folder of their own, with the scene."""
    work = tmp_path_factory.mktemp("slider_crank")
    for f in ("crank.yaml", "slider.yaml", "rod_2.yaml", "scene.yaml"):
        shutil.copy(os.path.join(EXAMPLES, "slider_crank_2d", f), work)
    for part in ("crank", "slider", "rod_2"):
        code, _, err = program("femb-reduce", "-q", f"{part}.yaml", "-o", f"{part}.h5", cwd=work)
        assert code == 0, err
    return work


def test_reduce_writes_the_programs_file(tmp_path):
    # femb.reduce and femb-reduce on examples/beam_rod: the same reduced K and M (bound 1e-14 of
    # their largest entries; the same code runs, so they agree to the bit unless the order of
    # operations differs).
    part = os.path.join(EXAMPLES, "beam_rod", "part.yaml")
    code, _, err = program("femb-reduce", "-q", part, "-o", str(tmp_path / "cli.h5"))
    assert code == 0, err
    lines = []
    se = femb.reduce(part, tmp_path / "py.h5", progress=lines.append)
    cli = femb.Superelement(tmp_path / "cli.h5")
    py = femb.Superelement(tmp_path / "py.h5")
    for a, b in ((cli.K, py.K), (cli.M, py.M), (cli.K, se.K)):
        assert a.shape == b.shape
        assert np.abs(a - b).max() <= 1e-14 * np.abs(a).max()
    assert py.labels == cli.labels and len(py.labels) == py.K.shape[0] == 16
    assert set(py.interfaces) == {"A", "B"}
    assert np.allclose(py.interfaces["B"][0], [0.3, 0, 0])
    # The rod's mass: rho A L = 7870 * pi * 0.003^2 * 0.3.
    assert py.mass_properties["mass"] == pytest.approx(7870 * np.pi * 0.003**2 * 0.3, rel=1e-12)
    assert len(py.frequencies) == 4 and (np.diff(py.frequencies) >= 0).all()
    assert any(line.startswith("write") for line in lines), lines
    report = py.checks()
    assert report["checks"] and all(c["ok"] for c in report["checks"].values()), report["checks"]


def test_reduce_from_a_dict_with_set(tmp_path):
    # A part given as a dict, with --set's key paths: the same file as the YAML with the override.
    import yaml
    with open(os.path.join(EXAMPLES, "beam_rod", "part.yaml")) as f:
        spec = yaml.safe_load(f)
    se = femb.reduce(spec, tmp_path / "rod6.h5", set={"reduction.internal_modes": 6})
    code, _, err = program("femb-reduce", "-q", os.path.join(EXAMPLES, "beam_rod", "part.yaml"), "-o",
                           str(tmp_path / "cli6.h5"), "--set", "reduction.internal_modes=6")
    assert code == 0, err
    assert se.K.shape == (18, 18)
    assert np.abs(se.K - femb.Superelement(tmp_path / "cli6.h5").K).max() <= 1e-14 * np.abs(se.K).max()


def test_reduce_refuses_the_distributed_solver(tmp_path):
    # The petsc solver runs in femb-reduce on MPI ranks: asked for here, one InputError naming the
    # key, before any work, and no file.
    with pytest.raises(femb.InputError, match="reduction.solver: the petsc solver .* mpirun -np N femb-reduce"):
        femb.reduce(os.path.join(EXAMPLES, "beam_rod", "part.yaml"), tmp_path / "rod.h5",
                    set={"reduction.solver": "petsc"})
    assert not (tmp_path / "rod.h5").exists()


def test_mode_shape_on_the_mesh(tmp_path):
    se = femb.reduce(os.path.join(EXAMPLES, "beam_rod", "part.yaml"), tmp_path / "rod.h5")
    nodes, cells = se.mesh
    shape = se.mode_shape(12)  # the first internal mode
    assert shape.shape == (nodes.shape[0], 6)
    assert np.abs(shape).max() > 0
    with pytest.raises(IndexError):
        se.mode_shape(16)
    assert se.to_vtu(tmp_path / "vtu") > 0


def test_scene_run_equals_femb_solve(slider_crank, tmp_path):
    # The slider-crank run from Python in memory equals femb-solve's results.h5 (the probes in
    # full precision, probes.csv's columns) to 1e-12 of each column's peak, and its probes.csv
    # to its 10 printed digits.
    import h5py
    code, _, err = program("femb-solve", "-q", "scene.yaml", "-o", str(tmp_path / "cli"), "--set",
                           "analysis.end_time=0.02", cwd=slider_crank)
    assert code == 0, err
    scene = femb.Scene.load(slider_crank / "scene.yaml").set("analysis.end_time", 0.02)
    results = scene.run()
    with h5py.File(tmp_path / "cli" / "results.h5") as f:
        names = [n.decode() for n in f["probes/names"][:]]
        values = f["probes/values"][:]
        time = f["time"][:]
        position = f["nodes/position"][:]
    assert list(results.probes) == names
    assert np.array_equal(results.time, time)
    for i, name in enumerate(names):
        peak = max(np.abs(values[:, i]).max(), 1e-300)
        assert np.abs(results.probes[name] - values[:, i]).max() <= 1e-12 * peak, name
    csv = np.genfromtxt(tmp_path / "cli" / "probes.csv", delimiter=",", names=True)
    assert np.allclose(csv["rod_midpositiony"], results.probes["rod_mid.position.y"], rtol=1e-9, atol=1e-15)
    k = list(results.nodes).index("rod_mid")
    assert np.array_equal(results.node("rod_mid")["position"], position[:, 3 * k:3 * k + 3])
    assert results.energy["kinetic"].shape == results.time.shape
    assert results.body("rod0")["modal_coordinates"].shape[0] == len(results.time)
    # Written afterwards, the same files as femb-solve's (its probes.csv byte for byte; its
    # results.h5 dataset by dataset).
    h5, csv = results.write(tmp_path / "later")
    with open(csv) as a, open(tmp_path / "cli" / "probes.csv") as b:
        assert a.read() == b.read()
    with h5py.File(h5) as a, h5py.File(tmp_path / "cli" / "results.h5") as b:
        names = []
        b.visit(names.append)
        for name in names:
            if isinstance(b[name], h5py.Dataset):
                assert np.array_equal(a[name][()], b[name][()]), name
        # The scene attribute names the file as it was given: here a full path, there a relative one.
        assert {k: v for k, v in a.attrs.items() if k != "scene"} == {k: v for k, v in b.attrs.items() if k != "scene"}
        assert a.attrs["scene"].decode().endswith("/scene.yaml")
    # The animation of the run kept in memory, made afterwards: femb-solve's, dataset by dataset
    # (mesh, positions, deformation, displacement of every frame) and the same .xdmf.
    xdmf = results.write_animation(tmp_path / "later")
    with open(xdmf) as a, open(tmp_path / "cli" / "animation.xdmf") as b:
        assert a.read() == b.read()
    with h5py.File(tmp_path / "later" / "animation.h5") as a, h5py.File(tmp_path / "cli" / "animation.h5") as b:
        names = []
        b.visit(names.append)
        assert len(names) > 10
        for name in names:
            if isinstance(b[name], h5py.Dataset):
                assert np.array_equal(a[name][()], b[name][()]), name
    # No files unless asked: the scene's folder holds what it held.
    assert sorted(os.listdir(slider_crank)) == sorted(
        ["crank.yaml", "slider.yaml", "rod_2.yaml", "scene.yaml", "crank.h5", "slider.h5", "rod_2.h5"])


def test_scene_run_writes_the_programs_files(slider_crank, tmp_path):
    scene = femb.Scene.load(slider_crank / "scene.yaml", set={"analysis.end_time": 0.005})
    lines = []
    scene.run(output=tmp_path / "py", progress=lines.append)
    code, _, err = program("femb-solve", "-q", "scene.yaml", "-o", str(tmp_path / "cli"), "--set",
                           "analysis.end_time=0.005", cwd=slider_crank)
    assert code == 0, err
    with open(tmp_path / "py" / "probes.csv") as a, open(tmp_path / "cli" / "probes.csv") as b:
        assert a.read() == b.read()
    assert os.path.exists(tmp_path / "py" / "checkpoint.h5")
    assert any(line.startswith("done in") for line in lines), lines
    # The animation of a run with an output folder is copied from there; one stepped in memory is
    # made from its kept frames and equals it; results sent between processes have none.
    results = femb.Scene.load(slider_crank / "scene.yaml", set={"analysis.end_time": 0.005}).run(output=tmp_path / "o")
    with open(results.write_animation(tmp_path / "copy")) as a, open(tmp_path / "cli" / "animation.xdmf") as b:
        assert a.read() == b.read()
    with femb.Scene.load(slider_crank / "scene.yaml", set={"analysis.end_time": 0.005}).start() as sim:
        sim.step_to(0.002)
        stepped = sim.finish()
    with open(stepped.write_animation(tmp_path / "stepped")) as a, open(tmp_path / "cli" / "animation.xdmf") as b:
        assert a.read() == b.read()
    with h5py.File(tmp_path / "stepped" / "animation.h5") as a, h5py.File(tmp_path / "cli" / "animation.h5") as b:
        assert all(np.array_equal(a[k][()], b[k][()]) for k in b.keys())
    with pytest.raises(femb.FembError, match="another process"):
        pickle.loads(pickle.dumps(stepped)).write_animation(tmp_path / "none")


def test_modes_and_statics_in_memory(slider_crank):
    scene = femb.Scene.load(slider_crank / "scene.yaml")
    modes = scene.set("analysis.type", "modes").set("analysis.count", 4).run()
    assert len(modes.frequencies) == 4 and (modes.frequencies > 0).all()


def test_bad_input_is_one_line(slider_crank, tmp_path):
    with pytest.raises(femb.InputError, match="analysis.*end_tme|end_tme"):
        femb.Scene.load(slider_crank / "scene.yaml").set("analysis.end_tme", 1.0)
    with pytest.raises(femb.InputError, match="no_such.yaml"):
        femb.Scene.load(tmp_path / "no_such.yaml")
    spec = {"name": "x", "bodies": [{"name": "b", "superelement": "missing.h5", "nodes": {"A": "a"}}],
            "analysis": {"type": "static"}, "colour": "red"}
    with pytest.raises(femb.InputError, match="colour"):
        femb.Scene(spec, base_dir=tmp_path)
    with pytest.raises(femb.InputError, match="missing.h5"):
        femb.Scene({k: v for k, v in spec.items() if k != "colour"}, base_dir=tmp_path).run()
    with pytest.raises(femb.InputError, match="missing required key .material."):
        femb.reduce({"name": "p", "type": "beam"}, tmp_path / "p.h5")
    assert not os.path.exists(tmp_path / "p.h5")
    assert issubclass(femb.InputError, femb.FembError)


def test_numerical_failure_keeps_the_results(tmp_path):
    # The energy watchdog's case from the command-line tests (a stiff rod of 40 modes at 5 ms
    # steps): NumericalError with femb-solve's line, the results up to the failure kept.
    work = tmp_path
    for f in ("rod.yaml", "scene.yaml"):
        shutil.copy(os.path.join(EXAMPLES, "pendulum", f), work)
    with open(work / "rod.yaml") as f:
        text = f.read().replace("internal_modes: 2", "internal_modes: 40").replace("elements: 6", "elements: 30")
    with open(work / "rod40.yaml", "w") as f:
        f.write(text)
    with pytest.warns(femb.FembWarning, match="keeps mode 40 .* but not mode 41"):
        femb.reduce(work / "rod40.yaml", work / "rod40.h5", set={"reduction.geometric_stiffening": False})
    spec = {"name": "blow", "units": "SI",
            "bodies": [{"name": "rod", "superelement": "rod40.h5",
                        "placement": {"rotation": [0, 0, -1.5207963267948966]},
                        "nodes": {"A": "pivot_rod", "B": "tip_rod"}}],
            "joints": [{"type": "revolute", "node": "pivot_rod", "axis": [0, 0, 1]}],
            "loads": [{"type": "gravity", "g": [0, -9.81, 0]}],
            "analysis": {"type": "dynamic", "end_time": 3.0, "step": 5e-3, "rho_inf": 0.9}}
    with pytest.raises(femb.NumericalError, match="numerical failure: the energy grew by") as failure, \
            pytest.warns(femb.FembWarning, match="the energy grew by"):
        femb.Scene(spec, base_dir=work).run()
    kept = failure.value.results
    assert not kept.ok and len(kept.time) > 1 and kept.time[-1] < 3.0


def example_env(extra=None):
    """The environment of an example's process (and of a sweep's workers): femb importable."""
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1",
               PYTHONPATH=os.path.join(ROOT, "build", "python"))
    if "PYTHONPATH" in os.environ:
        env["PYTHONPATH"] = os.environ["PYTHONPATH"]
    env.update(extra or {})
    return env


def run_example(script, *args, env=None):
    env = example_env(env)
    p = subprocess.run(["/usr/bin/python3", os.path.join(EXAMPLES, "python", script), *args], capture_output=True,
                       text=True, env=env, timeout=600)
    assert p.returncode == 0, p.stdout + p.stderr
    return p.stdout


def test_slider_crank_example(tmp_path):
    # The example's peak deflection is examples/slider_crank_2d's (README: its peak 4.67 mm).
    out = run_example("slider_crank.py", str(tmp_path))
    peak = float(out.split("peak midpoint deflection ")[1].split(" mm")[0])
    assert peak == pytest.approx(4.67, abs=0.01)
    assert os.path.getsize(tmp_path / "deflection.png") > 0


def test_dask_sweep_example(tmp_path):
    # 16 designs on a LocalCluster of 2 workers: the same peaks as 16 serial runs; a broken design
    # returns its error line while the others finish; the peak falls as the rod thickens.
    out = run_example("diameter_sweep.py", str(tmp_path), "--end-time", "0.02", "--check", "--broken")
    peaks = [float(line.split("peak deflection ")[1].split(" mm")[0]) for line in out.splitlines()
             if "peak deflection" in line]
    assert len(peaks) == 16 and all(np.diff(peaks) < 0), out
    assert "d =  -6.000 mm: InputError: --set section.diameter: must be positive, got -0.006" in out, out
    assert "17 designs on 2 local workers" in out and "1 failed" in out, out
    assert "serial runs in" in out and "the same peaks" in out, out


def test_dask_sweep_against_a_scheduler(tmp_path):
    # The example's code against a cluster's scheduler (FEMB_DASK_SCHEDULER): a dask-scheduler
    # process and a dask-worker process of 2 workers, reached over TCP as a cluster's are; the same
    # peaks as the serial runs, the broken design's line in its place.
    import socket
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    address = f"tcp://127.0.0.1:{port}"
    env = example_env()
    logs = open(tmp_path / "dask.log", "w")
    scheduler = subprocess.Popen(["/usr/bin/python3", "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1",
                                  "--port", str(port), "--no-dashboard"], stdout=logs, stderr=logs, env=env)
    worker = subprocess.Popen(["/usr/bin/python3", "-m", "distributed.cli.dask_worker", address, "--nworkers", "2",
                               "--nthreads", "1", "--no-dashboard"], stdout=logs, stderr=logs, env=env)
    try:
        out = run_example("diameter_sweep.py", str(tmp_path / "out"), "--end-time", "0.005", "--check", "--broken",
                          env={"FEMB_DASK_SCHEDULER": address})
    finally:
        worker.terminate(), scheduler.terminate()
        worker.wait(30), scheduler.wait(30)
        logs.close()
    assert "17 designs on the cluster's workers" in out and "1 failed" in out, out
    assert "the same peaks" in out, out
    assert "InputError: --set section.diameter: must be positive, got -0.006" in out, out


def test_sweep_returns_errors_in_place(slider_crank):
    # In this process (client None): Results, and the error of a scene that cannot run.
    good = femb.Scene.load(slider_crank / "scene.yaml", set={"analysis.end_time": 0.002})
    bad = femb.Scene.load(slider_crank / "scene.yaml", set={"bodies[0].superelement": "nothing.h5"})
    outcomes = femb.sweep([good, bad, good])
    assert isinstance(outcomes[0], femb.Results) and isinstance(outcomes[2], femb.Results)
    assert isinstance(outcomes[1], femb.InputError) and "nothing.h5" in str(outcomes[1])
    assert np.array_equal(outcomes[0].time, outcomes[2].time)
    # Results travel between processes (pickled) with their series.
    import pickle
    back = pickle.loads(pickle.dumps(outcomes[0]))
    assert np.array_equal(back.probes["rod_mid.position.y"], outcomes[0].probes["rod_mid.position.y"])
    assert np.array_equal(back.node("rod_mid")["position"], outcomes[0].node("rod_mid")["position"])


def test_bump_stop_example(tmp_path):
    # A Hunt-Crossley contact written in Python: the bar rebounds with a restitution within 0.02
    # of Hunt and Crossley's estimate 1 - 2/3 alpha v (the estimate is first order in alpha v =
    # 0.54 here; measured 0.646 against 0.639).
    out = run_example("bump_stop.py", str(tmp_path), "--end-time", "0.5")
    line = [x for x in out.splitlines() if "restitution" in x][0]
    measured = float(line.split("restitution ")[1].split(" ")[0])
    estimate = float(line.split("alpha v = ")[1].rstrip(")"))
    assert abs(measured - estimate) <= 0.02, line
    assert os.path.getsize(tmp_path / "bump_stop.png") > 0
