#!/usr/bin/env bash
# The state a run reached (OUTDIR/checkpoint.h5): another analysis started from it
# (initial_state: {from: OUTDIR}: a dynamic run from a static equilibrium starts at rest, a
# dynamic run continues another's, modes about a saved static state), and a stopped or killed
# run continued in its folder to the bit (--restart OUTDIR); bad checkpoints are one line, exit
# 2, and nothing in the output folder is touched.
# Usage: restart_cli_test.sh BIN_DIR SOURCE_DIR
set -u
bin=$1
src=$2
source "$(dirname "$0")/test_lib.sh"

cp "$src/examples/solid_bar/part.yaml" "$work/bar.yaml"
"$bin/femb-reduce" -q "$work/bar.yaml" -o "$work/bar.h5" || fail "reduce the bar"
model='units: SI
bodies:
  - {name: bar, superelement: bar.h5, nodes: {root: root, tip: tip}}
joints:
  - {type: clamp, node: root}'
probes='outputs:
  probes:
    - {name: tip, node: tip, quantities: [position, velocity, acceleration]}'
printf '%s\n' "name: bar_static" "$model" "loads:" "  - {type: gravity, g: [0, -9.81, 0]}" \
  "analysis: {type: static, end_time: 1, steps: 4}" "$probes" > "$work/static.yaml"
printf '%s\n' "name: bar_drop" "$model" "loads:" "  - {type: gravity, g: [0, -9.81, 0]}" \
  "analysis: {type: dynamic, end_time: 0.02, step: 1.0e-3, rho_inf: 0.8}" "$probes" > "$work/drop.yaml"
cp "$work/drop.yaml" "$work/settled.yaml"
echo "initial_state: {from: static}" >> "$work/settled.yaml"

# A dynamic run from the static equilibrium under gravity: it stays there (the tip's
# acceleration below 1e-9 g at every output step, measured 3e-10 g), where the same run from
# the undeformed placement swings (its tip's acceleration near g).
"$bin/femb-solve" -q "$work/static.yaml" -o "$work/static" && [ -s "$work/static/checkpoint.h5" ] \
  && "$bin/femb-solve" -q "$work/settled.yaml" -o "$work/settled" && "$bin/femb-solve" -q "$work/drop.yaml" -o "$work/drop" \
  && ok || fail "static, then dynamic from it"
$py - "$work" <<'PY' && ok || fail "dynamic run from a static equilibrium"
import sys, numpy as np
w = sys.argv[1]
def rows(d):
    return np.genfromtxt(f"{w}/{d}/probes.csv", delimiter=",", names=True)
s, d, st = rows("settled"), rows("drop"), rows("static")
acc = np.sqrt(sum(s[f"tipacceleration{c}"] ** 2 for c in "xyz"))
print("settled: largest tip acceleration %.3g g" % (acc.max() / 9.81))
assert acc.max() < 1e-9 * 9.81, acc.max()
assert abs(s["tippositiony"][0] - st["tippositiony"][-1]) == 0  # the static run's last state
assert np.abs(d["tipaccelerationy"]).max() > 0.5 * 9.81, d["tipaccelerationy"]
PY

# A run started from another's state, stopped and restarted, equals the run in one go (the
# restart continues its own state: initial_state is not read again).
"$bin/femb-solve" -q "$work/settled.yaml" -o "$work/settled_half" --set analysis.end_time=0.01 \
  && "$bin/femb-solve" -q "$work/settled.yaml" --restart "$work/settled_half" \
  && cmp -s "$work/settled/probes.csv" "$work/settled_half/probes.csv" && ok || fail "restart of a run started with initial_state"

# The Radau IIA integrator stopped at half time and restarted equals its run in one go (the
# predictor's stage accelerations travel in the checkpoint).
"$bin/femb-solve" -q "$work/drop.yaml" -o "$work/radau" --set analysis.integrator=radau \
  && "$bin/femb-solve" -q "$work/drop.yaml" -o "$work/radau_half" --set analysis.integrator=radau --set analysis.end_time=0.01 \
  && "$bin/femb-solve" -q "$work/drop.yaml" --restart "$work/radau_half" --set analysis.integrator=radau \
  && cmp -s "$work/radau/probes.csv" "$work/radau_half/probes.csv" && ok || fail "restart of a Radau IIA run"

# Modes about the saved static state equal modes_about_static (the same static solve).
printf '%s\n' "name: bar_modes" "$model" "loads:" "  - {type: gravity, g: [0, -9.81, 0]}" \
  "analysis: {type: modes, count: 4, end_time: 1, steps: 4, about: static}" > "$work/modes.yaml"
sed 's/, about: static//' "$work/modes.yaml" > "$work/modes_from.yaml"
echo "initial_state: {from: static}" >> "$work/modes_from.yaml"
"$bin/femb-solve" -q "$work/modes.yaml" -o "$work/modes" && "$bin/femb-solve" -q "$work/modes_from.yaml" -o "$work/modes_from" \
  && $py - "$work" <<'PY' && ok || fail "modes about a saved static state"
import sys, numpy as np
w = sys.argv[1]
a = np.genfromtxt(f"{w}/modes/modes.csv", delimiter=",", skip_header=1)[:, 1]
b = np.genfromtxt(f"{w}/modes_from/modes.csv", delimiter=",", skip_header=1)[:, 1]
assert len(a) == 4 and np.abs(a - b).max() <= 1e-9 * a.max(), (a, b)
PY

# A dynamic run continued by a new analysis from its end: it starts at the state's time, at the
# state's positions and velocities (accelerations consistent anew: generalized-alpha's own start
# differs from the run's algorithmic ones: measured 3.2e-6 of the tip's travel).
printf '%s\n' "name: bar_tip" "$model" "functions:" "  on: {type: step, value: 1, t_start: 0}" "loads:" \
  "  - {type: force, node: tip, force: [0, 0, -1000], function: on}" \
  "analysis: {type: dynamic, end_time: 0.1, step: 1.0e-4, rho_inf: 0.8}" "$probes" > "$work/tip.yaml"
cp "$work/tip.yaml" "$work/tip_more.yaml"
echo "initial_state: {from: half}" >> "$work/tip_more.yaml"
"$bin/femb-solve" -q "$work/tip.yaml" -o "$work/whole" && "$bin/femb-solve" -q "$work/tip.yaml" -o "$work/half" --set analysis.end_time=0.05 \
  && "$bin/femb-solve" -q "$work/tip_more.yaml" -o "$work/more" && $py - "$work" <<'PY' && ok || fail "a dynamic run continued"
import sys, numpy as np
w = sys.argv[1]
whole = np.genfromtxt(f"{w}/whole/probes.csv", delimiter=",", names=True)
half = np.genfromtxt(f"{w}/half/probes.csv", delimiter=",", names=True)
more = np.genfromtxt(f"{w}/more/probes.csv", delimiter=",", names=True)
assert more["time"][0] == half["time"][-1] == 0.05 and more["time"][-1] == 0.1 and len(more) == 501
for c in "xyz":
    assert more[f"tipposition{c}"][0] == half[f"tipposition{c}"][-1]
    assert more[f"tipvelocity{c}"][0] == half[f"tipvelocity{c}"][-1]
tail = whole[500:]
travel = np.abs(whole["tippositionz"] - whole["tippositionz"][0]).max()
err = np.abs(tail["tippositionz"] - more["tippositionz"]).max() / travel
print("continued run against the whole run: %.2g of the tip's travel" % err)
assert err < 1e-5, err
PY

# Bad input: one line, exit 2, the output folder left as it was.
cp -r "$work/drop" "$work/kept"
before=$(cd "$work/kept" && md5sum *)
check_bad() {  # label, scene, expected message part
  "$bin/femb-solve" -q "$2" -o "$work/kept" 2> "$work/err.txt"; local code=$?
  [ $code = 2 ] && [ "$(wc -l < "$work/err.txt")" = 1 ] && grep -q "$3" "$work/err.txt" \
    && [ "$(cd "$work/kept" && md5sum *)" = "$before" ] && ok || fail "$1: exit $code, $(cat "$work/err.txt")"
}
sed 's/from: static/from: nowhere/' "$work/settled.yaml" > "$work/bad1.yaml"
check_bad "no checkpoint" "$work/bad1.yaml" "nowhere/checkpoint.h5: no checkpoint"
# Another model: the bar reduced with 4 modes instead of 6.
mkdir -p "$work/other"
"$bin/femb-reduce" -q "$work/bar.yaml" -o "$work/other/bar.h5" --set reduction.internal_modes=4 2> /dev/null
printf '%s\n' "name: bar_other" "$model" "analysis: {type: static, end_time: 1, steps: 1}" > "$work/other/scene.yaml"
"$bin/femb-solve" -q "$work/other/scene.yaml" -o "$work/other/out" || fail "other model"
sed 's/from: static/from: other\/out/' "$work/settled.yaml" > "$work/bad2.yaml"
check_bad "another model's checkpoint" "$work/bad2.yaml" "checkpoint.h5: written for another model: it has 'body bar coordinates 16"
# A truncated checkpoint.
cp -r "$work/static" "$work/cut"
head -c 3000 "$work/static/checkpoint.h5" > "$work/cut/checkpoint.h5"
sed 's/from: static/from: cut/' "$work/settled.yaml" > "$work/bad3.yaml"
check_bad "truncated checkpoint" "$work/bad3.yaml" "cut/checkpoint.h5"
sed 's/end_time: 0.02/end_time: 0.02, type: static/' "$work/settled.yaml" > /dev/null
printf '%s\n' "name: bar_static2" "$model" "analysis: {type: static, end_time: 1, steps: 4}" "initial_state: {from: static}" > "$work/bad4.yaml"
check_bad "initial_state in a static analysis" "$work/bad4.yaml" "initial_state: a static analysis starts from the model's placement"
echo "initial_state: {from: half}" | cat "$work/tip.yaml" - | sed 's/end_time: 0.1,/end_time: 0.04,/' > "$work/bad5.yaml"
check_bad "end_time before the state's time" "$work/bad5.yaml" "analysis.end_time 0.04 is not after the initial state's time 0.05"

# --restart: a run stopped by SIGTERM, or killed by SIGKILL after a write during the run, and
# continued in its folder ends with probes.csv and results.h5 identical to the bit to the
# uninterrupted run's: the four-bar with a flexible coupler in 2 superelements and a cut joint,
# generalized-alpha (fixed steps; step: auto with body_matrices_every 3) and the midpoint scheme
# (fixed steps; step: auto), reactions on. A finished run extended to a later end time equals the
# run to that time directly.
mkdir -p "$work/fb"
$py "$src/examples/four_bar/make_scenes.py" "$work/fb" > /dev/null && "$bin/femb-reduce" -q "$work/fb/coupler_2.yaml" -o "$work/fb/coupler_2.h5" \
  || fail "four-bar scenes"
$py - "$bin" "$work/fb" <<'PY' && ok || fail "--restart after SIGTERM and SIGKILL, and extending a finished run"
import os, signal, subprocess, sys, time
import h5py, numpy as np
bin_dir, fb = sys.argv[1:3]
base = [bin_dir + "/femb-solve", fb + "/flexible.yaml", "-q", "--threads", "1", "--set", "analysis.end_time=0.05",
        "--set", "outputs.reactions=true", "--set", "outputs.flush_every_steps=300"]

def datasets(path):
    out = {}
    with h5py.File(path, "r") as f:
        f.visititems(lambda name, obj: out.__setitem__(name, obj[()]) if isinstance(obj, h5py.Dataset) else None)
        out["@"] = {k: f.attrs[k] for k in f.attrs}
    return out

def same(a, b):
    da, db = datasets(a + "/results.h5"), datasets(b + "/results.h5")
    assert set(da) == set(db), set(da) ^ set(db)
    for k in da:
        if k == "@":
            assert {k: str(v) for k, v in da[k].items()} == {k: str(v) for k, v in db[k].items()}, (da[k], db[k])
        elif da[k].dtype.kind == "O":
            assert list(da[k]) == list(db[k]), k
        else:
            assert da[k].shape == db[k].shape and np.array_equal(da[k], db[k]), (k, da[k].shape, db[k].shape)
    assert open(a + "/probes.csv").read() == open(b + "/probes.csv").read()

def has_resume(out):
    try:
        with h5py.File(out + "/checkpoint.h5", "r") as f:
            return "resume" in f
    except (OSError, KeyError):
        return False

cases = [("generalized-alpha", [], signal.SIGTERM),
         ("generalized-alpha, step: auto, body_matrices_every 3",
          ["--set", "analysis.step=auto", "--set", "analysis.body_matrices_every=3"], signal.SIGKILL),
         ("midpoint", ["--set", "analysis.integrator=midpoint"], signal.SIGKILL),
         ("midpoint, step: auto", ["--set", "analysis.integrator=midpoint", "--set", "analysis.step=auto"], signal.SIGTERM)]
for k, (name, extra, sig) in enumerate(cases):
    whole, part = f"{fb}/whole{k}", f"{fb}/part{k}"
    subprocess.run(base + extra + ["-o", whole], check=True)
    p = subprocess.Popen(base + extra + ["-o", part])
    while not has_resume(part) and p.poll() is None:
        time.sleep(0.01)
    p.send_signal(sig)
    p.wait()
    with h5py.File(part + "/checkpoint.h5", "r") as f:
        t_stop = f["state/numbers"][0]
    assert p.returncode in (-signal.SIGKILL, 143), (name, p.returncode)
    assert t_stop < 0.05, (name, t_stop)
    subprocess.run(base + extra + ["--restart", part], check=True)
    same(whole, part)
    print(f"{name}: stopped by {signal.Signals(sig).name} with its state at t = {t_stop:.6g}, restarted: identical")
# A finished run extended: to 0.03 s, then on to 0.05 s.
subprocess.run(base + ["-o", fb + "/short", "--set", "analysis.end_time=0.03"], check=True)
subprocess.run(base + ["--restart", fb + "/short"], check=True)
same(fb + "/whole0", fb + "/short")
print("extended from 0.03 s to 0.05 s: identical to the run to 0.05 s")
PY
# --restart's bad input: one line, exit 2, the folder left as it was.
check_restart_bad() {  # label, folder, expected message part, extra args...
  local label=$1 dir=$2 message=$3
  shift 3
  local before
  before=$(cd "$dir" 2>/dev/null && md5sum * 2>/dev/null)
  "$bin/femb-solve" -q "$work/fb/flexible.yaml" --restart "$dir" "$@" 2> "$work/err.txt"; local code=$?
  [ $code = 2 ] && [ "$(wc -l < "$work/err.txt")" = 1 ] && grep -q "$message" "$work/err.txt" \
    && [ "$(cd "$dir" 2>/dev/null && md5sum * 2>/dev/null)" = "$before" ] && ok || fail "$label: exit $code, $(cat "$work/err.txt")"
}
check_restart_bad "restart without a checkpoint" "$work/nowhere" "nowhere/checkpoint.h5: no checkpoint"
check_restart_bad "restart from another model's checkpoint" "$work/half" "written for another model"
check_restart_bad "restart of a finished run to its own end" "$work/fb/short" "the run reached t = 0.05.*not later" --set analysis.end_time=0.05
cp -r "$work/fb/short" "$work/fb/cut"
head -c 5000 "$work/fb/short/checkpoint.h5" > "$work/fb/cut/checkpoint.h5"
check_restart_bad "restart from a truncated checkpoint" "$work/fb/cut" "cut/checkpoint.h5"

echo "restart_cli_test: $passed passed, $failed failed"
[ "$failed" = 0 ]
