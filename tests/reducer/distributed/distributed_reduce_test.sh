#!/usr/bin/env bash
# femb-reduce on MPI ranks (reduction.solver: petsc: MUMPS' distributed Cholesky and SLEPc's
# Krylov-Schur) against the CHOLMOD path on the same part: the solid crank (TET10, 16 293 DOFs,
# 12 fixed-interface modes) with an RBE3 and an RBE2 bore, with two RBE2 bores, with two RBE3
# bores, and with the modal derivatives of 4 modes; np 1 and np 2 files equal to CHOLMOD's (on 2
# ranks K and M shared by columns, the full model's free-free check gathering them), a beam
# part on 2 and 3 ranks and the crank's matrices imported on 2
# (frequencies 1e-9, reduced K and M 1e-8 relative, compare_superelements.py) and femb-inspect's
# checks passing; rank 0 meshing the part, METIS cutting it, each rank assembling about half the
# elements. Then the faults: one rank's geometry unreadable, rank 0's mesh without volume
# elements, ranks given different parts, a hinge inside the part (K_ii singular where the
# connectivity check cannot see it), a rank killed during the run,
# the factor over the per-rank memory limit, a distributed reduction of a basis that is not
# distributed, a part with a free motion: one line (or mpirun's own report of the killed rank), a
# non-zero exit in bounded time, no file.
# Usage: distributed_reduce_test.sh BIN_DIR SOURCE_DIR
set -u
bin=$1
src=$(cd "$2" && pwd)
source "$src/tests/tools/test_lib.sh"
mpi="timeout 120 mpirun --allow-run-as-root --oversubscribe"
compare="$py $src/tests/reducer/distributed/compare_superelements.py"

crank() {  # crank NAME BIG_COUPLING SMALL_COUPLING [MODES [EXTRA REDUCTION KEYS]]
  cat > "$work/$1.yaml" <<EOT
name: $1
type: solid
units: SI
material: {E: 2.1e11, nu: 0.3, rho: 7850}
geometry: {file: $src/meshes/crank.geo}
mesh: {size: 0.006, order: 2}
interfaces:
  - {name: big_bore, group: big_bore, coupling: $2}
  - {name: small_bore, group: small_bore, coupling: $3}
reduction: {internal_modes: ${4:-12}, full_modes: 0${5:-}}
EOT
}

crank mixed rbe3 rbe2
crank pins rbe2 rbe2
crank seats rbe3 rbe3
crank derivatives rbe3 rbe2 4 ", modal_derivatives: {of: internal}"
for part in mixed pins seats derivatives; do
  "$bin/femb-reduce" "$work/$part.yaml" -q -o "$work/${part}_cholmod.h5" && ok || fail "$part: serial reduction"
  if [ "$part" = mixed ]; then
    $mpi -np 1 "$bin/femb-reduce" "$work/$part.yaml" -q -o "$work/${part}_np1.h5" --set reduction.solver=petsc &&
      ok || fail "$part: np 1"
    $compare "$work/${part}_cholmod.h5" "$work/${part}_np1.h5" && ok || fail "$part: np 1 differs"
  fi
  $mpi -np 2 "$bin/femb-reduce" "$work/$part.yaml" -q -o "$work/${part}_np2.h5" > "$work/$part.log" 2>&1 &&
    ok || fail "$part: np 2: $(cat "$work/$part.log")"
  $compare "$work/${part}_cholmod.h5" "$work/${part}_np2.h5" && ok || fail "$part: np 2 differs"
  "$bin/femb-inspect" "$work/${part}_np2.h5" --check > "$work/$part.check" && ok ||
    fail "$part: femb-inspect --check: $(cat "$work/$part.check")"
done
# The ranks share K and M by columns: rank 0 meshes the part and METIS cuts it in 2, each rank
# holds its part's columns and assembles the elements touching them (about half: the 2 882
# elements' cut is a few hundred); the full model's free-free check gathers them: its flexible
# frequencies equal the one-process run's.
$mpi -np 2 "$bin/femb-reduce" "$work/mixed.yaml" -o "$work/mixed_full_np2.h5" --set reduction.full_modes=6 \
  > "$work/mixed_full.log" 2>&1 && ok || fail "full modes on 2 ranks: $(cat "$work/mixed_full.log")"
grep -q "mesh .*rank 0 made it and METIS cut it in 2 parts" "$work/mixed_full.log" && ok ||
  fail "np 2: the mesh line does not say how it was cut: $(grep mesh "$work/mixed_full.log")"
assembly=$(grep -o "assembly .* [0-9]* of [0-9]* elements, [0-9]* stiffness entries in the [0-9]* of [0-9]* columns rank 0 holds" "$work/mixed_full.log" |
  sed -E 's/.* ([0-9]+) of ([0-9]+) elements, [0-9]+ stiffness entries in the ([0-9]+) of ([0-9]+) columns.*/\1 \2 \3 \4/')
read -r cells all_cells columns all_columns <<< "${assembly:-0 1 0 1}"
[ $((100 * cells / all_cells)) -le 60 ] && [ $((100 * columns / all_columns)) -ge 40 ] &&
  [ $((100 * columns / all_columns)) -le 60 ] && ok ||
  fail "np 2: rank 0 holds $columns of $all_columns columns from $cells of $all_cells elements (expected 40-60% of the columns from at most 60% of the elements)"
"$bin/femb-reduce" "$work/mixed.yaml" -q -o "$work/mixed_full.h5" --set reduction.full_modes=6 && ok ||
  fail "full modes on one process"
$compare "$work/mixed_full.h5" "$work/mixed_full_np2.h5" | grep -q "full model's flexible free-free frequencies" &&
  $compare "$work/mixed_full.h5" "$work/mixed_full_np2.h5" > /dev/null && ok || fail "full modes on 2 ranks differ"
# A beam part (assembled whole, each rank keeping its share of the columns; the interior small
# enough for the dense eigen solve, which gathers them) on 2 and 3 ranks.
"$bin/femb-reduce" "$src/examples/beam_rod/part.yaml" -q -o "$work/beam_cholmod.h5" && ok || fail "beam: serial"
for np in 2 3; do
  $mpi -np $np "$bin/femb-reduce" "$src/examples/beam_rod/part.yaml" -q -o "$work/beam_np$np.h5" && ok ||
    fail "beam: np $np"
  $compare "$work/beam_cholmod.h5" "$work/beam_np$np.h5" > /dev/null && ok || fail "beam: np $np differs"
done
# Imported matrices (the crank's, exported by femb-reduce in CalculiX's files, with the geometric
# stiffening of femb's elements on the imported mesh): read whole on every rank, each keeping an
# even share of the columns.
"$bin/femb-reduce" "$work/mixed.yaml" -q --export-matrices "$work/exported" && ok || fail "export the crank's matrices"
cat > "$work/imported.yaml" <<EOT
name: imported
type: imported
units: SI
geometry: {file: $work/exported/mixed.inp}
matrices: {format: calculix, stiffness: $work/exported/mixed.sti, mass: $work/exported/mixed.mas, dofs: $work/exported/mixed.dof}
interfaces:
  - {name: big_bore, group: big_bore, coupling: rbe3}
  - {name: small_bore, group: small_bore, coupling: rbe2}
material: {E: 2.1e11, nu: 0.3, rho: 7850}
reduction: {internal_modes: 12, full_modes: 0}
EOT
"$bin/femb-reduce" "$work/imported.yaml" -q -o "$work/imported_cholmod.h5" && ok || fail "imported: serial"
$mpi -np 2 "$bin/femb-reduce" "$work/imported.yaml" -q -o "$work/imported_np2.h5" && ok || fail "imported: np 2"
$compare "$work/imported_cholmod.h5" "$work/imported_np2.h5" > /dev/null && ok || fail "imported: np 2 differs"
# Without mpirun, reduction.solver: petsc runs on one rank.
"$bin/femb-reduce" "$work/mixed.yaml" -q -o "$work/mixed_one.h5" --set reduction.solver=petsc && ok ||
  fail "petsc without mpirun"
$compare "$work/mixed_cholmod.h5" "$work/mixed_one.h5" > /dev/null && ok || fail "petsc without mpirun differs"

# expect_failure NAME CODE TEXT COMMAND...: exit CODE, exactly one femb-reduce line holding TEXT, no file.
expect_failure() {
  local name=$1 code=$2 text=$3
  shift 3
  rm -f "$work/failed.h5"
  "$@" > "$work/out.txt" 2>&1
  local got=$?
  [ "$got" = "$code" ] && ok || fail "$name: exit $got, expected $code: $(cat "$work/out.txt")"
  [ "$(grep -c '^femb-reduce:' "$work/out.txt")" = 1 ] && grep -q -- "$text" "$work/out.txt" && ok ||
    fail "$name: expected one line with '$text': $(cat "$work/out.txt")"
  [ ! -e "$work/failed.h5" ] && ok || fail "$name: a file was written"
}
sed "s#$src/meshes/crank.geo#$work/nothing.geo#" "$work/mixed.yaml" > "$work/unreadable.yaml"
expect_failure "one rank's geometry missing" 2 "nothing.geo' not found" \
  $mpi -np 1 "$bin/femb-reduce" "$work/mixed.yaml" -q -o "$work/failed.h5" : \
  -np 1 "$bin/femb-reduce" "$work/unreadable.yaml" -q -o "$work/failed.h5"
expect_failure "every rank's geometry missing" 2 "nothing.geo' not found" \
  $mpi -np 2 "$bin/femb-reduce" "$work/unreadable.yaml" -q -o "$work/failed.h5"
# Rank 0 alone meshes: its failure reaches the rank waiting for the mesh.
cat > "$work/flat.geo" <<EOT
SetFactory("OpenCASCADE");
Rectangle(1) = {0, 0, 0, 0.1, 0.02};
Physical Surface("end") = {1};
EOT
sed "s#$src/meshes/crank.geo#$work/flat.geo#" "$work/mixed.yaml" > "$work/flat.yaml"
expect_failure "rank 0's mesh without volume elements" 2 "the mesh has no volume elements" \
  $mpi -np 2 "$bin/femb-reduce" "$work/flat.yaml" -q -o "$work/failed.h5"
sed "s#E: 2.1e11#E: 2.0e11#" "$work/mixed.yaml" > "$work/other.yaml"
expect_failure "ranks given different parts" 2 "the MPI ranks were given different parts" \
  $mpi -np 1 "$bin/femb-reduce" "$work/mixed.yaml" -q -o "$work/failed.h5" : \
  -np 1 "$bin/femb-reduce" "$work/other.yaml" -q -o "$work/failed.h5"
expect_failure "factor over the per-rank limit" 4 "MUMPS' factorization of K_ii needs" \
  $mpi -np 2 "$bin/femb-reduce" "$work/mixed.yaml" -q -o "$work/failed.h5" --set reduction.memory_limit_gb=0.02
expect_failure "petsc with a free-interface basis" 2 "reduction.solver: petsc reduces by craig_bampton only" \
  $mpi -np 2 "$bin/femb-reduce" "$work/mixed.yaml" -q -o "$work/failed.h5" --set reduction.method=free_interface

# A part with a free motion: a second block that no interface holds (K_ii singular), named on
# every rank as on one process.
cat > "$work/loose.geo" <<EOT
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 0.1, 0.02, 0.02};
Box(2) = {0.2, 0, 0, 0.05, 0.02, 0.02};
e = 1e-4;
end() = Surface In BoundingBox{-e, -e, -e, e, 0.02 + e, 0.02 + e};
Physical Surface("end") = end();
Physical Volume("blocks") = {1, 2};
EOT
cat > "$work/loose.yaml" <<EOT
name: loose
type: solid
units: SI
material: {E: 2.1e11, nu: 0.3, rho: 7850}
geometry: {file: $work/loose.geo}
mesh: {size: 0.01, order: 2}
interfaces:
  - {name: end, group: end, coupling: rbe2}
reduction: {internal_modes: 4, full_modes: 0}
EOT
expect_failure "a free motion, one process" 2 "is connected to no interface" \
  "$bin/femb-reduce" "$work/loose.yaml" -q -o "$work/failed.h5"
expect_failure "a free motion, 2 ranks" 2 "is connected to no interface" \
  $mpi -np 2 "$bin/femb-reduce" "$work/loose.yaml" -q -o "$work/failed.h5"
# The first block held by a rigid coupling on one of its edges only: free to turn about it (MUMPS
# factors such a K_ii without a word, a pivot at round-off), refused before the factorization.
sed -e '/^Box(2)/d' -e 's/{1, 2}/{1}/' "$work/loose.geo" > "$work/edge.geo"
sed -e "s#$work/loose.geo#$work/edge.geo#" \
  -e 's#{name: end, group: end, coupling: rbe2}#{name: end, coupling: rbe2, select: {box: {min: [-0.001, -0.001, -0.001], max: [0.001, 0.021, 0.001]}}}#' \
  "$work/loose.yaml" > "$work/edge.yaml"
expect_failure "a rigid coupling on one edge, 2 ranks" 2 "an RBE2 coupling needs at least 3 nodes not on one line" \
  $mpi -np 2 "$bin/femb-reduce" "$work/edge.yaml" -q -o "$work/failed.h5"

# A hidden mechanism: two blocks joined along one edge only, a hinge (the connectivity check sees one
# region; K_ii is singular, the turn about the edge free). CHOLMOD stops at its pivot; MUMPS
# factors it without a word (Cholesky, SYM=1, has no null-pivot detection: ICNTL(24) found none
# here even at a threshold of 1e-3), and the reduced model's check finds the seventh zero
# eigenvalue: exit 3 either way, no file.
cat > "$work/hinge.geo" <<EOT
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 0.1, 0.02, 0.02};
Box(2) = {0.1, 0.02, 0, 0.1, 0.02, 0.02};
BooleanFragments{ Volume{1}; Delete; }{ Volume{2}; Delete; }
e = 1e-4;
end() = Surface In BoundingBox{-e, -e, -e, e, 0.02 + e, 0.02 + e};
Physical Surface("end") = end();
Physical Volume("blocks") = {1, 2};
EOT
sed "s#$work/loose.geo#$work/hinge.geo#" "$work/loose.yaml" > "$work/hinge.yaml"
expect_failure "a hinge, one process" 3 "K_ii (stiffness with all interfaces clamped) is singular" \
  "$bin/femb-reduce" "$work/hinge.yaml" -q -o "$work/failed.h5"
expect_failure "a hinge, 2 ranks" 3 "7 eigenvalues with |lambda| <= 1e-8 max|lambda| (need 6)" \
  $mpi -np 2 "$bin/femb-reduce" "$work/hinge.yaml" -q -o "$work/failed.h5"

# A rank killed once the reduction runs: mpirun ends the others, non-zero, no file.
rm -f "$work/failed.h5"
$mpi -np 2 "$bin/femb-reduce" "$work/mixed.yaml" -o "$work/failed.h5" > "$work/killed.txt" 2>&1 &
job=$!
for _ in $(seq 1 500); do grep -q "assembly" "$work/killed.txt" 2>/dev/null && break; sleep 0.02; done
for p in $(pgrep -f "femb-reduce $work/mixed.yaml"); do
  tr '\0' '\n' < "/proc/$p/environ" 2>/dev/null | grep -q "^OMPI_COMM_WORLD_RANK=1$" && kill -9 "$p"
done
start=$(date +%s)
wait $job
code=$?
[ "$code" != 0 ] && [ $(($(date +%s) - start)) -lt 60 ] && ok || fail "killed rank: exit $code after $(($(date +%s) - start)) s"
[ ! -e "$work/failed.h5" ] && ok || fail "killed rank: a file was written"

echo "distributed reduction: $passed passed, $failed failed"
[ "$failed" = 0 ]
