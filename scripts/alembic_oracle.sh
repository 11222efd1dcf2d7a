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
# and that vdbhair reads its own .abc back to the same .hair bytes; and, for `interpolate`'s groom
# (INPUT as guides and roots), the objects /guides and /hair with Unreal's groom attributes.
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
cmp "$OUT/a.hair" "$OUT/b.hair" || { echo "alembic_oracle: the .abc reads back differently" >&2; exit 1; }
echo "ok: vdbhair reads its .abc back to the same .hair bytes"
"$VDBHAIR" convert "$OUT/a.hair" "$OUT/a.obj" --obj-lines polylines --quiet
strands=$("$VDBHAIR" info "$OUT/a.abc" | awk '$1 == "strands:" {print $2}')
vertices=$("$VDBHAIR" info "$OUT/a.abc" | awk '$1 == "vertices:" {print $2}')

"$ABC/abctree" "$OUT/a.abc" | grep -q -- '`--hair' || { echo "alembic_oracle: abctree does not show ABC -> hair" >&2; exit 1; }
echo "ok: abctree shows ABC -> hair"
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

# Unreal's groom from `interpolate` (INPUT's strands as guides, new hair at their roots): the guides
# and the hair as sibling objects, groom_guide 1 and 0, ids 0..G-1 and G.., each hair's three guides
# among the guides' ids with weights summing to 1; vdbhair reads the hair back (guides left out).
"$VDBHAIR" interpolate "$OUT/a.hair" --roots "$OUT/a.hair" --head none -o "$OUT/groom.abc" --quiet
"$VDBHAIR" interpolate "$OUT/a.hair" --roots "$OUT/a.hair" --head none -o "$OUT/groom.hair" --quiet
"$VDBHAIR" convert "$OUT/groom.abc" "$OUT/groom_back.hair" --quiet
cmp "$OUT/groom.hair" "$OUT/groom_back.hair" || { echo "alembic_oracle: the groom's hair reads back differently" >&2; exit 1; }
echo "ok: vdbhair reads the groom's hair back to the bytes interpolate writes as .hair"
"$ABC/abctree" "$OUT/groom.abc" | tr -d '|`\r-' | awk 'NF' | tr '\n' ' ' | grep -Eq "^ABC +guides +hair *$" ||
    { echo "alembic_oracle: abctree does not show ABC -> guides, hair" >&2; exit 1; }
echo "ok: abctree shows ABC -> guides, hair"
for obj in guides hair; do
    "$ABC/abcls" -l -v "$OUT/groom.abc/$obj/.geom/.arbGeomParams" | sed 's/\x1b\[[0-9;]*m//g' > "$OUT/$obj.txt"
done
python3 - "$OUT/guides.txt" "$OUT/hair.txt" "$strands" <<'PY'
import sys
def blocks(path):
    lines, out, name = open(path).read().split('\n'), {}, None
    for l in lines:
        w = l.split()
        if w and w[0].endswith('Property'):
            name = w[-1].replace('[1]', '')
            out[name] = []
        elif name and l.strip() and '=' not in l and l.strip() not in ('{', '}'):
            out[name].append([float(x) for x in l.split(',')])
    return out
g, h, n = blocks(sys.argv[1]), blocks(sys.argv[2]), int(sys.argv[3])
for b in (g, h):
    assert b['groom_version_major'] == [[1]] and b['groom_version_minor'] == [[5]], 'groom schema version is not 1.5'
assert g['groom_guide'] == [[1]] and h['groom_guide'] == [[0]], 'groom_guide is not 1 on /guides and 0 on /hair'
assert [int(v[0]) for v in g['groom_id']] == list(range(n)), 'guide ids are not 0..G-1'
assert [int(v[0]) for v in h['groom_id']] == list(range(n, 2 * n)), 'hair ids are not G..G+S-1'
cg, w = h['groom_closest_guides'], h['groom_guide_weights']
assert len(cg) == n and len(w) == n and all(len(r) == 3 for r in cg + w), 'not three guides and weights per curve'
assert all(0 <= x < n for r in cg for x in r), 'a closest guide is not a guide id'
assert all(abs(sum(r) - 1) < 1e-5 and min(r) >= 0 for r in w), 'weights do not sum to 1'
print('ok: abcls reads /guides (groom_guide 1, ids 0..%d) and /hair (groom_guide 0, %d curves, each with three '
      'guides among them and weights summing to 1), groom schema 1.5' % (n - 1, n))
PY
