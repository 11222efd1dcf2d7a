#!/usr/bin/env bash
# The README's test command: install, build, and run every test (unit and command-line).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/build.sh
cd build
ctest --output-on-failure -j 2 "$@"
