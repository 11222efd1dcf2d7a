"""head= of synth and comb is the command line's --head: the same head changes the same thing, and
CLI and Python make the same strands from it (a small synthetic groom on a sphere head)."""
import json
import os
import pathlib
import subprocess

import numpy as np
import pytest

import vdbhair

RADIUS = 10.0  # the head: a sphere of this radius at the origin


def cli():
    """The `vdbhair` command of the same build (VDBHAIR_CLI, else bin/ next to the module's python/)."""
    path = os.environ.get("VDBHAIR_CLI") or str(pathlib.Path(vdbhair.__file__).resolve().parents[1] / "bin" / "vdbhair")
    assert os.access(path, os.X_OK), f"no vdbhair command at {path} (set VDBHAIR_CLI)"
    return path


def run_json(*args):
    """`vdbhair ARGS --json`'s report."""
    done = subprocess.run([cli(), *map(str, args), "--json"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def dipping_groom(count=240, vertices=24, seed=5):
    """Strands rooted on the sphere's upper half, each following the scalp along an arc of 8 units:
    up to a third of a unit above it, then back down, the last third inside the head (its tip a
    unit deep)."""
    rng = np.random.default_rng(seed)
    strands = []
    s = np.linspace(0.0, 1.0, vertices)
    height = 2.0 * s - 3.0 * s * s
    angle = 8.0 * s / RADIUS
    while len(strands) < count:
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        if n[1] < 0.3:
            continue
        t = np.cross(n, rng.normal(size=3))
        t /= np.linalg.norm(t)
        direction = np.cos(angle)[:, None] * n + np.sin(angle)[:, None] * t
        strands.append((RADIUS + height)[:, None] * direction)
    offsets = np.arange(count + 1, dtype=np.int64) * vertices
    return vdbhair.Strands(np.concatenate(strands).astype(np.float32), offsets)


def inside(strands):
    """Vertices more than a twentieth of a unit inside the head."""
    return int((np.linalg.norm(strands.positions, axis=1) < RADIUS - 0.05).sum())


@pytest.fixture(scope="module")
def groom(tmp_path_factory):
    """The groom as a .hair file and as read back from it (what the command reads), and the head as
    a .vdb level set."""
    folder = tmp_path_factory.mktemp("head_keyword")
    hair = folder / "groom.hair"
    vdbhair.write(dipping_groom(), hair)
    head = folder / "head.vdb"
    surface, _ = vdbhair.scalp(sphere=(0.0, 0.0, 0.0, RADIUS), voxel_size=0.25)
    vdbhair.write_grids(str(head), [surface])
    return folder, hair, vdbhair.read(hair), head


SYNTH = dict(levels=2, vertices=16, strands=150, seed=1)
SYNTH_FLAGS = ["--levels", 2, "--vertices", 16, "--strands", 150, "--seed", 1]


def test_synth_head_as_the_command_line(groom):
    folder, hair, example, head = groom
    assert inside(example) > 1000
    outputs = {}
    for name, value in [("default", None), ("none", "none"), ("vdb", head)]:
        given = {} if value is None else {"head": value}  # no head= and no --head: the default head
        out, report = vdbhair.synth(example, return_report=True, **given, **SYNTH)
        cli_out = folder / f"synth_{name}.hair"
        cli_report = run_json("synth", hair, "-o", cli_out, *([] if value is None else ["--head", value]), *SYNTH_FLAGS)
        # The same strands from the command line and from Python, and the same head figures.
        from_cli = vdbhair.read(cli_out)
        np.testing.assert_array_equal(out.offsets, from_cli.offsets)
        np.testing.assert_array_equal(out.positions, from_cli.positions)
        assert report["head"]["pushed_out"] == cli_report["head"]["pushed_out"]
        assert report["head"]["entering"] == cli_report["head"]["entering"]
        outputs[name] = (out, report)
    # What head= changes is what --head changes: without a head the new hair follows the example
    # into it; the level set pushes it out.
    (none, none_report), (kept, kept_report) = outputs["none"], outputs["vdb"]
    assert none_report["head"]["head"] == "none" and none_report["head"]["pushed_out"] == 0
    assert "level set" in kept_report["head"]["head"] and kept_report["head"]["pushed_out"] > 0
    assert inside(none) > 100 and inside(kept) < inside(none) // 4
    # By default (no head=, no --head), the sphere fitted to the roots: here the head itself.
    default, default_report = outputs["default"]
    assert "fitted to the roots" in default_report["head"]["head"] and inside(default) < inside(none) // 4
    # A sphere (x, y, z, r), Python's other way to give a head (as refine's and comb's head=), keeps it out as well.
    sphere = vdbhair.synth(example, head=(0.0, 0.0, 0.0, RADIUS), **SYNTH)
    assert inside(sphere) < inside(none) // 4
    with pytest.raises(OSError, match="no_head.ply.*cannot open"):
        vdbhair.synth(example, head=folder / "no_head.ply", **SYNTH)
    with pytest.raises(TypeError, match="head: must be None, 'none', a path"):
        vdbhair.synth(example, head=3, **SYNTH)


def test_comb_head_as_the_command_line(groom):
    folder, hair, strands, head = groom
    # A stroke pressing the crown's hair down into the head.
    strokes = folder / "press.json"
    strokes.write_text(json.dumps({"vdbhair": "strokes/1", "strokes": [{"points": [[0, 16, 0], [0, 9, 0]], "radius": 6, "strength": 1}]}))
    results = {}
    for name, value in [("none", "none"), ("vdb", head)]:
        out, report = vdbhair.comb(strands, strokes, head=value, return_report=True)
        cli_out = folder / f"comb_{name}.hair"
        cli_report = run_json("comb", hair, "--stroke", strokes, "--head", value, "-o", cli_out)
        from_cli = vdbhair.read(cli_out)
        np.testing.assert_array_equal(out.positions, from_cli.positions)
        assert report["head"]["deflected_strands"] == cli_report["head"]["deflected_strands"]
        assert report["head"]["inside_vertices"] == cli_report["head"]["inside_vertices"]
        results[name] = (out, report)
    assert results["none"][1]["head"]["deflected_strands"] == 0 and results["vdb"][1]["head"]["deflected_strands"] > 0
    assert inside(results["vdb"][0]) < inside(results["none"][0])
