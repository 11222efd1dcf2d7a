#!/bin/sh
# Cross-check vdbhair's Alembic writer and reader against the reference Alembic tools.
#
#   scripts/alembic_oracle.sh ALEMBIC_BIN [VDBHAIR] [INPUT]
#
# ALEMBIC_BIN: a folder with the reference library's abcls, abcecho and abctree (an Alembic you
# installed yourself: it is a test oracle only, never part of vdbhair's build; docs/development.md).
# VDBHAIR: the vdbhair program (default build/bin/vdbhair). INPUT: a strand file (default the test
# fixture good.hair, made by the tests).
#
# Checks, on INPUT converted to .abc by vdbhair:
#   abctree   the hierarchy is ABC -> hair
#   abcecho   /hair is an AbcGeom_Curve_v2 whose .geom has .selfBnds, P, nVertices,
#             curveBasisAndType and width, with P's and nVertices' sizes equal to vdbhair's counts
#   abcls -l -v  every point the reference library reads equals vdbhair's (to the 6 significant digits
#             abcls prints), every curve count too, and the basis is kLinear
#   .arbGeomParams (when INPUT has colours and thicknesses): Cd and groom_width per vertex, and
#             every colour abcls reads equals vdbhair's
# and that vdbhair reads its own .abc back to the same .hair bytes.
set -eu
ABC=${1:?usage: $0 ALEMBIC_BIN [VDBHAIR] [INPUT]}
VDBHAIR=${2:-build/bin/vdbhair}
INPUT=${3:-build/tests/apps/fixtures/good.hair}
for t in abcls abcecho abctree; do
    [ -x "$ABC/$t" ] || { echo "alembic_oracle: $ABC/$t is not there; pass the folder of the reference Alembic tools" >&2; exit 2; }
done
[ -f "$INPUT" ] || { echo "alembic_oracle: $INPUT is not there (build and run the CLI tests, or pass a strand file)" >&2; exit 2; }
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT

"$VDBHAIR" convert "$INPUT" "$OUT/a.hair" --quiet
"$VDBHAIR" convert "$OUT/a.hair" "$OUT/a.abc" --quiet
"$VDBHAIR" convert "$OUT/a.abc" "$OUT/b.hair" --quiet
cmp "$OUT/a.hair" "$OUT/b.hair" && echo "ok: vdbhair reads its .abc back to the same .hair bytes"
"$VDBHAIR" convert "$OUT/a.hair" "$OUT/a.obj" --obj-lines polylines --quiet
strands=$("$VDBHAIR" info "$OUT/a.abc" | awk '$1 == "strands:" {print $2}')
vertices=$("$VDBHAIR" info "$OUT/a.abc" | awk '$1 == "vertices:" {print $2}')

"$ABC/abctree" "$OUT/a.abc" | grep -q -- '`--hair' && echo "ok: abctree shows ABC -> hair"
"$ABC/abcecho" "$OUT/a.abc" > "$OUT/echo.txt"
grep -q "CompoundProperty name=.geom;schema=AbcGeom_Curve_v2" "$OUT/echo.txt"
grep -q "ScalarProperty name=.selfBnds;interpretation=box;datatype=float64_t\[6\]" "$OUT/echo.txt"
grep -q "ArrayProperty name=P;interpretation=point;datatype=float32_t\[3\];arraysize=$vertices;numsamps=1" "$OUT/echo.txt"
grep -q "ArrayProperty name=nVertices;interpretation=;datatype=int32_t;arraysize=$strands;numsamps=1" "$OUT/echo.txt"
grep -q "ScalarProperty name=curveBasisAndType;interpretation=;datatype=uint8_t\[4\]" "$OUT/echo.txt"
grep -q "ArrayProperty name=width;interpretation=;datatype=float32_t" "$OUT/echo.txt"
echo "ok: abcecho shows /hair as AbcGeom_Curve_v2 with $vertices points in $strands curves"

# Values: abcls -l -v prints sample 0 of every property of /hair/.geom.
"$ABC/abcls" -l -v "$OUT/a.abc/hair/.geom" | sed 's/\x1b\[[0-9;]*m//g' > "$OUT/values.txt"
python3 - "$OUT/values.txt" "$OUT/a.obj" <<'EOF'
import sys
lines = open(sys.argv[1]).read().split('\n')
def block(name):
    for i, l in enumerate(lines):
        if l.split() and l.split()[-1] == name + '[1]':
            out = []
            for v in lines[i + 1:]:
                if not v.strip() or 'Property' in v:
                    break
                out.append([float(x) for x in v.split(',')])
            return out
    sys.exit('alembic_oracle: abcls printed no %s' % name)
P = block('P')
n = [int(v[0]) for v in block('nVertices')]
basis = block('curveBasisAndType')[0]
obj_v, obj_n = [], []
for l in open(sys.argv[2]):
    if l.startswith('v '):
        obj_v.append([float(x) for x in l.split()[1:4]])
    elif l.startswith('l '):
        obj_n.append(len(l.split()) - 1)
assert len(P) == len(obj_v), (len(P), len(obj_v))
assert n == obj_n, 'curve counts differ'
worst = max(abs(a - b) / max(abs(b), 1e-30) if abs(a - b) > 1e-6 * max(abs(b), 1.0) else 0.0
            for p, q in zip(P, obj_v) for a, b in zip(p, q))
assert worst < 1e-5, 'a point differs by %g (relative)' % worst
assert basis[0] == 1 and basis[1] == 0, 'not linear, non-periodic: %s' % basis
print('ok: abcls -v reads all %d points and %d curve counts as vdbhair wrote them (worst relative '
      'difference %.2g, within abcls\'s 6 printed digits)' % (len(P), len(n), worst))
EOF

# Colours and Unreal's groom attributes (.arbGeomParams), when INPUT has colours and thicknesses:
# the reference library lists them with one value per vertex, and reads Cd as vdbhair wrote it.
if grep -q "ArrayProperty name=Cd;" "$OUT/echo.txt"; then
    grep -q "CompoundProperty name=.arbGeomParams" "$OUT/echo.txt"
    grep -q "ArrayProperty name=Cd;interpretation=rgb;datatype=float32_t\[3\];arraysize=$vertices;numsamps=1" "$OUT/echo.txt"
    grep -q "ArrayProperty name=groom_width;interpretation=;datatype=float32_t;arraysize=$vertices;numsamps=1" "$OUT/echo.txt"
    "$ABC/abcls" -l -v "$OUT/a.abc/hair/.geom/.arbGeomParams" | sed 's/\x1b\[[0-9;]*m//g' > "$OUT/arb.txt"
    python3 - "$OUT/arb.txt" "$OUT/a.hair" <<'PY'
import struct, sys
lines = open(sys.argv[1]).read().split('\n')
start = next(i for i, l in enumerate(lines) if l.split() and l.split()[-1] == 'Cd[1]')
cd = []
for v in lines[start + 1:]:
    if not v.strip() or 'Property' in v:
        break
    cd.append([float(x) for x in v.split(',')])
# cyHair: the colour array is the last array of the file, 3 floats a vertex.
data = open(sys.argv[2], 'rb').read()
n = len(cd)
hair = struct.unpack('<%df' % (3 * n), data[len(data) - 12 * n:])
worst = max(abs(a - b) for i, c in enumerate(cd) for a, b in zip(c, hair[3 * i:3 * i + 3]))
assert worst < 1e-5, 'a colour differs by %g' % worst
print('ok: abcecho lists .arbGeomParams Cd and groom_width per vertex; abcls reads all %d colours as vdbhair wrote them '
      '(worst difference %.2g)' % (n, worst))
PY
fi
