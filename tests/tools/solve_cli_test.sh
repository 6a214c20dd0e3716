#!/usr/bin/env bash
# femb-solve from the command line: the static cantilever example end to end, outputs, and one
# clear line with exit code 2 (input) or 3 (numerical failure, results kept) for bad cases.
# Usage: solve_cli_test.sh BIN_DIR SOURCE_DIR
set -u
bin=$1
src=$2
source "$(dirname "$0")/test_lib.sh"

"$bin/femb-solve" --help | grep -q "usage: femb-solve" && ok || fail "--help"
cp "$src/examples/cantilever_static/segment.yaml" "$src/examples/cantilever_static/scene.yaml" "$work/"
# The linear segment, said explicitly (the energy checks below rely on it; segment_gs further
# down has the geometric stiffening).
"$bin/femb-reduce" -q "$work/segment.yaml" -o "$work/segment.h5" --set reduction.geometric_stiffening=false || fail "reduce segment"
"$bin/femb-solve" "$work/scene.yaml" -o "$work/out" > "$work/log.txt" && ok || fail "solve: $(cat "$work/log.txt")"
grep -q "Newton iterations" "$work/log.txt" && ok || fail "no progress line"
head -1 "$work/out/probes.csv" | grep -qx "time,tip.position.x,tip.position.y,tip.position.z,tip.rotation.w,tip.rotation.x,tip.rotation.y,tip.rotation.z,kinetic_energy,elastic_energy,external_work" \
  && ok || fail "CSV header: $(head -1 "$work/out/probes.csv")"
$py - "$work/out" <<'PY' && ok || fail "results content"
import csv, sys, h5py
rows = list(csv.DictReader(open(sys.argv[1] + "/probes.csv")))
assert len(rows) == 101, len(rows)
assert float(rows[-1]["time"]) == 100.0
# 10 kN tip force: the elastica gives (du, w) = (0.8055, 0.9195) m; femb within 1%.
du = 1 - float(rows[-1]["tip.position.x"]); w = -float(rows[-1]["tip.position.y"])
err = ((du - 0.80554) ** 2 + (w - 0.91945) ** 2) ** 0.5 / (0.80554 ** 2 + 0.91945 ** 2) ** 0.5
assert err < 0.01, err
f = h5py.File(sys.argv[1] + "/results.h5", "r")
assert f.attrs["status"] in (b"completed", "completed")
assert f["nodes/position"].shape == (101, 33)
assert f["nodes/quaternion"].shape == (101, 44)
assert f["bodies/b0/modal_coordinates"].shape == (101, 2)
PY
ls "$work/out" | grep -q tmp && fail "temporary file left" || ok
# A conservative static problem: the work of the load equals the strain energy, up to the
# trapezoidal rule's error, which falls 4x when the load steps are halved.
"$bin/femb-solve" -q "$work/scene.yaml" -o "$work/out200" --set analysis.steps=200 || fail "200 steps"
$py - "$work/out/probes.csv" "$work/out200/probes.csv" <<'PY' && ok || fail "static work"
import csv, sys
def gap(path):
    last = list(csv.DictReader(open(path)))[-1]
    W, U = float(last["external_work"]), float(last["elastic_energy"])
    return abs(W - U) / U
g100, g200 = gap(sys.argv[1]), gap(sys.argv[2])
print("work - energy:", g100, g200)
assert g100 < 5e-3 and 3.5 < g100 / g200 < 4.5, (g100, g200)
PY
# The ParaView animation: readable by meshio (an independent XDMF reader); the deformed mesh
# passes through the system nodes (mesh node 0 of body i is interface A = scene node n_i).
$py - "$work/out" <<'PY' && ok || fail "animation"
import sys, meshio, h5py, numpy as np
reader = meshio.xdmf.TimeSeriesReader(sys.argv[1] + "/animation.xdmf")
points, cells = reader.read_points_cells()
assert cells[0].type == "line" and points.shape == (50, 3), (cells[0].type, points.shape)
assert reader.num_steps == 101
t, point_data, cell_data = reader.read_data(100)
assert t == 100.0
deformed = points + point_data["displacement"]
nodes = h5py.File(sys.argv[1] + "/results.h5", "r")["nodes/position"][100].reshape(-1, 3)
# frames are single precision (24-bit mantissa): 1 m positions to 1e-7 m; 1e-6 m is the bound
for i in range(10):
    assert np.abs(deformed[5 * i] - nodes[i]).max() < 1e-6, i   # 5 mesh nodes per body
# The node vector 'deformation' is the elastic part R_j Phi q_loc alone: zero in the unloaded
# first frame, and the deformed mesh less it is each body's undeformed mesh moved rigidly (the
# node-to-node distances within a body are those of the first frame, to single precision).
_, d0, _ = reader.read_data(0)
assert np.abs(d0["deformation"]).max() < 1e-12
d = point_data["deformation"]
assert 1e-4 < np.abs(d).max() < 0.2 * np.abs(point_data["displacement"]).max(), (np.abs(d).max())
rigid = deformed - d
for i in range(10):
    a, b = rigid[5 * i:5 * i + 5], points[5 * i:5 * i + 5]
    da = np.linalg.norm(a[:, None] - a[None], axis=2)
    db = np.linalg.norm(b[:, None] - b[None], axis=2)
    assert np.abs(da - db).max() < 2e-6, (i, np.abs(da - db).max())
PY
# outputs.animation_every thins the frames (every 10th of the 101 output steps) and keeps the times.
"$bin/femb-solve" -q "$work/scene.yaml" -o "$work/thin" --set outputs.animation_every=10 && $py - "$work/thin" <<'PY' \
  && ok || fail "animation_every"
import sys, meshio
reader = meshio.xdmf.TimeSeriesReader(sys.argv[1] + "/animation.xdmf")
reader.read_points_cells()
assert reader.num_steps == 11, reader.num_steps
assert [reader.read_data(k)[0] for k in (0, 1, 10)] == [0.0, 10.0, 100.0]
PY
# By default a long run gets about 500 frames: 1200 load steps -> every 3rd (401 frames).
"$bin/femb-solve" -q "$work/scene.yaml" -o "$work/long" --set analysis.steps=1200 && $py - "$work/long" <<'PY' \
  && ok || fail "automatic animation_every"
import sys, meshio
reader = meshio.xdmf.TimeSeriesReader(sys.argv[1] + "/animation.xdmf")
reader.read_points_cells()
assert reader.num_steps == 401, reader.num_steps
assert [reader.read_data(k)[0] for k in (0, 1, 400)] == [0.0, 0.25, 100.0], [reader.read_data(k)[0] for k in (0, 1, 400)]
PY

# Linearized modes of the clamped 10-body tube: the first bending pair equals the ringing
# frequency of one clamped tube body (19.16 Hz, tests/solver/analysis/flexible_dynamics_test).
"$bin/femb-solve" -q "$work/scene.yaml" -o "$work/modes" --set analysis.type=modes --set analysis.count=4 \
  && ok || fail "modes analysis"
$py - "$work/modes/modes.csv" <<'PY' && ok || fail "modes.csv"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert len(rows) == 4
f = [float(r["frequency_hz"]) for r in rows]
assert abs(f[0] - 19.16) < 0.05 and abs(f[1] - f[0]) < 1e-6 * f[0], f
PY

# Spin-up beam (revolute joint to ground with prescribed angle): the hub angle equals the
# prescribed function at every output, the lag stays bounded and dies out.
mkdir -p "$work/spin_src"
cp "$src/examples/spin_up_beam/segment.yaml" "$src/examples/spin_up_beam/scene.yaml" "$work/spin_src/"
"$bin/femb-reduce" -q "$work/spin_src/segment.yaml" -o "$work/spin_src/segment.h5" && \
  "$bin/femb-solve" -q "$work/spin_src/scene.yaml" -o "$work/spin" && ok || fail "spin_up_beam"
$py - "$work/spin/probes.csv" <<'PY' && ok || fail "spin_up_beam results"
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
Ts, w = 15.0, 4.0
c = Ts / (2 * math.pi)
worst, lag, late = 0.0, 0.0, 0.0
for r in rows:
    t = float(r["time"])
    theta = w * (t - Ts / 2) if t >= Ts else w / Ts * (t * t / 2 + c * c * (math.cos(t / c) - 1))
    worst = max(worst, abs(float(r["hub.joint.0"]) - theta))
    x, y = float(r["tip.position.x"]), float(r["tip.position.y"])
    tip = -math.sin(theta) * x + math.cos(theta) * y
    lag = max(lag, abs(tip))
    if t > 17: late = max(late, abs(tip))
assert worst < 1e-9 * 50, worst  # the CSV holds 10 significant digits
assert 0.3 < lag < 0.5 and late < 0.02, (lag, late)
assert abs(float(rows[-1]["hub.angular_velocity.z"]) - w) < 1e-12
PY

# Slider-crank: joints between nodes; the rod ends stay on the crank pin and the slider, the
# slider stays on its line, the crank angle is the prescribed 150 t.
mkdir -p "$work/sc"
cp "$src"/examples/slider_crank_2d/*.yaml "$work/sc/"
for part in crank rod_2 slider; do "$bin/femb-reduce" -q "$work/sc/$part.yaml" -o "$work/sc/$part.h5" || fail "reduce $part"; done
"$bin/femb-solve" -q "$work/sc/scene.yaml" -o "$work/sc_out" --set analysis.end_time=0.02 && ok || fail "slider crank"
$py - "$work/sc_out" <<'PY' && ok || fail "slider crank results"
import sys, h5py, numpy as np
f = h5py.File(sys.argv[1] + "/results.h5", "r")
names = [n.decode() if isinstance(n, bytes) else n for n in f["nodes/names"][:]]
pos = f["nodes/position"][:].reshape(len(f["time"]), len(names), 3)
i = {n: k for k, n in enumerate(names)}
assert np.abs(pos[:, i["rod_a"]] - pos[:, i["A"]]).max() < 1e-12       # hinge at the crank pin
assert np.abs(pos[:, i["rod_b"]] - pos[:, i["slider"]]).max() < 1e-12  # hinge at the slider
assert np.abs(pos[:, i["slider"], 1:]).max() < 1e-12                   # slider on the x axis
t = f["time"][:]
phi = np.arctan2(pos[:, i["A"], 1], pos[:, i["A"], 0])
err = np.abs(np.unwrap(phi) - 150 * t).max()
assert err < 1e-5, err  # the crank is a very stiff (not rigid) body: its tip lags elastically
PY

# Pendulums: a stiff superelement and a rigid body (pivot at one of its points) swing at the
# rigid pendulum period (closed form with the amplitude correction) within 1e-4.
mkdir -p "$work/pend"
cp "$src"/examples/pendulum/rod.yaml "$src"/examples/pendulum/scene.yaml "$work/pend/"
"$bin/femb-reduce" -q "$work/pend/rod.yaml" -o "$work/pend/rod.h5" && \
  "$bin/femb-solve" -q "$work/pend/scene.yaml" -o "$work/pend_out" && ok || fail "pendulum"
$py "$src/examples/pendulum/period.py" "$work/pend_out" > "$work/period.txt" && \
  awk '{e = $NF < 0 ? -$NF : $NF; if (e > 1e-4) bad = 1} END {exit bad}' "$work/period.txt" && ok || fail "pendulum period: $(cat "$work/period.txt")"

# A solid superelement in a scene: a cantilever TET10 bar (RBE2 faces) sagging under gravity;
# the animation holds quadratic tetrahedra that meshio reads back.
mkdir -p "$work/solid"
cp "$src/examples/solid_bar/part.yaml" "$work/solid/bar.yaml"
"$bin/femb-reduce" -q "$work/solid/bar.yaml" -o "$work/solid/bar.h5" && "$bin/femb-inspect" "$work/solid/bar.h5" --check > /dev/null \
  && ok || fail "solid bar reduce/inspect"
cat > "$work/solid/scene.yaml" <<'YAML'
name: solid_sag
units: SI
bodies:
  - {name: bar, superelement: bar.h5, nodes: {root: root, tip: tip}}
joints:
  - {type: clamp, node: root}
loads:
  - {type: gravity, g: [0, -9.81, 0]}
analysis: {type: dynamic, end_time: 0.02, step: 1.0e-3, rho_inf: 0.8}
outputs:
  probes:
    - {name: tip, node: tip, quantities: [position]}
YAML
"$bin/femb-solve" -q "$work/solid/scene.yaml" -o "$work/solid/out" && ok || fail "solid scene"
# The midpoint integrator on the same scene; dynamic results carry the momentum.
"$bin/femb-solve" -q "$work/solid/scene.yaml" -o "$work/solid/mid" --set analysis.integrator=midpoint \
  && ok || fail "midpoint integrator"
$py -c "
import h5py; f = h5py.File('$work/solid/mid/results.h5')
assert f['energy/angular_momentum'].shape == (f['time'].shape[0], 3), f['energy/angular_momentum'].shape
assert f['energy/linear_momentum'][-1, 1] != 0  # gravity pulls, the clamp holds: momentum changes" \
  && ok || fail "momentum in results.h5"
# Reactions: the pivots' reactions close the momentum balance of both pendulums in impulse
# form, L(t) = int_0^t (m g + R_rod + R_block) dt (trapezoidal rule on the recorded steps; the
# stiff rod's pivot force carries its unresolved high modes, which the integral averages out):
# within 1e-3 of the largest momentum (measured 2e-4).
"$bin/femb-solve" -q "$work/pend/scene.yaml" -o "$work/pend_react" --set analysis.end_time=0.5 --set outputs.reactions=true \
  && ok || fail "pendulum with reactions"
$py - "$work/pend_react" <<'PY' && ok || fail "pivot reactions vs momentum balance"
import sys, h5py, numpy as np
f = h5py.File(sys.argv[1] + "/results.h5")
names = [n.decode() if isinstance(n, bytes) else n for n in f["nodes/names"][:]]
R = f["nodes/reaction"][:].reshape(len(f["time"]), len(names), 6)
t, L = f["time"][:], f["energy/linear_momentum"][:]
m = 2 * 0.0667557023            # the rod and the block have the same mass
F = m * np.array([0, -9.81, 0]) + R[:, names.index("pivot_rod"), :3] + R[:, names.index("pivot_block"), :3]
impulse = np.concatenate([[np.zeros(3)], np.cumsum(0.5 * (F[1:] + F[:-1]) * np.diff(t)[:, None], axis=0)])
err = np.abs(L - impulse).max() / np.abs(L).max()
print("momentum balance with the reactions:", err)
assert err < 1e-3, err
assert np.abs(R[:, names.index("tip_rod")]).max() == 0  # a free node has no reaction
PY
# Static: the clamp's reaction balances the tip load, moment about the clamp of the deformed tip.
"$bin/femb-solve" -q "$work/scene.yaml" -o "$work/react_static" --set outputs.reactions=true && ok || fail "static reactions"
$py - "$work/react_static" <<'PY' && ok || fail "clamp reaction"
import sys, h5py, numpy as np
f = h5py.File(sys.argv[1] + "/results.h5")
names = [n.decode() if isinstance(n, bytes) else n for n in f["nodes/names"][:]]
pos = f["nodes/position"][-1].reshape(-1, 3)
R = f["nodes/reaction"][-1].reshape(-1, 6)[names.index("n0")]
F = np.array([0, -100.0 * f["time"][-1], 0])
r = pos[names.index("n10")] - pos[names.index("n0")]
assert np.abs(R[:3] + F).max() < 1e-6 * 1e4, R
assert np.abs(R[3:] + np.cross(r, F)).max() < 1e-6 * 1e4, (R[3:], -np.cross(r, F))
PY
# The energy watchdog: the stiff rod with 40 modes (30 elements) at h = 5 ms
# gains energy with rho_inf 0.8-1.0 and once ended "completed" with 4x the kinetic energy; now
# it stops with exit 3 and says why, results kept. rho_inf 0.5 damps the unresolved modes.
sed 's/internal_modes: 2/internal_modes: 40/; s/elements: 6/elements: 30/' "$work/pend/rod.yaml" > "$work/pend/rod40.yaml"
"$bin/femb-reduce" -q "$work/pend/rod40.yaml" -o "$work/pend/rod40.h5" --set reduction.geometric_stiffening=false || fail "reduce rod40"
cat > "$work/pend/blow.yaml" <<'YAML'
name: blow
units: SI
bodies:
  - {name: rod, superelement: rod40.h5, placement: {rotation: [0, 0, -1.5207963267948966]}, nodes: {A: pivot_rod, B: tip_rod}}
joints:
  - {type: revolute, node: pivot_rod, axis: [0, 0, 1]}
loads:
  - {type: gravity, g: [0, -9.81, 0]}
analysis: {type: dynamic, end_time: 3.0, step: 5e-3, rho_inf: 0.9}
YAML
"$bin/femb-solve" -q "$work/pend/blow.yaml" -o "$work/blow" 2> "$work/err.txt" > /dev/null; code=$?
[ $code = 3 ] && grep -q "numerical failure: the energy grew by .* numerically unstable at step 0.005; reduce analysis.step or analysis.rho_inf" "$work/err.txt" \
  && [ -s "$work/blow/results.h5" ] && ok || fail "energy watchdog: exit $code $(cat "$work/err.txt")"
"$bin/femb-solve" -q "$work/pend/blow.yaml" -o "$work/blow5" --set analysis.rho_inf=0.5 > /dev/null && ok || fail "rho_inf 0.5 should run"
# Initial joint rates: the pendulums started with 2 rad/s at their pivot joints have kinetic
# energy from the first output; a wrong number of rates is an input error.
cat "$work/pend/scene.yaml" > "$work/pend/rate.yaml"
printf 'initial_velocity:\n  pivot_rod: {joint: [2.0]}\n  pivot_block: {joint: [2.0]}\n' >> "$work/pend/rate.yaml"
"$bin/femb-solve" -q "$work/pend/rate.yaml" -o "$work/pend_rate" --set analysis.end_time=0.02 && ok || fail "joint rates"
$py -c "
import csv; rows = list(csv.DictReader(open('$work/pend_rate/probes.csv')))
assert float(rows[0]['kinetic_energy']) > 0, rows[0]['kinetic_energy']" && ok || fail "joint rates: no initial kinetic energy"
# --threads: the bodies on 1 or 2 threads give the same numbers to the last digit; a bad count is
# an input error.
"$bin/femb-solve" -q "$work/pend/rate.yaml" -o "$work/pend_t1" --set analysis.end_time=0.02 --threads 1 \
  && "$bin/femb-solve" -q "$work/pend/rate.yaml" -o "$work/pend_t2" --set analysis.end_time=0.02 --threads 2 \
  && cmp -s "$work/pend_t1/probes.csv" "$work/pend_t2/probes.csv" && ok || fail "--threads 1 and 2 differ"
"$bin/femb-solve" -q "$work/pend/rate.yaml" -o "$work/pend_t0" --threads 0 2> "$work/err.txt"; [ $? = 2 ] \
  && grep -q "^femb-solve: --threads 0: expected a whole number from 1 to 1024$" "$work/err.txt" && ok || fail "--threads 0: $(cat "$work/err.txt")"
# Error-controlled steps (step: auto): results at every output_step exactly, the step sizes and
# the rejected steps in results.h5 and in the log; bad settings are one line, exit 2; a step that
# must fall below min_step stops with exit 3, results kept.
"$bin/femb-solve" "$work/pend/rate.yaml" -o "$work/pend_auto" --set analysis.end_time=0.2 --set analysis.step=auto \
  --set analysis.output_step=0.01 --threads 1 > "$work/auto.txt" && grep -q "steps rejected (.* by the error test" "$work/auto.txt" \
  && grep -q "steps: smallest .* s (ending at t = .*), largest .* s, mean .* s; every step in results.h5 /steps" "$work/auto.txt" \
  && ok || fail "step: auto: $(tail -3 "$work/auto.txt")"
$py - "$work/pend_auto" <<'PY' && ok || fail "step: auto: results.h5"
import sys, h5py, numpy as np
f = h5py.File(sys.argv[1] + "/results.h5")
t, h = f["time"][:], f["step_size"][:]
assert len(t) == 21 and np.abs(t - 0.01 * np.arange(21)).max() < 1e-15, t
assert f.attrs["steps"] > 20 and f.attrs["rejected_steps_error"] >= 0 and f.attrs["rejected_steps_newton"] >= 0
assert h[0] == 0 and (h[1:] > 0).all() and (h[1:] <= 0.01 + 1e-15).all(), h
# Every step taken: as many as the attribute says, each ending where the next begins, to 0.2 s.
ts, hs = f["steps/time"][:], f["steps/size"][:]
assert len(ts) == f.attrs["steps"] == len(hs), (len(ts), f.attrs["steps"])
assert abs(ts[-1] - 0.2) < 1e-12 and np.abs(np.diff(ts) - hs[1:]).max() < 1e-12 and abs(ts[0] - hs[0]) < 1e-15
PY
# A fixed step Newton cannot take is cut: said once as a warning, even with -q, with the step used.
"$bin/femb-solve" -q "$work/pend/rate.yaml" -o "$work/pend_big" --set analysis.step=0.5 --set analysis.end_time=1 \
  > "$work/big.txt" 2>&1; code=$?
[ $code = 0 ] && [ "$(grep -c "^femb-solve: warning: Newton did not converge with analysis.step 0.5 from t = .* on (.* cuts): steps there were shortened, to .* at the least" "$work/big.txt")" = 1 ] \
  && ok || fail "fixed step cut by Newton: exit $code $(cat "$work/big.txt")"
# Clean stops: SIGTERM (a batch system's time limit) and SIGINT (Ctrl-C) finish the step under
# way, write every result up to it and exit with 128 + the signal (143, 130); results.h5's status
# says where the run stopped; no temporary file is left.
$py - "$bin" "$work/pend/rate.yaml" "$work" <<'PY' && ok || fail "clean stops on SIGTERM and SIGINT"
import glob, h5py, signal, subprocess, sys
bin_dir, scene, work = sys.argv[1:4]
for sig, code, name in ((signal.SIGTERM, 143, "SIGTERM"), (signal.SIGINT, 130, "SIGINT")):
    out = f"{work}/pend_{name}"
    p = subprocess.Popen([bin_dir + "/femb-solve", scene, "-o", out, "--set", "analysis.end_time=1000"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    for line in p.stdout:  # the first progress line: the analysis runs
        if line.startswith("femb-solve: t = "):
            break
    p.send_signal(sig)
    stdout, stderr = p.communicate(timeout=120)
    assert p.returncode == code, (name, p.returncode, stderr)
    assert f"stopped by {name} at t = " in stderr and f"results up to it are in {out}" in stderr, stderr
    with h5py.File(out + "/results.h5") as f:
        status = f.attrs["status"]
        status = status.decode() if isinstance(status, bytes) else str(status)
        t = f["time"][:]
    assert status.startswith(f"stopped by {name} at t = "), status
    assert 0 < t[-1] < 1000 and f"at t = {t[-1]:.6g} of 1000" in status, (t[-1], status)
    rows = open(out + "/probes.csv").read().splitlines()
    assert len(rows) == len(t) + 1, (len(rows), len(t))
    assert not glob.glob(out + "/*.tmp*"), glob.glob(out + "/*")
PY
"$bin/femb-solve" -q "$work/pend/rate.yaml" -o "$work/pend_auto_bad" --set analysis.step=auto --set analysis.min_step=0.1 \
  --set analysis.max_step=0.01 2> "$work/err.txt"; [ $? = 2 ] && grep -q "analysis.min_step.*min_step 0.1 is above max_step 0.01" "$work/err.txt" \
  && [ $(wc -l < "$work/err.txt") = 1 ] && ok || fail "min_step > max_step: $(cat "$work/err.txt")"
"$bin/femb-solve" -q "$work/pend/rate.yaml" -o "$work/pend_auto_bad" --set analysis.step=auto --set analysis.step_tolerance=0 \
  2> "$work/err.txt"; [ $? = 2 ] && grep -q "step_tolerance" "$work/err.txt" && ok || fail "step_tolerance 0: $(cat "$work/err.txt")"
"$bin/femb-solve" -q "$work/pend/rate.yaml" -o "$work/pend_auto_min" --set analysis.step=auto --set analysis.min_step=0.005 \
  --set analysis.step_tolerance=1e-9 2> "$work/err.txt"; [ $? = 3 ] && grep -q "the step fell below min_step 0.005 at t = " "$work/err.txt" \
  && [ -s "$work/pend_auto_min/results.h5" ] && ok || fail "below min_step: $(cat "$work/err.txt")"
printf 'initial_velocity:\n  pivot_rod: {joint: [2.0, 1.0]}\n' | cat "$work/pend/scene.yaml" - > "$work/pend/bad_rate.yaml"
"$bin/femb-solve" -q "$work/pend/bad_rate.yaml" -o "$work/pend_bad" 2> "$work/err.txt"; [ $? = 2 ] && grep -q "has 1 joint coordinates, got 2 joint rates" "$work/err.txt" && ok || fail "bad joint rates: $(cat "$work/err.txt")"
# Mode shapes as VTU: one file per reduced coordinate; quadratic tetrahedra in VTK node order
# (edge nodes 7, 8, 9 at the middles of edges 0-3, 1-3, 2-3).
"$bin/femb-inspect" "$work/solid/bar.h5" --vtu "$work/solid/vtu" > /dev/null && ok || fail "--vtu"
$py - "$work/solid/vtu" <<'PY' && ok || fail "vtu content"
import sys, glob, meshio, numpy as np
files = sorted(glob.glob(sys.argv[1] + "/solid_bar_*.vtu"))
assert len(files) == 18, len(files)
m = meshio.read(files[12])
assert m.cells[0].type == "tetra10"
c, p = m.cells[0].data, m.points
for node, (a, b) in ((7, (0, 3)), (8, (1, 3)), (9, (2, 3)), (4, (0, 1)), (5, (1, 2)), (6, (0, 2))):
    assert np.abs(p[c[:, node]] - 0.5 * (p[c[:, a]] + p[c[:, b]])).max() < 1e-9, node
assert np.abs(m.point_data["displacement"]).max() > 0
PY
$py - "$work/solid/out" <<'PY' && ok || fail "solid animation"
import sys, meshio, numpy as np
reader = meshio.xdmf.TimeSeriesReader(sys.argv[1] + "/animation.xdmf")
points, cells = reader.read_points_cells()
assert cells[0].type == "tetra10", cells[0].type
t, pd, cd = reader.read_data(reader.num_steps - 1)
sag = pd["displacement"][:, 1].min()
assert -1e-3 < sag < 0, sag   # sags: static tip sag q L^4 / 8 EI = 0.22 mm, dynamically up to twice
PY
# Every body is in the animation (it once held only the first body's kind): the solid bar,
# a beam rod on a revolute hinge at its tip and a rigid block (a stick figure): XDMF Mixed
# topology (quadratic tetrahedra and lines); counted from the file itself.
cp "$work/pend/rod.h5" "$work/solid/rod.h5"
cat > "$work/solid/mixed.yaml" <<'YAML'
name: mixed
units: SI
bodies:
  - {name: bar, superelement: bar.h5, nodes: {root: r, tip: t}}
  - {name: rod, superelement: rod.h5, placement: {position: [1, 0.025, 0.025]}, nodes: {A: t2, B: t3}}
  - {name: block, type: rigid, mass: 1, center_of_mass: [0, 0, 0], inertia: [1e-3, 1e-3, 1e-3], points: {P: [0, 0, 0]}, placement: {position: [1.3, 0.025, 0.025]}, nodes: {P: t3}}
joints:
  - {type: clamp, node: r}
  - {type: revolute, node: t2, parent: t, axis: [0, 0, 1]}
loads:
  - {type: gravity, g: [0, -9.81, 0]}
analysis: {type: dynamic, end_time: 0.003, step: 1e-3}
outputs:
  animation: true
  probes:
    - {name: hinge, node: t2, quantities: [joint]}
YAML
"$bin/femb-solve" -q "$work/solid/mixed.yaml" -o "$work/solid/mixed" && ok || fail "mixed scene"
$py - "$work/solid/mixed" <<'PY' && ok || fail "mixed animation / hinge probe"
import sys, csv, h5py, numpy as np
f = h5py.File(sys.argv[1] + "/animation.h5")
flat, body = f["cells"][...], f["body"][...].ravel()
xml = open(sys.argv[1] + "/animation.xdmf").read()
assert 'TopologyType="Mixed"' in xml
counts, r = {}, 0
while r < len(flat):
    code = flat[r]
    n = {38: 10, 2: None}[code]
    if code == 2:
        n = flat[r + 1]; r += 1
    counts[code] = counts.get(code, 0) + 1
    r += 1 + n
assert counts[2] == 6 + 1, counts                 # rod: 6 beam elements; block: one (zero-length) line
assert counts[38] == (body == 0).sum(), counts    # the bar's tetrahedra
assert set(np.unique(body)) == {0, 1, 2}
assert f["x_0"].shape[0] == f["x_3"].shape[0] > 0
# A joint probe on a revolute joint between two nodes (it was refused: exit 2).
rows = list(csv.DictReader(open(sys.argv[1] + "/probes.csv")))
assert "hinge.joint.0" in rows[0] and len(rows) == 4, rows[0].keys()
PY

# A modes analysis writes its mode shapes: animation steps 1..3 are the state moved along each
# mode (its largest node motion 5% of the scene's 1 m).
"$bin/femb-solve" -q "$work/scene.yaml" -o "$work/modes_out" --set analysis.type=modes --set analysis.count=3 \
  --set outputs.animation=true && ok || fail "modes run"
$py - "$work/modes_out" <<'PY' && ok || fail "mode shapes in the animation"
import sys, meshio, numpy as np
r = meshio.xdmf.TimeSeriesReader(sys.argv[1] + "/animation.xdmf")
r.read_points_cells()
assert r.num_steps == 4, r.num_steps
for s in range(1, 4):
    t, pd, cd = r.read_data(s)
    assert t == s
    d = np.linalg.norm(pd["displacement"], axis=1).max()
    assert abs(d - 0.05) < 1e-3, (s, d)
PY

expect() {  # name, exit code, expected text, scene text transformation (sed)
  local name=$1 code=$2 text=$3 script=$4
  sed "$script" "$work/scene.yaml" > "$work/bad.yaml"
  rm -rf "$work/bad_out"
  "$bin/femb-solve" -q "$work/bad.yaml" -o "$work/bad_out" 2> "$work/err.txt" > /dev/null
  local got=$?
  [ $got = "$code" ] || { fail "$name: exit $got, want $code ($(cat "$work/err.txt"))"; return; }
  [ "$(wc -l < "$work/err.txt")" = 1 ] || { fail "$name: not one line: $(cat "$work/err.txt")"; return; }
  grep -qF -- "$text" "$work/err.txt" || { fail "$name: '$(cat "$work/err.txt")' lacks '$text'"; return; }
  ok
}
expect "unknown joint type" 2 "bad.yaml:18: joints[0].type: unknown joint type 'weld'" 's/type: clamp/type: weld/'
expect "unknown node" 2 "node 'n42' is not a node of any body" 's/node: n10, force/node: n42, force/'
expect "unknown body type" 2 "unknown body type 'rigid_blob'" 's/{name: b0, /{name: b0, type: rigid_blob, /'
# Loops: a rigid body on two supports, a cycle of rigid joints: the joint that closes
# each loop is cut (constraint equations with multipliers) and the log names it.
sed 's/^joints:/joints:\n  - {type: spherical, node: n9}\n  - {type: spherical, node: n10}/; s/{name: b9, superelement: segment.h5, placement: {position: \[0.9, 0, 0\]}, nodes: {A: n9, B: n10}}/{name: b9, type: rigid, mass: 1, inertia: [1, 1, 1], points: {A: [0, 0, 0], B: [0.1, 0, 0]}, placement: {position: [0.9, 0, 0]}, nodes: {A: n9, B: n10}}/; s/  - {type: force, node: n10, force/  - {type: force, node: n8, force/' "$work/scene.yaml" > "$work/loop.yaml"
"$bin/femb-solve" "$work/loop.yaml" -o "$work/loop_out" > "$work/loop_log.txt" 2>&1 \
  && grep -q "spherical joint of node 'n10' to the ground closes a loop: 2 constraint equations with Lagrange multipliers; 1 more (translation along (-1, 0, 0) of the parent's axes) repeat" "$work/loop_log.txt" \
  && ok || fail "rigid body on two supports: $(cat "$work/loop_log.txt")"
expect "missing superelement" 2 "body 'b3': " 's/{name: b3, superelement: segment.h5/{name: b3, superelement: nothere.h5/'
expect "missing superelement names file" 2 "nothere.h5: cannot open file" 's/{name: b3, superelement: segment.h5/{name: b3, superelement: nothere.h5/'
expect "load on clamped node" 2 "load on node 'n0', which is clamped" 's/node: n10, force/node: n0, force/'
expect "bad option value" 2 "bodies[0].options.tangent: expected full or K1, got 'K2'" 's/{name: b0, superelement: segment.h5,/{name: b0, superelement: segment.h5, options: {tangent: K2},/'
expect "unknown analysis" 2 "unknown analysis type 'eigen'" 's/type: static/type: eigen/'
expect "unknown integrator" 2 "analysis.integrator: expected generalized_alpha, midpoint or radau, got 'rk4'" 's/type: static/type: static\n  integrator: rk4/'
expect "node placed twice" 2 "node 'n1' is placed at" 's/position: \[0.1, 0, 0\]}, nodes: {A: n1/position: [0.15, 0, 0]}, nodes: {A: n1/'
# Wrong version superelement file.
cp "$work/segment.h5" "$work/v2.h5"
$py -c "import h5py; f=h5py.File('$work/v2.h5','r+'); f.attrs['format_version_major']=2" 
# Geometric stiffening asked for explicitly from a file without it: one line, exit 2.
expect "stiffening not in the file" 2 "options.geometric_stiffening is true but" 's/{name: b3, superelement: segment.h5/{name: b3, options: {geometric_stiffening: true}, superelement: segment.h5/'
"$bin/femb-reduce" -q "$work/segment.yaml" -o "$work/segment_gs.h5" --set reduction.geometric_stiffening=true || fail "reduce with stiffening"
sed 's/{name: b3, superelement: segment.h5/{name: b3, options: {geometric_stiffening: true}, superelement: segment_gs.h5/' "$work/scene.yaml" > "$work/gs.yaml"
"$bin/femb-solve" "$work/gs.yaml" -o "$work/gs_out" > "$work/gs_log.txt" 2>&1 && grep -q "note: body 'b0': .*has no geometric stiffening" "$work/gs_log.txt" \
  && ! grep -q "note: body 'b3'" "$work/gs_log.txt" && ok || fail "stiffening file used, note for the others: $(cat "$work/gs_log.txt")"
# A file with modal derivatives but without the stiffening: the note says the body is nonlinear
# inside through their cubic force, not that it is linear.
"$bin/femb-reduce" -q "$work/segment.yaml" -o "$work/segment_md.h5" --set reduction.geometric_stiffening=false \
  --set reduction.modal_derivatives=true || fail "reduce with modal derivatives"
sed 's/{name: b3, superelement: segment.h5/{name: b3, superelement: segment_md.h5/' "$work/scene.yaml" > "$work/md.yaml"
"$bin/femb-solve" "$work/md.yaml" -o "$work/md_out" > "$work/md_log.txt" 2>&1 \
  && grep -q "note: body 'b3': .*has no geometric stiffening; the body is nonlinear inside through its modal derivatives' cubic force alone" "$work/md_log.txt" \
  && grep -q "note: body 'b0': .*has no geometric stiffening; the body is linear inside" "$work/md_log.txt" \
  && ok || fail "modal derivatives without stiffening: $(cat "$work/md_log.txt")"
# The exact inertia asked for from a file without the invariants: one line, exit 2; a corrupted
# invariant: the load gate names the dataset and the check.
# A file of an older femb-reduce (without the invariants: they are deleted here) keeps loading,
# with a note naming the consequence; the exact inertia asked for from it is one line naming
# the file and how to reduce it again.
cp "$work/segment.h5" "$work/old.h5"
$py -c "import h5py; f=h5py.File('$work/old.h5','r+'); del f['/reduced/inertia_invariants']"
expect "inertia invariants not in the file" 2 "old.h5 has no inertia invariants (an older femb-reduce wrote it: reduce the part again" 's/{name: b3, superelement: segment.h5/{name: b3, options: {inertia: exact}, superelement: old.h5/'
sed 's/{name: b3, superelement: segment.h5/{name: b3, superelement: old.h5/; s/type: static/type: dynamic\n  step: 0.01\n  end_time: 0.02/' "$work/scene.yaml" > "$work/old.yaml"
"$bin/femb-solve" "$work/old.yaml" -o "$work/old_out" > "$work/old_log.txt" 2>&1 \
  && grep -q "note: body 'b3': .*old.h5 has no inertia invariants (an older femb-reduce wrote it): the corotational inertia" "$work/old_log.txt" \
  && ! grep -q "note: body 'b2': .*inertia invariants" "$work/old_log.txt" && ok || fail "old file without invariants: $(cat "$work/old_log.txt")"
# The midpoint integrator takes the exact inertia too (its momenta and source are the exact
# kinetic energy's): no note about the corotational one.
sed 's/{name: b3, superelement: segment.h5/{name: b3, options: {inertia: exact}, superelement: segment_gs.h5/; s/type: static/type: dynamic\n  integrator: midpoint\n  step: 0.01\n  end_time: 0.02/' "$work/scene.yaml" > "$work/mid_exact.yaml"
"$bin/femb-solve" "$work/mid_exact.yaml" -o "$work/mid_exact_out" > "$work/mid_exact_log.txt" 2>&1 \
  && ! grep -q "note: .*corotational" "$work/mid_exact_log.txt" && grep -q "10 flexible bodies: 10 with the exact inertia" "$work/mid_exact_log.txt" && ok || fail "exact inertia under the midpoint scheme: $(cat "$work/mid_exact_log.txt")"
expect "bad inertia option" 2 "options.inertia: expected exact or corotational (exact: the file's inertia invariants), got 'lumped'" 's/{name: b3, superelement: segment.h5/{name: b3, options: {inertia: lumped}, superelement: segment.h5/'
cp "$work/segment_gs.h5" "$work/bad_gamma.h5"
$py -c "import h5py; f=h5py.File('$work/bad_gamma.h5','r+'); a=f['/reduced/inertia_invariants/Gamma'][...]; a[0,1]+=1.0; f['/reduced/inertia_invariants/Gamma'][...]=a"
expect "corrupt Gamma" 2 "bad_gamma.h5: /reduced/inertia_invariants: check inertia_invariants failed" 's/{name: b3, superelement: segment.h5/{name: b3, superelement: bad_gamma.h5/'
expect "wrong version" 2 "is not supported by this femb" 's/{name: b3, superelement: segment.h5/{name: b3, superelement: v2.h5/'
# Corrupt superelement files: one line naming the file, the dataset and the check (a NaN in
# Phi_CB, the origin or the interface frames once crashed femb-solve; an indefinite M ran to the end).
for case in "Phi_CB:/floating_frame/Phi_CB:(0,0):nan:check finite" "origin:/floating_frame/origin:(1,):inf:check finite" \
            "positions:/interfaces/positions:(1,0):nan:check finite" "orientations:/interfaces/orientations:(0,4):nan:check finite" \
            "K:/reduced/K:(3,3):nan:check finite" "M:/reduced/M:(2,2):-1.0:check M_positive_definite"; do
  IFS=: read -r name dataset index value check <<< "$case"
  cp "$work/segment.h5" "$work/bad_$name.h5"
  $py -c "import h5py; f=h5py.File('$work/bad_$name.h5','r+'); a=f['$dataset'][...]; a[$index]=float('$value'); f['$dataset'][...]=a"
  expect "corrupt $name" 2 "bad_$name.h5: $dataset: $check failed" "s/{name: b3, superelement: segment.h5/{name: b3, superelement: bad_$name.h5/"
done
sed 's/^joints:/joints:\n  - {type: rigid, node: n3, parent: n5}\n  - {type: rigid, node: n5, parent: n7}\n  - {type: rigid, node: n7, parent: n3}/' "$work/scene.yaml" > "$work/cycle.yaml"
"$bin/femb-solve" "$work/cycle.yaml" -o "$work/cycle_out" > "$work/cycle_log.txt" 2>&1 \
  && grep -q "rigid joint of node 'n7' on node 'n3' closes a loop: the other joints already hold it; its 6 equations repeat theirs" "$work/cycle_log.txt" \
  && ok || fail "cycle of rigid joints: $(cat "$work/cycle_log.txt")"
# A node with two joints: the second is cut.
sed 's/^joints:/joints:\n  - {type: rigid, node: n3, parent: n5}\n  - {type: rigid, node: n3, parent: n7}/' "$work/scene.yaml" > "$work/two.yaml"
"$bin/femb-solve" "$work/two.yaml" -o "$work/two_out" > "$work/two_log.txt" 2>&1 \
  && grep -q "rigid joint of node 'n3' on node 'n7' closes a loop: 6 constraint equations" "$work/two_log.txt" \
  && ok || fail "node with two joints: $(cat "$work/two_log.txt")"
# A joint whose nodes are apart at t = 0 (the gap would silently become a rigid arm).
expect "joint gap" 2 "revolute joint between nodes 'n3' and 'n5': the nodes are 0.2 apart" 's/^joints:/joints:\n  - {type: revolute, node: n3, parent: n5, axis: [0, 0, 1]}/'
# --set reaches list items by index (the docs say any key); a bad index is one line, exit 2.
"$bin/femb-solve" -q "$work/scene.yaml" -o "$work/set_out" --set 'bodies[1].options.tangent=K7' 2> "$work/err.txt"; code=$?
[ $code = 2 ] && grep -qF -- "--set bodies[1].options.tangent: expected full or K1, got 'K7'" "$work/err.txt" && ok || fail "--set list item: exit $code $(cat "$work/err.txt")"
"$bin/femb-solve" -q "$work/scene.yaml" -o "$work/set_out" --set 'bodies[10].options.tangent=K1' 2> "$work/err.txt"; code=$?
[ $code = 2 ] && grep -qF "'bodies' has no item 10 in" "$work/err.txt" && ok || fail "--set index out of range: exit $code $(cat "$work/err.txt")"
# A singular system is diagnosed, not reported as "Newton did not converge": the free motion is named.
expect "free static body" 3 "static tangent at the start: the system matrix is singular (6 free motions" 's/type: clamp, node: n0/type: rigid, node: n1, parent: n2/'
expect "pinned cantilever" 3 "(3 free motions, smallest/largest singular value" 's/type: clamp, node: n0/type: spherical, node: n0/'
# Numerical failure: K1-only tangent at high load: exit 3, results up to it kept.
sed 's/{name: b\([0-9]\), superelement: segment.h5,/{name: b\1, superelement: segment.h5, options: {tangent: K1},/' "$work/scene.yaml" > "$work/k1.yaml"
"$bin/femb-solve" -q "$work/k1.yaml" -o "$work/k1_out" 2> "$work/err.txt" > /dev/null
code=$?
[ $code = 3 ] && grep -q "numerical failure: Newton did not converge" "$work/err.txt" && ok || fail "K1 only: exit $code: $(cat "$work/err.txt")"
[ -s "$work/k1_out/probes.csv" ] && [ -s "$work/k1_out/results.h5" ] && ok || fail "K1 only: results not kept"
$py -c "import h5py; f=h5py.File('$work/k1_out/results.h5'); s=f.attrs['status']; s = s.decode() if isinstance(s, bytes) else s; assert 'did not converge' in s" && ok || fail "status not stored"

echo "solve cli: $passed passed, $failed failed"
[ $failed = 0 ]
