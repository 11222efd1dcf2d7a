"""The sidebar panel (3D View > Sidebar > vdbhair), the add-on's preferences and the scene settings
the panel edits. The panel's buttons run the operators with those settings."""
import textwrap

import bpy
from bpy.props import PointerProperty

from . import hair_ops, loader


def draw_problem(layout, width=70):
    """The module's status; when it could not load, the whole explanation, wrapped."""
    problem = loader.problem()
    if problem is None:
        layout.label(text=loader.status(), icon='CHECKMARK')
        return False
    box = layout.box()
    box.alert = True
    for paragraph in problem.split("\n"):
        for line in textwrap.wrap(paragraph, width):
            box.label(text=line)
    return True


# One PropertyGroup per operator, with the operator's own options (hair_ops.*Options).
settings_classes = {
    verb: type("VDBHAIR_PG_%s" % verb, (bpy.types.PropertyGroup, options), {})
    for verb, options in hair_ops.OPTIONS.items()
}
VDBHAIR_PG_settings = type("VDBHAIR_PG_settings", (bpy.types.PropertyGroup,), {
    "__annotations__": {verb: PointerProperty(type=cls) for verb, cls in settings_classes.items()}})


class VDBHAIR_PT_hair(bpy.types.Panel):
    bl_label = "vdbhair"
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = "vdbhair"

    def draw(self, context):
        layout = self.layout
        if draw_problem(layout, 40):
            return
        obj = context.active_object
        if obj is None or obj.type not in {'CURVES', 'CURVE'}:
            layout.label(text="Make a hair object active (Curves or Curve)", icon='INFO')
        settings = context.scene.vdbhair
        for verb, label, icon in (("refine", "Refine", 'MOD_SMOOTH'), ("interpolate", "Interpolate", 'CURVES'),
                                  ("synth", "Synthesize", 'DUPLICATE'), ("comb", "Comb", 'BRUSH_DATA')):
            box = layout.box()
            box.label(text=label)
            group = getattr(settings, verb)
            names = hair_ops.option_names(hair_ops.OPTIONS[verb])
            for name in names:
                box.prop(group, name)
            op = box.operator("vdbhair." + verb, text=label, icon=icon)
            for name in names:
                setattr(op, name, getattr(group, name))
        layout.label(text="Esc cancels a running operation")


class VDBHAIR_AP_preferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    def draw(self, context):
        draw_problem(self.layout, 100)


classes = tuple(settings_classes.values()) + (VDBHAIR_PG_settings, VDBHAIR_PT_hair, VDBHAIR_AP_preferences)
