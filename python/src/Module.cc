// The `vdbhair` Python module (issue 18): strands as NumPy arrays and the toolkit's operations.
#include "Common.h"

#include <vdbhair/Version.h>
#include <vdbhair/io/VdbFile.h>

#include <pybind11/eval.h>

namespace {
const char* kArgumentTypeCheck = R"py(
import functools as _functools, numbers as _numbers, os as _os, re as _re

class ArgumentTypeError(Error, TypeError):
    """An argument of the wrong type, named with the type it must have (also a TypeError)."""

ArgumentTypeError.__module__ = "vdbhair"

def _split(text):
    depth, cur, out, quote = 0, "", [], None
    for ch in text:
        if quote:
            cur += ch
            if ch == quote: quote = None
            continue
        if ch in "'\"": quote = ch
        elif ch in "[(": depth += 1
        elif ch in "])": depth -= 1
        if ch == "," and depth == 0 and not quote:
            out.append(cur.strip()); cur = ""
        else:
            cur += ch
    if cur.strip(): out.append(cur.strip())
    return out

def _signature(name, doc):
    for line in (doc or "").splitlines():
        m = _re.match(r"^\s*(?:\d+\.\s*)?" + _re.escape(name) + r"\((.*)\)\s*(?:->.*)?$", line)
        if m and m.group(1) != "*args, **kwargs":
            params, kwonly = [], False
            for p in _split(m.group(1)):
                if p == "*": kwonly = True; continue
                head, _, default = p.partition("=")
                pname, _, ann = head.partition(":")
                params.append((pname.strip(), ann.strip(), bool(default.strip()), kwonly))
            return m.group(0).strip().lstrip("0123456789. "), params
    return None, None

def _inner(ann, prefix):
    return ann[len(prefix):-1]

def _accepts(ann, v):
    if ann.startswith("Optional["): return v is None or _accepts(_inner(ann, "Optional["), v)
    if ann.startswith("Union["): return any(_accepts(a, v) for a in _split(_inner(ann, "Union[")))
    if ann in ("", "object", "Any") or ann.startswith("numpy.ndarray") or ann.startswith("Buffer"): return True
    if ann == "os.PathLike | str": return isinstance(v, (str, bytes, _os.PathLike))
    if ann == "str": return isinstance(v, str)
    if ann == "bool": return isinstance(v, bool) or type(v).__name__ == "bool_"
    if ann == "int": return isinstance(v, _numbers.Integral) or hasattr(v, "__index__")
    if ann == "float": return isinstance(v, _numbers.Real) or hasattr(v, "__float__") or hasattr(v, "__index__")
    if ann.startswith("Callable"): return callable(v)
    if ann.startswith("Dict["): return isinstance(v, dict)
    if ann.startswith(("List[", "Tuple[", "Sequence[", "Annotated[")): return hasattr(v, "__iter__") and not isinstance(v, (str, bytes, dict))
    if ann.startswith("vdbhair."):
        cls = globals().get(ann.split(".", 1)[1])
        return not isinstance(cls, type) or isinstance(v, cls)
    return True

def _expected(ann):
    if ann.startswith("Optional["): return _expected(_inner(ann, "Optional[")) + " or None"
    if ann.startswith("Union["): return " or ".join(_expected(a) for a in _split(_inner(ann, "Union[")))
    return {"os.PathLike | str": "a path (str or os.PathLike such as pathlib.Path)", "str": "a str", "bool": "a bool (True or False)",
            "int": "an integer", "float": "a number"}.get(ann) or (
        "a callable" if ann.startswith("Callable") else "a dict" if ann.startswith("Dict[") else
        "a sequence (" + ann + ")" if ann.startswith(("List[", "Tuple[", "Sequence[", "Annotated[")) else
        "a " + ann if ann.startswith("vdbhair.") else ann)

def _explain(name, params, args, kwargs):
    names = [p[0] for p in params]
    positional = [p for p in params if not p[3]]
    if len(args) > len(positional):
        return "%s: takes %d positional argument(s) (%s), got %d" % (name, len(positional), ", ".join(p[0] for p in positional), len(args))
    for k in kwargs:
        if k not in names:
            return "%s: no argument named %s; its arguments are %s" % (name, k, ", ".join(names))
    given = dict(zip([p[0] for p in positional], args))
    for k, v in kwargs.items():
        if k in given: return "%s: %s given twice (by position and by keyword)" % (name, k)
        given[k] = v
    for pname, ann, has_default, kwonly in params:
        if pname not in given:
            if not has_default: return "%s: %s is required" % (name, pname)
            continue
        v = given[pname]
        if not _accepts(ann, v):
            return "%s: %s must be %s, got %s" % (name, pname, _expected(ann), type(v).__name__)
    return None

def _check_keywords(name, checks):
    for k, ann, v in checks:
        if not _accepts(ann, v):
            raise ArgumentTypeError("%s: %s must be %s, got %s" % (name, k, _expected(ann), type(v).__name__))
def _wrap(qualname, f):
    sig, params = _signature(f.__name__, f.__doc__)
    if params is None: return f
    if params and params[0][0] == "self": params = params[1:]
    @_functools.wraps(f)
    def checked(*args, **kwargs):
        try:
            return f(*args, **kwargs)
        except TypeError as e:
            text = str(e)
            if "incompatible function arguments" not in text: raise
            rest = args[1:] if qualname != f.__name__ else args
            why = _explain(qualname, params, rest, kwargs)
            if why is None: why = "%s: the arguments do not match %s" % (qualname, sig)
            raise ArgumentTypeError(why) from None
    return checked

for _n, _f in list(globals().items()):
    if _n.startswith("_") or not callable(_f) or isinstance(_f, type): continue
    if type(_f).__name__ == "builtin_function_or_method": globals()[_n] = _wrap(_n, _f)
for _cn, _cls in list(globals().items()):
    if not isinstance(_cls, type) or _cls.__module__ != "vdbhair" or issubclass(_cls, BaseException): continue
    for _mn, _m in list(vars(_cls).items()):
        if _mn.startswith("_") or type(_m).__name__ != "instancemethod": continue
        setattr(_cls, _mn, _wrap(_cls.__name__ + "." + _mn, _m.__func__))
)py";
} // namespace

PYBIND11_MODULE(vdbhair, m)
{
    namespace py = vdbhair::py;
    namespace pyb = pybind11;
    m.doc() = R"doc(vdbhair: hair geometry on OpenVDB, from Python.

Strands are NumPy arrays (vdbhair.Strands: positions (V, 3) float32, offsets (S+1,) int64);
fields are sparse VDB grids with NumPy access (vdbhair.TangentField, vdbhair.Grid).

    import vdbhair, numpy as np
    hair = vdbhair.read("hair.hair")
    field = vdbhair.estimate_tangent_field(hair, voxel_size=0.5)
    np.save("orientation.npy", field.to_dense())           # (D, H, W, 3) float32
    smooth = vdbhair.retrace(hair, field)
    vdbhair.write(smooth, "smooth.vdb")

Long calls release the GIL, take ``threads=`` (0: all cores; results never depend on it) and
``progress=`` (a callable progress(stage, done, total, unit)), and stop on Ctrl-C with
KeyboardInterrupt. Errors are vdbhair.Error subclasses that are also the matching built-in
exceptions (IoError is an OSError; FormatError, ArgumentError, UnsupportedError and LimitError
are ValueErrors; NotFoundError a LookupError; GridTypeError and ArgumentTypeError TypeErrors), with
the library's one-line messages. Paths may be str or any os.PathLike (pathlib.Path).)doc";
    m.attr("__version__") = VDBHAIR_VERSION_STRING;
    vdbhair::initializeOpenVdb();
    py::registerExceptions(m);
    py::bindStrands(m);
    py::bindFields(m);
    py::bindOperations(m);
    py::bindSynthesis(m);
    py::bindScalp(m);
    py::bindDataset(m);
    // Arguments of the wrong type: instead of pybind11's "incompatible function arguments" with
    // every overload's signature, the library's kind of message, naming the function, the
    // argument, the type it must have and the type it got ("read: strict must be a bool (True or
    // False), got str"), as vdbhair.ArgumentTypeError (a vdbhair.Error and a TypeError). Every
    // function and method is wrapped once, here; the check runs only after pybind11 refused the
    // call, so a good call costs one Python frame.
    pyb::exec(kArgumentTypeCheck, m.attr("__dict__"));
}
