#!/usr/bin/env bash
# The README's main job: install, build, and run vdbhair on the bundled default hairstyle.
# Results land in ./vdbhair-demo (or the folder given as the first argument).
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-vdbhair-demo}"
./scripts/build.sh
./build/bin/vdbhair demo scenes/default/head.json -o "$out"
