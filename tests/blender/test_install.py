"""Installing the build tree's zip as a user does (Preferences > Add-ons > Install, then enable),
into the scripts folder BLENDER_USER_SCRIPTS names (the test's own, never the user's):
- when Blender's Python cannot load vdbhair, the add-on still enables and says why, what was
  tried and what to do, in its preferences, its panel and every operator's error; nothing is created;
- otherwise it finds the module it was built with (the recorded build directory, not PYTHONPATH),
  registers its menus, operators, panel and settings, and unregisters them all when disabled."""
import os
import sys
import types

sys.path.insert(0, os.path.dirname(__file__))
import addon_utils  # noqa: E402
import bpy  # noqa: E402

from addon_test import ADDON_PARENT, OUT, PONYTAIL, check, expect_error, fail  # noqa: E402

scripts = os.environ.get("BLENDER_USER_SCRIPTS")
if not scripts or not os.path.abspath(scripts).startswith(os.path.abspath(OUT)):
    fail("BLENDER_USER_SCRIPTS must name a folder under the test's OUT folder (the install must not touch the user's)")
check(not any(os.path.isfile(os.path.join(p, "vdbhair_addon", "__init__.py")) for p in sys.path),
      "vdbhair_addon is not on sys.path before the install")

bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.preferences.addon_install(filepath=os.path.join(ADDON_PARENT, "vdbhair_addon.zip"), overwrite=True)
installed = os.path.join(bpy.utils.user_resource('SCRIPTS', path="addons"), "vdbhair_addon")
check(installed.startswith(os.path.abspath(scripts)) and os.path.isfile(os.path.join(installed, "_build_info.py")),
      "the zip installed into %s with its _build_info.py" % installed)


class Layout:
    """Stands in for a UILayout to run the panel's and preferences' draw() headless: records labels."""

    def __init__(self, lines):
        self.lines, self.alert = lines, False

    def label(self, text="", icon='NONE'):
        self.lines.append(text)

    def box(self):
        return self

    def prop(self, data, name):
        if not hasattr(data, name):
            fail("the panel draws a setting %s that does not exist" % name)

    def operator(self, idname, text="", icon='NONE'):
        category, name = idname.split(".")
        known = getattr(getattr(bpy.ops, category), name).get_rna_type().properties.keys()

        class Properties:  # the operator's properties the panel sets must exist
            def __setattr__(_, prop, value):
                if prop not in known:
                    fail("the panel sets %s.%s, which the operator does not have" % (idname, prop))
        self.lines.append("[%s]" % text)
        return Properties()


def draw(cls):
    lines = []
    cls.draw(types.SimpleNamespace(layout=Layout(lines)), bpy.context)  # draw() uses self.layout only
    return "\n".join(lines)


# 1. vdbhair cannot be imported (as in an official blender.org build): the add-on says so.
sys.modules["vdbhair"] = None  # makes every `import vdbhair` fail, as a module built for another Python does
addon_utils.enable("vdbhair_addon", default_set=True, handle_error=lambda e: fail("enable: %s" % e))
addon = sys.modules["vdbhair_addon"]
problem = addon.loader.problem() or ""
print(problem)
check("cannot load the vdbhair module" in problem and "Python %d.%d" % sys.version_info[:2] in problem,
      "the problem names Blender's Python and its version")
check("Tried the default sys.path" in problem and "Tried %s" % addon.loader.build_info.MODULE_DIR in problem,
      "the problem lists both places tried")
check("official blender.org build" in problem and "apt-get install blender" in problem
      and "-DPython_EXECUTABLE" in problem, "the problem says what to do")
shown = draw(addon.ui.VDBHAIR_AP_preferences)
check("official blender.org build" in shown.replace("\n", " "), "the preferences show it")
check("cannot load the vdbhair" in draw(addon.ui.VDBHAIR_PT_hair).replace("\n", " "), "the panel shows it")
expect_error(bpy.ops.import_scene.vdbhair, "official blender.org build", filepath=PONYTAIL)
check(len(bpy.data.objects) == 0, "the failed import created nothing")
addon_utils.disable("vdbhair_addon", default_set=True)
del sys.modules["vdbhair"]

# 2. The module loads from the recorded build directory (enabling again reloads the add-on's modules).
addon_utils.enable("vdbhair_addon", default_set=True, handle_error=lambda e: fail("enable: %s" % e))
addon = sys.modules["vdbhair_addon"]
check(addon.loader.problem() is None, "the add-on loaded vdbhair")
import vdbhair  # noqa: E402
module_dir = addon.loader.build_info.MODULE_DIR
check(os.path.dirname(vdbhair.__file__) == module_dir, "from the build directory it recorded: %s" % vdbhair.__file__)
check(module_dir not in os.environ.get("PYTHONPATH", "").split(os.pathsep), "which is not on PYTHONPATH")
for idname in ("IMPORT_SCENE_OT_vdbhair", "EXPORT_SCENE_OT_vdbhair", "VDBHAIR_OT_refine", "VDBHAIR_OT_interpolate",
               "VDBHAIR_OT_synth", "VDBHAIR_OT_comb", "VDBHAIR_PT_hair"):
    check(hasattr(bpy.types, idname), "%s is registered" % idname)
check(addon.io_ops.menu_import in bpy.types.TOPBAR_MT_file_import._dyn_ui_initialize()
      and addon.io_ops.menu_export in bpy.types.TOPBAR_MT_file_export._dyn_ui_initialize(),
      "File > Import and File > Export have the entries")
settings = bpy.context.scene.vdbhair
check(settings.refine.levels == 1 and settings.refine.mode == 'consistent' and settings.synth.levels == 3
      and abs(settings.comb.smoothing - 0.125) < 1e-7, "the panel's settings start at vdbhair's defaults")
panel = draw(addon.ui.VDBHAIR_PT_hair)
check(all("[%s]" % b in panel for b in ("Refine", "Interpolate", "Synthesize", "Comb")), "the panel has the four operators")
check(addon.loader.status() in draw(addon.ui.VDBHAIR_AP_preferences), "the preferences name the module loaded")
addon_utils.disable("vdbhair_addon", default_set=True)
check(not hasattr(bpy.types, "VDBHAIR_OT_refine") and not hasattr(bpy.types.Scene, "vdbhair"),
      "disabling unregisters everything")
print("ok: install checked")
