#!/usr/bin/env bash
# femb-solve's results on disk during the run: a run killed with SIGKILL at five moments leaves
# results.h5, probes.csv and the animation readable, holding every output step up to the last
# write, equal to the bit to an uninterrupted run's; a finished run gathers the animation into
# animation.h5 and leaves no part files.
# Usage: flush_cli_test.sh BIN_DIR SOURCE_DIR
set -u
bin=$1
src=$2
source "$(dirname "$0")/test_lib.sh"

# A clamped solid bar (TET10) sagging under gravity, stresses on, every step an output step.
cp "$src/examples/solid_bar/part.yaml" "$work/bar.yaml"
"$bin/femb-reduce" -q "$work/bar.yaml" -o "$work/bar.h5" || fail "reduce the bar"
cat > "$work/scene.yaml" <<'YAML'
name: bar_flush
units: SI
bodies:
  - {name: bar, superelement: bar.h5, nodes: {root: root, tip: tip}}
joints:
  - {type: clamp, node: root}
loads:
  - {type: gravity, g: [0, -9.81, 0]}
analysis: {type: dynamic, end_time: 2.0, step: 1.0e-4, rho_inf: 0.8}
outputs:
  stresses: true
  flush_every: 0.2
  flush_every_steps: 200
  probes:
    - {name: tip, node: tip, quantities: [position, velocity]}
    - {name: mid, body: bar, point: [0.5, 0.025, 0.025], quantities: [deformation]}
YAML

$py - "$bin" "$work" <<'PY' && ok || fail "SIGKILL at five moments"
import glob, os, random, signal, subprocess, sys, time
import h5py, meshio, numpy as np
bin_dir, work = sys.argv[1:3]
solve = [bin_dir + "/femb-solve", work + "/scene.yaml", "--threads", "1", "-q"]

start = time.monotonic()
subprocess.run(solve + ["-o", work + "/full"], check=True)
wall = time.monotonic() - start
full = h5py.File(work + "/full/results.h5", "r")
full_csv = open(work + "/full/probes.csv").read().splitlines()
assert full.attrs["status"] in (b"completed", "completed")
assert not glob.glob(work + "/full/animation.part-*"), os.listdir(work + "/full")
rng = random.Random(7)
for k in range(5):
    at = rng.uniform(0.15, 0.9) * wall
    out = f"{work}/killed{k}"
    p = subprocess.Popen(solve + ["-o", out])
    time.sleep(at)
    p.send_signal(signal.SIGKILL)
    p.wait()
    killed = time.time()
    with h5py.File(out + "/results.h5", "r") as f:
        status = f.attrs["status"]
        status = status.decode() if isinstance(status, bytes) else str(status)
        t = f["time"][:]
        n = len(t)
        print(f"killed at {at:.2f} s of {wall:.2f} s: {n} of {len(full['time'])} output steps, {status}")
        assert status.startswith("running: t = ") and f"t = {t[-1]:.6g} of 2 " in status, status
        assert 1 <= n <= len(full["time"])
        # Every series equals the uninterrupted run's first n rows, to the bit.
        for name in ("time", "probes/values", "nodes/position", "nodes/velocity", "energy/kinetic",
                     "bodies/bar/modal_coordinates", "bodies/bar/max_von_mises"):
            assert np.array_equal(f[name][:], full[name][:n]), name
    # Written within one write interval (200 output steps; the time rule's interval grows with
    # the writes' duration) and the write's own time of the kill.
    age = killed - os.path.getmtime(out + "/results.h5")
    assert age < 1.5, age
    rows = open(out + "/probes.csv").read().splitlines()
    assert rows == full_csv[: len(rows)] and len(rows) >= n + 1, (len(rows), n)
    # The animation so far: the frames up to the last write, from the part files.
    reader = meshio.xdmf.TimeSeriesReader(out + "/animation.xdmf")
    points, cells = reader.read_points_cells()
    assert cells[0].type == "tetra10" and reader.num_steps >= 1
    tf, pd, _ = reader.read_data(reader.num_steps - 1)
    assert tf <= t[-1] + 1e-12 and "von_mises" in pd, (tf, list(pd))
    assert glob.glob(out + "/animation.part-*.h5")
PY

# A finished run: the animation gathered into animation.h5, equal to a run that wrote only at the
# start and the end (the geometry rounded per write: positions within 2^-21 of the largest
# coordinate, stresses as computed), no part or temporary file left.
"$bin/femb-solve" -q "$work/scene.yaml" -o "$work/once" --threads 1 --set outputs.flush_every=1000 --set outputs.flush_every_steps=0 --set analysis.end_time=0.2 \
  && "$bin/femb-solve" -q "$work/scene.yaml" -o "$work/often" --threads 1 --set outputs.flush_every_steps=100 --set outputs.flush_every=1000 --set analysis.end_time=0.2 \
  && ok || fail "runs with and without writes during the run"
$py - "$work" <<'PY' && ok || fail "animation gathered from its parts"
import glob, os, sys
import h5py, meshio, numpy as np
work = sys.argv[1]
assert not [f for f in os.listdir(work + "/often") if "part-" in f or ".tmp" in f], os.listdir(work + "/often")
assert open(work + "/once/probes.csv").read() == open(work + "/often/probes.csv").read()
a, b = (meshio.xdmf.TimeSeriesReader(work + f"/{d}/animation.xdmf") for d in ("once", "often"))
a.read_points_cells(); b.read_points_cells()
assert a.num_steps == b.num_steps > 100, (a.num_steps, b.num_steps)
for s in (0, 57, a.num_steps - 1):
    ta, pa, _ = a.read_data(s)
    tb, pb, _ = b.read_data(s)
    assert ta == tb
    assert np.abs(pa["von_mises"] - pb["von_mises"]).max() == 0
    assert np.abs(pa["displacement"] - pb["displacement"]).max() <= 2.0 ** -21 * 1.1, s
assert "animation.part" not in open(work + "/often/animation.xdmf").read()
PY
"$bin/femb-solve" -q "$work/scene.yaml" -o "$work/bad" --set outputs.flush_every=-1 2> "$work/err.txt"; [ $? = 2 ] \
  && grep -q "flush_every must be >= 0" "$work/err.txt" && [ $(wc -l < "$work/err.txt") = 1 ] && ok || fail "flush_every -1: $(cat "$work/err.txt")"

echo "flush_cli_test: $passed passed, $failed failed"
[ "$failed" = 0 ]
