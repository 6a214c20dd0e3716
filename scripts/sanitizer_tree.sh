#!/usr/bin/env bash
# Configures build-san/, the sanitizer tree that scripts/sanitize.sh (unit tests) and
# scripts/fuzz.sh (libFuzzer targets) share: clang, AddressSanitizer + UndefinedBehaviorSanitizer,
# the fuzzers' coverage instrumentation, -O1 -g1 with assertions. Installs clang and its runtime
# (Debian packages) when they are missing. Safe to run twice.
set -euo pipefail
cd "$(dirname "$0")/.."
missing=()
for p in clang libclang-rt-14-dev; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  sudo_cmd=""; [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  $sudo_cmd apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -q --no-install-recommends "${missing[@]}"
fi
CC=clang CXX=clang++ cmake -S . -B build-san -DCMAKE_BUILD_TYPE=Sanitize -DCMAKE_CXX_FLAGS_SANITIZE="-O1 -g1" \
  -DCMAKE_C_FLAGS_SANITIZE="-O1 -g1" -DFEMB_FUZZ=ON >/dev/null
