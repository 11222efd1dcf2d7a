"""What the Blender tests share. Each test runs inside Blender (headless):
    blender -b --factory-startup --python-exit-code 1 --python TEST.py -- ADDON_PARENT CLI OUT
ADDON_PARENT is the build tree's folder holding vdbhair_addon/ and vdbhair_addon.zip
(build/blender), CLI the vdbhair program, OUT a folder for the test's files. A failed check raises
SystemExit("FAIL: ..."), which makes Blender exit with status 1."""
import os
import subprocess
import sys
import time

import bpy
import numpy as np

args = sys.argv[sys.argv.index("--") + 1:]
ADDON_PARENT, CLI, OUT = args[0], args[1], args[2]
SOURCE_DIR = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
PONYTAIL = os.path.join(SOURCE_DIR, "scenes", "default", "ponytail.hair")
os.makedirs(OUT, exist_ok=True)


def fail(message):
    raise SystemExit("FAIL: " + message)


def check(condition, message):
    """Print what was checked; fail with the message when it does not hold."""
    if not condition:
        fail(message)
    print("ok: " + message)


def out(name):
    return os.path.join(OUT, name)


def cli(*arguments):
    """Run the vdbhair command; fail with its stderr when it fails."""
    run = subprocess.run([CLI, *arguments, "--quiet"], capture_output=True, text=True)
    if run.returncode != 0:
        fail("vdbhair %s: exit %d: %s" % (" ".join(arguments), run.returncode, run.stderr.strip()))


def enable_addon(empty=True):
    """Register the build tree's add-on (its folder on sys.path, as Blender's add-on folder would
    be); return the add-on package. empty: in a factory-fresh, empty scene (else the scene as it is)."""
    import addon_utils
    if ADDON_PARENT not in sys.path:
        sys.path.insert(0, ADDON_PARENT)
    if empty:
        bpy.ops.wm.read_factory_settings(use_empty=True)
    module = addon_utils.enable("vdbhair_addon", default_set=True, handle_error=lambda e: fail("enable: %s" % e))
    if module is None:
        fail("the add-on did not enable")
    return module


def new_scene():
    """An empty scene for the next case (reading the factory settings again would disable the add-on)."""
    for collection in (bpy.data.objects, bpy.data.hair_curves, bpy.data.curves, bpy.data.meshes):
        for item in list(collection):
            collection.remove(item)
    bpy.context.scene.unit_settings.scale_length = 1.0


def object_arrays(obj):
    """(positions (V, 3) in Blender's coordinates, offsets (S+1,)) of a hair Curves or Curve object."""
    if obj.type == 'CURVES':
        c = obj.data
        p = np.empty(len(c.points) * 3, np.float32)
        c.position_data.foreach_get("vector", p)
        o = np.empty(len(c.curves) + 1, np.int32)
        c.curve_offset_data.foreach_get("value", o)
        return p.reshape(-1, 3), o.astype(np.int64)
    chunks, counts = [], []
    for s in obj.data.splines:
        co = np.empty(len(s.points) * 4, np.float32)
        s.points.foreach_get("co", co)
        chunks.append(co.reshape(-1, 4)[:, :3])
        counts.append(len(s.points))
    return np.concatenate(chunks), np.concatenate([[0], np.cumsum(counts)])


def y_up_to_blender(p):
    """vdbhair's +Y up to Blender's +Z up, written out here independently of the add-on."""
    p = np.asarray(p, np.float32)
    return np.stack([p[:, 0], -p[:, 2], p[:, 1]], axis=1)


def blender_to_y_up(q):
    q = np.asarray(q, np.float32)
    return np.stack([q[:, 0], q[:, 2], -q[:, 1]], axis=1)


def same_strands(what, a_positions, a_offsets, b_positions, b_offsets, tolerance=0.0):
    """Check two strand sets: the same counts in the same order, positions equal (or within
    `tolerance`, world units); print the largest difference."""
    check(np.array_equal(np.asarray(a_offsets), np.asarray(b_offsets)),
          "%s: the same %d strands in the same order, the same vertex counts" % (what, len(b_offsets) - 1))
    diff = float(np.abs(np.asarray(a_positions, np.float64) - np.asarray(b_positions, np.float64)).max())
    if tolerance == 0.0:
        check(diff == 0.0, "%s: every position identical (%d vertices)" % (what, len(b_positions)))
    else:
        check(diff <= tolerance, "%s: positions within %g (largest difference %.3g)" % (what, tolerance, diff))


def run_operator(op, **options):
    """Call an operator; return (result, seconds). An error report raises RuntimeError (Blender's way)."""
    start = time.perf_counter()
    result = op(**options)
    return result, time.perf_counter() - start


def expect_error(op, needle, **options):
    """The operator must fail with an error report containing `needle`; return the message."""
    try:
        op(**options)
    except RuntimeError as e:
        message = str(e)
        check(needle in message, "error report says %r: %s" % (needle, message.strip()))
        return message
    fail("expected an error report containing %r" % needle)
