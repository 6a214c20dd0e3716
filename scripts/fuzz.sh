#!/usr/bin/env bash
# Third CI stage: libFuzzer targets (tests/fuzz) built with clang, AddressSanitizer and
# UndefinedBehaviorSanitizer in build-asan/ (scripts/sanitizer_tree.sh: the sanitizer stage's tree,
# whose library objects they share), each run from a seed corpus made of the examples'
# files for a fixed number of inputs with a fixed random seed (about 30 s each here), so that a
# run is reproducible: the same commit explores the same inputs on every machine, and a failure
# in CI is one that `bash scripts/fuzz.sh` shows locally. FEMB_FUZZ_SCALE multiplies the input
# counts (a longer exploratory run: FEMB_FUZZ_SCALE=20 FEMB_FUZZ_SEED=$RANDOM); FEMB_FUZZ_SECONDS
# (default 120) caps each target's time on a slow machine. A crash, a hang (10 s per input) or an exception that
# is not an InputError stops the run; the input is kept in build-asan/artifacts/ and becomes a
# regression test. Needs build/bin/femb-reduce (scripts/build.sh) for the seed superelement.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${FEMB_FUZZ_SECONDS:-120}
scale=${FEMB_FUZZ_SCALE:-1}
fuzz_seed=${FEMB_FUZZ_SEED:-1}
declare -A runs=([yaml_fuzz]=15000 [part_fuzz]=75000 [scene_fuzz]=30000 [superelement_fuzz]=2000 [matrix_fuzz]=20000)
targets=(yaml_fuzz part_fuzz scene_fuzz superelement_fuzz matrix_fuzz)
source scripts/sanitizer_tree.sh
cmake --build build-asan -j "$(nproc)" --target femb_fuzz_targets -- --no-print-directory -s 2>&1 | grep -v "^\[" || true
for t in "${targets[@]}"; do test -x "build-asan/fuzz/$t" || { echo "fuzz: $t did not build"; exit 1; }; done

work=$(pwd)/build-asan/work
rm -rf "$work" && mkdir -p "$work" build-asan/artifacts
build/bin/femb-reduce -q examples/pendulum/rod.yaml -o "$work/seg.h5"
for t in "${targets[@]}"; do mkdir -p "$work/corpus_$t"; done
i=0
for f in $(git ls-files 'examples/*.yaml'); do
  i=$((i + 1))
  cp "$f" "$work/corpus_yaml_fuzz/$i.yaml"
  if grep -q '^type: \(beam\|solid\)' "$f"; then cp "$f" "$work/corpus_part_fuzz/$i.yaml"; fi
  if grep -q '^bodies:' "$f"; then
    # Scenes name the seed superelement, whose interfaces are A and B.
    sed 's/superelement: [^,}]*/superelement: seg.h5/' "$f" > "$work/corpus_scene_fuzz/$i.yaml"
  fi
done
printf '\x00\x01\x02\x03' > "$work/corpus_superelement_fuzz/seed"
# matrix_fuzz: a reader byte, then its files cut by 0x01 (tests/fuzz/matrix_fuzz.cpp), from the
# seed part's matrices exported in every format, and a small shapes file.
for f in calculix abaqus abaqus_coordinate matrix_market; do
  build/bin/femb-reduce -q examples/pendulum/rod.yaml --export-matrices "$work/export_$f" --matrix-format $f
done
m=$work/corpus_matrix_fuzz
e=$work/export_calculix
{ printf '\x00'; cat "$e"/*.sti; printf '\x01'; cat "$e"/*.mas; printf '\x01'; cat "$e"/*.dof; } > "$m/calculix"
e=$work/export_abaqus
{ printf '\x01'; cat "$e"/*_STIF1.mtx; printf '\x01'; cat "$e"/*_MASS1.mtx; } > "$m/abaqus"
e=$work/export_abaqus_coordinate
{ printf '\x04'; cat "$e"/*.inp; printf '\x01'; cat "$e"/*_STIF1.mtx; printf '\x01'; cat "$e"/*_MASS1.mtx; } > "$m/abaqus_coordinate"
e=$work/export_matrix_market
{ printf '\x02'; cat "$e"/*_K.mtx; printf '\x01'; cat "$e"/*_M.mtx; printf '\x01'; cat "$e"/*_dofs.csv; } > "$m/matrix_market"
{ printf '\x03%%%%MatrixMarket matrix array real general\n3 2\n1\n2\n3\n4\n5\n6\n\x01ab'; } > "$m/shapes"
printf '\x05DMIG    KAAX           0       6       2       0\nDMIG    KAAX           1       1               1       14.+6\n+              2       1-1.+6\nDMIG*   MAAX                           0               6\n*       2               0\nDMIG,MAAX,1,1,,1,1,4.,\n+,2,1,-1.\n' > "$m/nastran"
{ printf '\x06title                                                                   KEY\n             5             1             1             1             0\nRSA                        2             2             3             0\n(10I8)          (10I8)          (3E26.16)\n'
  printf '       1       3       4\n       1       2       2\n'; printf '%26s%26s%26s\n' 4.0E+06 -1.0E+06 4.0E+06
  printf '\x01%%%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n1 1 1.0\n2 2 1.0\n\x01 Matrix Eqn   Node   DOF\n 1 1 UX\n 2 1 UY\n'; } > "$m/ansys"
# Every input that once failed stays in the corpus (tests/fuzz/regressions/TARGET/).
for t in "${targets[@]}"; do
  if [ -d "tests/fuzz/regressions/$t" ]; then cp "tests/fuzz/regressions/$t"/* "$work/corpus_$t/"; fi
done

export FEMB_FUZZ_DIR=$work FEMB_FUZZ_SEED_H5=$work/seg.h5 OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
export ASAN_OPTIONS=detect_leaks=0 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
status=0
for t in "${targets[@]}"; do
  start=$(date +%s)
  if build-asan/fuzz/$t "$work/corpus_$t" -seed="$fuzz_seed" -runs=$((runs[$t] * scale)) \
       -max_total_time="$seconds" -timeout=10 -rss_limit_mb=4096 \
       -artifact_prefix="build-asan/artifacts/$t-" -print_final_stats=1 > "build-asan/$t.log" 2>&1; then
    echo "fuzz: $t: $(grep -m1 'stat::number_of_executed_units' "build-asan/$t.log" | awk '{print $2}') inputs" \
         "(seed $fuzz_seed) in $(($(date +%s) - start)) s, no failure"
  else
    echo "fuzz: $t FAILED (input in build-asan/artifacts/):"; tail -40 "build-asan/$t.log"; status=1
  fi
done
exit $status
