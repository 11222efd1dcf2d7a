"""File > Import and File > Export of every vdbhair strand format.

Reading and writing are vdbhair's own (vdbhair.read, vdbhair.write: atomic, a failed write leaves
nothing), so a file imported here holds exactly what `vdbhair convert` reads, and a file exported
here is what `vdbhair convert` writes from the same strands.
"""
import os
import warnings

import bpy
import numpy as np
from bpy.props import BoolProperty, EnumProperty, IntProperty, StringProperty
from bpy_extras.io_utils import ExportHelper, ImportHelper

from . import convert, jobs, loader

READ_EXTENSIONS = (".hair", ".data", ".obj", ".ply", ".vdb", ".usda", ".usd", ".abc", ".tfx", ".bin", ".convdata")
WRITE_FORMATS = (
    ('HAIR', ".hair", "cyHair (Cem Yuksel's .hair)"),
    ('DATA', ".data", "USC-HairSalon binary"),
    ('OBJ', ".obj", "OBJ line elements (what Blender's OBJ importer reads whole)"),
    ('PLY', ".ply", "PLY (hairutil's layout, binary)"),
    ('VDB', ".vdb", "OpenVDB points grid 'strands'"),
    ('USDA', ".usda", "USD text, linear BasisCurves"),
    ('ABC', ".abc", "Alembic Curves"),
)
UNITS = {'M': 1.0, 'CM': 0.01, 'MM': 0.001}
UP_ITEMS = (
    ('AUTO', "Auto", "Import: the axis the file declares (USD), else +Y (vdbhair's convention). "
                     "Export: the axis the object was imported with, else +Y"),
    ('Y', "+Y", "The file's +Y is up: turned +90 degrees about X to stand on Blender's +Z"),
    ('Z', "+Z", "The file's +Z is up, as Blender's: no turn"),
)


def _up(choice, declared):
    return choice if choice != 'AUTO' else (declared or "Y")


class IMPORT_SCENE_OT_vdbhair(bpy.types.Operator, ImportHelper):
    """Import strands (any vdbhair format) as a hair Curves object or a legacy curve object"""
    bl_idname = "import_scene.vdbhair"
    bl_label = "Import Hair Strands (vdbhair)"
    bl_options = {'REGISTER', 'UNDO', 'PRESET'}

    filter_glob: StringProperty(default=";".join("*" + e for e in READ_EXTENSIONS), options={'HIDDEN'})
    object_type: EnumProperty(name="Object", default='CURVES', items=(
        ('CURVES', "Hair Curves", "A hair Curves object (every attribute kept)"),
        ('CURVE', "Curve", "A legacy curve object of poly splines (thickness as the points' radius)")))
    up_axis: EnumProperty(name="Up", items=UP_ITEMS, default='AUTO')
    unit: EnumProperty(name="Scale", default='KEEP', items=(
        ('KEEP', "Keep", "One file unit is one Blender unit (coordinates as stored)"),
        ('SCENE', "Scene Unit", "Convert from the file's unit to the scene's unit length")))
    file_unit: EnumProperty(name="File Unit", default='NONE', items=(
        ('NONE', "Declared", "The unit the file declares (USD); other formats declare none"),
        ('M', "Metres", ""), ('CM', "Centimetres", ""), ('MM', "Millimetres", "")),
        description="The unit of the file's coordinates when it declares none (or to correct it)")
    roots: EnumProperty(name="Roots", default='first', items=(
        ('first', "First", "Strands are stored root first (the convention)"),
        ('last', "Last", "Strands are stored tip first: reverse them"),
        ('auto', "Auto", "Decide for the whole file (vdbhair's rule)")))
    points_per_strand: IntProperty(name="Points per Strand", min=0, default=0,
                                   description="For a .ply of points only: each run of this many points is a strand")

    def execute(self, context):
        path = self.filepath
        try:
            vdbhair = loader.module()
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                strands = vdbhair.read(path, roots=self.roots, points_per_strand=self.points_per_strand)
            for w in caught:  # the reader's notes (dropped strands, reversed roots), not its up-axis advice
                if "upAxis is" not in str(w.message):  # to renderers: the import turns the axes itself
                    self.report({'WARNING'}, str(w.message))
            obj, text = import_strands(context, strands, os.path.basename(path), path, self.object_type,
                                       self.up_axis, self.unit, self.file_unit)
        except Exception as e:
            self.report({'ERROR'}, "vdbhair import: %s" % jobs.error_text(e))
            return {'CANCELLED'}
        self.report({'INFO'}, text)
        return {'FINISHED'}


def import_strands(context, strands, name, source, object_type, up_choice, unit, file_unit):
    """A new hair object in the active collection holding `strands`, selected and active."""
    if bpy.ops.object.mode_set.poll():  # as Blender's importers do: the new object in Object Mode
        bpy.ops.object.mode_set(mode='OBJECT')
    up = _up(up_choice, strands.up_axis)
    declared = strands.meters_per_unit
    meters_per_unit = UNITS[file_unit] if file_unit != 'NONE' else declared
    scale = 1.0
    if unit == 'SCENE':
        if meters_per_unit is None:
            raise ValueError("%s declares no unit: choose its File Unit to convert to the scene's unit" % name)
        scale = meters_per_unit / context.scene.unit_settings.scale_length
    hair = convert.from_strands(strands, up, scale)
    stem = os.path.splitext(name)[0]
    if object_type == 'CURVES':
        data = convert.build_curves(context, stem, hair)
    else:
        data = convert.build_legacy_curve(stem, hair)
    data[convert.PROP_UP], data[convert.PROP_SCALE], data[convert.PROP_SOURCE] = up, scale, source
    data[convert.PROP_DEFAULTS] = strands.defaults  # written back by the export (.hair headers keep them)
    if meters_per_unit is not None:
        data[convert.PROP_UNIT] = meters_per_unit
    obj = bpy.data.objects.new(data.name, data)
    context.collection.objects.link(obj)
    for o in list(context.view_layer.objects.selected):
        o.select_set(False)
    obj.select_set(True)
    context.view_layer.objects.active = obj
    text = "imported %d strands, %d points from %s as %s (%s; %s)" % (
        len(hair.counts), len(hair.positions), name, obj.name,
        "+Y up turned to Blender's +Z" if up == "Y" else "+Z up, not turned",
        "1 file unit = 1 Blender unit" if scale == 1.0 else "scaled by %g to the scene's unit" % scale)
    return obj, text


class EXPORT_SCENE_OT_vdbhair(bpy.types.Operator, ExportHelper):
    """Export hair objects (Curves and legacy curve objects) to a vdbhair strand format"""
    bl_idname = "export_scene.vdbhair"
    bl_label = "Export Hair Strands (vdbhair)"
    bl_options = {'REGISTER', 'PRESET'}

    filename_ext = ".hair"
    filter_glob: StringProperty(default=";".join("*" + e for _, e, _ in WRITE_FORMATS), options={'HIDDEN'})
    file_format: EnumProperty(name="Format", default='HAIR', items=[(k, e, d) for k, e, d in WRITE_FORMATS],
                              description="The format; a file name ending in another writable extension chooses that one")
    use_selection: BoolProperty(name="Selected Only", default=True,
                                description="The selected hair objects (else every hair object of the view layer)")
    apply_transform: BoolProperty(name="Apply Transform", default=True,
                                  description="World coordinates (the objects' transforms applied)")
    use_modifiers: BoolProperty(name="Apply Modifiers", default=True,
                                description="Hair Curves objects as evaluated (their modifiers applied)")
    up_axis: EnumProperty(name="Up", items=UP_ITEMS, default='AUTO')
    unit: EnumProperty(name="Unit", default='AUTO', items=(
        ('AUTO', "Auto", "Undo the import's scaling: the file's own unit; objects made in Blender in Blender "
                         "units, declared as the scene's unit length"),
        ('M', "Metres", "Converted from the scene's unit"), ('CM', "Centimetres", "Converted from the scene's unit"),
        ('MM', "Millimetres", "Converted from the scene's unit")))

    def check(self, context):
        """Keep the file name's extension that of the chosen format (as Blender's glTF exporter does)."""
        ext = dict((k, e) for k, e, _ in WRITE_FORMATS)[self.file_format]
        root, old = os.path.splitext(self.filepath)
        if old.lower() == ext:
            return False
        self.filepath = (root if old.lower() in READ_EXTENSIONS else self.filepath) + ext
        return True

    def execute(self, context):
        path = self.filepath
        ext = os.path.splitext(path)[1].lower()
        if ext not in [e for _, e, _ in WRITE_FORMATS]:
            path += dict((k, e) for k, e, _ in WRITE_FORMATS)[self.file_format]
        try:
            vdbhair = loader.module()
            objects = sorted((o for o in (context.view_layer.objects.selected if self.use_selection else context.view_layer.objects)
                              if o.type in convert.HAIR_TYPES), key=lambda o: o.name)
            if not objects:
                raise ValueError("no hair object to export (select a Curves or Curve object)")
            strands, up, notes = export_strands(context, vdbhair, objects, self.apply_transform, self.use_modifiers,
                                                self.up_axis, self.unit)
            options = {"usd_up": up.lower()} if path.lower().endswith(".usda") else {}
            vdbhair.write(strands, path, **options)
        except Exception as e:
            self.report({'ERROR'}, "vdbhair export: %s" % jobs.error_text(e))
            return {'CANCELLED'}
        for note in notes:
            self.report({'WARNING'}, note)
        self.report({'INFO'}, "exported %d strands, %d points from %d object(s) to %s"
                    % (len(strands), strands.num_vertices, len(objects), os.path.basename(path)))
        return {'FINISHED'}


def export_strands(context, vdbhair, objects, apply_transform, use_modifiers, up_choice, unit):
    """One vdbhair.Strands of the objects' strands, in name order. Returns (strands, up, warnings)."""
    depsgraph = context.evaluated_depsgraph_get() if use_modifiers else None
    scene_unit = context.scene.unit_settings.scale_length
    first = objects[0].data
    up = _up(up_choice, first.get(convert.PROP_UP))
    if unit == 'AUTO':
        declared = first.get(convert.PROP_UNIT) if convert.PROP_SCALE in first else scene_unit
    else:
        declared = UNITS[unit]
    parts, scales, notes = [], [], []
    for obj in objects:
        hair, warned = convert.read_object(obj, depsgraph)
        convert.check_strands(hair, obj.name)
        notes += warned
        if apply_transform:
            m = np.array(obj.matrix_world, dtype=np.float64)
            if not np.array_equal(m, np.identity(4)):  # identity: the coordinates as they are, exactly
                world = hair.positions.astype(np.float64) @ m[:3, :3].T + m[:3, 3]
                hair.positions = world.astype(np.float32)
                if "thickness" in hair.attrs:  # widths scale with the transform's mean scale
                    hair.attrs["thickness"] = (hair.attrs["thickness"] * abs(np.linalg.det(m[:3, :3])) ** (1 / 3)
                                               ).astype(np.float32)
        scale = obj.data.get(convert.PROP_SCALE, 1.0) if unit == 'AUTO' else UNITS[unit] / scene_unit
        parts.append(convert.to_strands(vdbhair, hair, _up(up_choice, obj.data.get(convert.PROP_UP)), scale))
        scales.append(scale)
    strands = parts[0] if len(parts) == 1 else concatenate(vdbhair, parts, notes)
    if declared is not None:
        strands.meters_per_unit = declared
    if convert.PROP_DEFAULTS in first:  # the first object's file defaults, its thickness in the output's unit
        defaults = first[convert.PROP_DEFAULTS].to_dict()
        defaults["color"] = tuple(defaults["color"])
        factor = first.get(convert.PROP_SCALE, 1.0) / scales[0]
        if factor != 1.0:
            defaults["thickness"] *= factor
        strands.defaults = defaults
    return strands, up, notes


def concatenate(vdbhair, parts, notes):
    """Strands of several objects in one set; an array is kept only when every object has it."""
    positions = np.concatenate([p.positions for p in parts])
    counts = np.concatenate([p.counts for p in parts])
    attrs = {}
    for name in ("thickness", "transparency", "color", "root_uv", "strand_id"):
        arrays = [getattr(p, name) for p in parts]
        if all(a is not None for a in arrays):
            attrs[name] = np.concatenate(arrays)
        elif any(a is not None for a in arrays):
            notes.append("%s dropped: not every exported object has it" % name)
    return vdbhair.Strands(positions, np.concatenate([[0], np.cumsum(counts)]), **attrs)


def menu_import(self, context):
    self.layout.operator(IMPORT_SCENE_OT_vdbhair.bl_idname, text="Hair Strands (vdbhair)")


def menu_export(self, context):
    self.layout.operator(EXPORT_SCENE_OT_vdbhair.bl_idname, text="Hair Strands (vdbhair)")


classes = (IMPORT_SCENE_OT_vdbhair, EXPORT_SCENE_OT_vdbhair)
