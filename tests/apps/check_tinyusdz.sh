#!/usr/bin/env bash
# Installs tinyusdz from the npm registry into SCRATCH (once) and reads FILE.usda with it:
#   check_tinyusdz.sh SCRATCH FILE.usda STRANDS VERTICES [WANT...]
#   check_tinyusdz.sh SCRATCH FILE.usda world VDBHAIR.obj   (check_tinyusdz_world.mjs)
# Each WANT (mpu=1, up=Z, widths=constant, color=constant, width=0.5) is checked against what
# tinyusdz parsed.
# Skips (prints SKIPPED: and exits 0) when node or npm is missing or the registry is unreachable.
set -u
scratch=$1; file=$2; strands=$3; vertices=$4; shift 4
here=$(cd "$(dirname "$0")" && pwd)
command -v node >/dev/null 2>&1 || { echo "SKIPPED: node is not installed (apt-get install nodejs npm)"; exit 0; }
command -v npm >/dev/null 2>&1 || { echo "SKIPPED: npm is not installed (apt-get install npm)"; exit 0; }
pkg="$scratch/node_modules/tinyusdz"
if [ ! -f "$pkg/tinyusdz.wasm" ]; then
  mkdir -p "$scratch"
  # A package of its own, so npm installs here whatever folder ctest runs in.
  [ -f "$scratch/package.json" ] || echo '{"name": "vdbhair-tinyusdz-check", "private": true}' > "$scratch/package.json"
  if ! (cd "$scratch" && timeout 180 npm install --no-audit --no-fund tinyusdz > npm.log 2>&1); then
    echo "SKIPPED: could not install tinyusdz from the npm registry (offline?): $(tail -n 2 "$scratch/npm.log" | tr '\n' ' ')"
    exit 0
  fi
fi
[ "$strands" = world ] && exec node "$here/check_tinyusdz_world.mjs" "$pkg" "$file" "$vertices"
exec node "$here/check_tinyusdz.mjs" "$pkg" "$file" "$strands" "$vertices" "$@"
