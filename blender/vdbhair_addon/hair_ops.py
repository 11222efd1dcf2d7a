"""Operators on the active hair object: refine, interpolate, synth and comb.

Each reads the object's strands in its own (local) coordinates turned to vdbhair's +Y up (exact,
see convert.py), so lengths such as the voxel size are in the object's Blender units and vdbhair's
up-dependent defaults hold. The options are defined once, in the *Options classes, which both
the operators and the panel's scene settings (ui.py) use; their defaults are vdbhair's.
"""
import bpy
import numpy as np
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty

from . import convert, jobs

HEAD_ITEMS = (
    ('FITTED', "Fitted Sphere", "A sphere fitted to the roots (vdbhair's default)"),
    ('SURFACE', "Surface Object", "The hair's surface mesh (the Curves object's Surface; Sculpt Mode's Surface Set)"),
    ('NONE', "None", "No head: strands may go anywhere"),
)


def head_option():
    return EnumProperty(name="Head", items=HEAD_ITEMS, default='FITTED',
                        description="What the strands are kept out of (vdbhair's head=)")


class RefineOptions:
    voxel_size: FloatProperty(name="Voxel Size", subtype='DISTANCE', min=0.0, default=0.0,
                              description="The finest level's voxel size (0: vdbhair's suggestion from the strands)")
    levels: IntProperty(name="Levels", min=1, max=8, default=1,
                        description="Levels, coarse (voxel size times 2^(levels-1)) to fine")
    mode: EnumProperty(name="Mode", default='consistent', items=(
        ('consistent', "Consistent", "Fix only the strands that stray from the flow"),
        ('field', "Field", "The paper's rule: every strand replaced by its streamline")))
    iterations: IntProperty(name="Iterations", min=1, max=50, default=2,
                            description="Iterations of each field's robust estimation (Wang et al. Eq. 9)")
    head: head_option()


class InterpolateOptions:
    guides: EnumProperty(name="Guides", default='SELECTED', items=(
        ('SELECTED', "Selected Curves", "The curves selected in Sculpt Mode are the guides; every other curve is "
                                        "regrown from them at its own root"),
        ('OBJECT', "Other Selected Object", "Every curve of the other selected hair object is a guide; every curve "
                                            "of the active object is regrown at its own root")))
    method: EnumProperty(name="Method", default='points', items=(
        ('points', "Points", "Blend the guides' own points by group and likeness of shape"),
        ('helicoid', "Helicoid", "Blend the guides' fitted helicoid parameters (Piuze et al. Sec. 4)")))
    neighbors: IntProperty(name="Neighbors", min=0, default=0,
                           description="Blend the K nearest guides (0: vdbhair's default, 4 for points, all for helicoid)")
    clump_radius: FloatProperty(name="Clump Radius", subtype='DISTANCE', min=0.0, default=0.0,
                                description="Hairs within this distance of a clump centre are pulled to its hair (0: none)")
    curl: FloatProperty(name="Curl", subtype='DISTANCE', min=0.0, default=0.0,
                        description="Amplitude of the waviness about each hair (0: none)")
    curl_frequency: FloatProperty(name="Curl Frequency", min=0.0, default=0.0,
                                  description="Waviness frequency, radians per unit length")
    frizz: FloatProperty(name="Frizz", subtype='DISTANCE', min=0.0, default=0.0,
                         description="Deviation of a random offset across each hair at its tip")
    head: head_option()


class SynthOptions:
    levels: IntProperty(name="Levels", min=2, max=5, default=3,
                        description="Levels of the hierarchy, the strands included")
    strands: IntProperty(name="Strands", min=0, default=0,
                         description="Strands in the new hairstyle (0: the example's density)")
    vertices: IntProperty(name="Vertices", min=2, default=64, description="Vertices a strand")
    seed: IntProperty(name="Seed", min=0, default=0)
    refine: BoolProperty(name="Refine", default=True, description="Refine every level (Wang et al. Sec. 5.3)")


class CombOptions:
    radius: FloatProperty(name="Radius", subtype='DISTANCE', min=0.0, default=0.0,
                          description="Reach of each stroke (0: a tenth of the hair's bounding-box diagonal)")
    strength: FloatProperty(name="Strength", min=0.0, max=1.0, default=1.0, subtype='FACTOR')
    smoothing: FloatProperty(name="Smoothing", min=0.0, default=0.125,
                             description="Sigma of the strand directions the strokes turn, a fraction of the vertices")
    levels: IntProperty(name="Levels", min=1, max=5, default=2, description="Levels of the wisp hierarchy")
    seed: IntProperty(name="Seed", min=0, default=0)
    head: head_option()


OPTIONS = {"refine": RefineOptions, "interpolate": InterpolateOptions, "synth": SynthOptions, "comb": CombOptions}


def option_names(options):
    return [name for cls in options.__mro__ for name in getattr(cls, "__annotations__", {})]


# Reading the scene ------------------------------------------------------------------------------

def object_strands(vdbhair, obj):
    """(HairArrays in Blender coordinates, vdbhair.Strands turned +Y up) of a hair object's own data."""
    hair, _ = convert.read_object(obj)
    convert.check_strands(hair, obj.name)
    return hair, convert.to_strands(vdbhair, hair, "Y")


def to_local(obj, world_points):
    """World-space points (N, 3) into obj's local coordinates, turned +Y up."""
    m = np.array(obj.matrix_world.inverted(), dtype=np.float64)
    p = np.asarray(world_points, dtype=np.float64) @ m[:3, :3].T + m[:3, 3]
    return convert.from_blender(p.astype(np.float32), "Y")


def head_argument(op, context, obj, choice):
    """vdbhair's head= for the choice: None (fitted sphere), "none", or a PLY of the surface mesh
    in the hair object's coordinates, written into the run's temporary folder."""
    if choice == 'FITTED':
        return None
    if choice == 'NONE':
        return "none"
    surface = obj.data.surface if obj.type == 'CURVES' else None
    if surface is None or surface.type != 'MESH':
        raise ValueError("%s has no surface mesh (set one in Sculpt Mode: Curves > Surface Set, or choose "
                         "another head)" % obj.name)
    evaluated = surface.evaluated_get(context.evaluated_depsgraph_get())
    mesh = evaluated.to_mesh()
    try:
        mesh.calc_loop_triangles()
        verts = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
        mesh.vertices.foreach_get("co", verts)
        tris = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
        mesh.loop_triangles.foreach_get("vertices", tris)
    finally:
        evaluated.to_mesh_clear()
    world = verts.reshape(-1, 3).astype(np.float64) @ np.array(surface.matrix_world)[:3, :3].T \
        + np.array(surface.matrix_world)[:3, 3]
    return write_ply(op.temp_path("head.ply"), to_local(obj, world), tris.reshape(-1, 3))


def write_ply(path, vertices, triangles):
    """A binary little-endian PLY triangle mesh (what vdbhair's mesh reader takes)."""
    header = ("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
              "property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n"
              % (len(vertices), len(triangles)))
    faces = np.zeros(len(triangles), dtype=[("n", "u1"), ("v", "<i4", (3,))])
    faces["n"], faces["v"] = 3, triangles
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(np.ascontiguousarray(vertices, dtype="<f4").tobytes())
        f.write(faces.tobytes())
    return path


def other_selected_hair(context, obj, kind):
    """The selected objects of the given types other than the active one, by name."""
    return sorted((o for o in context.view_layer.objects.selected if o != obj and o.type in kind), key=lambda o: o.name)


# Operators --------------------------------------------------------------------------------------

class VDBHAIR_OT_refine(jobs.HairJobOperator, RefineOptions):
    """Refine the active hair object through its own tangent field (vdbhair refine; Wang et al. 2009, Sec. 5.3)"""
    bl_idname = "vdbhair.refine"
    bl_label = "Refine Hair"
    verb = "refine"

    def prepare(self, context, vdbhair):
        obj = context.active_object
        _, strands = object_strands(vdbhair, obj)
        head = head_argument(self, context, obj, self.head)
        options = dict(voxel_size=self.voxel_size, levels=self.levels, mode=self.mode,
                       iterations=self.iterations, head=head)
        return lambda progress: vdbhair.refine(strands, progress=progress, **options)

    def apply(self, context, result):
        obj = self.target()
        convert.replace_geometry(context, obj, convert.from_strands(result, "Y"))
        return "refined %d strands of %s" % (len(result), obj.name)


class VDBHAIR_OT_interpolate(jobs.HairJobOperator, InterpolateOptions):
    """Regrow hair from guide curves (vdbhair interpolate; Piuze et al. 2011, Sec. 4): every curve that is not a guide is replaced by a new hair at its own root"""
    bl_idname = "vdbhair.interpolate"
    bl_label = "Interpolate Hair"
    verb = "interpolate"

    @classmethod
    def poll(cls, context):
        obj = context.active_object
        return obj is not None and obj.type == 'CURVES'

    def prepare(self, context, vdbhair):
        obj = context.active_object
        hair, strands = object_strands(vdbhair, obj)
        n = len(hair.counts)
        if self.guides == 'SELECTED':
            selected = convert.selected_curves(obj.data)
            if selected is None or len(selected) in (0, n):
                raise ValueError("%s: select the guide curves in Sculpt Mode (selection at least 0.5) and leave "
                                 "the curves to regrow unselected; %s of %d curves are selected"
                                 % (obj.name, "all" if selected is None else len(selected), n))
            guides = convert.to_strands(vdbhair, hair.subset(selected), "Y")
            regrow = np.setdiff1d(np.arange(n), selected)
        else:
            others = other_selected_hair(context, obj, convert.HAIR_TYPES)
            if len(others) != 1:
                raise ValueError("select one other hair object as the guides (found %d)" % len(others))
            source, _ = convert.read_object(others[0])
            convert.check_strands(source, others[0].name)
            world = source.positions.astype(np.float64) @ np.array(others[0].matrix_world)[:3, :3].T \
                + np.array(others[0].matrix_world)[:3, 3]
            guides = vdbhair.Strands(to_local(obj, world), source.offsets)
            regrow = np.arange(n)
        roots = strands.positions[strands.offsets[regrow]]
        head = head_argument(self, context, obj, self.head)
        options = dict(method=self.method, neighbors=self.neighbors or None, head=head,
                       clump_radius=self.clump_radius, curl=self.curl, curl_frequency=self.curl_frequency,
                       frizz=self.frizz)
        self._keep, self._regrow, self._hair = np.setdiff1d(np.arange(n), regrow), regrow, hair
        return lambda progress: vdbhair.interpolate(guides, roots, progress=progress, **options)

    def apply(self, context, result):
        obj, hair, regrow, keep = self.target(), self._hair, self._regrow, self._keep
        new = convert.from_strands(result, "Y")
        # Curve i keeps its place: guides as they were, every other curve the new hair at its root.
        pieces = [None] * len(hair.counts)
        for i in keep:
            pieces[i] = hair.positions[hair.offsets[i]:hair.offsets[i + 1]]
        for j, i in enumerate(regrow):
            pieces[i] = new.positions[new.offsets[j]:new.offsets[j + 1]]
        counts = [len(p) for p in pieces]
        combined = convert.HairArrays(np.concatenate(pieces), np.concatenate([[0], np.cumsum(counts)]))
        convert.replace_geometry(context, obj, combined)
        if self.guides == 'SELECTED':  # the guides stay selected for the next run
            mark = np.zeros(len(counts), dtype=np.float32)
            mark[keep] = 1.0
            a = obj.data.attributes.get(".selection_curve_float") \
                or obj.data.attributes.new(".selection_curve_float", 'FLOAT', 'CURVE')
            a.data.foreach_set("value", mark)
        return "regrew %d of %d curves of %s from %d guides" % (len(regrow), len(counts), obj.name,
                                                               len(keep) if self.guides == 'SELECTED' else 0)


class VDBHAIR_OT_synth(jobs.HairJobOperator, SynthOptions):
    """Make a new hair object in the style of the active one (vdbhair synth; Wang et al. 2009, Sec. 3-5)"""
    bl_idname = "vdbhair.synth"
    bl_label = "Synthesize Hair"
    verb = "synth"

    def prepare(self, context, vdbhair):
        _, strands = object_strands(vdbhair, context.active_object)
        options = dict(levels=self.levels, strands=self.strands or None, vertices=self.vertices,
                       seed=self.seed, refine=self.refine)
        return lambda progress: vdbhair.synth(strands, progress=progress, **options)

    def apply(self, context, result):
        example = self.target()
        hair = convert.from_strands(result, "Y")
        with convert.object_mode(context):
            if example.type == 'CURVES':
                data = convert.build_curves(context, example.name + "_synth", hair)
                data.surface, data.surface_uv_map = example.data.surface, example.data.surface_uv_map
            else:
                data = convert.build_legacy_curve(example.name + "_synth", hair)
            for m in example.data.materials:
                data.materials.append(m)
            convert.copy_recorded(example.data, data)
            obj = bpy.data.objects.new(data.name, data)
            for collection in example.users_collection:
                collection.objects.link(obj)
            obj.parent, obj.matrix_world = example.parent, example.matrix_world.copy()
            example.select_set(False)
            obj.select_set(True)
            context.view_layer.objects.active = obj
        return "made %s: %d strands in the style of %s" % (obj.name, len(result), example.name)


class VDBHAIR_OT_comb(jobs.HairJobOperator, CombOptions):
    """Comb the active hair object along strokes: the splines of the other selected curve objects (vdbhair comb; Wang et al. 2009, Sec. 6)"""
    bl_idname = "vdbhair.comb"
    bl_label = "Comb Hair"
    verb = "comb"

    def prepare(self, context, vdbhair):
        obj = context.active_object
        hair, strands = object_strands(vdbhair, obj)
        stroke_objects = other_selected_hair(context, obj, {'CURVE'})
        if not stroke_objects:
            raise ValueError("select one or more curve objects to comb along (each spline a stroke), "
                             "then the hair object last (active)")
        radius = self.radius
        if radius <= 0.0:
            radius = 0.1 * float(np.linalg.norm(hair.positions.max(axis=0) - hair.positions.min(axis=0)))
        strokes = []
        for stroke_object in stroke_objects:
            splines, _ = convert.read_legacy_curve(stroke_object.data)
            m = np.array(stroke_object.matrix_world, dtype=np.float64)
            world = splines.positions.astype(np.float64) @ m[:3, :3].T + m[:3, 3]
            local = to_local(obj, world)
            for i in range(len(splines.counts)):
                points = local[splines.offsets[i]:splines.offsets[i + 1]]
                strokes.append({"points": points.tolist(), "radius": radius, "strength": self.strength})
        head = head_argument(self, context, obj, self.head)
        options = dict(smoothing=self.smoothing, levels=self.levels, seed=self.seed, head=head)
        return lambda progress: vdbhair.comb(strands, strokes, progress=progress, **options)

    def apply(self, context, result):
        obj = self.target()
        convert.replace_geometry(context, obj, convert.from_strands(result, "Y"))
        return "combed %d strands of %s" % (len(result), obj.name)


classes = (VDBHAIR_OT_refine, VDBHAIR_OT_interpolate, VDBHAIR_OT_synth, VDBHAIR_OT_comb)
