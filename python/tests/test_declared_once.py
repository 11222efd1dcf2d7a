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


# The options many verbs share are declared once too: the readers' (readParameters(): read()'s
# keywords and every reading verb's options) and threads (runParameters(): every verb's).
def _help_text(verb):
    return " ".join(subprocess.run([cli(), verb, "--help"], capture_output=True, text=True, check=True).stdout.split())


def _keyword_doc(function, keyword):
    """The help of a keyword in a verb's docstring (its line in Args)."""
    lines = [line for line in vdbhair.__dict__[function].__doc__.splitlines() if line.startswith(f"    {keyword}: ")]
    assert len(lines) == 1, (function, keyword)
    return lines[0].split(": ", 1)[1]


READING = {"strict": "--strict", "grid": "--grid", "points_per_strand": "--points-per-strand", "curve_samples": "--curve-samples",
           "roots": "--roots"}
READING_VERBS = {"convert": READING, "render": {k: f for k, f in READING.items() if k != "strict"},
                 "info": {k: f for k, f in READING.items() if k != "grid"}, "field": {k: f for k, f in READING.items() if k != "grid"},
                 "compare": {k: f for k, f in READING.items() if k not in ("grid", "strict")}}


@pytest.mark.parametrize("verb", sorted(READING_VERBS))
def test_read_keywords_are_the_reading_options_of_every_verb(verb):
    text = _help_text(verb)
    python = keyword_defaults("read")
    for keyword, flag in READING_VERBS[verb].items():
        help_line = _keyword_doc("read", keyword).rstrip(".")
        assert flag in text, f"{verb} --help has no {flag}"
        # The help each side shows is the declaration's; the default (a flag's: off) too.
        assert help_line in text, f"read({keyword}=): {help_line!r} is not what vdbhair {verb} {flag} says"
        shown = re.search(re.escape(flag) + r"(?:,--[\w-]+)? [A-Z]+(?::\{[^}]*\})?=(\S+)", text)
        assert (shown.group(1) if shown else "False") == python[keyword].strip("'"), (keyword, flag)


@pytest.mark.parametrize("function, verb", [("read", "convert"), ("refine", "refine"), ("compare", "compare"), ("synth", "synth"),
                                            ("roots", "roots"), ("strand_statistics", "info")])
def test_threads_is_one_declaration(function, verb):
    assert keyword_defaults(function)["threads"] == "0" and flag_defaults(verb)["--threads"] == "0"
    assert _keyword_doc(function, "threads").rstrip(".") in _help_text(verb)


def _cli_error(*args):
    run = subprocess.run([cli(), *map(str, args)], capture_output=True, text=True)
    assert run.returncode == 2, run.stderr
    return run.stderr.strip()


def _python_error(call):
    with pytest.raises(ValueError) as e:
        call()
    return str(e.value)


def test_shared_options_refuse_a_value_with_one_rule(tmp_path):
    """Each bad value: the same rule from both front ends, the parameters spelled as each spells them
    (--curve-samples, curve_samples)."""
    path = tmp_path / "b.hair"
    straight_bundle().write(str(path))
    hair = vdbhair.read(str(path))
    cases = [(("compare", path, path, "--unit", "furlong"), lambda: vdbhair.compare(hair, hair, unit="furlong"), "--unit", "unit"),
             (("compare", path, path, "--threshold", "2"), lambda: vdbhair.compare(hair, hair, threshold="2"), "--threshold", "threshold"),
             (("convert", path, tmp_path / "o.obj", "--threads", "-1"), lambda: vdbhair.read(str(path), threads=-1), "--threads", "threads"),
             (("info", path, "--curve-samples", "1"), lambda: vdbhair.read(str(path), curve_samples=1), "--curve-samples", "curve_samples")]
    for args, call, flag, keyword in cases:
        command = _cli_error(*args)
        python = _python_error(call)
        rule = python.split(keyword, 1)[1]  # after the keyword: the value and the rule
        assert flag in command and (keyword + rule).replace("_", "-") in command.replace("--", ""), (command, python)


def test_compare_unit_and_threshold_mean_the_same_in_both(tmp_path):
    a = straight_bundle(count=4, vertices=17, length=4.0, spacing=1.0)
    b = vdbhair.Strands(a.positions + np.float32([0.0, 0.0, 0.25]), a.offsets)
    a.write(str(tmp_path / "a.hair"))
    b.write(str(tmp_path / "b.hair"))
    python = vdbhair.compare(a, b, unit="cm", threshold=["2:20", "3:30"])
    command = _command("compare", tmp_path / "a.hair", tmp_path / "b.hair", "--unit", "cm", "--threshold", "2:20", "--threshold", "3:30")
    assert python["oriented_points"] == command["oriented_points"]
    assert [m["distance_mm"] for m in python["oriented_points"]] == [2.0, 3.0]
    assert vdbhair.compare(a, b, unit="cm", threshold="2:20 3:30")["oriented_points"] == python["oriented_points"]
