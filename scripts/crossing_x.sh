#!/bin/sh
# Two wisps of 49 strands crossing at 60 degrees (the unit test "two wisps crossing in an X stay an
# X"), refined in both modes and rendered: docs/refine/x_{input,consistent,field}.png.
# Usage: scripts/crossing_x.sh [build/bin/vdbhair] [outdir]
set -e
VDBHAIR=${1:-build/bin/vdbhair}
OUT=${2:-docs/refine}
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
python3 - "$TMP/x.obj" <<'PY'
import math, sys
a = math.radians(30.0)
lines, verts = [], []
for w in (0, 1):
    d = (math.cos(a), math.sin(a) if w == 0 else -math.sin(a), 0.0)
    side = (-d[1], d[0], 0.0)
    for j in range(7):
        for k in range(7):
            root = [-5.0 * d[i] + 0.15 * (j - 3) * side[i] for i in range(3)]
            root[2] += 0.15 * (k - 3)
            first = len(verts) + 1
            for v in range(41):
                t = 10.0 * v / 40.0
                verts.append([root[i] + t * d[i] for i in range(3)])
            lines += ["l %d %d" % (first + v, first + v + 1) for v in range(40)]
with open(sys.argv[1], "w") as f:
    f.write("".join("v %.6f %.6f %.6f\n" % tuple(p) for p in verts))
    f.write("\n".join(lines) + "\n")
PY
for mode in consistent field; do
    "$VDBHAIR" refine "$TMP/x.obj" -o "$TMP/x_$mode.hair" --voxel-size 0.4 --levels 2 --head none --mode $mode --quiet
done
mkdir -p "$OUT"
for name in input consistent field; do
    src="$TMP/x_$name.hair"; [ "$name" = input ] && src="$TMP/x.obj"
    "$VDBHAIR" render "$src" -o "$OUT/x_$name.png" --view front --color-by root --width 320 --height 320 --title "$name" --quiet
done
