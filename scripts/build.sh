#!/usr/bin/env bash
# Configure and build vdbhair in ./build (Release, at most two compile jobs).
set -euo pipefail
cd "$(dirname "$0")/.."
"$(pwd)/scripts/setup.sh"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
cmake --build build -j 2
