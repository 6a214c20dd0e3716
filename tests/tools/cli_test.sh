#!/usr/bin/env bash
# Command-line behaviour of femb-reduce and femb-inspect: outputs, exit codes, one-line errors,
# and no output file on bad input. Usage: cli_test.sh BIN_DIR SOURCE_DIR
set -u
bin=$1
src=$2
source "$(dirname "$0")/test_lib.sh"

# The output's folder is made when missing; a folder that cannot be made is one line, exit 2, and
# refused before the work (no stage line).
"$bin/femb-reduce" -q "$src/examples/beam_rod/part.yaml" -o "$work/new/nested/rod.h5" && [ -s "$work/new/nested/rod.h5" ] \
  && ok || fail "reduce into a missing folder"
touch "$work/plain_file"
"$bin/femb-reduce" "$src/examples/beam_rod/part.yaml" -o "$work/plain_file/rod.h5" > "$work/out.txt" 2> "$work/err.txt"
code=$?
[ $code = 2 ] && [ "$(wc -l < "$work/err.txt")" = 1 ] && grep -q "cannot create the folder" "$work/err.txt" \
  && ! grep -q "factorize" "$work/out.txt" && ok || fail "unwritable folder: exit $code, $(cat "$work/err.txt")"

# --help on every program.
for p in femb-reduce femb-inspect; do
  "$bin/$p" --help | grep -q "usage: $p" && ok || fail "$p --help"
done

# Examples reduce with one command and pass the checks.
for ex in beam_rod tube_cantilever; do
  if "$bin/femb-reduce" "$src/examples/$ex/part.yaml" -o "$work/$ex.h5" --full-modes 10 > "$work/$ex.log"; then ok; else fail "reduce $ex"; fi
  grep -q "factorize K_ii" "$work/$ex.log" && ok || fail "$ex: no progress line with timing"
  "$bin/femb-inspect" "$work/$ex.h5" --check > "$work/$ex.txt" && ok || fail "inspect --check $ex"
  grep -q "rel. error" "$work/$ex.txt" && ok || fail "$ex: summary has no full vs reduced table"
  "$bin/femb-inspect" "$work/$ex.h5" --json > "$work/$ex.json" || fail "inspect --json $ex"
  $py - "$work/$ex.json" <<'PY' && ok || fail "$ex: JSON keys"
import json, sys
j = json.load(open(sys.argv[1]))
keys = ["format_version", "name", "units", "n_interface_nodes", "interface_names", "n_internal_modes",
        "n_modal_derivatives", "n_reduced_dofs", "n_full_dofs", "mass", "center_of_mass", "inertia_com",
        "floating_frame", "internal_frequencies_hz", "free_free_frequencies_hz",
        "full_free_free_frequencies_hz", "checks"]
missing = [k for k in keys if k not in j]
assert not missing, missing
for c in ["K_symmetric", "M_symmetric", "M_positive_definite", "rigid_body_modes"]:
    assert j["checks"][c]["ok"], c
assert len(j["inertia_com"]) == 3 and len(j["inertia_com"][0]) == 3
assert len(j["free_free_frequencies_hz"]) == j["n_reduced_dofs"] == 16
ff = j["free_free_frequencies_hz"]; assert ff == sorted(ff)
full = j["full_free_free_frequencies_hz"]; assert len(full) == 16
# reduced frequencies are Rayleigh-Ritz upper bounds of the full ones
for r, f in zip(ff[6:10], full[6:10]):
    assert r >= f * (1 - 1e-9) and r < 1.01 * f, (r, f)
# Geometric stiffening is on by default for femb's own Craig-Bampton parts.
assert j["geometric_stiffening"] is True
PY
  grep -q "stiffening .* 12 inertia load case geometric stiffnesses" "$work/$ex.log" && ok || fail "$ex: no stiffening progress line"
done

# --dump: K as CSV is 16 x 16; PhiCB as Matrix Market 6 x 16.
rows=$("$bin/femb-inspect" "$work/beam_rod.h5" --dump K --format csv | wc -l)
[ "$rows" = 16 ] && ok || fail "--dump K csv rows $rows"
"$bin/femb-inspect" "$work/beam_rod.h5" --dump PhiCB | sed -n 3p | grep -qx "6 16" && ok || fail "--dump PhiCB mtx"
# --vtu: beam mode shapes as VTU line meshes with displacement, rotation and the modal stress
# (von Mises, tensor); without a stored
# mesh it is a clear error.
"$bin/femb-inspect" "$work/beam_rod.h5" --vtu "$work/vtu" > /dev/null && [ "$(ls "$work/vtu" | wc -l)" = 16 ] && ok || fail "--vtu beam"
# A cut inside a pair of equal modes (a round section's two bending planes at 728.342 Hz) is said
# once, also with -q, and the file is written; the whole pair kept, nothing is said.
for m in 1 2; do
  printf 'name: round\ntype: beam\nmaterial: {E: 7.0e10, nu: 0.33, rho: 2700}\nsection: {shape: circle, diameter: 0.02}\nbeam:\n  points: {A: [0, 0, 0], B: [0.35, 0, 0]}\n  segments: [{from: A, to: B, elements: 10}]\ninterfaces: [{name: A}, {name: B}]\nreduction: {internal_modes: %s}\n' "$m" > "$work/round_$m.yaml"
  "$bin/femb-reduce" -q "$work/round_$m.yaml" -o "$work/round_$m.h5" > "$work/round_$m.txt" 2>&1 || fail "round beam, $m modes"
done
[ "$(grep -c "^femb-reduce: warning: .*round_1.yaml: reduction.internal_modes = 1 keeps mode 1 at 728.342 Hz but not mode 2 at the same frequency" "$work/round_1.txt")" = 1 ] \
  && [ -s "$work/round_1.h5" ] && [ ! -s "$work/round_2.txt" ] && ok || fail "split pair of equal modes: $(cat "$work/round_1.txt" "$work/round_2.txt")"
$py -c "
import meshio; m = meshio.read('$work/vtu/beam_rod_013.vtu')
assert m.cells[0].type == 'line' and set(m.point_data) == {'displacement', 'rotation', 'von_mises', 'stress'}" && ok || fail "vtu beam content"
# --export-mbdyn: MBDyn's modal element file, the interfaces as FEM nodes (the mesh nodes too
# with --mbdyn-mesh); an unwritable path is one line, exit 2, and no file (tests/inspect/
# mbdyn_export_test.cpp checks the content).
"$bin/femb-inspect" "$work/beam_rod.h5" --export-mbdyn "$work/rod.fem" > "$work/mbdyn.txt" \
  && grep -q "wrote $work/rod.fem: 10 modes at 2 FEM nodes (interfaces: \"A\" \"B\")" "$work/mbdyn.txt" \
  && grep -qx "REV0 2 10 0 0 0" "$work/rod.fem" && ok || fail "--export-mbdyn: $(cat "$work/mbdyn.txt")"
"$bin/femb-inspect" "$work/beam_rod.h5" --export-mbdyn "$work/rod_mesh.fem" --mbdyn-mesh > /dev/null \
  && [ "$(sed -n '/RECORD GROUP 1,/{n;n;p}' "$work/rod_mesh.fem" | cut -d' ' -f2)" -gt 2 ] && ok || fail "--export-mbdyn --mbdyn-mesh"
"$bin/femb-inspect" "$work/beam_rod.h5" --export-mbdyn "$work/no/such/dir/rod.fem" 2> "$work/err.txt"
[ $? = 2 ] && [ "$(wc -l < "$work/err.txt")" = 1 ] && grep -q "cannot write the MBDyn file" "$work/err.txt" && ok || fail "--export-mbdyn unwritable: $(cat "$work/err.txt")"
"$bin/femb-reduce" -q "$src/examples/beam_rod/part.yaml" -o "$work/nomesh.h5" --set reduction.keep_mesh=false
"$bin/femb-inspect" "$work/nomesh.h5" --vtu "$work/vtu2" 2> "$work/err.txt"; [ $? = 2 ] && grep -q "no mesh and mode shapes stored" "$work/err.txt" && ok || fail "--vtu without mesh"
# A foreign mesh through the meshio bridge: an Abaqus .inp hex block with node sets.
mkdir -p "$work/inp"
$py - "$work/inp/block.inp" <<'PY'
import sys, meshio, numpy as np
nx, ny, nz = 10, 2, 2
xs, ys, zs = np.linspace(0, 1, nx + 1), np.linspace(0, 0.1, ny + 1), np.linspace(0, 0.1, nz + 1)
idx = lambda i, j, k: (i * (ny + 1) + j) * (nz + 1) + k
pts = np.array([[x, y, z] for x in xs for y in ys for z in zs])
cells = [[idx(i, j, k), idx(i + 1, j, k), idx(i + 1, j + 1, k), idx(i, j + 1, k), idx(i, j, k + 1), idx(i + 1, j, k + 1),
          idx(i + 1, j + 1, k + 1), idx(i, j + 1, k + 1)] for i in range(nx) for j in range(ny) for k in range(nz)]
sets = {"LEFT": np.where(pts[:, 0] == 0)[0], "RIGHT": np.where(pts[:, 0] == 1)[0]}
meshio.write(sys.argv[1], meshio.Mesh(pts, [("hexahedron", np.array(cells))], point_sets=sets))
PY
cat > "$work/inp/part.yaml" <<'YAML'
name: block
type: solid
material: {E: 2.1e11, nu: 0.3, rho: 7850}
geometry: {file: block.inp}
interfaces:
  - {name: root, group: LEFT}
  - {name: tip, group: RIGHT, coupling: rbe3}
reduction: {internal_modes: 4, floating_frame: mean_axes}
YAML
"$bin/femb-reduce" -q "$work/inp/part.yaml" -o "$work/inp/block.h5" && "$bin/femb-inspect" "$work/inp/block.h5" --check --json > "$work/inp/j.json" \
  && $py -c "import json; j = json.load(open('$work/inp/j.json')); assert abs(j['mass'] - 78.5) < 1e-9 and j['n_full_dofs'] == 276" \
  && ok || fail "meshio .inp import"
# A file name with a quote and a space (the bridge once ran through a shell), and femb-reduce
# copied away from the build tree: it finds the bridge beside itself.
cp "$work/inp/block.inp" "$work/inp/it's a block.inp"
mkdir -p "$work/inst" && cp "$bin/femb-reduce" "$bin/meshio_bridge.py" "$work/inst/"
sed "s/block.inp/\"it's a block.inp\"/" "$work/inp/part.yaml" > "$work/inp/quoted.yaml"
"$work/inst/femb-reduce" -q "$work/inp/quoted.yaml" -o "$work/inp/quoted.h5" 2> "$work/err.txt" \
  && "$bin/femb-inspect" "$work/inp/quoted.h5" --check > /dev/null && ok || fail "quoted mesh name / installed bridge: $(cat "$work/err.txt")"
FEMB_MESHIO_BRIDGE=/nonexistent/bridge.py "$bin/femb-reduce" -q "$work/inp/part.yaml" -o "$work/inp/nob.h5" 2> "$work/err.txt"; code=$?
[ $code = 2 ] && grep -q "needs the meshio bridge, not found at /nonexistent/bridge.py" "$work/err.txt" && ok || fail "missing bridge: $code $(cat "$work/err.txt")"
echo "not a mesh" > "$work/inp/junk.vtu"
sed 's/block.inp/junk.vtu/' "$work/inp/part.yaml" > "$work/inp/junk.yaml"
"$bin/femb-reduce" -q "$work/inp/junk.yaml" -o "$work/inp/junk.h5" 2> "$work/err.txt"; code=$?
[ $code = 2 ] && grep -q "junk.vtu: cannot read with meshio" "$work/err.txt" && [ ! -e "$work/inp/junk.h5" ] && ok || fail "bad foreign mesh: $code $(cat "$work/err.txt")"

# Solid parts, bad input: each gives exit code 2, one line naming the file and what is wrong,
# and no output file.
mkdir -p "$work/solid"
solid_error() {  # name, expected text, part file
  local out="$work/solid/$1.h5"
  "$bin/femb-reduce" -q "$3" -o "$out" 2> "$work/solid/err.txt"; local code=$?
  if [ $code = 2 ] && [ "$(wc -l < "$work/solid/err.txt")" = 1 ] && grep -qF "$2" "$work/solid/err.txt" && [ ! -e "$out" ]; then
    ok
  else
    fail "solid $1: exit $code, $(cat "$work/solid/err.txt")"
  fi
}
solid_part() {  # file name, geometry line, interfaces line, [extra lines]
  printf 'name: s\ntype: solid\nunits: SI\nmaterial: {E: 2.1e11, nu: 0.3, rho: 7850}\n%s\nmesh: {size: 0.02, order: 2}\ninterfaces: %s\n%s' \
    "$2" "$3" "${4:-}" > "$work/solid/$1"
  echo "$work/solid/$1"
}
echo "this is not a STEP file" > "$work/solid/broken.step"
solid_error "unreadable CAD" "broken.step: gmsh failed" \
  "$(solid_part cad.yaml 'geometry: {file: broken.step}' '[{name: A, group: a}]')"
cat > "$work/solid/flat.geo" <<'GEO'
SetFactory("OpenCASCADE");
Rectangle(1) = {0, 0, 0, 0.1, 0.1};
Physical Surface("face") = {1};
GEO
solid_error "no volume elements" "the mesh has no volume elements" \
  "$(solid_part flat.yaml 'geometry: {file: flat.geo}' '[{name: A, group: face}]')"
cat > "$work/solid/two.geo" <<'GEO'
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 0.1, 0.02, 0.02};
Box(2) = {0.2, 0, 0, 0.1, 0.02, 0.02};
Physical Surface("end") = {1};
Physical Surface("empty") = {};
Physical Volume("all") = {1, 2};
GEO
solid_error "missing physical group" "interface 'A': node set 'hole' not found in the mesh (known: end; or pick the nodes by geometry with 'select')" \
  "$(solid_part group.yaml 'geometry: {file: two.geo}' '[{name: A, group: hole}]')"
solid_error "region held by no interface" "is connected to no interface" \
  "$(solid_part island.yaml 'geometry: {file: two.geo}' '[{name: A, group: end}]')"
# A rigid coupling on the nodes of one edge (or one corner): the part could turn about them, which
# K_ii does not resist (a factorization may or may not notice: a pivot at round-off).
cat > "$work/solid/one.geo" <<'GEO'
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 0.1, 0.02, 0.02};
Physical Volume("all") = {1};
GEO
solid_error "rigid coupling on one line" "interface 'A': an RBE2 coupling needs at least 3 nodes not on one line (it ties 5 nodes on one line: the rotation about it would be free)" \
  "$(solid_part edge.yaml 'geometry: {file: one.geo}' '[{name: A, select: {box: {min: [-0.001, -0.001, -0.001], max: [0.001, 0.021, 0.001]}}}]')"
solid_error "rigid coupling on one node" "interface 'B': an RBE2 coupling needs at least 3 nodes not on one line (it ties 1 node: the rotations about it would be free)" \
  "$(solid_part corner.yaml 'geometry: {file: one.geo}' '[{name: A, select: {plane: {point: [0, 0, 0], normal: [1, 0, 0]}}}, {name: B, select: {sphere: {center: [0.1, 0.02, 0.02], radius: 1.0e-6}}}]')"
solid_error "mixed units" "it looks like mm-t-s or mm-kg-ms (mixed units?)" \
  "$(solid_part mm.yaml 'geometry: {shape: box, size: [1000, 50, 50]}' '[{name: A, group: xmin}]')"
printf '*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 0, 0, 1\n*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n*NSET, NSET=A\n1, 2, 3\n' > "$work/solid/tet.inp"
printf '#!/bin/sh\nexec /usr/bin/python3 -S "$@"\n' > "$work/solid/python-without-meshio"
chmod +x "$work/solid/python-without-meshio"
FEMB_PYTHON="$work/solid/python-without-meshio" solid_error "meshio not installed" "meshio is not installed: apt-get install python3-meshio" \
  "$(solid_part inp.yaml 'geometry: {file: tet.inp}' '[{name: A, group: A}]')"
# CAD input: the crank from a STEP file (meshes/crank.step through the .geo wrapper that names
# the bores) has the mass of the crank meshed from its .geo (same geometry, within 0.5%).
for g in crank.geo crank_from_step.geo; do
  printf 'name: crank\ntype: solid\nmaterial: {E: 2.1e11, nu: 0.3, rho: 7850}\ngeometry: {file: %s}\nmesh: {size: 0.008, order: 2}\ninterfaces: [{name: a, group: big_bore, coupling: rbe3}, {name: b, group: small_bore}]\nreduction: {internal_modes: 2}\n' \
    "$src/meshes/$g" > "$work/solid/$g.yaml"
  "$bin/femb-reduce" -q "$work/solid/$g.yaml" -o "$work/solid/$g.h5" || fail "reduce $g"
done
"$bin/femb-inspect" "$work/solid/crank.geo.h5" --json > "$work/solid/a.json" && "$bin/femb-inspect" "$work/solid/crank_from_step.geo.h5" --json > "$work/solid/b.json" \
  && $py -c "
import json; a = json.load(open('$work/solid/a.json')); b = json.load(open('$work/solid/b.json'))
assert abs(a['mass'] - b['mass']) < 5e-3 * a['mass'] and abs(a['mass'] - 0.6969) < 5e-3, (a['mass'], b['mass'])" \
  && ok || fail "STEP crank mass"
# Memory guard: a factor larger than the limit is refused before the numeric factorization.
"$bin/femb-reduce" -q "$src/examples/solid_bar/part.yaml" -o "$work/solid/big.h5" --set reduction.memory_limit_gb=0.001 \
  2> "$work/solid/err.txt"; code=$?
[ $code = 4 ] && grep -q "the Cholesky factor would need" "$work/solid/err.txt" && grep -q "coarsen the mesh" "$work/solid/err.txt" \
  && [ ! -e "$work/solid/big.h5" ] && ok || fail "memory guard: exit $code, $(cat "$work/solid/err.txt")"
# Element-count guard: mesh.size 1e-5 on a 0.1 m bar is refused before gmsh meshes (it once ran
# with no output and no end in sight).
timeout 60 "$bin/femb-reduce" -q "$src/examples/solid_bar/part.yaml" -o "$work/solid/huge.h5" --set mesh.size=1e-5 \
  2> "$work/solid/err.txt"; code=$?
[ $code = 4 ] && [ "$(wc -l < "$work/solid/err.txt")" = 1 ] && grep -q "more than mesh.max_elements = 3000000" "$work/solid/err.txt" \
  && [ ! -e "$work/solid/huge.h5" ] && ok || fail "element guard: exit $code, $(cat "$work/solid/err.txt")"

# --set works under the documented names.
"$bin/femb-reduce" -q "$src/examples/beam_rod/part.yaml" -o "$work/m8.h5" --set reduction.internal_modes=8 \
  --set reduction.floating_frame=mean_axes || fail "--set"
"$bin/femb-inspect" "$work/m8.h5" --json | $py -c "
import json,sys; j=json.load(sys.stdin); assert j['n_internal_modes']==8 and j['floating_frame']['type']=='mean_axes'" \
  && ok || fail "--set values not in file"
# The file is readable by h5py (an independent HDF5 reader) with the documented layout.
$py - "$work/beam_rod.h5" <<'PY' && ok || fail "h5py layout"
import sys, h5py
f = h5py.File(sys.argv[1], "r")
assert f.attrs["format"] in (b"femb-superelement", "femb-superelement")
assert f["reduced/K"].shape == (16, 16) and f["floating_frame/Phi_CB"].shape == (6, 16)
assert abs(f["mass_properties/mass"][()] - 7870 * 3.141592653589793 * 0.003**2 * 0.3) < 1e-12
PY

# Bad input: exit code 2, one line on stderr naming the file, no output file.
good="$src/examples/beam_rod/part.yaml"
expect_input_error() {  # name, expected text, femb-reduce arguments...
  local name=$1 text=$2
  shift 2
  rm -f "$work/bad.h5"
  "$bin/femb-reduce" -q "$@" -o "$work/bad.h5" 2> "$work/err.txt" > /dev/null
  local code=$?
  [ $code = 2 ] || { fail "$name: exit code $code, want 2"; return; }
  [ "$(wc -l < "$work/err.txt")" = 1 ] || { fail "$name: stderr not one line: $(cat "$work/err.txt")"; return; }
  grep -qF -- "$text" "$work/err.txt" || { fail "$name: stderr '$(cat "$work/err.txt")' lacks '$text'"; return; }
  [ ! -e "$work/bad.h5" ] || { fail "$name: output file written"; return; }
  ls "$work" | grep -q "bad.h5.tmp" && { fail "$name: temporary left behind"; return; }
  ok
}
variant() { sed "$1" "$good" > "$work/$2.yaml"; echo "$work/$2.yaml"; }
expect_input_error "missing file" "nope.yaml: cannot open part file" "$work/nope.yaml"
expect_input_error "yaml syntax" "YAML syntax error" "$(variant 's/B: \[0.3, 0.0, 0.0\]/B: [0.3, 0.0, 0.0/' syntax)"
expect_input_error "unknown key" "unknown key 'internal_mode'" "$(variant 's/^  internal_modes: 4/  internal_mode: 4/' unknown)"
expect_input_error "E <= 0" "e0.yaml:7: material.E: must be positive" "$(variant 's/E: 2.0e11/E: 0/' e0)"
expect_input_error "rho <= 0" "material.rho: must be positive" "$(variant 's/rho: 7870/rho: -1/' rho)"
expect_input_error "nu range" "Poisson's ratio must be in (-1, 0.5), got 0.7" "$(variant 's/nu: 0.3/nu: 0.7/' nu)"
expect_input_error "zero length" "zero-length element" "$(variant 's/B: \[0.3, 0.0, 0.0\]/B: [0.0, 0.0, 0.0]/' zero)"
expect_input_error "interface not found" "interface point 'Q' not found" "$(variant 's/{name: B}/{name: B, point: Q}/' iface)"
expect_input_error "no interface" "no interface defined" "$(variant '/^interfaces:/,/name: B}/d' none)"
expect_input_error "region held by no interface" "a mesh region of 3 nodes around (0.15, 1, 0) is connected to no interface" "$(variant 's/    B: \[0.3, 0.0, 0.0\]/    B: [0.3, 0.0, 0.0]\n    C: [0.0, 1.0, 0.0]\n    D: [0.3, 1.0, 0.0]/; s/    - {from: A, to: B, elements: 10}/    - {from: A, to: B, elements: 10}\n    - {from: C, to: D, elements: 2}/' island)"
expect_input_error "too many modes" "exceeds the 54 interior DOFs" "$good" --set reduction.internal_modes=500
expect_input_error "bad --set" "--set reduction.floating_frame: unknown floating frame 'centroid'" "$good" --set reduction.floating_frame=centroid

# Imported matrices: a native part exported with --export-matrices and read back as a
# part of type 'imported' gives the same frequencies; the file inspects and draws like any other.
"$bin/femb-reduce" -q "$src/examples/beam_rod/part.yaml" --export-matrices "$work/rod_mm" --matrix-format matrix_market \
  && [ -f "$work/rod_mm/beam_rod_K.mtx" ] && [ -f "$work/rod_mm/beam_rod.inp" ] && ok || fail "export matrices"
cat > "$work/rod_mm/imported.yaml" <<'YAML'
name: beam_rod
type: imported
geometry: {file: beam_rod.inp}
matrices: {format: matrix_market, stiffness: beam_rod_K.mtx, mass: beam_rod_M.mtx, dofs: beam_rod_dofs.csv}
interfaces: [{name: A, group: A}, {name: B, select: {plane: {point: [0.3, 0, 0], normal: [1, 0, 0]}}}]
reduction: {internal_modes: 4, floating_frame: mean_axes}
YAML
"$bin/femb-reduce" "$work/rod_mm/imported.yaml" -o "$work/rod_imported.h5" > "$work/imported.log" && ok || fail "reduce imported"
grep -q "B: 1 nodes by plane" "$work/imported.log" && grep -q "rigid-body residual" "$work/imported.log" && ok \
  || fail "imported progress lines: $(cat "$work/imported.log")"
"$bin/femb-inspect" "$work/rod_imported.h5" --check > /dev/null && ok || fail "inspect --check imported"
# Abaqus' coordinate form with its deck of parts and instances: read back to the same file as
# Matrix Market; an equation the deck does not number, an unknown instance and a DOF map one row
# short are one line each, exit 2, no output.
"$bin/femb-reduce" -q "$src/examples/beam_rod/part.yaml" --export-matrices "$work/rod_abq" --matrix-format abaqus_coordinate \
  && sed -e 's/matrix_market/abaqus/; s/beam_rod_K.mtx/beam_rod_STIF1.mtx/; s/beam_rod_M.mtx/beam_rod_MASS1.mtx/; s/, dofs: beam_rod_dofs.csv//' \
       "$work/rod_mm/imported.yaml" > "$work/rod_abq/imported.yaml" \
  && "$bin/femb-reduce" -q "$work/rod_abq/imported.yaml" -o "$work/rod_abq.h5" \
  && "$bin/femb-inspect" "$work/rod_abq.h5" --dump K | tail -n +3 > "$work/k_abq.txt" \
  && "$bin/femb-inspect" "$work/rod_imported.h5" --dump K | tail -n +3 > "$work/k_mm.txt" \
  && cmp -s "$work/k_abq.txt" "$work/k_mm.txt" && ok || fail "abaqus coordinate form vs matrix market"
cp "$work/rod_abq/beam_rod_STIF1.mtx" "$work/rod_abq/good_STIF1.mtx"
echo "67 67  1.0" >> "$work/rod_abq/beam_rod_STIF1.mtx"
expect_input_error "coordinate equations" "beam_rod_STIF1.mtx:$(wc -l < "$work/rod_abq/beam_rod_STIF1.mtx"): equation 67 is outside 1..66" "$work/rod_abq/imported.yaml"
cp "$work/rod_abq/good_STIF1.mtx" "$work/rod_abq/beam_rod_STIF1.mtx"
expect_input_error "unknown instance" "has no instance 'rod-2' (it has beam_rod-1)" "$work/rod_abq/imported.yaml" --set matrices.instance=rod-2
head -n -1 "$work/rod_mm/beam_rod_dofs.csv" > "$work/rod_mm/short_dofs.csv"
expect_input_error "DOF map one row short" "beam_rod_K.mtx:3: the matrix has 66 rows but" "$work/rod_mm/imported.yaml" --set matrices.dofs=short_dofs.csv
# Imported matrices have no element stresses: no geometric stiffening by default, and asking
# for it is one line with exit 2.
"$bin/femb-inspect" "$work/rod_imported.h5" --json | $py -c "import json,sys; assert json.load(sys.stdin)['geometric_stiffening'] is False" \
  && ok || fail "imported part has geometric stiffening"
"$bin/femb-reduce" "$work/rod_mm/imported.yaml" -o "$work/rod_imported_gs.h5" --set reduction.geometric_stiffening=true 2> "$work/err.txt"; code=$?
[ $code = 2 ] && grep -q "geometric stiffening of imported matrices needs the part's material" "$work/err.txt" && [ ! -e "$work/rod_imported_gs.h5" ] && ok \
  || fail "imported with stiffening: exit $code $(cat "$work/err.txt")"
# With a material the stiffening comes from femb's solid elements on the imported mesh: a beam
# mesh has none (one line, exit 2).
"$bin/femb-reduce" "$work/rod_mm/imported.yaml" -o "$work/rod_imported_gs.h5" --set reduction.geometric_stiffening=true \
  --set "material={E: 2.1e11, nu: 0.3, rho: 7850}" 2> "$work/err.txt"; code=$?
[ $code = 2 ] && grep -q "reduction.geometric_stiffening: the imported part cannot have it: its mesh has line2 cells" "$work/err.txt" \
  && [ "$(wc -l < "$work/err.txt")" = 1 ] && [ ! -e "$work/rod_imported_gs.h5" ] && ok \
  || fail "imported beam with a material and stiffening: exit $code $(cat "$work/err.txt")"
"$bin/femb-inspect" "$work/rod_imported.h5" --vtu "$work/rod_vtu" > /dev/null && [ -f "$work/rod_vtu/beam_rod_006.vtu" ] && ok \
  || fail "inspect --vtu imported"
$py - "$work/beam_rod.h5" "$work/rod_imported.h5" <<'PY' && ok || fail "imported frequencies differ from native"
import sys, h5py, numpy as np
a = h5py.File(sys.argv[1])["reduced/internal_frequencies_hz"][()]
b = h5py.File(sys.argv[2])["reduced/internal_frequencies_hz"][()]
assert np.abs(b / a - 1).max() < 1e-8, (a, b)
PY
# Thesis 8.2 case 4: the native rod on four of its free-free bending modes, computed
# here from the exported matrices (rows: the beam's nodes, 6 DOFs each), which cannot stretch or
# twist it. femb-reduce names the two constrained directions, femb-inspect shows and checks them,
# and femb-solve holds them: pulled by 20 kN and twisted by 2 N m, the rod's tip does not move
# (a Craig-Bampton rod would stretch by P L / E A = 1.1 mm).
$py - "$work/rod_mm" <<'PY' && ok || fail "bending shapes"
import sys, numpy as np, scipy.io, scipy.linalg
d = sys.argv[1]
K = scipy.io.mmread(d + "/beam_rod_K.mtx").toarray(); M = scipy.io.mmread(d + "/beam_rod_M.mtx").toarray()
w, V = scipy.linalg.eigh(K + M, M)
scipy.io.mmwrite(d + "/bending.mtx", V[:, 6:10])
PY
cp "$src/examples/beam_rod/part.yaml" "$work/rod_mm/bending.yaml"
"$bin/femb-reduce" "$work/rod_mm/bending.yaml" -o "$work/rod_bending.h5" --set reduction.method=general \
  --set reduction.basis.file=bending.mtx --set reduction.floating_frame=mean_axes > "$work/bending.log" \
  && grep -q "interface rank 10 of 12 (thesis 8.2), 12 reduced DOFs; constrained inside the body (thesis 8.2 case 4): " "$work/bending.log" \
  && grep -q "[AB].u_x & [AB].u_x" "$work/bending.log" && grep -q "[AB].theta_x & [AB].theta_x" "$work/bending.log" \
  && ok || fail "reduce on bending shapes: $(cat "$work/bending.log")"
"$bin/femb-inspect" "$work/rod_bending.h5" --check > "$work/bending.txt" \
  && grep -q "interface constraint (basis moves 10 of 12 interface directions" "$work/bending.txt" && ok \
  || fail "inspect the constrained rod: $(cat "$work/bending.txt")"
# The same shapes as HDF5 (/shapes, written by h5py) give the same file; a wrong row count is
# one line, exit 2, no output.
$py - "$work/rod_mm" <<'PY' && ok || fail "bending shapes as HDF5"
import sys, h5py, scipy.io
d = sys.argv[1]
V = scipy.io.mmread(d + "/bending.mtx")
with h5py.File(d + "/bending.h5", "w") as f: f["shapes"] = V
with h5py.File(d + "/short.h5", "w") as f: f["shapes"] = V[:-1]
PY
"$bin/femb-reduce" -q "$work/rod_mm/bending.yaml" -o "$work/rod_bending_h5.h5" --set reduction.method=general \
  --set reduction.basis.file=bending.h5 --set reduction.floating_frame=mean_axes && $py - "$work/rod_bending.h5" "$work/rod_bending_h5.h5" <<'PY' && ok || fail "HDF5 shapes differ"
import sys, h5py, numpy as np
a, b = (h5py.File(p)["reduced"] for p in sys.argv[1:])
for k in ["K", "M", "interface_constraint"]:
    assert np.abs(a[k][()] - b[k][()]).max() <= 1e-12 * np.abs(a[k][()]).max(), k
PY
"$bin/femb-reduce" -q "$work/rod_mm/bending.yaml" -o "$work/short.h5" --set reduction.method=general \
  --set reduction.basis.file=short.h5 2> "$work/err.txt"
[ $? = 2 ] && [ "$(wc -l < "$work/err.txt")" = 1 ] && grep -q "short.h5: /shapes is (65 x 4), expected (66 x shapes)" "$work/err.txt" \
  && [ ! -e "$work/short.h5" ] && ok || fail "HDF5 shapes with a wrong row count: $(cat "$work/err.txt")"
cat > "$work/rod_mm/pull.yaml" <<'YAML'
name: pull
units: SI
bodies:
  - {name: rod, superelement: ../rod_bending.h5, nodes: {A: n0, B: n1}}
joints:
  - {type: clamp, node: n0}
loads:
  - {type: force, node: n1, force: [20000, 0, 0], moment: [2, 0, 0]}
analysis: {type: static, steps: 1}
outputs:
  probes:
    - {name: tip, node: n1, quantities: [position, rotation]}
YAML
"$bin/femb-solve" -q "$work/rod_mm/pull.yaml" -o "$work/pull_out" && $py - "$work/pull_out/probes.csv" <<'PY' && ok || fail "constrained rod pulled"
import csv, sys
last = list(csv.DictReader(open(sys.argv[1])))[-1]
assert abs(float(last["tip.position.x"]) - 0.3) < 1e-12, last
assert abs(float(last["tip.rotation.x"])) < 1e-12, last
PY
# A surface mesh for the pictures (S3 triangles on the boundary of an exported TET4 box): the
# imported model draws triangles (VTK type 5); center_of_mass has nothing to interpolate in.
cat > "$work/box.yaml" <<'YAML'
name: box
type: solid
material: {E: 2.1e11, nu: 0.3, rho: 7850}
geometry: {shape: box, size: [0.2, 0.02, 0.02]}
mesh: {size: 0.01, order: 1}
interfaces: [{name: a, group: xmin}, {name: b, group: xmax}]
reduction: {internal_modes: 4, floating_frame: mean_axes}
YAML
"$bin/femb-reduce" -q "$work/box.yaml" -o "$work/box_native.h5" && "$bin/femb-reduce" -q "$work/box.yaml" --export-matrices "$work/boxm" \
  && ok || fail "box export"
$py - "$work/boxm/box.inp" "$work/boxm/surface.inp" <<'PY' && ok || fail "surface mesh"
import collections, sys, meshio
m = meshio.read(sys.argv[1])
tets = [c.data for c in m.cells if c.type == "tetra"][0]
count = collections.Counter()
faces = {}
for t in tets:
    for f in ((0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)):
        tri = tuple(t[list(f)])
        count[tuple(sorted(tri))] += 1
        faces[tuple(sorted(tri))] = tri
with open(sys.argv[2], "w") as out:
    out.write("*NODE\n")
    for i, p in enumerate(m.points):
        out.write("%d, %.13g, %.13g, %.13g\n" % (i + 1, p[0], p[1], p[2]))
    out.write("*ELEMENT, TYPE=S3, ELSET=SKIN\n")
    k = 0
    for key, n in count.items():
        if n == 1:
            k += 1
            a, b, c = faces[key]
            out.write("%d, %d, %d, %d\n" % (k, a + 1, b + 1, c + 1))
PY
cat > "$work/boxm/surface.yaml" <<'YAML'
name: box
type: imported
geometry: {file: surface.inp}
matrices: {format: calculix, stiffness: box.sti, mass: box.mas, dofs: box.dof}
interfaces:
  - {name: a, select: {plane: {point: [0, 0, 0], normal: [1, 0, 0]}}}
  - {name: b, select: {plane: {point: [0.2, 0, 0], normal: [1, 0, 0]}}}
reduction: {internal_modes: 4, floating_frame: mean_axes}
YAML
"$bin/femb-reduce" -q "$work/boxm/surface.yaml" -o "$work/box_surface.h5" && ok || fail "reduce with a surface mesh"
"$bin/femb-inspect" "$work/box_surface.h5" --vtu "$work/box_vtu" > /dev/null && ok || fail "inspect --vtu surface"
$py - "$work/box_native.h5" "$work/box_surface.h5" "$work/box_vtu/box_000.vtu" <<'PY' && ok || fail "surface model frequencies or cells"
import sys, h5py, meshio, numpy as np
a = h5py.File(sys.argv[1])["reduced/internal_frequencies_hz"][()]
b = h5py.File(sys.argv[2])["reduced/internal_frequencies_hz"][()]
assert np.abs(b / a - 1).max() < 1e-8, (a, b)
assert h5py.File(sys.argv[2])["visualization"].attrs["cell_type"] in (b"tri3", "tri3")
m = meshio.read(sys.argv[3])
assert [c.type for c in m.cells] == ["triangle"], m.cells
PY
expect_input_error "center of mass on a surface mesh" "has no volume cells to interpolate in" "$work/boxm/surface.yaml" \
  --set reduction.floating_frame=center_of_mass
expect_input_error "matrix format" "--matrix-format: unknown format 'hdf'" "$good" --export-matrices "$work/x" --matrix-format hdf
expect_input_error "read-only matrix format" "--matrix-format: nastran is read, not written" "$good" --export-matrices "$work/x" --matrix-format nastran
sed 's/^1,1$/77777,1/' "$work/rod_mm/beam_rod_dofs.csv" > "$work/rod_mm/bad_dofs.csv"
sed 's/beam_rod_dofs.csv/bad_dofs.csv/' "$work/rod_mm/imported.yaml" > "$work/rod_mm/bad.yaml"
expect_input_error "node not in mesh" "node 77777 of the matrices is not in" "$work/rod_mm/bad.yaml"
sed 's/point: \[0.3, 0, 0\]/point: [300, 0, 0]/' "$work/rod_mm/imported.yaml" > "$work/rod_mm/far.yaml"
expect_input_error "selection takes no node" "interface 'B': the plane through (300, 0, 0) normal to (1, 0, 0) selects no node" "$work/rod_mm/far.yaml"

# femb-inspect on bad files: exit 2, one line.
"$bin/femb-inspect" "$work/none.h5" 2> "$work/err.txt"; [ $? = 2 ] && grep -q "cannot open file" "$work/err.txt" && ok || fail "inspect missing"
head -c 2000 "$work/beam_rod.h5" > "$work/trunc.h5"
"$bin/femb-inspect" "$work/trunc.h5" 2> "$work/err.txt"; [ $? = 2 ] && [ "$(wc -l < "$work/err.txt")" = 1 ] && ok || fail "inspect truncated: $(cat "$work/err.txt")"

echo "cli: $passed passed, $failed failed"
[ $failed = 0 ]
