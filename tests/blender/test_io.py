"""File > Import and File > Export of the add-on against vdbhair.read and `vdbhair convert`:
strand order, counts and positions, the axis turn, attributes, the unit and up axis of a USD stage,
legacy curve objects, and bad input (one error report naming the file, nothing created)."""
import os
import sys

sys.path.insert(0, os.path.dirname(__file__))
import bpy  # noqa: E402
import numpy as np  # noqa: E402

from addon_test import (PONYTAIL, check, cli, enable_addon, expect_error,  # noqa: E402
                        new_scene, object_arrays, out, run_operator, same_strands, y_up_to_blender)

enable_addon()
import vdbhair  # noqa: E402  (found by the add-on: the build tree's module)

BYTE_FORMATS = ("hair", "data", "obj", "ply", "usda", "abc")  # .vdb holds a random UUID: compared by value
import_op, export_op = bpy.ops.import_scene.vdbhair, bpy.ops.export_scene.vdbhair


def import_file(path, **options):
    new_scene()
    result, seconds = run_operator(import_op, filepath=path, **options)
    check(result == {'FINISHED'}, "import %s finished (%.3f s)" % (os.path.basename(path), seconds))
    return bpy.context.active_object


def same_file(ours, theirs):
    with open(ours, "rb") as a, open(theirs, "rb") as b:
        check(a.read() == b.read(), "%s is byte-identical to vdbhair convert's %s"
              % (os.path.basename(ours), os.path.basename(theirs)))


# The ponytail: import matches vdbhair.read, turned +Y up -> +Z up; every format exported as convert writes it.
truth = vdbhair.read(PONYTAIL)
obj = import_file(PONYTAIL)
check(obj.type == 'CURVES' and obj.name == "ponytail", "a hair Curves object named after the file")
positions, offsets = object_arrays(obj)
same_strands("import ponytail.hair", positions, offsets, y_up_to_blender(truth.positions), truth.offsets)
check(tuple(obj.matrix_world.translation) == (0, 0, 0) and obj.rotation_euler.x == 0, "identity object transform")
check("radius" not in obj.data.attributes, "no radius attribute for strands without thickness")
for fmt in BYTE_FORMATS + ("vdb",):
    ours, theirs = out("pony_blender.%s" % fmt), out("pony_cli.%s" % fmt)
    result, seconds = run_operator(export_op, filepath=ours)
    check(result == {'FINISHED'}, "export .%s finished (%.3f s)" % (fmt, seconds))
    cli("convert", PONYTAIL, theirs)
    if fmt in BYTE_FORMATS:
        same_file(ours, theirs)
    else:
        a, b = vdbhair.read(ours), vdbhair.read(theirs)
        same_strands(".vdb export against convert's", a.positions, a.offsets, b.positions, b.offsets)
    back = vdbhair.read(ours)  # and every written file imports again as the same strands
    again = import_file(ours)
    p, o = object_arrays(again)
    same_strands("import of the exported .%s" % fmt, p, o, y_up_to_blender(back.positions), back.offsets)

# Attributes: thickness <-> radius (x 0.5), colour and transparency as point attributes.
rng = np.random.default_rng(53)
v = len(truth.positions)
rich = vdbhair.Strands(truth.positions, truth.offsets, thickness=rng.uniform(0.02, 0.1, v).astype(np.float32),
                       color=rng.uniform(0, 1, (v, 3)).astype(np.float32),
                       transparency=rng.uniform(0, 0.5, v).astype(np.float32))
rich.write(out("rich.hair"))
obj = import_file(out("rich.hair"))
radius = np.empty(v, np.float32)
obj.data.attributes["radius"].data.foreach_get("value", radius)
check(np.array_equal(radius * 2, rich.thickness), "radius is half the thickness, exactly")
color = np.empty(v * 4, np.float32)
obj.data.attributes["color"].data.foreach_get("color", color)
check(np.array_equal(color.reshape(-1, 4)[:, :3], rich.color), "colour kept as a point colour attribute")
for fmt in ("hair", "usda"):
    run_operator(export_op, filepath=out("rich_blender.%s" % fmt))
    cli("convert", out("rich.hair"), out("rich_cli.%s" % fmt))
    same_file(out("rich_blender.%s" % fmt), out("rich_cli.%s" % fmt))

# A cyHair header's defaults (no per-vertex arrays) are kept: .hair and .usda (widths) as convert writes them.
plain = vdbhair.Strands(truth.positions, truth.offsets)
plain.defaults = {"thickness": 0.1, "transparency": 0.25, "color": (1.0, 0.9, 0.5)}
plain.write(out("defaults.hair"))
import_file(out("defaults.hair"))
for fmt in ("hair", "usda"):
    run_operator(export_op, filepath=out("defaults_blender.%s" % fmt))
    cli("convert", out("defaults.hair"), out("defaults_cli.%s" % fmt))
    same_file(out("defaults_blender.%s" % fmt), out("defaults_cli.%s" % fmt))

# A USD stage that declares +Z up and metres comes in unturned, and goes out so declared.
cli("convert", PONYTAIL, out("z.usda"), "--usd-up", "z", "--meters-per-unit", "1")
z = vdbhair.read(out("z.usda"))
obj = import_file(out("z.usda"))
p, o = object_arrays(obj)
same_strands("import of a +Z-up stage (not turned)", p, o, z.positions, z.offsets)
check(obj.data["vdbhair_up_axis"] == "Z" and obj.data["vdbhair_meters_per_unit"] == 1.0,
      "the object records +Z up and 1 m per unit")
run_operator(export_op, filepath=out("z_blender.usda"))
cli("convert", out("z.usda"), out("z_cli.usda"))
same_file(out("z_blender.usda"), out("z_cli.usda"))

# Scale to the scene's unit: a metre stage into a centimetre scene is 100 times larger; the export undoes it.
new_scene()
bpy.context.scene.unit_settings.scale_length = 0.01
run_operator(import_op, filepath=out("z.usda"), unit='SCENE')
p, _ = object_arrays(bpy.context.active_object)
check(np.allclose(p, z.positions * 100, rtol=1e-6), "a 1 m stage in a 0.01 m scene: coordinates x 100")
run_operator(export_op, filepath=out("z_scaled.usda"))
back = vdbhair.read(out("z_scaled.usda"))
tolerance = 3e-7 * float(np.abs(z.positions).max())  # float32 rounding of x 100, then of / 100
same_strands("metres -> centimetre scene -> metres", back.positions, back.offsets, z.positions, z.offsets, tolerance)
check(back.meters_per_unit == 1.0 and back.up_axis == "Z", "the export declares 1 m per unit and +Z up again")
expect_error(import_op, "declares no unit", filepath=PONYTAIL, unit='SCENE')

# Legacy curve objects: one poly spline a strand, in order; exported as the hair object is.
obj = import_file(PONYTAIL, object_type='CURVE')
check(obj.type == 'CURVE' and len(obj.data.splines) == len(truth), "a legacy curve object of %d splines" % len(truth))
p, o = object_arrays(obj)
same_strands("legacy curve import", p, o, y_up_to_blender(truth.positions), truth.offsets)
run_operator(export_op, filepath=out("legacy_blender.hair"))
same_file(out("legacy_blender.hair"), out("pony_cli.hair"))

# A moved object exports in world coordinates (Apply Transform); unmoved, the exact coordinates.
obj = import_file(PONYTAIL)
obj.location = (1.0, 2.0, 3.0)
bpy.context.view_layer.update()
run_operator(export_op, filepath=out("moved.hair"))
moved = vdbhair.read(out("moved.hair"))
check(np.allclose(moved.positions, truth.positions + np.array([1.0, 3.0, -2.0], np.float32), atol=1e-4),
      "Blender's +X+2Y+3Z is the file's +X+3Y-2Z (+Y up)")

# Bad input: one error line naming the file; nothing created, nothing written.
with open(out("bad.hair"), "wb") as f:
    f.write(b"HAIR" + b"\0" * 20)
new_scene()
expect_error(import_op, "bad.hair", filepath=out("bad.hair"))
check(len(bpy.data.objects) == 0 and len(bpy.data.hair_curves) == 0 and len(bpy.data.curves) == 0,
      "a failed import leaves no object and no datablock")
expect_error(export_op, "no hair object", filepath=out("nothing.hair"))
check(not os.path.exists(out("nothing.hair")), "a failed export writes nothing")
import_file(PONYTAIL)
expect_error(export_op, "missing_dir", filepath=out("missing_dir/x.hair"))
print("ok: import and export checked")
