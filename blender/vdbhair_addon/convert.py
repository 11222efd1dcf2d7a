"""Strands between vdbhair's arrays and Blender's hair objects.

Axes. vdbhair's convention is +Y up; Blender's is +Z up. A +Y-up strand file comes into Blender
turned +90 degrees about X, in the coordinates themselves: Blender (x, y, z) = file (x, -z, y),
the turn Blender's OBJ and glTF importers make (the OBJ importer puts it in the object's
transform; here the object keeps an identity transform, so hair tools, the 3D cursor and a surface
mesh see upright hair). Going back is file (x, y, z) = Blender (x, z, -y). Both are a swap and a
sign change, exact in floating point, so vdbhair -> Blender -> vdbhair gives back every bit.
A +Z-up file (a USD stage declaring upAxis Z, or hair modelled Z-up) comes in unturned.

Units. By default one file unit is one Blender unit (nothing is scaled, exact). The import can
instead convert to the scene's unit; the factor is recorded on the object's data and the export
undoes it (then exact only to float rounding).

Blender 3.4's Python cannot size a hair `Curves` datablock, so new hair is built as a legacy curve
of poly splines and converted with `object.convert(target='CURVES')`, which keeps the splines'
order and every coordinate (measured: bit-identical, 4,933 and 10,000 strands).
"""
import contextlib

import bpy
import numpy as np

# Properties recorded on an imported object's data, read back by the export and the operators.
PROP_UP = "vdbhair_up_axis"            # "Y" or "Z": the file's up axis as imported
PROP_SCALE = "vdbhair_scale"           # Blender units per file unit applied by the import
PROP_UNIT = "vdbhair_meters_per_unit"  # the file's unit in metres, when known
PROP_SOURCE = "vdbhair_source"         # the imported file
PROP_DEFAULTS = "vdbhair_defaults"     # the file's per-vertex defaults (a cyHair header's), file units
RECORDED = (PROP_UP, PROP_SCALE, PROP_UNIT, PROP_SOURCE, PROP_DEFAULTS)

HAIR_TYPES = {'CURVES', 'CURVE'}

# vdbhair's per-strand and per-vertex arrays and the Blender attributes that carry them.
# thickness (a diameter) is Blender's radius times two.
POINT_ATTRS = (("color", 'FLOAT_COLOR'), ("transparency", 'FLOAT'))
CURVE_ATTRS = (("strand_id", 'INT'), ("root_uv", 'FLOAT2'))
STRAND_ARRAYS = {name for name, _ in CURVE_ATTRS}  # one value a strand; the others one a vertex


def to_blender(positions, up):
    """File coordinates (V, 3) with up axis `up` ("Y" or "Z") to Blender's Z-up coordinates."""
    p = np.asarray(positions, dtype=np.float32)
    if up == "Z":
        return np.array(p, dtype=np.float32)
    return np.stack([p[:, 0], -p[:, 2], p[:, 1]], axis=1)


def from_blender(positions, up):
    """Blender coordinates (V, 3) to a file's coordinates with up axis `up`; exact inverse of to_blender."""
    q = np.asarray(positions, dtype=np.float32)
    if up == "Z":
        return np.array(q, dtype=np.float32)
    return np.stack([q[:, 0], q[:, 2], -q[:, 1]], axis=1)


class HairArrays:
    """Strands in Blender's coordinates: positions (V, 3) float32, offsets (S+1,) int64, and the
    optional arrays named as vdbhair names them (thickness, color, transparency, strand_id, root_uv)."""

    def __init__(self, positions, offsets, **attrs):
        self.positions = np.ascontiguousarray(positions, dtype=np.float32).reshape(-1, 3)
        self.offsets = np.asarray(offsets, dtype=np.int64)
        self.attrs = {k: v for k, v in attrs.items() if v is not None}

    @property
    def counts(self):
        return np.diff(self.offsets)

    def subset(self, strands):
        """The strands whose indices are given, in that order."""
        counts = self.counts[strands]
        offsets = np.concatenate([[0], np.cumsum(counts)])
        vertex = np.concatenate([np.arange(self.offsets[i], self.offsets[i + 1]) for i in strands]) \
            if len(strands) else np.zeros(0, np.int64)
        attrs = {k: v[strands] if k in STRAND_ARRAYS else v[vertex] for k, v in self.attrs.items()}
        return HairArrays(self.positions[vertex], offsets, **attrs)


def _scaled(values, factor):
    if values is None or factor == 1.0:
        return values
    return (np.asarray(values, dtype=np.float64) * factor).astype(np.float32)


def to_strands(vdbhair, hair, up, scale=1.0):
    """vdbhair.Strands in file coordinates (up axis `up`, file units = Blender units / scale)."""
    a = hair.attrs
    return vdbhair.Strands(_scaled(from_blender(hair.positions, up), 1.0 / scale), hair.offsets,
                           thickness=_scaled(a.get("thickness"), 1.0 / scale), color=a.get("color"),
                           transparency=a.get("transparency"), root_uv=a.get("root_uv"),
                           strand_id=a.get("strand_id"))


def from_strands(strands, up, scale=1.0):
    """HairArrays in Blender coordinates from vdbhair.Strands in file coordinates."""
    return HairArrays(_scaled(to_blender(strands.positions, up), scale), strands.offsets,
                      thickness=_scaled(strands.thickness, scale), color=strands.color,
                      transparency=strands.transparency, root_uv=strands.root_uv,
                      strand_id=strands.strand_id)


# Reading hair objects ---------------------------------------------------------------------------

def _attribute(data, name, domain, data_type):
    """The attribute of that name, domain and type, else None (a colour may be either kind)."""
    a = data.attributes.get(name)
    types = {'FLOAT_COLOR', 'BYTE_COLOR'} if data_type == 'FLOAT_COLOR' else {data_type}
    if a is None or a.domain != domain or a.data_type not in types:
        return None
    return a


def _get(attribute, count, width, key="value", dtype=np.float32):
    values = np.empty(count * width, dtype=dtype)
    attribute.data.foreach_get(key, values)
    return values.reshape(count, width) if width > 1 else values


def read_curves(curves):
    """A hair Curves datablock's control points and attributes. Returns (HairArrays, warnings)."""
    n_points, n_curves = len(curves.points), len(curves.curves)
    positions = np.empty(n_points * 3, dtype=np.float32)
    if n_points:
        curves.position_data.foreach_get("vector", positions)
    offsets = np.empty(n_curves + 1, dtype=np.int32)
    curves.curve_offset_data.foreach_get("value", offsets)
    attrs = {}
    radius = _attribute(curves, "radius", 'POINT', 'FLOAT')
    if radius is not None:
        attrs["thickness"] = _get(radius, n_points, 1) * np.float32(2)
    for name, data_type in POINT_ATTRS:
        a = _attribute(curves, name, 'POINT', data_type)
        if a is not None:
            attrs[name] = _get(a, n_points, 4, "color")[:, :3] if data_type == 'FLOAT_COLOR' else _get(a, n_points, 1)
    for name, data_type in CURVE_ATTRS:
        a = _attribute(curves, name, 'CURVE', data_type)
        if a is not None:
            attrs[name] = _get(a, n_curves, 1, dtype=np.int32) if data_type == 'INT' else _get(a, n_curves, 2, "vector")
    warnings = []
    types = _attribute(curves, "curve_type", 'CURVE', 'INT8')
    if types is not None and n_curves:
        kinds = set(_get(types, n_curves, 1, dtype=np.int8).tolist())
        if 3 in kinds:  # CURVE_TYPE_NURBS: control points off the curve
            warnings.append("%s: NURBS curves are written as their control points" % curves.name)
    return HairArrays(positions.reshape(-1, 3), offsets, **attrs), warnings


def read_legacy_curve(curve):
    """A legacy curve's splines as strands: poly and NURBS splines' points, Bezier splines' control
    points (handles dropped); thickness from the points' radius unless every radius is Blender's
    default, 1 (a curve drawn or imported without one). Returns (HairArrays, warnings)."""
    chunks, radii, counts, warnings = [], [], [], []
    for spline in curve.splines:
        pts = spline.bezier_points if spline.type == 'BEZIER' else spline.points
        n = len(pts)
        width = 3 if spline.type == 'BEZIER' else 4
        co = np.empty(n * width, dtype=np.float32)
        pts.foreach_get("co", co)
        r = np.empty(n, dtype=np.float32)
        pts.foreach_get("radius", r)
        chunks.append(co.reshape(n, width)[:, :3])
        radii.append(r)
        counts.append(n)
        if spline.type != 'POLY' and not warnings:
            warnings.append("%s: Bezier and NURBS splines are written as their control points" % curve.name)
    positions = np.concatenate(chunks) if chunks else np.zeros((0, 3), np.float32)
    offsets = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    radius = np.concatenate(radii) if radii else None
    thickness = radius * np.float32(2) if radius is not None and np.any(radius != 1.0) else None
    return HairArrays(positions, offsets, thickness=thickness), warnings


def read_object(obj, depsgraph=None):
    """The strands of a hair object in its own (local) coordinates; with a depsgraph, a Curves
    object's evaluated data (modifiers applied). Returns (HairArrays, warnings)."""
    if obj.type == 'CURVES':
        data = obj.evaluated_get(depsgraph).data if depsgraph is not None else obj.data
        return read_curves(data)
    if obj.type == 'CURVE':
        return read_legacy_curve(obj.data)
    raise ValueError("%s is a %s object, not hair (a Curves or Curve object)" % (obj.name, obj.type.lower()))


def check_strands(hair, name):
    """Every strand needs two points (vdbhair's rule); say which one breaks it."""
    short = np.flatnonzero(hair.counts < 2)
    if len(short):
        raise ValueError("%s: curve %d has %d point(s); a strand needs at least 2"
                         % (name, int(short[0]), int(hair.counts[short[0]])))


def selected_curves(curves):
    """Indices of the curves selected in Sculpt Mode (selection at least 0.5 on the curve, or on
    any of its points), or None when the object has no selection (Blender: all selected)."""
    n_curves = len(curves.curves)
    a = _attribute(curves, ".selection_curve_float", 'CURVE', 'FLOAT')
    if a is not None:
        return np.flatnonzero(_get(a, n_curves, 1) >= 0.5)
    a = _attribute(curves, ".selection_point_float", 'POINT', 'FLOAT')
    if a is not None:
        offsets = np.empty(n_curves + 1, dtype=np.int32)
        curves.curve_offset_data.foreach_get("value", offsets)
        values = _get(a, len(curves.points), 1) >= 0.5
        hit = np.maximum.reduceat(values, offsets[:-1]) if n_curves else np.zeros(0, bool)
        return np.flatnonzero(hit)
    return None


# Building hair objects --------------------------------------------------------------------------

@contextlib.contextmanager
def object_mode(context):
    """Object Mode for the duration (object.convert needs it), then the active object's mode again."""
    obj = context.view_layer.objects.active
    mode = obj.mode if obj is not None else 'OBJECT'
    if mode != 'OBJECT':
        bpy.ops.object.mode_set(mode='OBJECT')
    try:
        yield
    finally:
        if mode != 'OBJECT' and obj.name in bpy.data.objects:
            context.view_layer.objects.active = obj
            bpy.ops.object.mode_set(mode=mode)


def build_legacy_curve(name, hair):
    """A legacy curve datablock of poly splines, one a strand, radius = thickness / 2."""
    curve = bpy.data.curves.new(name, 'CURVE')
    curve.dimensions = '3D'
    co = np.ones((len(hair.positions), 4), dtype=np.float32)
    co[:, :3] = hair.positions
    thickness = hair.attrs.get("thickness")
    offsets, counts = hair.offsets, hair.counts
    for i in range(len(counts)):
        spline = curve.splines.new('POLY')
        spline.points.add(int(counts[i]) - 1)
        spline.points.foreach_set("co", co[offsets[i]:offsets[i + 1]].ravel())
        if thickness is not None:
            spline.points.foreach_set("radius", thickness[offsets[i]:offsets[i + 1]] * np.float32(0.5))
    return curve


def _set(attribute, values, key="value"):
    attribute.data.foreach_set(key, np.ascontiguousarray(values).ravel())


def build_curves(context, name, hair):
    """A hair Curves datablock holding `hair` (positions, order and attributes exact)."""
    with object_mode(context):
        curves = _convert_legacy(context, build_legacy_curve(name, hair))
    # The conversion's defaults, absent when they say nothing (radius 1 would be a metre-wide hair).
    for attr in ("tilt", "cyclic") + (() if "thickness" in hair.attrs else ("radius",)):
        if attr in curves.attributes:
            curves.attributes.remove(curves.attributes[attr])
    write_attributes(curves, hair)
    return curves


def _convert_legacy(context, legacy):
    """object.convert(target='CURVES') on a temporary object holding `legacy`; the selection and
    the active object are left as they were, the temporary object and `legacy` removed."""
    temp = bpy.data.objects.new(legacy.name, legacy)
    context.scene.collection.objects.link(temp)
    view_layer = context.view_layer
    active, selected = view_layer.objects.active, list(view_layer.objects.selected)
    try:
        for o in selected:
            o.select_set(False)
        view_layer.objects.active = temp
        temp.select_set(True)
        bpy.ops.object.convert(target='CURVES')
        curves = temp.data
        if temp.type != 'CURVES':
            raise RuntimeError("Blender's object.convert did not make a Curves object")
    finally:
        bpy.data.objects.remove(temp)
        # Blender 3.4's convert leaves the legacy datablock with a user count but no user.
        if legacy.name in bpy.data.curves:
            legacy.user_clear()
            bpy.data.curves.remove(legacy)
        for o in selected:
            if o.name in bpy.data.objects:
                o.select_set(True)
        view_layer.objects.active = active
    return curves


def write_attributes(curves, hair):
    """Set the optional arrays of `hair` as attributes of `curves` (same topology)."""
    if "thickness" in hair.attrs:
        a = curves.attributes.get("radius") or curves.attributes.new("radius", 'FLOAT', 'POINT')
        _set(a, hair.attrs["thickness"] * np.float32(0.5))
    for name, data_type in POINT_ATTRS + CURVE_ATTRS:
        values = hair.attrs.get(name)
        if values is None:
            continue
        domain = 'CURVE' if (name, data_type) in CURVE_ATTRS else 'POINT'
        if name in curves.attributes:
            curves.attributes.remove(curves.attributes[name])
        a = curves.attributes.new(name, data_type, domain)
        if data_type == 'FLOAT_COLOR':
            rgba = np.ones((len(values), 4), dtype=np.float32)
            rgba[:, :3] = values
            _set(a, rgba, "color")
        elif data_type == 'FLOAT2':
            _set(a, values.astype(np.float32), "vector")
        else:
            _set(a, values.astype(np.int32 if data_type == 'INT' else np.float32))


def copy_recorded(source, target):
    """Carry the import's record (up axis, unit, scale, source) from one datablock to another."""
    for key in RECORDED:
        if key in source:
            target[key] = source[key]


def replace_geometry(context, obj, hair):
    """Give `obj` the strands `hair` (local coordinates), in Object Mode (the mode is restored).
    Positions are written in place when the topology is the same (attributes, selection, spline
    settings and everything else kept); otherwise a new datablock replaces the old one, keeping
    materials, the surface and the import's record."""
    with object_mode(context):
        if not _write_in_place(obj.data, hair):
            _replace_data(context, obj, hair)


def _write_in_place(data, hair):
    """Write the positions into `data` if it has the topology of `hair` (poly splines only for a
    legacy curve); return whether it did."""
    counts = hair.counts
    if isinstance(data, bpy.types.Curves):
        if len(data.points) != len(hair.positions) or len(data.curves) != len(counts):
            return False
        offsets = np.empty(len(data.curves) + 1, dtype=np.int32)
        data.curve_offset_data.foreach_get("value", offsets)
        if not np.array_equal(offsets, hair.offsets):
            return False
        data.position_data.foreach_set("vector", hair.positions.ravel())
        data.update_tag()
        return True
    splines = data.splines
    if len(splines) != len(counts) or any(s.type != 'POLY' or len(s.points) != n for s, n in zip(splines, counts)):
        return False
    for i, spline in enumerate(splines):
        co = np.empty(len(spline.points) * 4, dtype=np.float32)
        spline.points.foreach_get("co", co)  # (x, y, z, w): each point's weight w is kept
        co = co.reshape(-1, 4)
        co[:, :3] = hair.positions[hair.offsets[i]:hair.offsets[i + 1]]
        spline.points.foreach_set("co", co.ravel())
    data.update_tag()
    return True


def _replace_data(context, obj, hair):
    old = obj.data
    if obj.type == 'CURVES':
        new = build_curves(context, old.name, hair)
        new.surface, new.surface_uv_map = old.surface, old.surface_uv_map
    else:
        new = build_legacy_curve(old.name, hair)
        for attr in ("bevel_depth", "bevel_resolution", "use_fill_caps"):
            setattr(new, attr, getattr(old, attr))
    for m in old.materials:
        new.materials.append(m)
    copy_recorded(old, new)
    obj.data = new
    if old.users == 0:
        (bpy.data.hair_curves if obj.type == 'CURVES' else bpy.data.curves).remove(old)
