#!/usr/bin/env bash
# Stress recovery end to end: femb-reduce stores modal stresses, femb-inspect --vtu
# shows them per mode, femb-solve recovers them (probe, results.h5 maximum, animation fields),
# and bad stress requests get one line and exit 2.
# Usage: stress_cli_test.sh BIN_DIR SOURCE_DIR
set -u
bin=$1
source "$(dirname "$0")/test_lib.sh"

# A steel cantilever 1 m x 50 mm x 50 mm in HEX20, clamped at root, 1 kN along y at the tip.
cat > "$work/bar.yaml" <<'EOF'
name: bar
type: solid
units: SI
material: {E: 2.1e11, nu: 0.3, rho: 7850}
geometry: {shape: box, size: [1.0, 0.05, 0.05]}
mesh: {size: 0.025, order: 2, elements: hexahedra}
interfaces:
  - {name: root, group: xmin, coupling: rbe2}
  - {name: tip, group: xmax, coupling: rbe2}
reduction: {internal_modes: 4, geometric_stiffening: false}
EOF
"$bin/femb-reduce" "$work/bar.yaml" -o "$work/bar.h5" > "$work/reduce.txt" && ok || fail "reduce: $(cat "$work/reduce.txt")"
grep -q "stresses .* stress points x 16 coordinates (solid_nodal_l2)" "$work/reduce.txt" && ok || fail "no stresses progress line: $(cat "$work/reduce.txt")"
"$bin/femb-inspect" "$work/bar.h5" --vtu "$work/vtu" > /dev/null && ok || fail "inspect --vtu"
$py - "$work/vtu/bar_006.vtu" <<'PY' && ok || fail "mode VTU has no stress"
import sys, meshio, numpy as np
m = meshio.read(sys.argv[1])
# Mode 6 is tip.u_x: a unit stretch of the bar, sigma_xx = E / L at mid-span; 1%: the RBE2 faces
# stop the lateral contraction at the ends, which stiffens them, so the middle strains 0.4% more.
vm, s = m.point_data["von_mises"], m.point_data["stress"]
mid = np.argmin(np.linalg.norm(m.points - [0.5, 0.025, 0.025], axis=1))
assert s.shape == (len(m.points), 6)
assert abs(s[mid, 0] - 2.1e11) < 1e-2 * 2.1e11 and abs(vm[mid] - s[mid, 0]) < 1e-6 * 2.1e11, (s[mid], vm[mid])
assert np.abs(s[mid, 1:]).max() < 1e-6 * 2.1e11, s[mid]
PY

cat > "$work/scene.yaml" <<'EOF'
name: bar_static
units: SI
bodies:
  - {name: bar, superelement: bar.h5, nodes: {root: r, tip: t}}
joints:
  - {type: clamp, node: r}
loads:
  - {type: force, node: t, force: [0, 1, 0]}
analysis: {type: static, end_time: 1, steps: 2}
outputs:
  stresses: true
  principal_stresses: true
  probes:
    - {name: top, body: bar, point: [0.5, 0.05, 0.025], quantities: [stress]}
    - {name: tip, node: t, quantities: [position]}
EOF
"$bin/femb-solve" "$work/scene.yaml" -o "$work/out" > "$work/log.txt" 2>&1 && ok || fail "solve: $(cat "$work/log.txt")"
grep -q "probe 'top': stress point .* of body 'bar' at (0.5, 0.05, 0.025) in part axes" "$work/log.txt" && ok || fail "probe note: $(cat "$work/log.txt")"
$py - "$work/out" <<'PY' && ok || fail "stress results"
import csv, sys, h5py, meshio, numpy as np
rows = list(csv.DictReader(open(sys.argv[1] + "/probes.csv")))
# Beam theory at mid-span: sigma_xx = -M c / I on the +y face (compression), M = F L / 2.
ref = -1.0 * 0.5 * 0.025 / (0.05 * 0.05 ** 3 / 12)
sxx, vm = float(rows[-1]["top.stress.xx"]), float(rows[-1]["top.stress.von_mises"])
assert abs(sxx - ref) < 0.02 * abs(ref) and abs(vm - abs(ref)) < 0.02 * abs(ref), (sxx, vm, ref)
assert abs(float(rows[1]["top.stress.xx"]) - 0.5 * sxx) < 1e-6 * abs(sxx)   # half the load, half the stress
f = h5py.File(sys.argv[1] + "/results.h5", "r")
g = f["bodies/bar"]
m = g["max_von_mises"][()]
assert m.shape == (3,) and m[0] == 0 and abs(m[2] - 2 * m[1]) < 1e-6 * m[2], m
# The largest von Mises stress is at the clamped end (bending moment F L there).
assert g["max_von_mises_point"][2][0] < 0.05 and m[2] > 0.9 * abs(ref) * 2, (g["max_von_mises_point"][2], m[2])
reader = meshio.xdmf.TimeSeriesReader(sys.argv[1] + "/animation.xdmf")
points, cells = reader.read_points_cells()
_, data, _ = reader.read_data(2)
vm_field, largest, smallest = (data[k].ravel() for k in ("von_mises", "max_principal", "min_principal"))
assert abs(vm_field.max() - m[2]) < 1e-6 * m[2], (vm_field.max(), m[2])
assert (largest >= smallest).all()
# The principal stresses bound the von Mises stress: sigma_vm <= sigma_1 - sigma_3 (Tresca), and
# sigma_vm >= (sigma_1 - sigma_3) sqrt(3) / 2 (to the fields' rounding)
tresca = largest - smallest
assert (vm_field <= tresca * (1 + 1e-3) + 1e-3 * m[2]).all() and (vm_field >= 0.866 * tresca - 1e-3 * m[2]).all()
# Stored compactly: every field rounded, a column a chunk, shuffled and deflated; the principal
# stresses rounded to multiples of the power of two 2^-12 of the frame's largest
a = h5py.File(sys.argv[1] + "/animation.h5")
for k in ("x_2", "displacement_2", "deformation_2", "von_mises_2", "max_principal_2", "min_principal_2"):
    assert a[k].compression == "gzip" and a[k].shuffle and a[k].chunks[1] == 1, k
principal = np.concatenate([largest, smallest])
step = 2.0 ** (np.floor(np.log2(np.abs(principal).max())) + 1 - 12)
assert np.abs(principal / step - np.round(principal / step)).max() < 1e-6, step
# The node field 'node' maps the animation's nodes (in spatial order) to the part's mesh nodes:
# at the mesh node results.h5 names, the field holds the largest von Mises stress, and the first
# frame's positions are the mesh's.
node = a["node"][...].ravel()
assert sorted(node) == list(range(len(node)))
k = int(np.where(node == g["max_von_mises_node"][2])[0][0])
vm2 = a["von_mises_2"][...].ravel()
assert vm2[k] == vm2.max(), (vm2[k], vm2.max())
nodes = h5py.File(sys.argv[1] + "/../bar.h5", "r")["visualization/nodes"][...]
assert np.abs(a["x_0"][...] - nodes[node]).max() < 1e-6
PY
# Without outputs.principal_stresses: the von Mises field alone, the same values.
"$bin/femb-solve" -q "$work/scene.yaml" -o "$work/vm" --set outputs.principal_stresses=false && $py - "$work/vm" "$work/out" <<'PY' \
  && ok || fail "von Mises alone"
import sys, h5py, numpy as np
a, b = (h5py.File(d + "/animation.h5", "r") for d in sys.argv[1:3])
assert "von_mises_2" in a and "max_principal_2" not in a and "min_principal_2" not in a
assert np.array_equal(a["von_mises_2"][...], b["von_mises_2"][...])
xdmf = open(sys.argv[1] + "/animation.xdmf").read()
assert "von_mises" in xdmf and "principal" not in xdmf
PY
# principal_stresses without stresses: one line, exit 2.
"$bin/femb-solve" -q "$work/scene.yaml" -o "$work/bad" --set outputs.stresses=false > "$work/bad.txt" 2>&1
[ $? = 2 ] && [ "$(wc -l < "$work/bad.txt")" = 1 ] && grep -q "principal_stresses: true needs stresses: true" "$work/bad.txt" \
  && [ ! -e "$work/bad/results.h5" ] && ok || fail "principal without stresses: $(cat "$work/bad.txt")"
# Without outputs.stresses: no fields, no maxima (the probe still works).
"$bin/femb-solve" -q "$work/scene.yaml" -o "$work/plain" --set outputs.stresses=false \
  --set outputs.principal_stresses=false && $py - "$work/plain" <<'PY' \
  && ok || fail "stresses off"
import sys, h5py
assert "max_von_mises" not in h5py.File(sys.argv[1] + "/results.h5", "r")["bodies/bar"]
assert "von_mises" not in open(sys.argv[1] + "/animation.xdmf").read()
assert "top.stress.xx" in open(sys.argv[1] + "/probes.csv").readline()
PY

# A rotating bar: the same bar with geometric stiffening, spun up to 100 rad/s
# about z through its root in 0.05 s, held 0.05 s. On its axis the stress is the centrifugal
# axial stress rho Omega^2 (L^2 - x^2) / 2 (closed form); with the inertia load cases' stresses
# (ModalStress::inertia_modes) its mean over the hold is within 1% of it at x = L/4, L/2, 3L/4
# (the spin-up leaves an axial vibration of about 3%). Without them the 4 bending modes and the
# tip's axial static mode cannot carry the quadratic distribution: 25% low at L/4, 60% high at 3L/4.
sed 's/geometric_stiffening: false/geometric_stiffening: true/' "$work/bar.yaml" > "$work/rbar.yaml"
cat > "$work/rotating.yaml" <<'EOF'
name: rotating_bar
units: SI
bodies:
  - {name: bar, superelement: rbar.h5, placement: {position: [0, -0.025, -0.025]}, nodes: {root: r, tip: t}}
joints:
  - {type: revolute, node: r, axis: [0, 0, 1], prescribed: spin}
functions:
  spin: {type: spin_up, omega: 100, t_spin: 0.05}
analysis: {type: dynamic, end_time: 0.1, step: 1e-4}
outputs:
  animation: false
  probes:
    - {name: s25, body: bar, point: [0.25, 0, 0], quantities: [stress]}
    - {name: s50, body: bar, point: [0.5, 0, 0], quantities: [stress]}
    - {name: s75, body: bar, point: [0.75, 0, 0], quantities: [stress]}
EOF
"$bin/femb-reduce" -q "$work/rbar.yaml" -o "$work/rbar.h5" && "$bin/femb-solve" -q "$work/rotating.yaml" -o "$work/rot" \
  && ok || fail "rotating bar run"
sed 's/rbar.h5/bar.h5/' "$work/rotating.yaml" > "$work/rotating_linear.yaml"
"$bin/femb-solve" -q "$work/rotating_linear.yaml" -o "$work/rot_linear" || fail "rotating bar without stiffening"
$py - "$work/rot/probes.csv" "$work/rot_linear/probes.csv" <<'PY' && ok || fail "centrifugal stress"
import csv, sys
def means(path):
    rows = [r for r in csv.DictReader(open(path)) if float(r["time"]) >= 0.06]
    out = []
    for x, name in ((0.25, "s25"), (0.5, "s50"), (0.75, "s75")):
        ref = 7850 * 100 ** 2 * (1 - x * x) / 2
        out.append(sum(float(r[name + ".stress.xx"]) for r in rows) / len(rows) / ref)
    return out
with_cases, without = means(sys.argv[1]), means(sys.argv[2])
print("rotating bar: mean axial stress / closed form at L/4, L/2, 3L/4:", with_cases, "without the inertia cases:", without)
assert all(abs(r - 1) < 0.01 for r in with_cases), with_cases
assert abs(without[0] - 1) > 0.1 and abs(without[2] - 1) > 0.1, without
PY

# A sagging wire (the stress of a body with modal derivatives keeps the strain's
# quadratic part): a 1 m steel beam of 2 mm diameter clamped at both ends, in ONE body with
# modal derivatives of all pairs, under 10 g (sag about 20 diameters: a membrane). Reference:
# axial equilibrium of the von Karman beam, N' = 0 - the normal force (the mean of the top and
# bottom fibre stresses times A) is the same at every station, though its parts u' and the
# quadratic (v'^2 + w'^2) / 2 vary along the wire. Measured uniform to 1e-4; asserted 1e-3.
cat > "$work/wire.yaml" <<'EOF'
name: wire
type: beam
units: SI
material: {E: 2.0e11, nu: 0.3, rho: 7850}
section: {shape: circle, diameter: 0.002}
beam:
  theory: euler_bernoulli
  points: {A: [0, 0, 0], B: [1, 0, 0]}
  segments: [{from: A, to: B, elements: 8}]
interfaces: [{name: A}, {name: B}]
reduction: {internal_modes: 4, modal_derivatives: {of: all, tolerance: 1e-9}}
EOF
cat > "$work/wire_scene.yaml" <<'EOF'
name: sagging_wire
units: SI
bodies:
  - {name: w, superelement: wire.h5, nodes: {A: a, B: b}}
joints:
  - {type: clamp, node: a}
  - {type: clamp, node: b}
loads:
  - {type: gravity, g: [0, 0, -98.1]}
analysis: {type: static, end_time: 1, steps: 10}
outputs:
  animation: false
  probes:
    - {name: t12, body: w, point: [0.125, 0, 0.001], quantities: [stress]}
    - {name: b12, body: w, point: [0.125, 0, -0.001], quantities: [stress]}
    - {name: t25, body: w, point: [0.25, 0, 0.001], quantities: [stress]}
    - {name: b25, body: w, point: [0.25, 0, -0.001], quantities: [stress]}
    - {name: t50, body: w, point: [0.5, 0, 0.001], quantities: [stress]}
    - {name: b50, body: w, point: [0.5, 0, -0.001], quantities: [stress]}
    - {name: t75, body: w, point: [0.75, 0, 0.001], quantities: [stress]}
    - {name: b75, body: w, point: [0.75, 0, -0.001], quantities: [stress]}
EOF
"$bin/femb-reduce" "$work/wire.yaml" -o "$work/wire.h5" > "$work/wire_reduce.txt" && \
  grep -q "element forms of the von Karman axial strain" "$work/wire_reduce.txt" && \
  "$bin/femb-solve" -q "$work/wire_scene.yaml" -o "$work/wire" && ok || fail "sagging wire: $(cat "$work/wire_reduce.txt")"
$py - "$work/wire/probes.csv" <<'PY' && ok || fail "sagging wire normal force"
import csv, math, sys
row = list(csv.DictReader(open(sys.argv[1])))[-1]
A = math.pi * 0.001 ** 2
N = [(float(row[f"t{x}.stress.xx"]) + float(row[f"b{x}.stress.xx"])) / 2 * A for x in ("12", "25", "50", "75")]
print("sagging wire: normal force along the wire [N]:", N)
assert N[0] > 1 and max(N) - min(N) < 1e-3 * N[0], N
PY

# Bad input: one line, exit 2.
expect() {  # label, expected message, sed on the scene, [part file override]
  sed "$3" "$work/scene.yaml" > "$work/bad.yaml"
  "$bin/femb-solve" -q "$work/bad.yaml" -o "$work/bad_out" 2> "$work/err.txt" > /dev/null
  local code=$?
  [ $code = 2 ] && grep -qF "$2" "$work/err.txt" && [ "$(wc -l < "$work/err.txt")" = 1 ] && ok \
    || fail "$1: exit $code: $(cat "$work/err.txt")"
}
expect "unknown body" "probe 'top': no body 'nobar' in the scene" 's/body: bar, point/body: nobar, point/'
expect "stress on a node" "probe quantity 'stress' needs body and point" 's/quantities: \[position\]/quantities: [stress]/'
expect "node quantity on a body" "probe quantity 'rotation' is a node quantity" 's/quantities: \[stress\]/quantities: [rotation]/'
"$bin/femb-reduce" -q "$work/bar.yaml" -o "$work/bar_plain.h5" --set reduction.stresses=false || fail "reduce without stresses"
expect "file without stresses" "body 'bar' has no modal stresses in bar_plain.h5" 's/bar.h5/bar_plain.h5/'

echo "stress cli: $passed passed, $failed failed"
[ $failed = 0 ]
