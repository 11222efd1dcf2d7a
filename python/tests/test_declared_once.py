"""What synth, transfer, comb, field, refine, interpolate, roots, render, compare and fit take in
both front ends is declared once in the library: each keyword below has the default its flag shows
in `--help` (an axis: None in Python is "auto" on the command line, a unit vector its name), and
Python takes the command's axis names. The renamed report keywords (retrace's return_stats, fit's return_summary) still work, with a
DeprecationWarning; estimate_tangent_field() and scalp() return their command's `--json` report."""
import json
import re
import subprocess
import warnings

import numpy as np
import pytest

import vdbhair
from conftest import SOURCE_DIR, straight_bundle, wavy_hairstyle
from test_defaults import cli, flag_defaults, keyword_defaults

AXES = {"(0.0, 1.0, 0.0)": "y", "(0.0, 0.0, 1.0)": "z", "None": "auto"}

# (function, keyword, verb, flag): declared once, so the signature's default is the flag's.
DECLARED = [
    ("synth", "strands", "synth", "--strands"),
    ("synth", "up", "synth", "--up"),
    ("synth", "front", "synth", "--front"),
    ("synth", "output_turn", "synth", "--output-turn"),
    ("transfer", "strands", "transfer", "--strands"),
    ("transfer", "up", "transfer", "--up"),
    ("transfer", "front", "transfer", "--front"),
    ("comb", "up", "comb", "--up"),
    ("comb", "head_policy", "comb", "--head-policy"),
    ("estimate_tangent_field", "levels", "field", "--levels"),
    ("estimate_tangent_field", "space", "field", "--space"),
    ("estimate_tangent_field", "up", "field", "--up"),
    ("refine", "space", "refine", "--space"),
    ("refine", "up", "refine", "--up"),
    ("refine", "head_policy", "refine", "--head-policy"),
    ("interpolate", "up", "interpolate", "--up"),
    ("roots", "up", "roots", "--up"),
    ("render", "up", "render", "--up"),
    ("render", "facing", "render", "--facing"),
    ("prepare", "target_up", "prepare", "--target-up"),
]


@pytest.mark.parametrize("function, keyword, verb, flag", DECLARED, ids=[f"{f}.{k}" for f, k, _, _ in DECLARED])
def test_declared_keyword_has_the_flags_default(function, keyword, verb, flag):
    python = keyword_defaults(function)
    shown = flag_defaults(verb)
    assert keyword in python and flag in shown, (sorted(python), sorted(shown))
    value = python[keyword]
    if value == "None":  # None: the library's own choice, which the command line calls auto or shows as 0 / 1
        assert shown[flag] in ("auto", "0", "1"), f"{function}({keyword}=None) but {verb} {flag} defaults to {shown[flag]}"
    elif value.startswith("("):
        assert AXES[value] == shown[flag]
    else:
        assert value.strip("'") == shown[flag] or float(value) == float(shown[flag])


# Switches that are flags on the command line (no default shown) and bools in Python.
SWITCHES = [("synth", "refine", "synth", "--no-refine", True), ("synth", "measure", "synth", "--measure", False),
            ("transfer", "refine", "transfer", "--no-refine", True), ("transfer", "measure", "transfer", "--measure", False),
            ("transfer", "smooth_base", "transfer", "--no-smooth-base", True), ("transfer", "smooth_base", "transfer", "--keep-base-detail", True),
            ("compare", "pair_strands", "compare", "--no-pair-strands", True), ("compare", "pair_strands", "compare", "--unpaired", True),
            ("fit", "skip_degenerate", "fit", "--skip-degenerate", False), ("render", "sheet", "render", "--sheet", False),
            ("retrace", "measure", "retrace", "--measure", False)]


@pytest.mark.parametrize("function, keyword, verb, flag, default", SWITCHES, ids=[f"{f}.{k}{fl}" for f, k, _, fl, _ in SWITCHES])
def test_declared_switch_is_a_flag_and_a_keyword(function, keyword, verb, flag, default):
    assert keyword_defaults(function)[keyword] == repr(default)
    text = subprocess.run([cli(), verb, "--help"], capture_output=True, text=True, check=True).stdout
    assert flag in text
    assert keyword in vdbhair.__dict__[function].__doc__


# Parameters each front end once declared on its own: now one declaration, so the docstring's line
# and the flag's `--help` text are the same sentence.
ONE_HELP = [("retrace", "measure", "retrace", "--measure"), ("prepare", "target_up", "prepare", "--target-up"),
            ("scalp", "region_vertex", "scalp", "--region-vertex")]


@pytest.mark.parametrize("function, keyword, verb, flag", ONE_HELP, ids=[f"{f}.{k}" for f, k, _, _ in ONE_HELP])
def test_the_keyword_and_the_flag_have_one_help(function, keyword, verb, flag):
    doc = vdbhair.__dict__[function].__doc__
    line = re.search(rf"^    {keyword}: (.+)$", doc, re.M)
    assert line, doc
    text = subprocess.run([cli(), verb, "--help"], capture_output=True, text=True, check=True).stdout
    option = re.search(rf"^\s+{flag}\b(.*?)(?=^\s+-|\Z)", text, re.M | re.S)
    assert option, text
    assert " ".join(line.group(1).split()) in " ".join(option.group(1).split())


@pytest.mark.data
def test_prepare_target_up_is_the_commands(tmp_path, shared_data):
    """prepare(target_up=) is --target-up (aligning by ICP, two different head meshes), by name or vector."""
    hair_path = shared_data / "hair" / "cyhair" / "straight.hair"
    head, target = shared_data / "scalp" / "cem_yuksel" / "woman_head.ply", shared_data / "scalp" / "usc_hairsalon" / "head_model.ply"
    hair = vdbhair.read(str(hair_path))
    out, report = vdbhair.prepare(hair, count=200, head=str(head), align_to=str(target), target_up="z")
    command = _command("prepare", hair_path, tmp_path / "out.data", "--strands", 200, "--head", head, "--align-to", target, "--target-up", "z")
    for key in ("input", "output", "head", "align_to", "seconds"):
        command.pop(key, None)
    assert report == command
    np.testing.assert_array_equal(vdbhair.read(str(tmp_path / "out.data")).positions, out.positions)
    by_vector, _ = vdbhair.prepare(hair, count=200, head=str(head), align_to=str(target), target_up=(0.0, 0.0, 1.0))
    np.testing.assert_array_equal(by_vector.positions, out.positions)
    with pytest.raises(ValueError, match=r"^prepare: target_up \(0, 0, 0\): must be a non-zero vector$"):
        vdbhair.prepare(hair, target_up=(0, 0, 0))
    with pytest.raises(ValueError, match=r"^prepare: target_up 'up': must be one of x, y, z, -x, -y, -z$"):
        vdbhair.prepare(hair, target_up="up")


def test_an_axis_is_a_name_or_a_vector():
    hair = wavy_hairstyle(count=40, vertices=12, seed=5)
    by_name = vdbhair.estimate_tangent_field(hair, voxel_size=0.5, space="scalp", up="z")
    by_vector = vdbhair.estimate_tangent_field(hair, voxel_size=0.5, space="scalp", up=(0.0, 0.0, 1.0))
    np.testing.assert_array_equal(by_name.to_dense(), by_vector.to_dense())
    with pytest.raises(ValueError, match=r"^estimate_tangent_field: up 'w': must be one of x, y, z, -x, -y, -z$"):
        vdbhair.estimate_tangent_field(hair, up="w")
    with pytest.raises(ValueError, match=r"^estimate_tangent_field: up \(0, 0, 0\): must be a non-zero vector$"):
        vdbhair.estimate_tangent_field(hair, up=(0, 0, 0))
    with pytest.raises(ValueError, match=r"^estimate_tangent_field: levels 17: must be between 1 and 16$"):
        vdbhair.estimate_tangent_field(hair, levels=17)


def test_renamed_report_keywords_still_work_with_a_warning():
    bundle = straight_bundle()
    field = vdbhair.estimate_tangent_field(bundle, voxel_size=0.25)
    _, report = vdbhair.retrace(bundle, field, return_report=True)
    with pytest.warns(DeprecationWarning, match=r"retrace\(return_stats=\.\.\.\) is deprecated: use return_report="):
        _, old = vdbhair.retrace(bundle, field, return_stats=True)
    assert old == report
    hair = wavy_hairstyle(count=4, vertices=20, seed=3)
    _, summary = vdbhair.fit(hair, return_report=True)
    with pytest.warns(DeprecationWarning, match=r"fit\(return_summary=\.\.\.\) is deprecated: use return_report="):
        _, old = vdbhair.fit(hair, return_summary=True)
    assert old == summary
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert isinstance(vdbhair.fit(hair), dict)  # no warning without the old keyword


def _command(*args):
    run = subprocess.run([cli(), *map(str, args), "--json"], check=True, capture_output=True, text=True)
    return json.loads(run.stdout)


def test_field_and_scalp_reports_are_the_commands(tmp_path):
    path = SOURCE_DIR / "scenes" / "default" / "ponytail.hair"
    hair = vdbhair.read(str(path))
    for args, kw in (([], {}), (["--levels", "2"], {"levels": 2}), (["--space", "scalp", "--up", "z"], {"space": "scalp", "up": "z"})):
        fields, report = vdbhair.estimate_tangent_field(hair, return_report=True, **kw)
        assert isinstance(fields, list) == ("levels" in kw)
        cmd = _command("field", path, "-o", tmp_path / "f.vdb", *args)
        del cmd["output"], cmd["seconds"]
        assert report == cmd, args
    for args, kw in ((["--sphere", "0,88,7,30"], {"sphere": (0, 88, 7, 30)}),
                     (["--sphere", "0,88,7,30", "--region", path], {"sphere": (0, 88, 7, 30), "region": hair})):
        surface, region, report = vdbhair.scalp(return_report=True, **kw)
        assert (region is None) == ("region" not in kw)
        cmd = _command("scalp", *args, "-o", tmp_path / "s.vdb")
        del cmd["output"], cmd["seconds"]
        assert report == cmd, args
    assert len(vdbhair.scalp(sphere=(0, 88, 7, 30))) == 2  # without return_report: (surface, region)
