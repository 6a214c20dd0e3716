# Sourced by the *_vs_base.sh benchmarks: builds commit $base of femb in a git worktree at
# $base_dir (once; kept for the next run) with the given make targets, and this tree's build if
# it has none. Needs $here (this tree), $base and $base_dir.
build_trees() {  # make targets of the base tree
  if [ ! -x "$base_dir/build/bin/femb-solve" ]; then
    echo "building $base in $base_dir (once; about 10 minutes)"
    [ -d "$base_dir" ] || git -C "$here" worktree add -f "$base_dir" "$base" > /dev/null
    mkdir -p "$base_dir/build"
    (cd "$base_dir/build" && cmake .. -DCMAKE_BUILD_TYPE=Release > /dev/null && make -j"$(nproc)" "$@" > /dev/null)
  fi
  [ -x "$here/build/bin/femb-solve" ] || bash "$here/scripts/build.sh" > /dev/null
}
