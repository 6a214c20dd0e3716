#!/usr/bin/env bash
# Configures and builds femb in build/ (Release). Binaries land in build/bin/.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j "$(nproc)" -- --no-print-directory -s
echo "build: binaries in $(pwd)/build/bin"
