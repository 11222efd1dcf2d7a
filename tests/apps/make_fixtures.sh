#!/usr/bin/env bash
# Writes the inputs of the command-line tests into $2 using the vdbhair binary $1:
# good files made by vdbhair itself and bad files, one per kind of error.
set -eu
bin="$1"; dir="$2"; src="$3"
rm -rf "$dir"; mkdir -p "$dir"; cd "$dir"
"$bin" convert "$src/scenes/default/ponytail.hair" good.hair --resample 8 --quiet
"$bin" convert good.hair good.vdb --quiet
"$bin" convert good.hair good.data --quiet
"$bin" convert good.hair good.obj --quiet
"$bin" field good.hair -o field.vdb --voxel-size 2 --quiet
cp good.hair existing.hair
# A file name that is not UTF-8 (byte 0xFF): JSON reports must still print.
cp good.hair "$(printf 'latin1_\377.hair')"
cp "$src/scenes/figures/fig2_waviness.json" existing_fit.json
# The default head scene with 16 strands a wisp instead of 124 (6,800 strands instead of 50,000): its
# shape and guides at an eighth of the work, for the tests that need a head of hair, not its count.
sed 's/"count":124/"count":16/g' "$src/scenes/default/head.json" > small_head.json
grep -q '"count":16' small_head.json || { echo "make_fixtures.sh: head.json has no wisp count 124 to lower" >&2; exit 1; }
# Many strands: fitting them takes long enough to interrupt (the Ctrl-C tests).
"$bin" grow small_head.json -o head.hair --quiet
cp "$src/scenes/figures/fig2_waviness.json" existing.json
# Strands with a known helicoid shape, sampled like the paper's data (30 vertices).
"$bin" grow "$src/scenes/figures/fig1_k_vectors.json" -o k_vectors.hair --quiet
"$bin" convert k_vectors.hair k_vectors30.hair --resample 30 --quiet
# A head for render --head: a tetrahedron around the fixture hairstyle's roots.
printf 'v -40 0 -40\nv 40 0 -40\nv 0 0 40\nv 0 80 0\nf 1 2 3\nf 1 2 4\nf 2 3 4\nf 3 1 4\n' > head.obj
# An octahedron of radius 10 with its top vertex painted (red 255, the others 0): scalp --region-vertex.
printf 'ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nelement face 8\nproperty list uchar int vertex_indices\nend_header\n10 0 0 0\n-10 0 0 0\n0 10 0 255\n0 -10 0 0\n0 0 10 0\n0 0 -10 0\n3 0 2 4\n3 4 2 1\n3 1 2 5\n3 5 2 0\n3 0 4 3\n3 4 1 3\n3 1 5 3\n3 5 0 3\n' > painted_octahedron.ply
# Bad inputs, one rule each.
{ printf 'HAIX'; head -c 124 /dev/zero; } > bad_magic.hair
head -c 200 good.hair > truncated.hair
printf '\xff\xff\xff\x7f' > huge_count.data
printf 'v 0 nan 0\nv 1 1 1\nl 1 2\n' > nan.obj
printf 'v 0 0 0\nv 1 1 1\nl 1 5\n' > bad_index.obj
printf 'this is not a vdb file\n' > not_a.vdb
printf 'ply\nformat binary_big_endian 1.0\nend_header\n' > big_endian.ply
{ printf '\x00\x00\x18\x41'; head -c 400 /dev/zero; } > version9.tfx
printf 'some text\n' > unknown.xyz
: > empty.obj
# Issue 50: a PLY of points only, 2 strands of 4 points (NeuralHaircut's layout), and an OBJ cubic Bezier curve.
printf 'ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n0 1 0\n0 2 0\n0 3 1\n1 0 0\n1 1 0\n1 2 0\n1 3 1\n' > runs_of_4.ply
printf 'v 0 0 0\nv 1 2 0\nv 3 2 0\nv 4 0 0\ncstype bezier\ndeg 3\ncurv 0 1 -4 -3 -2 -1\nend\n' > bezier.obj
# A .vdb written by another OpenVDB client (pyopenvdb) without a strands grid.
/usr/bin/python3 -c "import pyopenvdb as vdb; g = vdb.FloatGrid(); g.name = 'density'; g.fill((0, 0, 0), (3, 3, 3), 1.0); vdb.write('density.vdb', grids=[g])"
/usr/bin/python3 -c "import pyopenvdb as vdb; g = vdb.BoolGrid(); g.name = 'region'; vdb.write('empty_region.vdb', grids=[g])"
# Strands of one vertex only: all dropped, leaving an empty hairstyle.
printf 'v 0 0 0\nv 1 1 1\nl 1\nl 2\n' > only_short.obj
# A strand of zero length (one point repeated) after a good one.
printf 'v 0 0 0\nv 1 0 0\nv 2 1 0\nv 3 3 3\nv 3 3 3\nl 1 2 3\nl 4 5\n' > zero_length.obj
# Scenes with one mistake each.
printf '{"vdbhair": "scene/1", "guides": [{"root": [0,0,0], "frame": {"tangent": [1,0,0], "normal": [0,1,0]}, "pieces": [{"k": [1, 0, 0], "length": 1}]}]}\n' > bad_scene.json
# A piece whose RK4 trace at step 0.05 steps across its singular axis (issue 19): grow warns.
printf '{"vdbhair": "scene/1", "step": 0.05, "integrator": "rk4", "guides": [{"root": [0,0,0], "frame": {"tangent": [1,0,0], "normal": [0,1,0]}, "pieces": [{"k": [1.742, -1.385, -0.373, 0.049], "length": 4}]}]}\n' > near_axis.json
printf '{"vdbhair": "scene/1", "guides": [{"root": [0,0,0], "frame": {"tangent": [1,0,0], "normal": [0,1,0]}, "pieces": [{"k": [1, 0, 0, 0], "length": 1}], "wisp": {"count": 2, "radiuss": 1}}]}\n' > unknown_key.json
printf '{"vdbhair": "scene/1", "guides": [' > not_json.json
# Scalps: the default head's sphere with the region of its hairstyle's roots; oriented points on
# a sphere (ascii PLY with normals); too few points; coplanar points; an empty mesh.
"$bin" scalp --sphere 0,0,0,10 -o scalp_sphere.vdb --voxel-size 0.25 --region head.hair --quiet
/usr/bin/python3 - <<'PY'
import math
n = 300; g = math.pi * (3 - math.sqrt(5))
rows = []
for i in range(n):
    y = 1 - 2 * (i + 0.5) / n; r = math.sqrt(1 - y * y); t = g * i
    u = (r * math.cos(t), y, r * math.sin(t))
    rows.append("%.6f %.6f %.6f %.6f %.6f %.6f" % (10 * u[0], 10 * u[1] + 5, 10 * u[2], u[0], u[1], u[2]))
hdr = "ply\nformat ascii 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nend_header\n"
open("points.ply", "w").write(hdr % n + "\n".join(rows) + "\n")
open("few_points.ply", "w").write(hdr % 4 + "0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n1 1 1 0 0 1\n")
open("coplanar.ply", "w").write(hdr % 6 + "".join("%d %d 2 0 0 1\n" % (i % 3, i // 3) for i in range(6)))
PY
: > empty_mesh.obj
printf 'ply\nformat ascii 1.0\nelement vertex 0\nend_header\n' > existing_roots.ply
"$bin" roots scalp_sphere.vdb -o roots.ply --count 500 --quiet
# Interpolation: guides with one mistake each, and roots without normals.
printf '{"vdbhair": "scene/1", "guides": []}\n' > no_guides.json
printf '{"vdbhair": "scene/1", "guides": [{"root": [0,0,0], "frame": {"tangent": [1,0,0], "normal": [0,1,0]}, "pieces": [{"k": [1, 0, 0, 0], "length": 0}]}]}\n' > zero_guide.json
printf '{"vdbhair": "scene/1", "guides": [{"root": [0,0,0], "frame": {"tangent": [1,0,0], "normal": [0,1,0]}, "pieces": [{"k": [1, 1e999, 0, 0], "length": 1}]}]}\n' > inf_guide.json
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 10 0\n1 10 0\n0 10 1\n' > roots_no_normals.ply
# Comb strokes with one mistake each.
printf '{"strokes": [{"points": [[0, 0, -15]], "radius": 4}]}\n' > stroke_one_point.json
printf '{"strokes": [{"points": [[0, 2, -15], [9, -10, -15]], "radius": 0}]}\n' > stroke_zero_radius.json
printf '{"strokes": [{"points": [[0, 2, -15], [9, -10, -15]], "radius": 4, "strength": 0}]}\n' > stroke_zero_strength.json
printf '{"strokes": [{"points": [[0, 2, 1e999], [9, -10, -15]], "radius": 4}]}\n' > stroke_inf.json
printf '{"strokes": [{"points": [[0, 60, 0], [20, 40, 0]], "radius": 30}]}\n' > stroke_pony.json
# Down and back into the ponytail's head (the sphere fitted to its roots: centre (0.3, 87.9, 7.3), radius 32).
printf '{"strokes": [{"points": [[0, 150, 40], [0, 100, 15]], "radius": 35}]}\n' > stroke_into_head.json
# USD prims under transforms (translate, rotateXYZ, scale, a pivot with !invert!,
# !resetXformStack!, orient, a matrix), three levels deep: vdbhair's points against tinyusdz's
# world matrices (check_tinyusdz_world.mjs).
cat > transformed.usda <<'USDA'
#usda 1.0
def Xform "root"
{
    double3 xformOp:translate = (10, 0, 0)
    float3 xformOp:rotateXYZ = (30, 0, 90)
    float3 xformOp:scale = (2, 2, 2)
    uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:rotateXYZ", "xformOp:scale"]
    def BasisCurves "hair"
    {
        double3 xformOp:translate = (0, 1, 0)
        uniform token[] xformOpOrder = ["xformOp:translate"]
        uniform token type = "linear"
        int[] curveVertexCounts = [2, 3]
        point3f[] points = [(0, 0, 0), (1, 0, 0), (0, 0, 1), (0, 1, 1), (1, 1, 1)]
    }
    def Xform "pivoted"
    {
        double3 xformOp:translate = (100, 0, 0)
        float xformOp:rotateY = 45
        uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:rotateY"]
        def BasisCurves "reset"
        {
            uniform token[] xformOpOrder = ["!resetXformStack!", "xformOp:translate:pivot", "xformOp:rotateY", "!invert!xformOp:translate:pivot"]
            double3 xformOp:translate:pivot = (1, 0, 0)
            float xformOp:rotateY = 180
            uniform token type = "linear"
            int[] curveVertexCounts = [2]
            point3f[] points = [(1, 0, 0), (2, 0, 3)]
        }
        def BasisCurves "oriented"
        {
            quatf xformOp:orient = (0.8660254, 0.5, 0, 0)
            matrix4d xformOp:transform = ( (1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (0, 0, 5, 1) )
            uniform token[] xformOpOrder = ["xformOp:transform", "xformOp:orient"]
            uniform token type = "linear"
            int[] curveVertexCounts = [2]
            point3f[] points = [(0, 1, 0), (0, 2, 3)]
        }
    }
}
USDA
