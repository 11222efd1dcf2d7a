"""The operators as a user runs them, with a window (under xvfb-run; `blender -b` has none):
    xvfb-run -a blender --factory-startup --enable-event-simulate --python test_modal.py -- ADDON_PARENT CLI OUT
Refine is invoked from the 3D View; it runs modal, vdbhair works in a thread and reports its
progress, and an Esc (simulated) stops it with the object unchanged. Invoked again, it finishes
and changes the object as `bpy.ops.vdbhair.refine()` does. A listener slows the progress reports so
that the Esc comes mid-run. Runs from a timer: failures print FAIL and quit with status 1."""
import os
import sys
import time
import traceback

sys.path.insert(0, os.path.dirname(__file__))
import bpy  # noqa: E402
import numpy as np  # noqa: E402

import addon_test  # noqa: E402
from addon_test import OUT, PONYTAIL, check, object_arrays  # noqa: E402

try:  # a GUI Blender does not exit on a script's error: fail here with status 1
    addon = addon_test.enable_addon(empty=False)  # --factory-startup: the default window with a 3D View
    bpy.context.preferences.filepaths.temporary_directory = OUT  # quit.blend goes there, not to /tmp
    addon_test.new_scene()
    bpy.ops.import_scene.vdbhair(filepath=PONYTAIL)
    obj = bpy.context.view_layer.objects.active
    before = object_arrays(obj)[0]
    window = bpy.context.window_manager.windows[0]
    area = next(a for a in window.screen.areas if a.type == 'VIEW_3D')
except BaseException:
    traceback.print_exc()
    print("FAIL: setting up the modal run", flush=True)
    os._exit(1)
reports = []


def slow(job, stage, done, total, unit):
    reports.append((job, job.status_text()))
    time.sleep(0.2)  # in the worker thread: the window keeps handling events meanwhile


def invoke(**options):
    with bpy.context.temp_override(window=window, area=area):
        return bpy.ops.vdbhair.refine('INVOKE_DEFAULT', **options)


def wait_for(condition, seconds):
    """A generator for the timer: yields until condition() or the time is up."""
    end = time.time() + seconds
    while not condition() and time.time() < end:
        yield


def steps():
    addon.jobs.progress_listeners.append(slow)
    check(invoke(levels=3) == {'RUNNING_MODAL'}, "refine invoked from the 3D View runs modal")
    yield from wait_for(lambda: len(reports) >= 2, 10)
    check(reports[-1][0].running(), "vdbhair works in its thread: %s" % reports[-1][1])
    window.event_simulate(type='ESC', value='PRESS')
    window.event_simulate(type='ESC', value='RELEASE')
    job = reports[-1][0]
    yield from wait_for(lambda: not job.running(), 10)
    check(job.cancelled, "Esc cancelled the job after %d progress reports" % len(reports))
    check(np.array_equal(object_arrays(obj)[0], before), "the object is unchanged")
    addon.jobs.progress_listeners.remove(slow)
    check(invoke() == {'RUNNING_MODAL'}, "refine invoked again")
    yield from wait_for(lambda: not np.array_equal(object_arrays(obj)[0], before), 20)
    modal = object_arrays(obj)[0]
    obj.data.position_data.foreach_set("vector", before.ravel())
    bpy.ops.vdbhair.refine()
    check(np.array_equal(object_arrays(obj)[0], modal), "the modal run changed the object as the script call does")
    print("ok: modal checked")


runner = steps()


def tick():
    try:
        next(runner)
        return 0.05
    except StopIteration:
        bpy.ops.wm.quit_blender()
    except BaseException:  # SystemExit from check() included: say why, exit with status 1
        traceback.print_exc()
        print("FAIL: the modal run stopped early", flush=True)
        os._exit(1)
    return None


bpy.app.timers.register(tick, first_interval=0.5)
