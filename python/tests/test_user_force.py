"""Forces written in Python (Scene.add_force) against the built-in spring-damper (the same
force law, femb's own implementation): a hinged rigid bar under gravity pulled by an axial
spring-damper from its tip to a fixed point, in statics and with both integrators."""

import math

import numpy as np
import pytest

import femb

K, C, L0 = 40.0, 0.3, 0.1          # N/m, N s/m, m
GROUND = np.array([0.35, 0.25, 0.0])  # the spring's fixed end [m]


def bar(spring=True, analysis=None):
    """The pendulum example's rigid bar (0.3 m, 66.8 g) hinged at P, released horizontal."""
    spec = {
        "name": "sprung_bar", "units": "SI",
        "bodies": [{"name": "block", "type": "rigid", "mass": 0.0667557023, "center_of_mass": [0.15, 0, 0],
                    "inertia": [3.004006603e-07, 0.0005008179676, 0.0005008179676],
                    "points": {"P": [0, 0, 0], "T": [0.3, 0, 0]}, "nodes": {"P": "pivot", "T": "tip"}}],
        "joints": [{"type": "revolute", "node": "pivot", "axis": [0, 0, 1]}],
        "loads": [{"type": "gravity", "g": [0, -9.81, 0]}],
        "analysis": analysis or {"type": "dynamic", "end_time": 0.5, "step": 1e-3, "rho_inf": 0.9},
        "outputs": {"probes": [{"name": "tip", "node": "tip", "quantities": ["position", "reaction"]},
                               {"name": "pivot", "node": "pivot", "quantities": ["reaction"]}],
                    "reactions": True},
    }
    if spring:
        spec["loads"].append({"type": "spring", "node": "tip", "point": GROUND.tolist(), "stiffness": K,
                              "damping": C, "free_length": L0})
    return spec


def spring_force(t, x, R, v, w):
    d = x - GROUND
    length = np.linalg.norm(d)
    e = d / length
    tension = K * (length - L0) + C * e.dot(v)
    return np.concatenate([-tension * e, np.zeros(3)])


def spring_with_jacobian(t, x, R, v, w):
    d = x - GROUND
    length = np.linalg.norm(d)
    e = d / length
    tension = K * (length - L0) + C * e.dot(v)
    P = np.eye(3) - np.outer(e, e)
    Kj, Cj = np.zeros((6, 6)), np.zeros((6, 6))
    # f = -N e: df/dx = -(e dN/dx + N de/dx), dN/dx = K e + C P v / l, de/dx = P / l.
    Kj[:3, :3] = -(K * np.outer(e, e) + C * np.outer(e, P @ v) / length + tension * P / length)
    Cj[:3, :3] = -C * np.outer(e, e)
    return np.concatenate([-tension * e, np.zeros(3)]), Kj, Cj


ANALYSES = {
    "generalized_alpha": {"type": "dynamic", "end_time": 0.5, "step": 1e-3, "rho_inf": 0.9},
    "midpoint": {"type": "dynamic", "end_time": 0.5, "step": 1e-3, "integrator": "midpoint"},
    "auto": {"type": "dynamic", "end_time": 0.5, "step": "auto", "step_tolerance": 1e-5, "output_step": 0.01},
    "static": {"type": "static", "end_time": 1.0, "steps": 10},
}


@pytest.mark.parametrize("analysis", list(ANALYSES))
def test_python_spring_equals_the_built_in_one(analysis, capsys):
    # The tip's motion and the reactions at tip and pivot: within 1e-8 of the built-in spring's
    # (m and N; the two sum the same force in another order), and Newton takes as many
    # iterations with the Jacobian given; the differenced one's count is printed. With
    # error-controlled steps the differenced matrix takes other Newton iterates, within the
    # Newton tolerance, and the step controller other steps from them: its bound there is the
    # step tolerance, 1e-5 of the peak of the probes of its kind (positions, reactions; measured
    # 1.6e-6 N of a reaction).
    builtin = femb.Scene(bar(True, ANALYSES[analysis])).run()
    given = femb.Scene(bar(False, ANALYSES[analysis])).add_force("tip", spring_with_jacobian, jacobian=True).run()
    differenced = femb.Scene(bar(False, ANALYSES[analysis])).add_force("tip", spring_force).run()
    assert len(builtin.time) > 5
    worst = {"given": 0.0, "differenced": 0.0}
    for name, values in builtin.probes.items():
        for label, other in (("given", given), ("differenced", differenced)):
            difference = np.abs(other.probes[name] - values).max()
            worst[label] = max(worst[label], difference)
            if label == "differenced" and analysis == "auto":
                kind = name.split(".")[1]
                peak = max(np.abs(v).max() for n, v in builtin.probes.items() if n.split(".")[1] == kind)
                assert difference <= 1e-5 * peak, (name, difference, peak)
    assert worst["given"] <= 1e-8, worst
    if analysis != "auto":
        assert worst["differenced"] <= 1e-8, worst
    assert np.ptp(builtin.probes["tip.position.y"]) > 0.05  # it moves
    assert given.newton_iterations == builtin.newton_iterations
    with capsys.disabled():
        print(f"\n  {analysis}: Newton iterations {builtin.newton_iterations} built-in, {given.newton_iterations} "
              f"Python with Jacobian, {differenced.newton_iterations} Python differenced "
              f"({differenced.newton_iterations - builtin.newton_iterations:+d}) over {builtin.step_count} steps; "
              f"largest difference from the built-in spring {worst['given']:.2g} and {worst['differenced']:.2g}")


def test_a_moment_and_the_energy_balance():
    # A torque on the bar's pivot node, tau = -kt theta - ct omega about z (a torsion spring-damper
    # written in Python): the motion of a damped torsional pendulum; the energy balance holds,
    # kinetic + gravity's and the spring's potential = the work of the forces (external_work).
    kt, ct = 0.2, 0.0

    def torsion(t, x, R, v, w):
        theta = math.atan2(R[1, 0], R[0, 0])
        return [0, 0, 0, 0, 0, -kt * theta - ct * w[2]]

    r = femb.Scene(bar(False, ANALYSES["midpoint"])).add_force("pivot", torsion).run()
    theta = np.arctan2(r.probes["tip.position.y"], r.probes["tip.position.x"])
    assert theta.min() < -0.2
    # The midpoint scheme conserves energy: kinetic + elastic - work (gravity and the torque) constant.
    balance = r.energy["kinetic"] + r.energy["elastic"] - r.energy["external_work"]
    assert np.abs(balance - balance[0]).max() <= 1e-6 * r.energy["kinetic"].max()


def test_a_failing_function_stops_the_run_with_its_name_and_time():
    def after(t_fail, what):
        def force(t, x, R, v, w):
            if t > t_fail:
                if what == "raise":
                    raise ValueError("out of the table's range")
                if what == "nan":
                    return [float("nan")] * 6
                return [1.0, 2.0]
            return [0.0] * 6
        return force

    for what, message in (("raise", r"force 'bump' at t = 0\.1\d*: raised ValueError: out of the table's range"),
                          ("nan", r"force 'bump' at t = 0\.1\d*: the force .* is not finite"),
                          ("shape", r"force 'bump' at t = 0\.1\d*: the force .* must be 6 numbers, got \[1\.0, 2\.0\]")):
        scene = femb.Scene(bar(True)).add_force("tip", after(0.1, what), name="bump")
        with pytest.raises(femb.NumericalError, match=message) as failure:
            scene.run()
        kept = failure.value.results
        assert 0.09 <= kept.time[-1] <= 0.1, kept.time[-1]
    with pytest.raises(femb.InputError, match="force 'bump': no node 'nowhere'"):
        femb.Scene(bar(True)).add_force("nowhere", spring_force, name="bump").run()


def test_stepping_under_control_gives_run_s_results():
    # step_to in 50 pieces, reading the tip between them: the same results to the bit as run();
    # the time reached is the first step end at or after each target (1 ms steps).
    scene = femb.Scene(bar(True))
    whole = scene.run()
    tips = []
    with scene.start() as sim:
        for target in np.arange(0.01, 0.5, 0.01):
            reached = sim.step_to(target)
            assert target - 1e-12 <= reached < target + 1e-3, (target, reached)
            tips.append(sim.node("tip")["position"])
        stepped = sim.finish()
    assert sim.done
    for name, values in whole.probes.items():
        assert np.array_equal(stepped.probes[name], values), name
    k = list(whole.time).index(whole.time[np.argmin(np.abs(whole.time - 0.25))])
    assert np.allclose(tips[24], whole.node("tip")["position"][k], atol=1e-15)


def test_a_controller_between_steps():
    # A controller that reads the bar's angle between steps and sets the torque its Python force
    # applies (a PD law about 0.3 rad below horizontal, updated every 5 ms): the bar settles there.
    state = {"torque": 0.0}
    scene = femb.Scene(bar(False, {"type": "dynamic", "end_time": 3.0, "step": 1e-3, "rho_inf": 0.9}))
    scene.add_force("pivot", lambda t, x, R, v, w: [0, 0, 0, 0, 0, state["torque"]])
    goal, previous = -0.3, None
    with scene.start() as sim:
        for target in np.arange(0.005, 3.0, 0.005):
            sim.step_to(target)
            tip = sim.node("tip")["position"]
            angle = math.atan2(tip[1], tip[0])
            rate = 0.0 if previous is None else (angle - previous) / 0.005
            previous = angle
            state["torque"] = -2.0 * (angle - goal) - 0.05 * rate
        results = sim.finish()
    final = np.arctan2(results.probes["tip.position.y"][-1], results.probes["tip.position.x"][-1])
    # Gravity's moment m g L/2 cos(goal) = 0.187 N m is held by the proportional term: the angle
    # settles 0.187 / 2 = 0.094 rad below the goal (a P controller's steady-state offset).
    offset = 0.0667557023 * 9.81 * 0.15 * math.cos(final) / 2.0
    assert abs(final - (goal - offset)) < 2e-3, (final, goal - offset)


def test_close_stops_an_unfinished_run():
    sim = femb.Scene(bar(True)).start()
    sim.step_to(0.1)
    partial = sim.results()
    assert partial.status == "paused" and 0.1 <= partial.time[-1] < 0.1 + 1e-3
    sim.close()
    assert sim.done
    with pytest.raises(femb.InputError, match="start.. steps a dynamic analysis"):
        femb.Scene(bar(True, ANALYSES["static"])).start()


def two_bars(spring, gravity=True, analysis=None):
    """Two bars: `bar` hinged at the origin along +x, `bar2` hinged at (0.8, 0, 0) along -x (tips
    0.2 m apart); with `spring` the built-in spring-damper between the tips."""
    spec = bar(False, analysis)
    spec["bodies"].append(dict(spec["bodies"][0], name="bar2", nodes={"P": "pivot2", "T": "tip2"},
                               placement={"position": [0.8, 0, 0], "rotation": [0, 0, math.pi]}))
    spec["joints"].append({"type": "revolute", "node": "pivot2", "axis": [0, 0, 1]})
    spec["outputs"]["probes"].append({"name": "tip2", "node": "tip2", "quantities": ["position", "reaction"]})
    if not gravity:
        spec["loads"] = []
    if spring:
        spec["loads"].append({"type": "spring", "node": "tip", "node_b": "tip2", "stiffness": K, "damping": C,
                              "free_length": L0})
    return spec


def pair_spring(t, x, R, v, w, xo, Ro, vo, wo):
    d = x - xo
    length = np.linalg.norm(d)
    e = d / length
    tension = K * (length - L0) + C * e.dot(v - vo)
    return np.concatenate([-tension * e, np.zeros(3)])


def pair_spring_with_jacobian(t, x, R, v, w, xo, Ro, vo, wo):
    """pair_spring and its derivatives (6 x 12: this node's x, theta, then the other's)."""
    d, u = x - xo, v - vo
    length = np.linalg.norm(d)
    e = d / length
    tension = K * (length - L0) + C * e.dot(u)
    P = (np.eye(3) - np.outer(e, e)) / length  # de/dd
    dforce_dd = -np.outer(e, K * e + C * (P @ u)) - tension * P
    dforce_du = -C * np.outer(e, e)
    Kx, Cv = np.zeros((6, 12)), np.zeros((6, 12))
    Kx[:3, 0:3], Kx[:3, 6:9] = dforce_dd, -dforce_dd
    Cv[:3, 0:3], Cv[:3, 6:9] = dforce_du, -dforce_du
    return np.concatenate([-tension * e, np.zeros(3)]), Kx, Cv


@pytest.mark.parametrize("analysis", ["generalized_alpha", "midpoint", "static"])
def test_a_force_between_two_nodes_equals_the_built_in_spring(analysis):
    # Differenced and with its Jacobian: the built-in spring's motion to 1e-8, and with the
    # Jacobian the built-in spring's Newton iterations.
    builtin = femb.Scene(two_bars(True, analysis=ANALYSES[analysis])).run()
    python = femb.Scene(two_bars(False, analysis=ANALYSES[analysis])).add_force("tip", pair_spring, other="tip2").run()
    given = femb.Scene(two_bars(False, analysis=ANALYSES[analysis])).add_force(
        "tip", pair_spring_with_jacobian, jacobian=True, other="tip2").run()
    assert np.ptp(builtin.probes["tip2.position.y"]) > 0.02
    for r in (python, given):
        for name, values in builtin.probes.items():
            assert np.abs(r.probes[name] - values).max() <= 1e-8, (name, np.abs(r.probes[name] - values).max())
    assert given.newton_iterations == builtin.newton_iterations, (given.newton_iterations, builtin.newton_iterations)
    print(f"\n  pair force, {analysis}: Newton iterations {builtin.newton_iterations} built-in, "
          f"{given.newton_iterations} given, {python.newton_iterations} differenced")


def test_a_force_between_two_nodes_balances():
    # Two hinged bars, no gravity, tied tip to tip by a force that is not central (a linear spring
    # with a rest vector, f = k (x_other - x - d0)) and a moment: in equilibrium the hinges'
    # reactions must balance each other, force and moment about the origin (to Newton's
    # tolerance), as they do when the tie's reaction on the other node carries the opposite
    # moment about that node; without the moment of the force about the line between the nodes
    # they would be off by |(x - x_other) x f|, about 1 N m here.
    d0 = np.array([-0.15, 0.05, 0.02])

    def tie(t, x, R, v, w, xo, Ro, vo, wo):
        return t * np.concatenate([50.0 * (xo - x - d0), [0.0, 0.0, 0.05]])

    spec = two_bars(False, gravity=False, analysis=dict(ANALYSES["static"], tolerance=1e-12))
    spec["outputs"]["probes"].append({"name": "pivot2", "node": "pivot2", "quantities": ["reaction"]})
    r = femb.Scene(spec).add_force("tip", tie, other="tip2").run()
    force = np.array([[r.probes[f"{p}.reaction.f{c}"][-1] for c in "xyz"] for p in ("pivot", "pivot2")])
    moment = np.array([[r.probes[f"{p}.reaction.m{c}"][-1] for c in "xyz"] for p in ("pivot", "pivot2")])
    pivots = np.array([[0.0, 0.0, 0.0], [0.8, 0.0, 0.0]])
    assert np.abs(force).max() > 1.0  # the tie pulls
    assert np.abs(force.sum(axis=0)).max() <= 1e-9 * np.abs(force).max(), force
    total = moment.sum(axis=0) + np.cross(pivots, force).sum(axis=0)
    assert np.abs(total).max() <= 1e-9 * np.abs(force).max(), total

    # The same tie with its Jacobian: femb derives the reaction's (with the moment of the force
    # about the moving arm between the nodes) from it. Newton then converges as with the
    # differenced matrix, to the same state.
    def tie_with_jacobian(t, x, R, v, w, xo, Ro, vo, wo):
        Kx = np.zeros((6, 12))
        Kx[:3, 0:3], Kx[:3, 6:9] = -50.0 * t * np.eye(3), 50.0 * t * np.eye(3)
        return tie(t, x, R, v, w, xo, Ro, vo, wo), Kx, np.zeros((6, 12))

    given = femb.Scene(spec).add_force("tip", tie_with_jacobian, jacobian=True, other="tip2").run()
    for name, values in r.probes.items():
        assert np.abs(given.probes[name] - values).max() <= 1e-9 * max(np.abs(values).max(), 1.0), name
    assert given.newton_iterations == r.newton_iterations, (given.newton_iterations, r.newton_iterations)
    # (Without the arm's term in the reaction's derivative, -(dx - dx_other) x F, Newton takes
    # more iterations and the count above differs: mutation-tested.)


@pytest.fixture(scope="module")
def rod(tmp_path_factory):
    """examples/beam_rod (0.3 m steel rod, 4 internal modes) reduced linear inside (without the
    geometric stiffening, whose cubic terms make a clamped-clamped rod's response 1e-4 stiffer
    already at q = 1e-5), its floating frame on interface A."""
    import os
    work = tmp_path_factory.mktemp("rod")
    root = os.path.join(os.path.dirname(__file__), "..", "..")
    return femb.reduce(os.path.join(root, "examples", "beam_rod", "part.yaml"), work / "rod.h5",
                       set={"reduction.floating_frame": "interface:A", "reduction.geometric_stiffening": False})


def clamped_rod(rod, analysis):
    return {"name": "clamped_rod", "units": "SI",
            "bodies": [{"name": "rod", "superelement": rod.path, "nodes": {"A": "a", "B": "b"}}],
            "joints": [{"type": "clamp", "node": "a"}, {"type": "clamp", "node": "b"}],
            "analysis": analysis}


def test_a_modal_force_in_statics_deflects_as_the_reduced_stiffness_says(rod):
    # Both ends clamped, a generalized force Q on the first internal mode (ramped by the load
    # factor): the modal coordinates solve K_qq q = Q with K_qq the file's internal block (the
    # Craig-Bampton basis keeps it apart from the interface's; the rod is linear inside). Given or
    # differenced, the same Newton iterations.
    labels = rod.labels
    modes = [i for i, label in enumerate(labels) if "mode" in label]
    Kqq = rod.K[np.ix_(modes, modes)]
    Q = np.zeros(len(modes))
    Q[0] = 1e-5 * Kqq[0, 0]
    expected = np.linalg.solve(Kqq, Q)
    analysis = {"type": "static", "end_time": 1.0, "steps": 2, "tolerance": 1e-12}
    given = femb.Scene(clamped_rod(rod, analysis)).add_modal_force(
        "rod", lambda t, q, qd: (t * Q, np.zeros((4, 4)), np.zeros((4, 4))), jacobian=True).run()
    differenced = femb.Scene(clamped_rod(rod, analysis)).add_modal_force("rod", lambda t, q, qd: t * Q).run()
    for r in (given, differenced):
        q = r.body("rod")["modal_coordinates"][-1]
        assert np.abs(q - expected).max() <= 1e-9 * np.abs(expected).max(), (q, expected)
    assert given.newton_iterations == differenced.newton_iterations


def test_a_modal_damper_and_the_energy_balance(rod):
    # A modal damper written in Python, Q = -c qdot, on a rod released from a bent shape: under
    # the midpoint scheme kinetic + elastic energy fall by exactly the damper's work (the external
    # work), to Newton's tolerance; with its Jacobian the same as differenced.
    c = 0.05

    def damper(t, q, qdot):
        return -c * qdot, np.zeros((4, 4)), -c * np.eye(4)

    analysis = {"type": "dynamic", "end_time": 0.01, "step": 1e-5, "integrator": "midpoint", "tolerance": 1e-12}
    spec = clamped_rod(rod, analysis)
    spec["initial_velocity"] = {}
    kick = {"t0": 0.0}

    def pulse(t, q, qdot):  # a short push on the first mode, then the damper alone
        Q, K, C = damper(t, q, qdot)
        if t < 1e-3:
            Q = Q + np.array([1e-3, 0, 0, 0]) * rod.K[12, 12] * 1e-3
        return Q, K, C

    r = femb.Scene(spec).add_modal_force("rod", pulse, jacobian=True).run()
    e = r.energy
    balance = e["kinetic"] + e["elastic"] - e["external_work"]
    assert e["kinetic"].max() > 0
    assert np.abs(balance - balance[0]).max() <= 1e-7 * (e["kinetic"].max() + e["elastic"].max()), \
        np.abs(balance - balance[0]).max()
    # The damper took energy out after the push: the total falls from its value at 1 ms.
    total = e["kinetic"] + e["elastic"]
    after = r.time >= 1e-3
    assert total[after][-1] < total[after][0]


def test_ctrl_c_stops_a_run_and_keeps_its_results(tmp_path):
    # A long run interrupted by SIGINT after 0.5 s (in a process of its own): KeyboardInterrupt
    # within a second, and the results up to the step it stopped at in the output folder.
    import os
    import subprocess
    import sys
    import h5py
    script = f"""
import os, signal, sys, threading, time
sys.path.insert(0, {os.path.dirname(os.path.abspath(__file__))!r})
import femb, test_user_force as t
scene = femb.Scene(t.bar(True, {{"type": "dynamic", "end_time": 1000.0, "step": 1e-4, "rho_inf": 0.9}}))
threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
start = time.perf_counter()
try:
    scene.run(output={str(tmp_path / "out")!r})
    print("not interrupted")
except KeyboardInterrupt:
    print(f"interrupted after {{time.perf_counter() - start:.2f}} s")
"""
    p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert "interrupted after" in p.stdout, p.stdout + p.stderr
    assert float(p.stdout.split("interrupted after ")[1].split(" s")[0]) < 1.5, p.stdout
    with h5py.File(tmp_path / "out" / "results.h5") as f:
        status = f.attrs["status"]
        status = status.decode() if isinstance(status, bytes) else status
        assert status.startswith("stopped by SIGINT at t ="), status
        assert 0 < f["time"][-1] < 1000.0
