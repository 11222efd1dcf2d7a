"""The hair operators against the vdbhair command with the same options: refine (both modes, and
with the hair's surface mesh as the head), interpolate (guides = the selected curves), comb (a
curve object as the stroke) and synth; cancelling through the progress callback; errors."""
import json
import os
import sys

sys.path.insert(0, os.path.dirname(__file__))
import bpy  # noqa: E402
import numpy as np  # noqa: E402

from addon_test import (PONYTAIL, SOURCE_DIR, blender_to_y_up, check, cli, enable_addon, expect_error,  # noqa: E402
                        new_scene, object_arrays, out, run_operator, same_strands, y_up_to_blender)

addon = enable_addon()
import vdbhair  # noqa: E402

truth = vdbhair.read(PONYTAIL)


def import_ponytail():
    new_scene()
    bpy.ops.import_scene.vdbhair(filepath=PONYTAIL)
    return bpy.context.active_object


def object_strands(obj):
    p, o = object_arrays(obj)
    return blender_to_y_up(p), o


def same_as_cli(what, obj, path):
    """The object's strands (turned back to +Y up) against a file the command wrote."""
    cli_result = vdbhair.read(path)
    p, o = object_strands(obj)
    same_strands(what, p, o, cli_result.positions, cli_result.offsets)


# Refine: consistent mode over two levels (positions in place), field mode (the topology may change).
for options, flags in (({"levels": 2}, ["--levels", "2"]), ({"mode": 'field'}, ["--mode", "field"])):
    obj = import_ponytail()
    result, seconds = run_operator(bpy.ops.vdbhair.refine, **options)
    check(result == {'FINISHED'}, "refine %s finished (%.3f s)" % (options, seconds))
    cli("refine", PONYTAIL, "-o", out("refined.hair"), *flags)
    same_as_cli("refine %s against vdbhair refine %s" % (options, " ".join(flags)), obj, out("refined.hair"))

# A legacy curve object is refined in place, as the hair object is.
new_scene()
bpy.ops.import_scene.vdbhair(filepath=PONYTAIL, object_type='CURVE')
legacy = bpy.context.active_object
run_operator(bpy.ops.vdbhair.refine, levels=2)
cli("refine", PONYTAIL, "-o", out("refined.hair"), "--levels", "2")
same_as_cli("refine of a legacy curve object against vdbhair refine --levels 2", legacy, out("refined.hair"))

# The hair's surface mesh as the head: an icosphere inside the ponytail, written for the command as a PLY.
obj = import_ponytail()
bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=3, radius=10.0, location=(0.0, 0.0, 60.0))
head = bpy.context.active_object
obj.data.surface = head
mesh = head.data
mesh.calc_loop_triangles()
verts = np.array([head.matrix_world @ v.co for v in mesh.vertices], np.float32)
with open(out("head.ply"), "w") as f:
    f.write("ply\nformat ascii 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
            "element face %d\nproperty list uchar int vertex_indices\nend_header\n" % (len(verts), len(mesh.loop_triangles)))
    for v in blender_to_y_up(verts):
        f.write("%.9g %.9g %.9g\n" % tuple(v))
    for t in mesh.loop_triangles:
        f.write("3 %d %d %d\n" % tuple(t.vertices))
bpy.context.view_layer.objects.active = obj
run_operator(bpy.ops.vdbhair.refine, head='SURFACE')
cli("refine", PONYTAIL, "-o", out("refined_head.hair"), "--head", out("head.ply"))
same_as_cli("refine with the surface mesh as the head against vdbhair refine --head", obj, out("refined_head.hair"))

# Cancelling: the progress callback raises at the first report; the object is unchanged.
obj = import_ponytail()
before = object_arrays(obj)
reports = []


def cancel_at_once(job, stage, done, total, unit):
    reports.append((stage, job.status_text()))
    job.cancel()


addon.jobs.progress_listeners.append(cancel_at_once)
try:
    result, seconds = run_operator(bpy.ops.vdbhair.refine, levels=3)
finally:
    addon.jobs.progress_listeners.remove(cancel_at_once)
check(result == {'CANCELLED'}, "a cancelled refine returns CANCELLED (%.3f s)" % seconds)
check(len(reports) == 1, "the work stopped at the first progress report: %s" % reports[0][1])
after = object_arrays(obj)
check(np.array_equal(before[0], after[0]) and np.array_equal(before[1], after[1]),
      "the cancelled object is unchanged")
expect_error(bpy.ops.vdbhair.refine, "has no surface mesh", head='SURFACE')
check(np.array_equal(object_arrays(obj)[0], before[0]), "the object is unchanged after the error")

# Interpolate: every 20th curve selected as a guide, the others regrown at their roots.
obj = import_ponytail()
expect_error(bpy.ops.vdbhair.interpolate, "select the guide curves")
n = len(truth)
guides = np.arange(0, n, 20)
rest = np.setdiff1d(np.arange(n), guides)
selection = np.zeros(n, np.float32)
selection[guides] = 1.0
obj.data.attributes.new(".selection_curve_float", 'FLOAT', 'CURVE').data.foreach_set("value", selection)


def subset(strands, indices):
    pieces = [strands[int(i)] for i in indices]
    return vdbhair.Strands(np.concatenate(pieces), np.concatenate([[0], np.cumsum([len(p) for p in pieces])]))


subset(truth, guides).write(out("guides.hair"))
subset(truth, rest).write(out("rest.hair"))
bpy.ops.object.mode_set(mode='SCULPT_CURVES')  # where curves are selected; the new datablock needs Object Mode
result, seconds = run_operator(bpy.ops.vdbhair.interpolate)
check(result == {'FINISHED'}, "interpolate finished (%.3f s)" % seconds)
check(obj.mode == 'SCULPT_CURVES' and bpy.context.view_layer.objects.active == obj,
      "the object is active and in Sculpt Mode again")
cli("interpolate", out("guides.hair"), "--roots", out("rest.hair"), "-o", out("interpolated.hair"))
p, o = object_strands(obj)
got = vdbhair.Strands(p, o)
same_strands("the guides are kept in place", subset(got, guides).positions, subset(got, guides).offsets,
             subset(truth, guides).positions, subset(truth, guides).offsets)
expected = vdbhair.read(out("interpolated.hair"))
same_strands("the other curves against vdbhair interpolate guides --roots rest",
             subset(got, rest).positions, subset(got, rest).offsets, expected.positions, expected.offsets)
kept = np.empty(n, np.float32)
obj.data.attributes[".selection_curve_float"].data.foreach_get("value", kept)
check(np.array_equal(kept, selection), "the guides stay selected")

# Comb along a curve object made from a stroke's points (+Y up turned to Blender's +Z). The stroke
# runs along the longest strand (its vertices at 20, 50 and 80 % of its length), sweeping toward
# +x; it is written as a stroke file for the command too.
obj = import_ponytail()
longest = truth[int(np.argmax(np.diff(truth.offsets)))]
mid = np.array([longest[int(f * (len(longest) - 1))] for f in (0.2, 0.5, 0.8)], dtype=np.float64)
mid[:, 0] += np.array([0.0, 6.0, 15.0])
# Multiples of 1/64 and a strength of 0.75: exact in float32 (the curve object's points and the
# operator's properties) and in the JSON (the command's); 0.8 differs by 1.2e-8 as a float32.
stroke = {"points": (np.round(mid * 64.0) / 64.0).tolist(), "radius": 12.0, "strength": 0.75}
stroke_file = out("stroke.json")
with open(stroke_file, "w") as f:
    json.dump({"vdbhair": "strokes/1", "strokes": [stroke]}, f)
curve = bpy.data.curves.new("stroke", 'CURVE')
spline = curve.splines.new('POLY')
spline.points.add(len(stroke["points"]) - 1)
points = np.ones((len(stroke["points"]), 4), np.float32)
points[:, :3] = y_up_to_blender(np.array(stroke["points"], np.float32))
spline.points.foreach_set("co", points.ravel())
stroke_obj = bpy.data.objects.new("stroke", curve)
bpy.context.scene.collection.objects.link(stroke_obj)
expect_error(bpy.ops.vdbhair.comb, "select one or more curve objects")
stroke_obj.select_set(True)
obj.select_set(True)
result, seconds = run_operator(bpy.ops.vdbhair.comb, radius=stroke["radius"], strength=stroke["strength"])
check(result == {'FINISHED'}, "comb finished (%.3f s)" % seconds)
cli("comb", PONYTAIL, "--stroke", stroke_file, "-o", out("combed.hair"))
moved = np.linalg.norm(object_strands(obj)[0] - truth.positions, axis=1)
check(np.count_nonzero(moved > 1e-3) > 0.05 * len(moved), "the stroke moved %d of %d vertices" % (np.count_nonzero(moved > 1e-3), len(moved)))
same_as_cli("comb along the curve object against vdbhair comb --stroke", obj, out("combed.hair"))

# Synth: a new object in the active one's style; the example is left as it was.
obj = import_ponytail()
result, seconds = run_operator(bpy.ops.vdbhair.synth, levels=2)
check(result == {'FINISHED'}, "synth finished (%.3f s)" % seconds)
made = bpy.context.active_object
check(made.name == "ponytail_synth" and made.type == 'CURVES', "synth made a new hair object %s" % made.name)
cli("synth", PONYTAIL, "-o", out("synth.hair"), "--levels", "2")
same_as_cli("synth against vdbhair synth --levels 2", made, out("synth.hair"))
check(np.array_equal(object_strands(obj)[0], truth.positions), "the example object is unchanged")
check(len(bpy.data.curves) == 0, "no legacy curve datablock is left behind by the conversions")
print("ok: operators checked")
