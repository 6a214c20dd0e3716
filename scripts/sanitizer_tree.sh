#!/usr/bin/env bash
# Configures build-asan/, the tree of the sanitizer and fuzzing stages (scripts/sanitize.sh,
# scripts/fuzz.sh; sourced by both): clang with AddressSanitizer and UndefinedBehaviorSanitizer at
# -O1, the fuzz targets with libFuzzer's coverage on the parsers (CMakeLists.txt, FEMB_FUZZ), and
# the library compiled once for both stages. Clang, not gcc: 40% less compile time on the
# Eigen-heavy sources (superelement_body.cpp 28 -> 17 s) and 27% on a test (exact_inertia_test.cpp
# 29 -> 21 s), measured under these flags. Without -march=native (the release build's): 6% less,
# and the instrumented code is about memory and UB, not speed. Installs clang if it is missing.
missing=()
for p in clang libclang-rt-14-dev; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  sudo_cmd=""; [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  $sudo_cmd apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -q --no-install-recommends "${missing[@]}"
fi
CC=clang CXX=clang++ cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Sanitize -DCMAKE_CXX_FLAGS_SANITIZE="-O1 -g1" \
  -DCMAKE_C_FLAGS_SANITIZE="-O1 -g1" -DFEMB_SANITIZE=ON -DFEMB_FUZZ=ON -DFEMB_NATIVE=OFF >/dev/null
