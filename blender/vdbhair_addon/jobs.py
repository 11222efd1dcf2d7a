"""Long vdbhair calls with progress in Blender's status bar and Esc to cancel.

A `Job` runs one vdbhair call in a worker thread (the call releases Python's lock while it works,
so Blender stays responsive and redraws). vdbhair calls `progress(stage, done, total, unit)` at
each stage's start and at most ten times a second; the job records it and, once cancelled, raises
`Cancelled` from inside it, which stops the C++ work and comes back out of the call. The result is
applied to the scene only after the call returned, so a cancelled or failed job changes nothing.

`HairJobOperator` is the base of the hair operators. Run from the UI (invoke) it is modal: a timer
shows the stage in the status bar and the cursor's progress, Esc cancels. Run from a script
(execute) it waits for the job; `progress_listeners` lets a script watch or cancel it.
"""
import shutil
import tempfile
import threading

import bpy

from . import convert, loader

# Callables fn(job, stage, done, total, unit), called from the worker thread at every progress
# report (before the cancel check): for scripts and tests that watch a job or call job.cancel().
progress_listeners = []


class Cancelled(Exception):
    """Raised inside vdbhair's progress callback to stop the call."""


class Job:
    def __init__(self, label, work):
        self.label = label          # "vdbhair refine"
        self.work = work            # work(progress) -> result; runs in the worker thread, no bpy
        self.result = None
        self.error = None
        self.stage = "starting"
        self.done, self.total, self.unit = 0, 0, ""
        self._cancel = threading.Event()
        self._thread = threading.Thread(target=self._run, name=label, daemon=True)

    def progress(self, stage, done, total, unit):
        self.stage, self.done, self.total, self.unit = stage, done, total, unit
        for listener in list(progress_listeners):
            listener(self, stage, done, total, unit)
        if self._cancel.is_set():
            raise Cancelled()

    def _run(self):
        try:
            self.result = self.work(self.progress)
        except BaseException as e:  # handed to the main thread, which reports it
            self.error = e

    def start(self):
        self._thread.start()

    def wait(self, timeout=None):
        self._thread.join(timeout)
        return not self._thread.is_alive()

    def running(self):
        return self._thread.is_alive()

    def cancel(self):
        self._cancel.set()

    @property
    def cancelled(self):
        return isinstance(self.error, (Cancelled, KeyboardInterrupt))

    def fraction(self):
        return min(1.0, self.done / self.total) if self.total else 0.0

    def status_text(self):
        count = " %d/%d %s" % (self.done, self.total, self.unit) if self.total else ""
        return "%s: %s%s  (Esc to cancel)" % (self.label, self.stage, count)


def error_text(error):
    """vdbhair's one-line messages (its errors are ValueError, OSError, LookupError or TypeError
    subclasses) and the add-on's own as they are; anything else (a bug) with its type."""
    text = str(error).strip()
    if isinstance(error, (ValueError, OSError, LookupError, TypeError, RuntimeError)) and text:
        return text
    return "%s: %s" % (type(error).__name__, text) if text else type(error).__name__


class HairJobOperator(bpy.types.Operator):
    """Base of the operators that run a vdbhair call on the active hair object."""
    bl_options = {'REGISTER', 'UNDO'}
    verb = ""  # the vdbhair function, for messages

    # Events the modal operator lets through, so the view can be turned while it works.
    NAVIGATION = {'MIDDLEMOUSE', 'WHEELUPMOUSE', 'WHEELDOWNMOUSE', 'MOUSEMOVE', 'INBETWEEN_MOUSEMOVE',
                  'TRACKPADPAN', 'TRACKPADZOOM', 'MOUSEROTATE', 'NDOF_MOTION'}

    @classmethod
    def poll(cls, context):
        obj = context.active_object
        return obj is not None and obj.type in convert.HAIR_TYPES

    # Subclasses: prepare(context, vdbhair) reads the scene and returns work(progress) -> result
    # (vdbhair calls only: it runs in the worker thread); apply(context, result) changes the scene
    # (the object the run started on is self.target()) and returns a line for the report.
    def prepare(self, context, vdbhair):
        raise NotImplementedError

    def apply(self, context, result):
        raise NotImplementedError

    def temp_path(self, name):
        """A path in a folder of this run's own, removed when the run ends (e.g. a head mesh)."""
        if getattr(self, "_tmpdir", None) is None:
            self._tmpdir = tempfile.mkdtemp(prefix="vdbhair_blender_")
        return "%s/%s" % (self._tmpdir, name)

    def _cleanup(self):
        if getattr(self, "_tmpdir", None) is not None:
            shutil.rmtree(self._tmpdir, ignore_errors=True)
            self._tmpdir = None

    def target(self):
        """The hair object the run started on (looked up again: the scene may change meanwhile)."""
        obj = bpy.data.objects.get(self._target)
        if obj is None:
            raise RuntimeError("the object %s was removed while vdbhair worked" % self._target)
        return obj

    def _start(self, context):
        self._tmpdir = None
        self._target = context.active_object.name
        try:
            vdbhair = loader.module()
            work = self.prepare(context, vdbhair)
        except Exception as e:  # bad input: one line, nothing changed
            self._cleanup()
            self.report({'ERROR'}, "vdbhair %s: %s" % (self.verb, error_text(e)))
            return None
        self._job = Job("vdbhair " + self.verb, work)
        self._job.start()
        return self._job

    def _finish(self, context):
        job = self._job
        self._cleanup()
        if job.cancelled:
            self.report({'WARNING'}, "%s: cancelled; %s is unchanged" % (job.label, self._target))
            return {'CANCELLED'}
        if job.error is not None:
            self.report({'ERROR'}, "%s: %s" % (job.label, error_text(job.error)))
            return {'CANCELLED'}
        try:
            message = self.apply(context, job.result)
        except Exception as e:
            self.report({'ERROR'}, "%s: %s" % (job.label, error_text(e)))
            return {'CANCELLED'}
        if message:
            self.report({'INFO'}, "%s: %s" % (job.label, message))
        return {'FINISHED'}

    def execute(self, context):
        if self._start(context) is None:
            return {'CANCELLED'}
        self._job.wait()
        return self._finish(context)

    def invoke(self, context, event):
        if context.window is None:  # no window (blender -b): nothing to show progress in
            return self.execute(context)
        if self._start(context) is None:
            return {'CANCELLED'}
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.progress_begin(0.0, 1.0)
        wm.modal_handler_add(self)
        return {'RUNNING_MODAL'}

    def modal(self, context, event):
        job = self._job
        if event.type == 'ESC' and event.value == 'PRESS':
            job.cancel()
        if job.running():
            if event.type == 'TIMER':
                context.workspace.status_text_set(job.status_text())
                context.window_manager.progress_update(job.fraction())
            return {'PASS_THROUGH'} if event.type in self.NAVIGATION else {'RUNNING_MODAL'}
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        context.workspace.status_text_set(None)
        return self._finish(context)
