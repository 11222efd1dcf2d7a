"""Every function and method names a wrong argument's type in the library's words, never with
pybind11's generic "incompatible function arguments" (issue 50)."""
import inspect
import re

import numpy as np
import pytest

import vdbhair


def signature(f):
    if inspect.isfunction(f) and not hasattr(f, "__wrapped__"):  # a verb made from declared parameters
        parts = []
        for p in inspect.signature(f).parameters.values():
            if p.kind == p.KEYWORD_ONLY and "*" not in parts:
                parts.append("*")
            annotation = ": vdbhair.Strands" if p.name == "strands" else ""
            parts.append(p.name + annotation + ("" if p.default is p.empty else " = " + repr(p.default)))
        return ", ".join(parts)
    for line in (f.__doc__ or "").splitlines():
        m = re.match(r"^\s*(?:\d+\.\s*)?" + re.escape(f.__name__) + r"\((.*)\)\s*(?:->.*)?$", line)
        if m and m.group(1) != "*args, **kwargs":
            return m.group(1)
    return None


def split(text):
    depth, cur, out = 0, "", []
    for ch in text:
        depth += ch in "[(" and 1 or ch in "])" and -1 or 0
        if ch == "," and depth == 0:
            out.append(cur.strip())
            cur = ""
        else:
            cur += ch
    return out + ([cur.strip()] if cur.strip() else [])


def test_no_call_with_a_wrong_type_gets_the_generic_message(tmp_path):
    hair = vdbhair.Strands(np.array([[0, 0, 0], [0, 1, 0], [1, 0, 0], [1, 1, 0]], dtype=np.float32), np.array([0, 2, 4]))
    path = str(tmp_path / "a.hair")
    vdbhair.write(hair, path)
    wrong, calls, generic = object(), 0, []
    for name in dir(vdbhair):
        f = getattr(vdbhair, name)
        if name.startswith("_") or not callable(f) or isinstance(f, type):
            continue
        params = [p for p in split(signature(f) or "") if p != "*"]
        kwonly = split(signature(f) or "").index("*") if "*" in split(signature(f) or "") else len(params)
        for i, p in enumerate(params):
            pname = p.split(":")[0].strip()
            if pname == "progress":
                continue
            args, kwargs = [], {}
            for j, q in enumerate(params):
                qname, has_default = q.split(":")[0].strip(), "=" in q
                if j == i:
                    if j >= kwonly or has_default:
                        kwargs[qname] = wrong
                    else:
                        args.append(wrong)
                elif not has_default:
                    args.append(hair if "Strands" in q else path if "str" in q or "PathLike" in q else 1)
            calls += 1
            try:
                f(*args, **kwargs)
            except Exception as e:  # noqa: BLE001 - any error but the generic one is the point
                if "incompatible function arguments" in str(e):
                    generic.append(f"{name}({pname}=object())")
                elif isinstance(e, vdbhair.ArgumentTypeError):
                    assert str(e).startswith(name + ": "), str(e)
    assert calls > 200
    assert generic == []


def test_the_message_names_the_argument_the_type_it_must_have_and_what_it_got():
    with pytest.raises(vdbhair.ArgumentTypeError, match=r"^read: strict must be a bool \(True or False\), got str$"):
        vdbhair.read("a.hair", strict="yes")
    with pytest.raises(TypeError, match=r"^read: path must be a path \(str or os.PathLike such as pathlib.Path\), got int$"):
        vdbhair.read(3)
    with pytest.raises(vdbhair.ArgumentTypeError, match=r"^write: no argument named codek; its arguments are strands, path, ply_encoding"):
        vdbhair.write(vdbhair.Strands(np.zeros((2, 3)), [0, 2]), "a.vdb", codek="float")
    with pytest.raises(TypeError, match=r"unexpected keyword argument 'stric'"):  # read() is made from its declaration, as the verbs are
        vdbhair.read("a.hair", stric=True)
    with pytest.raises(vdbhair.ArgumentTypeError, match=r"^write: path is required$"):
        vdbhair.write(vdbhair.Strands(np.zeros((2, 3)), [0, 2]))
    hair = vdbhair.Strands(np.zeros((2, 3)), [0, 2])
    with pytest.raises(vdbhair.ArgumentTypeError, match=r"^Strands.write: ply_encoding must be a str, got int$"):
        hair.write("x.ply", ply_encoding=1)
    assert issubclass(vdbhair.ArgumentTypeError, vdbhair.Error) and issubclass(vdbhair.ArgumentTypeError, TypeError)
