"""The Python keyword defaults and the command's defaults are the library's, so they agree:
each keyword below against what `vdbhair <verb> --help` shows for the flag that sets the same
parameter. Both come from the library's parameter structs (FieldParams, TraceParams,
RefineParams, ...); a default restated in either front end fails here once it drifts."""
import inspect
import os
import pathlib
import re
import subprocess

import pytest

import vdbhair

# (function, keyword, verb, flag)
PAIRS = [
    ("estimate_tangent_field", "iterations", "field", "--iterations"),
    ("estimate_tangent_field", "max_voxels", "field", "--max-voxels"),
    ("retrace", "integrator", "retrace", "--integrator"),
    ("retrace", "vanish", "retrace", "--vanish"),
    ("retrace", "max_steps", "retrace", "--max-steps"),
    ("retrace", "margin", "retrace", "--margin"),
    ("retrace", "vertices", "retrace", "--vertices"),
    ("refine", "levels", "refine", "--levels"),
    ("refine", "mode", "refine", "--mode"),
    ("refine", "iterations", "refine", "--iterations"),
    ("refine", "outlier_start", "refine", "--outlier-start"),
    ("refine", "outlier_full", "refine", "--outlier-full"),
    ("refine", "min_spread", "refine", "--min-spread"),
    ("refine", "head_policy", "refine", "--head-policy"),
    ("refine", "integrator", "refine", "--integrator"),
    ("refine", "margin", "refine", "--margin"),
    ("refine", "max_voxels", "refine", "--max-voxels"),
    ("grow", "max_vertices", "grow", "--max-vertices"),
    ("fit", "max_error", "fit", "--max-error"),
    ("fit", "max_pieces", "fit", "--max-pieces"),
    ("fit", "max_evaluations", "fit", "--max-evaluations"),
    ("fit", "prefit_iterations", "fit", "--prefit-iterations"),
    ("interpolate", "power", "interpolate", "--power"),
    ("interpolate", "max_vertices", "interpolate", "--max-vertices"),
    ("interpolate", "clump_radius", "interpolate", "--clump-radius"),
    ("interpolate", "clump_tightness", "interpolate", "--clump-tightness"),
    ("interpolate", "clump_profile", "interpolate", "--clump-profile"),
    ("interpolate", "clump_likeness", "interpolate", "--clump-likeness"),
    ("interpolate", "curl", "interpolate", "--curl"),
    ("interpolate", "curl_frequency", "interpolate", "--curl-frequency"),
    ("interpolate", "frizz", "interpolate", "--frizz"),
    ("render", "view", "render", "--view"),
    ("render", "width", "render", "--width"),
    ("render", "height", "render", "--height"),
    ("render", "color_by", "render", "--color-by"),
    ("synth", "levels", "synth", "--levels"),
    ("synth", "vertices", "synth", "--vertices"),
    ("synth", "threshold", "synth", "--threshold"),
    ("synth", "components", "synth", "--components"),
    ("synth", "map_spacing", "synth", "--map-spacing"),
    ("synth", "detail", "synth", "--detail"),
    ("synth", "detail_scale", "synth", "--detail-scale"),
    ("synth", "match_balance", "synth", "--match-balance"),
    ("synth", "match_candidates", "synth", "--match-candidates"),
    ("transfer", "detail_scale", "transfer", "--detail-scale"),
    ("transfer", "match_balance", "transfer", "--match-balance"),
    ("transfer", "match_candidates", "transfer", "--match-candidates"),
    ("transfer", "smoothing", "transfer", "--smoothing"),
    ("comb", "smoothing", "comb", "--smoothing"),
    ("comb", "levels", "comb", "--levels"),
    ("prepare", "points", "prepare", "--points"),
    ("prepare", "count", "prepare", "--strands"),
    ("prepare", "overlap", "prepare", "--overlap"),
    ("prepare", "head_crop", "prepare", "--head-crop"),
    ("prepare", "root_depth", "prepare", "--root-depth"),
    ("strand_statistics", "bins", "info", "--bins"),
]


def cli():
    """The `vdbhair` command of the same build (VDBHAIR_CLI, else bin/ next to the module's python/)."""
    path = os.environ.get("VDBHAIR_CLI") or str(pathlib.Path(vdbhair.__file__).resolve().parents[1] / "bin" / "vdbhair")
    assert os.access(path, os.X_OK), f"no vdbhair command at {path} (set VDBHAIR_CLI)"
    return path


def keyword_defaults(name):
    """The keyword defaults of a function: its signature's for a verb made from declared parameters
    (a Python function), else pybind11's signature line."""
    function = getattr(vdbhair, name)
    if inspect.isfunction(function) and not hasattr(function, "__wrapped__"):
        return {k: repr(p.default) for k, p in inspect.signature(function).parameters.items() if p.default is not p.empty}
    signature = function.__doc__.splitlines()[0]
    return dict(re.findall(r"(\w+): [\w.\[\], ]+? = ([^,()]+|\([^)]*\))", signature))


def flag_defaults(verb, cache={}):
    """The defaults `vdbhair VERB --help` shows (`--flag TYPE=default`)."""
    if verb not in cache:
        text = subprocess.run([cli(), verb, "--help"], capture_output=True, text=True, check=True).stdout
        cache[verb] = dict(re.findall(r"^\s+(?:-\w,)?(--[\w-]+) [A-Z]+(?::\S+?)?=(\S+)", text, re.M))
    return cache[verb]


def same(python_value, cli_value):
    python_value = python_value.strip().strip("'")
    if cli_value.endswith("%"):  # reconstruct --guides 10%: a fraction in Python
        return abs(float(python_value) * 100.0 - float(cli_value[:-1])) < 1e-9
    if python_value in ("True", "False"):
        return python_value.lower() == cli_value
    try:
        return float(python_value) == float(cli_value)
    except ValueError:
        return python_value == cli_value


@pytest.mark.parametrize("function, keyword, verb, flag", PAIRS, ids=[f"{f}.{k}" for f, k, _, _ in PAIRS])
def test_python_defaults_are_the_commands(function, keyword, verb, flag):
    python = keyword_defaults(function)
    shown = flag_defaults(verb)
    assert keyword in python, f"{function}() has no keyword default for {keyword}: {sorted(python)}"
    assert flag in shown, f"vdbhair {verb} --help shows no default for {flag}: {sorted(shown)}"
    assert same(python[keyword], shown[flag]), f"{function}({keyword}={python[keyword]}) but vdbhair {verb} {flag} defaults to {shown[flag]}"


# Verbs whose parameters are declared once (vdbhair/Parameters.h): every keyword of the signature
# that has a flag of the same name shows the same default in --help, by construction; this checks
# the two generators.
# (function, verb, the least number of keywords with a flag and a default to compare)
DECLARED = [("refine", "refine", 5), ("retrace", "retrace", 5), ("estimate_tangent_field", "field", 5), ("fit", "fit", 5),
            ("interpolate", "interpolate", 5), ("reconstruct", "reconstruct", 5), ("roots", "roots", 4), ("grow", "grow", 1),
            ("synth", "synth", 10), ("transfer", "transfer", 8), ("comb", "comb", 4), ("scalp", "scalp", 6), ("prepare", "prepare", 4),
            ("write", "convert", 6), ("inspect", "inspect", 2),
            ("strand_statistics", "info", 1)]


@pytest.mark.parametrize("function, verb, least", DECLARED)
def test_declared_verbs_generate_the_same_keywords_and_flags(function, verb, least):
    python = keyword_defaults(function)
    shown = flag_defaults(verb)
    compared = 0
    for keyword, value in python.items():
        flag = "--" + keyword.rstrip("_").replace("_", "-")  # lambda_ is --lambda
        if flag in shown and not value.startswith("(") and value != "None":  # up: an axis name on the command line, a vector in Python; levels: None for one field
            assert same(value, shown[flag]), f"{function}({keyword}={value}) but vdbhair {verb} {flag} defaults to {shown[flag]}"
            compared += 1
    assert compared >= least, f"only {compared} keywords of {function}() have a flag with a default"
