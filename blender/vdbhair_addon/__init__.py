"""vdbhair for Blender: strand files in and out of hair objects, and vdbhair's refine, interpolate,
synth and comb on them. Needs the vdbhair Python module (see loader.py and docs/blender.md)."""

bl_info = {
    "name": "vdbhair",
    "author": "vdbhair",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "File > Import/Export > Hair Strands (vdbhair); 3D View > Sidebar > vdbhair",
    "description": "Hair strand formats (.hair .data .obj .ply .vdb .usda .abc, and more to read) and "
                   "vdbhair's refine, interpolate, synth and comb on hair Curves objects",
    "category": "Import-Export",
}

if "bpy" in locals():  # Reload Scripts (F3 > Reload Scripts) reloads the modules too
    import importlib
    for _m in (loader, convert, jobs, io_ops, hair_ops, ui):  # noqa: F821
        importlib.reload(_m)

import bpy
from bpy.props import PointerProperty

from . import convert, hair_ops, io_ops, jobs, loader, ui

classes = io_ops.classes + hair_ops.classes + ui.classes


def register():
    loader.load(retry=True)  # now, so that the panel and the preferences can say whether it worked
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.Scene.vdbhair = PointerProperty(type=ui.VDBHAIR_PG_settings)
    bpy.types.TOPBAR_MT_file_import.append(io_ops.menu_import)
    bpy.types.TOPBAR_MT_file_export.append(io_ops.menu_export)


def unregister():
    bpy.types.TOPBAR_MT_file_export.remove(io_ops.menu_export)
    bpy.types.TOPBAR_MT_file_import.remove(io_ops.menu_import)
    del bpy.types.Scene.vdbhair
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
