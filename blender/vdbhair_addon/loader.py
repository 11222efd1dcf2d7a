"""Finding the `vdbhair` Python module from inside Blender.

The module is a compiled extension built for one Python (Debian's /usr/bin/python3 by default).
Blender can load it only when Blender itself runs that Python, as Debian's `blender` package does.
The copy of this add-on that CMake makes in the build tree holds `_build_info.py`, which names the
directory of the module it was built with; the add-on tries a plain `import vdbhair` first (an
installed module, or PYTHONPATH), then that directory. When both fail, `problem()` says why, in
words a user can act on; the panel, the preferences and every operator show it.
"""
import importlib
import os
import sys

try:  # Written by CMake into the build tree's copy only (blender/CMakeLists.txt).
    from . import _build_info as build_info
except ImportError:
    build_info = None

_module = None
_problem = None
_attempts = []  # (where, error) of each failed import, for the message


def _try_import(where):
    global _module
    try:
        _module = importlib.import_module("vdbhair")
        return True
    except ImportError as e:  # also a module built for another Python's ABI, or a missing library
        _attempts.append((where, "%s: %s" % (type(e).__name__, e)))
        return False


def load(retry=False):
    """Import vdbhair once; return the module or None (then problem() says why). With retry, a
    failed import is tried again (enabling the add-on does: after installing the module)."""
    global _problem
    if retry and _module is None:
        _problem = None
        _attempts.clear()
    if _module is not None or _problem is not None:
        return _module
    if _try_import("the default sys.path"):
        return _module
    module_dir = getattr(build_info, "MODULE_DIR", None)
    if module_dir:
        if module_dir not in sys.path:
            sys.path.insert(0, module_dir)
        if _try_import(module_dir):
            return _module
        sys.path.remove(module_dir)  # leave Blender's path as it was
    _problem = _describe_problem(module_dir)
    return None


def module():
    """The vdbhair module; raises RuntimeError with the full explanation when it cannot load."""
    m = load()
    if m is None:
        raise RuntimeError(_problem)
    return m


def problem():
    """None when vdbhair loaded, else a paragraph saying why and what to do."""
    load()
    return _problem


def status():
    """One line for the panel and preferences: which vdbhair loaded, or that none did."""
    m = load()
    if m is None:
        return "vdbhair module not loaded"
    return "vdbhair module: %s" % getattr(m, "__file__", "?")


def _describe_problem(module_dir):
    here = "%d.%d" % sys.version_info[:2]
    library = os.path.dirname(os.__file__)  # /usr/lib/python3.11 for Debian's Blender (sys.executable can mislead)
    built_for = getattr(build_info, "PYTHON_EXECUTABLE", None)
    built_version = getattr(build_info, "PYTHON_VERSION", None)
    lines = ["Blender's Python (Python %s, library %s) cannot load the vdbhair module." % (here, library)]
    for where, error in _attempts:
        lines.append("Tried %s: %s" % (where, error))
    if not module_dir:
        lines.append("This copy of the add-on names no build directory (copy build/blender/vdbhair_addon "
                     "from a vdbhair build, or put the module on PYTHONPATH).")
    elif not os.path.isdir(module_dir):
        lines.append("The recorded build directory %s does not exist any more: rebuild vdbhair, "
                     "or reinstall the add-on from the new build." % module_dir)
    if built_for:
        lines.append("The module was built for %s (Python %s)." % (built_for, built_version))
    lines.append("An official blender.org build runs its own bundled Python and cannot load a module built "
                 "for the system's Python: use Debian's blender package (apt-get install blender), which runs "
                 "/usr/bin/python3, or configure vdbhair with -DPython_EXECUTABLE=<Blender's python> "
                 "(with its headers and NumPy) and build again.")
    return "\n".join(lines)
