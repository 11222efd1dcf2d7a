"""Strands through Blender and back, run inside Blender (headless):
    blender -b --python-exit-code 1 --python check_blender_obj.py -- IN.obj OUT.obj VERTICES STRANDS
Imports vdbhair's OBJ with Blender's default OBJ importer (wm.obj_import), checks that every
vertex and segment arrived (VERTICES vertices, VERTICES - STRANDS edges, STRANDS connected chains
with no branch), that the importer stood +Y up as Blender's +Z (a +90 degree turn about X in the
object's transform, the vertices unchanged), converts the mesh to a curve object (one poly spline
per strand) and exports that with Blender's default OBJ exporter (wm.obj_export) to OUT.obj,
which the calling test reads back with vdbhair."""
import math
import sys

import bpy

args = sys.argv[sys.argv.index("--") + 1:]
src, dst, want_vertices, want_strands = args[0], args[1], int(args[2]), int(args[3])


def fail(msg):
    raise SystemExit("FAIL: " + msg)


bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.wm.obj_import(filepath=src)
if len(bpy.context.selected_objects) != 1:
    fail("expected one imported object, got %d" % len(bpy.context.selected_objects))
obj = bpy.context.selected_objects[0]
mesh = obj.data
nv, ne = len(mesh.vertices), len(mesh.edges)

# Connected chains: union-find over the edges; a strand is a path (no vertex joins three).
parent = list(range(nv))
degree = [0] * nv


def find(a):
    while parent[a] != a:
        parent[a] = parent[parent[a]]
        a = parent[a]
    return a


for e in mesh.edges:
    a, b = e.vertices
    degree[a] += 1
    degree[b] += 1
    ra, rb = find(a), find(b)
    if ra != rb:
        parent[ra] = rb
chains = len({find(v) for v in range(nv)})
branches = sum(1 for d in degree if d > 2)
print("Blender imported %d vertices, %d edges, %d connected strands, %d branching vertices" % (nv, ne, chains, branches))
if nv != want_vertices:
    fail("Blender has %d vertices, vdbhair wrote %d" % (nv, want_vertices))
if ne != want_vertices - want_strands:
    fail("Blender has %d edges, vdbhair wrote %d segments" % (ne, want_vertices - want_strands))
if chains != want_strands or branches:
    fail("Blender sees %d connected strands (%d branching vertices), vdbhair wrote %d" % (chains, branches, want_strands))

# Axes: Blender's importer (Up: Y, Forward: -Z) turns the object +90 degrees about X.
m = obj.matrix_world
if abs(m[2][1] - 1.0) > 1e-6 or abs(m[1][2] + 1.0) > 1e-6:
    fail("unexpected import transform %s" % [list(r) for r in m])
print("Blender stands the file's +Y up as +Z (object rotated %.0f degrees about X)" % math.degrees(obj.rotation_euler.x))

# Back as curves: one poly spline per strand, exported with Blender's defaults.
bpy.ops.object.convert(target='CURVE')
curve = bpy.context.selected_objects[0]
splines = curve.data.splines
points = sum(len(s.points) for s in splines)
print("Blender curve object: %d splines, %d points" % (len(splines), points))
if len(splines) != want_strands or points != want_vertices:
    fail("the curve object has %d splines and %d points, expected %d and %d" % (len(splines), points, want_strands, want_vertices))
bpy.ops.wm.obj_export(filepath=dst, export_selected_objects=True, export_materials=False)
print("ok: Blender read every vertex and segment of %d strands and exported them to %s" % (want_strands, dst))
