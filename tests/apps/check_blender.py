"""Interop check run inside Blender (headless):
    blender -b --python-exit-code 1 --python check_blender.py -- FIELD.vdb
Imports the .vdb as a volume object and checks that 'tangent' loads as a vector grid and
'density' as a float grid."""
import sys

import bpy

path = sys.argv[sys.argv.index("--") + 1]
bpy.ops.object.volume_import(filepath=path)
volume = bpy.context.selected_objects[0].data
if not volume.grids.load():
    raise SystemExit("FAIL: Blender could not load the grids of " + path)
types = {g.name: g.data_type for g in volume.grids}
print("grids:", types)
if types.get("tangent") != "VECTOR_FLOAT":
    raise SystemExit("FAIL: 'tangent' is %s in Blender, expected VECTOR_FLOAT" % types.get("tangent"))
if types.get("density") != "FLOAT":
    raise SystemExit("FAIL: 'density' is %s in Blender, expected FLOAT" % types.get("density"))
print("ok: Blender loads tangent as a vector grid and density as a float grid")
