"""grow, fit, render, inspect, and the module's documentation."""
import inspect as pyinspect
import importlib.util
import json
import os
import pathlib

import numpy as np
import pytest

import vdbhair
from conftest import SOURCE_DIR, straight_bundle, wavy_hairstyle


def test_fit_then_grow_regrows_the_strands(tmp_path):
    s = wavy_hairstyle(count=6, vertices=20, seed=3)
    scene, summary = vdbhair.fit(s, return_report=True)
    assert summary["fitted"] == 6 and len(scene["guides"]) == 6
    assert summary["frechet_relative"]["mean"] < 0.05
    assert summary["step_convergence"]["unconverged"] == 0 and summary["step_convergence"]["max"] < 1e-3
    grown = vdbhair.grow(scene)
    assert len(grown) == 6
    # Each regrown strand starts at its root and ends near its tip (within the fit's error).
    for a, b in zip(s, grown):
        np.testing.assert_allclose(b[0], a[0], atol=1e-5)
        length = np.linalg.norm(np.diff(a, axis=0), axis=1).sum()
        assert np.linalg.norm(b[-1] - a[-1]) < 0.1 * length
    # A scene file grows the same strands.
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(scene))
    np.testing.assert_array_equal(vdbhair.grow(str(path)).positions, grown.positions)
    with pytest.raises(vdbhair.FormatError):
        vdbhair.grow({"vdbhair": "scene/1", "guides": "many"})


@pytest.mark.parametrize("keyword, value, message", [
    ("max_error", 0.0, "fit: max_error 0: must be above 0"),
    ("lambda_", -1.0, "fit: lambda_ -1: must be at least 0"),
    ("max_pieces", 65, "fit: max_pieces 65: must be between 1 and 64"),
    ("max_evaluations", 9, "fit: max_evaluations 9: must be at least 10"),
    ("step", -1.0, "fit: step -1: must be at least 0 world units"),
])
def test_fit_refuses_a_keyword_out_of_range_by_its_name(keyword, value, message):
    with pytest.raises(ValueError, match="^" + message.replace("(", r"\(")):
        vdbhair.fit(straight_bundle(count=2), **{keyword: value})


def test_render_returns_rgba_or_writes_a_file(tmp_path):
    s = straight_bundle(count=3)
    image = vdbhair.render(s, width=64, height=48, view="front")
    assert image.shape == (48, 64, 4) and image.dtype == np.uint8
    assert np.all(image[:, :, 3] == 255)
    # White background with darker hair somewhere.
    hair = (image[:, :, :3] < 250).any(axis=-1)
    assert not hair[0, 0] and hair.sum() > 20
    path = tmp_path / "hair.png"
    assert vdbhair.render(s, str(path), width=64, height=48, view="front") is None
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    np.testing.assert_array_equal(read_png_rgb(path), image[:, :, :3])


def test_render_colours_by_the_distance_to_a_reference():
    s = straight_bundle(count=3)
    # The bundle and a copy half of it moved away: the moved strands take the map's high end
    # (yellow), those on the reference its low end (dark purple).
    positions = np.array(s.positions)
    positions[len(positions) // 2:] += np.array([0.0, 5.0, 0.0], dtype=np.float32)
    moved = vdbhair.Strands(positions, np.array(s.offsets))
    image = vdbhair.render(moved, width=96, height=96, view="front", color_by="error", reference=s)
    rgb = image[:, :, :3].astype(int)
    hair = (rgb < 245).any(axis=-1)
    yellow = hair & (rgb[:, :, 0] > 150) & (rgb[:, :, 1] > 150) & (rgb[:, :, 2] < 120)
    purple = hair & (rgb[:, :, 1] < 60)
    assert yellow.sum() > 10 and purple.sum() > 10
    # Rows: the moved half is above the other in the front view (+y up).
    assert np.nonzero(yellow)[0].mean() < np.nonzero(purple)[0].mean()
    with pytest.raises(ValueError, match="color_by error needs a reference"):
        vdbhair.render(s, width=64, height=48, color_by="error")


def read_png_rgb(path):
    """An 8-bit RGB PNG's pixels, decoded by the command-line tests' own reader (tests/apps/check_legend.py)."""
    spec = importlib.util.spec_from_file_location("check_legend", SOURCE_DIR / "tests" / "apps" / "check_legend.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    width, height, rows = module.read_png(str(path))
    return np.array(rows, dtype=np.uint8).reshape(height, width, 3)


@pytest.mark.skipif(not os.path.exists("/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf"),
                    reason="DejaVu Sans (fonts-dejavu-core) is not installed: titles are not drawn")
def test_render_draws_its_title_in_the_written_png(tmp_path):
    s = straight_bundle(count=3)
    bare = vdbhair.render(s, width=96, height=64, view="front")
    titled = vdbhair.render(s, width=96, height=64, view="front", title="Hair 42")
    # The title is drawn in the top-left corner, dark on the white background, and nowhere else.
    changed = (bare != titled).any(axis=-1)
    rows, cols = np.nonzero(changed)
    assert changed.sum() > 30 and rows.max() < 32 and cols.min() < 16
    assert titled[:, :, :3].min() < 100
    path = tmp_path / "titled.png"
    vdbhair.render(s, str(path), width=96, height=64, view="front", title="Hair 42")
    np.testing.assert_array_equal(read_png_rgb(path), titled[:, :, :3])
    with pytest.raises(ValueError, match="view"):
        vdbhair.render(s, view="sideways")


def test_every_function_has_a_docstring_with_its_defaults():
    names = ["read", "write", "estimate_tangent_field", "retrace", "refine", "grow", "fit", "render", "inspect",
             "read_grid", "read_grids", "write_grids", "suggest_voxel_size", "interpolate", "synth", "transfer", "comb",
             "scalp", "roots", "reconstruct"]
    for name in names:
        doc = getattr(vdbhair, name).__doc__
        assert doc and len(doc) > 150, name
    # help(vdbhair.retrace) shows the defaults of the library's TraceParams (its signature) and the units.
    signature = pyinspect.signature(vdbhair.retrace).parameters
    assert signature["step"].default == 0.0 and signature["vanish"].default == 0.001 and signature["margin"].default == 3
    assert signature["integrator"].default == "euler" and "world units" in vdbhair.retrace.__doc__
    assert pyinspect.signature(vdbhair.estimate_tangent_field).parameters["iterations"].default == 2
    for cls in (vdbhair.Strands, vdbhair.TangentField, vdbhair.Grid):
        assert cls.__doc__
        for attr, value in vars(cls).items():
            if not attr.startswith("_"):
                assert value.__doc__, f"{cls.__name__}.{attr}"


def test_synth(tmp_path):
    # Every second strand of the bundled ponytail (2,467 of 4,933: the same hairstyle at half the
    # work), 800 output strands.
    full = vdbhair.read(str(SOURCE_DIR / "scenes" / "default" / "ponytail.hair"))
    kept = [full.positions[full.offsets[i]:full.offsets[i + 1]] for i in range(0, len(full), 2)]
    example = vdbhair.Strands(np.concatenate(kept), np.concatenate([[0], np.cumsum([len(k) for k in kept])]))
    out, report = vdbhair.synth(example, strands=800, seed=3, measure=True, return_report=True)
    assert len(out) == 800
    # measure=True: the output against the example, vdbhair.compare's report (strands not paired).
    measured = vdbhair.compare(example, out, pair_strands=False)
    del measured["per_strand"]
    assert report["compare"] == measured and measured["paired"] is False and measured["chamfer"]["mean"] > 0.0
    assert [lv["output"] for lv in report["levels"]][0] == 800
    assert {"scalp", "clustering", "feature maps"} <= set(report["stages"])
    assert len(report["cluster_of"]) == 2 and report["cluster_of"][0].shape == (800,)
    # The head (the sphere fitted to the example's roots, which a third of the example's strands
    # pass into): the new hair is pushed out of it, at most a strand in a hundred still touching it.
    head = report["head"]
    assert "fitted to the roots" in head["head"] and head["pushed_out"] > 0
    assert head["entering"]["output"] <= 0.01 and head["entering"]["example"] > 400 / len(example)
    # Deterministic for a seed and independent of the thread count; another seed differs.
    again = vdbhair.synth(example, strands=800, seed=3, threads=1)
    assert np.array_equal(again.positions, out.positions)
    other = vdbhair.synth(example, strands=800, seed=4)
    assert not np.array_equal(other.positions, out.positions)
    # An output region: the roots of the example's half with x above the middle give about half
    # the strands (the example's density), all on that side; strands= still sets the count.
    roots = example.positions[example.offsets[:-1]]
    half = roots[roots[:, 0] > np.median(roots[:, 0])]
    part, rep = vdbhair.synth(example, layout="example", region=half, seed=3, return_report=True)
    assert 0.4 * len(example) < len(part) < 0.65 * len(example) and rep["output_area"] > 0
    assert part.positions[part.offsets[:-1]][:, 0].min() > np.median(roots[:, 0]) - 5.0
    assert len(vdbhair.synth(example, layout="example", region=half, strands=300)) == 300
    # Onto another head: a sphere of radius 20 at (100, 0, 0), hair on its upper half.
    surface, _ = vdbhair.scalp(sphere=(100.0, 0.0, 0.0, 20.0), voxel_size=1.0)
    vdbhair.write_grids(str(tmp_path / "other.vdb"), [surface])
    upper = vdbhair.roots(surface, count=400)["positions"]
    upper = upper[upper[:, 1] > 2.0]
    moved = vdbhair.synth(example, layout="example", region=upper, output_scalp=str(tmp_path / "other.vdb"), strands=300)
    r = np.linalg.norm(moved.positions[moved.offsets[:-1]] - np.array([100.0, 0.0, 0.0]), axis=1)
    assert len(moved) == 300 and np.all(np.abs(r - 20.0) < 2.0)
    with pytest.raises(ValueError, match="output_scalp needs region="):
        vdbhair.synth(example, output_scalp=str(tmp_path / "other.vdb"))
    with pytest.raises(ValueError, match=r"region must be an \(N, 3\) array"):
        vdbhair.synth(example, region=np.zeros((4, 2)))
    with pytest.raises(ValueError, match="layout 'tiled': must be one of synthesize, example"):
        vdbhair.synth(example, layout="tiled")
    with pytest.raises(ValueError, match=r"^synth: map_frame 'sideways': must be one of head, root$"):
        vdbhair.synth(example, map_frame="sideways")
    with pytest.raises(ValueError, match=r"^synth: strands -1: must be at least 0$"):
        vdbhair.synth(example, strands=-1)


def test_transfer_and_comb():
    pony = vdbhair.read(str(SOURCE_DIR / "scenes" / "default" / "ponytail.hair"))
    # A hairstyle onto itself keeps its strands' roots, in order.
    out, report = vdbhair.transfer(pony, pony, refine=False, measure=True, return_report=True)
    assert len(out) == len(pony)
    measured = vdbhair.compare(pony, out)  # measure=True: the output against the base, strands paired
    del measured["per_strand"]
    assert report["compare"] == measured and measured["paired"] is True
    roots = pony.positions[pony.offsets[:-1]]
    assert np.allclose(out.positions[out.offsets[:-1]], roots, atol=1e-3)
    assert report["detail_scale"] == pytest.approx(1.0)
    assert vdbhair.transfer(pony, pony, refine=False, return_report=True)[1]["compare"] is None
    # head= is --head: "none" transfers with no head; the default is the sphere fitted to the base's roots.
    assert report["head"]["head"] != "none"
    assert vdbhair.transfer(pony, pony, refine=False, head="none", return_report=True)[1]["head"] == {
        "head": "none", "pushed_out": 0, "entering": {"output": 0.0, "base": 0.0}}
    with pytest.raises(ValueError, match="strands needs guides=True"):
        vdbhair.transfer(pony, pony, strands=10)
    # Zero strength changes nothing; a stroke keeps every segment's length.
    stroke = {"points": [[0, 60, 0], [20, 40, 0]], "radius": 30.0}
    same = vdbhair.comb(pony, [dict(stroke, strength=0.0)])
    assert np.array_equal(same.positions, pony.positions)
    combed, rep = vdbhair.comb(pony, [stroke], return_report=True)
    assert rep["moved_strands"] > 0 and rep["angle_to_stroke_deg"]["after"] < rep["angle_to_stroke_deg"]["before"]
    seg = lambda s: np.linalg.norm(np.diff(s.positions, axis=0), axis=1)
    inner = np.ones(len(pony.positions) - 1, bool)
    inner[pony.offsets[1:-1] - 1] = False
    assert np.allclose(seg(combed)[inner], seg(pony)[inner], rtol=1e-4)
    with pytest.raises(ValueError, match="radius"):
        vdbhair.comb(pony, [{"points": [[0, 0, 0], [1, 0, 0]], "radius": 0.0}])
    # A stroke into the head: without a head hair goes in; a sphere head turns it aside (the
    # ponytail's roots lie inside this ball: "outside" moves the combed strands out of it).
    into = {"points": [[0, 150, 40], [0, 100, 15]], "radius": 35.0}
    ball = (0.32, 87.9, 7.3, 32.0)
    def inside(s):
        r = np.linalg.norm(s.positions - np.array(ball[:3], np.float32), axis=1)
        return int((r < ball[3] - 1e-3).sum())
    through = vdbhair.comb(pony, [into], head="none")
    kept, rep = vdbhair.comb(pony, [into], head=ball, head_policy="outside", return_report=True)
    no_deeper = vdbhair.comb(pony, [into], head=ball)
    assert inside(through) > inside(pony) + 5000
    assert inside(kept) < inside(pony) // 2 and inside(no_deeper) <= inside(pony)
    assert rep["head"]["deflected_strands"] > 0 and rep["head"]["head"].startswith("sphere")
    # A ball just inside the roots, no deeper than the input: pushed out along their length, the
    # strands gain no turn over 45 degrees between two edges (a strand the sweep would kink is
    # combed less: a few at most).
    _, rep28 = vdbhair.comb(pony, [into], head=(0.32, 87.9, 7.3, 28.0), return_report=True)
    assert rep28["head"]["deflected_strands"] > 1000 and rep28["new_kinks"]["strands"] == 0
    assert rep28["new_kinks"]["combed_less"] <= 2 and rep28["checks"]["no_new_kinks"]
    with pytest.raises(ValueError, match=r"^comb: head_policy 'sideways': must be one of no-deeper, outside$"):
        vdbhair.comb(pony, [into], head_policy="sideways")


def test_interpolate_groom_controls(tmp_path):
    # Straight guides along x; 400 roots between them. Density from an array, length from a list
    # file given as a pathlib.Path, clumps and curl: the counts, roots and lengths the controls say.
    guides = straight_bundle(count=5, vertices=9, length=4.0, spacing=0.25)
    rng = np.random.default_rng(0)
    roots = np.zeros((400, 3))
    roots[:, 1] = rng.uniform(-0.5, 0.5, 400)
    density = (roots[:, 1] > 0.0).astype(float)
    values = tmp_path / "length.txt"
    values.write_text("\n".join(["0.5"] * 400))
    out = vdbhair.interpolate(guides, roots, density=density, length=values, clump_radius=0.2, curl=0.02, curl_frequency=20.0, head="none")
    kept = roots[density > 0]
    assert len(out) == len(kept)
    for i, strand in enumerate(out):
        assert np.allclose(strand[0], kept[i], atol=1e-5)
        assert strand[-1][0] == pytest.approx(2.0, abs=0.05)  # half of 4 along x; curl and clumps act across
    # The same with one thread, and bad values named.
    again = vdbhair.interpolate(guides, roots, density=density, length=str(values), clump_radius=0.2, curl=0.02, curl_frequency=20.0, head="none", threads=1)
    assert np.array_equal(again.positions, out.positions)
    with pytest.raises(ValueError, match="--curl 0.02 needs --curl-frequency"):
        vdbhair.interpolate(guides, roots, curl=0.02)
    with pytest.raises(ValueError, match="density= has 3 values for 400 roots"):
        vdbhair.interpolate(guides, roots, density=[1.0, 1.0, 1.0])
    with pytest.raises(ValueError, match="density 2 at root 0"):
        vdbhair.interpolate(guides, roots, density=2.0)


def test_interpolate():
    # Straight parallel guides along x: every new hair between them is straight, as long, along x.
    guides = straight_bundle(count=5, vertices=9, length=4.0, spacing=0.25)
    roots = np.array([[0.0, 0.1, 0.0], [0.0, 0.6, 0.0], [0.0, 0.35, 0.0]])
    for method in ("helicoid", "points"):
        out = vdbhair.interpolate(guides, roots, method=method)
        assert len(out) == 3
        for i, strand in enumerate(out):
            assert np.allclose(strand[0], roots[i], atol=1e-5), method
            chord = strand[-1] - strand[0]
            length = np.linalg.norm(np.diff(strand, axis=0), axis=1).sum()
            assert length == pytest.approx(4.0, rel=1e-3), method
            assert np.linalg.norm(chord) == pytest.approx(length, rel=1e-3), method  # straight
            assert chord[0] / np.linalg.norm(chord) == pytest.approx(1.0, abs=1e-4), method
    # A root on a guide's root gives that guide back; the scene grows to the same strands; one or two threads.
    on_guide = vdbhair.interpolate(guides, guides.positions[guides.offsets[:-1]][:2])
    for i in range(2):  # points (the default): the guide itself
        assert np.array_equal(on_guide[i], guides[i])
    on_fit = vdbhair.interpolate(guides, guides.positions[guides.offsets[:-1]][:2], method="helicoid")
    for i in range(2):
        for end in (0, -1):  # the fit regrown at its own step: the same root and tip
            assert np.allclose(on_fit[i][end], guides[i][end], atol=1e-3)
    scene = vdbhair.interpolate(vdbhair.fit(guides), roots, method="helicoid", return_scene=True)
    assert len(scene["guides"]) == 3
    assert np.array_equal(vdbhair.grow(scene).positions, vdbhair.interpolate(vdbhair.fit(guides), roots, method="helicoid").positions)
    for method in ("helicoid", "points"):
        assert np.array_equal(vdbhair.interpolate(guides, roots, method=method, threads=1).positions,
                              vdbhair.interpolate(guides, roots, method=method, threads=2).positions)
    # Groups (one id per guide, one per root); the parting itself is tested in C++ (TestInterpolation.cc).
    groups = [int(guides[i][0][1] > 0.3) for i in range(len(guides))]
    out = vdbhair.interpolate(guides, roots, guide_groups=groups, root_groups=[1, 1, 1], neighbors=2, grouping="none")
    assert len(out) == 3 and np.allclose(out[0][-1] - out[0][0], [4.0, 0.0, 0.0], atol=1e-5)
    with pytest.raises(ValueError, match="root 0: group 7 has no guides"):
        vdbhair.interpolate(guides, roots, guide_groups=groups, root_groups=[7, 1, 1])
    with pytest.raises(ValueError, match="2 guide group ids for 25 guides"):
        vdbhair.interpolate(guides, roots, guide_groups=[0, 1])
    with pytest.raises(ValueError, match=r"^interpolate: grouping 'sideways': must be one of shape, none$"):
        vdbhair.interpolate(guides, roots, grouping="sideways")
    # The head: a sphere the straight guides would cut through is kept out of.
    through = vdbhair.interpolate(guides, roots, head=(2.0, 0.35, -0.5, 0.6))
    for strand in through:
        assert np.all(np.linalg.norm(strand - np.array([2.0, 0.35, -0.5]), axis=1) >= 0.6 - 1e-4)
    free = vdbhair.interpolate(guides, roots, head="none")
    assert any(np.any(np.linalg.norm(s - np.array([2.0, 0.35, -0.5]), axis=1) < 0.6 - 1e-3) for s in free)
    # Roots as a Strands, normals (surface frames) and the errors.
    assert len(vdbhair.interpolate(guides, guides, normals=np.tile([1.0, 0.0, 0.0], (25, 1)))) == 25
    with pytest.raises(ValueError, match="roots: must be an .N, 3. array"):
        vdbhair.interpolate(guides, np.zeros((3, 2)))
    with pytest.raises(ValueError, match=r"^interpolate: power 0: must be above 0$"):
        vdbhair.interpolate(guides, roots, power=0.0)
    with pytest.raises(ValueError, match="2 normals for 3 roots"):
        vdbhair.interpolate(guides, roots, normals=np.ones((2, 3)))
    with pytest.raises(ValueError, match="frames='surface' needs normals"):
        vdbhair.interpolate(guides, roots, frames="surface")
    with pytest.raises(ValueError, match="return_scene=True needs method='helicoid'"):
        vdbhair.interpolate(guides, roots, method="points", return_scene=True)
    with pytest.raises(ValueError, match="return_scene=True needs method='helicoid'"):
        vdbhair.interpolate(guides, roots, return_scene=True)


def test_synth_transfer_comb_reports_are_the_commands(tmp_path):
    import json
    import pathlib
    import subprocess
    # One report whichever front end ran it (SynthJson.h): synth, transfer and comb with
    # return_report=True return `--json`'s report, less the command's file names and the seconds,
    # plus Python's arrays; the stages are the same, their timings not.
    cli = pathlib.Path(vdbhair.__file__).resolve().parents[1] / "bin" / "vdbhair"
    if not cli.exists():
        pytest.skip(f"no command-line vdbhair at {cli}")
    full = vdbhair.read(str(SOURCE_DIR / "scenes" / "default" / "ponytail.hair"))
    kept = [full.positions[full.offsets[i]:full.offsets[i + 1]] for i in range(0, len(full), 4)]
    example = vdbhair.Strands(np.concatenate(kept), np.concatenate([[0], np.cumsum([len(k) for k in kept])]))
    hair = tmp_path / "example.hair"
    vdbhair.write(example, str(hair))
    stroke = {"points": [[0, 60, 0], [20, 40, 0]], "radius": 30.0}
    (tmp_path / "stroke.json").write_text(json.dumps({"strokes": [stroke]}))

    def command(*args):
        run = subprocess.run([str(cli), *args, "-o", str(tmp_path / "out.hair"), "--json"], check=True, capture_output=True, text=True)
        return json.loads(run.stdout)

    def same(report, cmd, front_end_keys, arrays):
        for k in front_end_keys:
            del cmd[k]
        for k in arrays:
            del report[k]
        assert set(report["stages"]) == set(cmd["stages"])
        del report["stages"], cmd["stages"]
        assert report == cmd

    _, report = vdbhair.synth(example, strands=300, levels=2, seed=2, measure=True, return_report=True)
    same(report, command("synth", str(hair), "--strands", "300", "--levels", "2", "--seed", "2", "--measure"),
         ["output", "example", "seconds"], ["cluster_of"])
    _, report = vdbhair.transfer(example, example, levels=2, refine=False, return_report=True)
    same(report, command("transfer", str(hair), str(hair), "--levels", "2", "--no-refine"),
         ["output", "details", "base", "seconds"], ["cluster_of", "base_label"])
    _, report = vdbhair.comb(example, [stroke], return_report=True)
    same(report, command("comb", str(hair), "--stroke", str(tmp_path / "stroke.json")), ["output", "input", "seconds"], ["cluster"])


def _command(*args):
    """`vdbhair ARGS --json`'s report from the command of the same build, or a skip without one."""
    import subprocess
    cli = os.environ.get("VDBHAIR_CLI") or str(pathlib.Path(vdbhair.__file__).resolve().parents[1] / "bin" / "vdbhair")
    if not os.access(cli, os.X_OK):
        pytest.skip(f"no command-line vdbhair at {cli} (set VDBHAIR_CLI)")
    run = subprocess.run([cli, *map(str, args), "--json"], check=True, capture_output=True, text=True)
    return json.loads(run.stdout)


def _same_report(report, cmd, front_end_keys, arrays=(), timings=()):
    """The Python report is the command's: the same keys once the command's own (file names, its
    clock) and Python's arrays are left out, and the same values but for timings (dotted paths,
    present in both)."""
    for k in front_end_keys:
        del cmd[k]
    for k in arrays:
        del report[k]
    assert set(report) == set(cmd)
    for path in timings:
        *outer, last = path.split(".")
        a, b = report, cmd
        for k in outer:
            a, b = a[k], b[k]
        assert isinstance(a.pop(last), float) and isinstance(b.pop(last), float), path
    assert report == cmd


def _front_and_head(shared_data):
    """The TressFX front groom and its head, or a skip saying they are not in the shared data."""
    path = shared_data / "hair" / "tressfx" / "ascii_v2" / "hair_front_16_guide.tfx"
    head = shared_data / "scalp" / "tressfx" / "head_max4.obj"
    if not path.exists() or not head.exists():
        pytest.skip(f"{path.name} or {head.name} is not in the shared data")
    return path, head


@pytest.mark.data
def test_roots_fit_reconstruct_retrace_reports_are_the_commands(tmp_path, shared_data):
    # One report whichever front end ran the verb (ScalpJson.h, HelicoidJson.h, FieldJson.h), on a
    # real hairstyle and head: Python's is `--json`'s less the command's file names and clock.
    path, head = _front_and_head(shared_data)
    hair = vdbhair.read(str(path))
    out = tmp_path / "out.hair"

    _, summary = vdbhair.fit(hair, return_report=True)
    _same_report(summary, _command("fit", path, "-o", tmp_path / "fits.json"), ["output", "strands_per_second"])

    _, _, report = vdbhair.reconstruct(hair, guides=0.3, meters_per_unit=0.01, head=str(head))
    assert report["per_strand"]["helicoid"].shape == (len(hair),) and len(report["guide_strands"]) == report["guides"]
    cmd = _command("reconstruct", path, "-o", out, "--guides", "30%", "--meters-per-unit", "0.01", "--head", head)
    _same_report(report, cmd, ["output", "method"], ["guide_strands", "per_strand"],
                 ["fit.seconds"] + [f"frechet_relative.{way}.seconds" for way in ("helicoid", "points", "nearest")])

    field = vdbhair.estimate_tangent_field(hair)
    field.write(str(tmp_path / "field.vdb"))
    _, stats = vdbhair.retrace(hair, field, return_report=True, measure=True)
    assert stats["tangent_angle_deg"]["after"] < stats["tangent_angle_deg"]["before"]
    _same_report(stats, _command("retrace", path, "--field", tmp_path / "field.vdb", "-o", out, "--measure"), ["output"])

    surface, region = vdbhair.scalp(str(head), region=hair)
    vdbhair.write_grids(str(tmp_path / "scalp.vdb"), [surface, region])
    roots = vdbhair.roots(str(tmp_path / "scalp.vdb"), count=200)
    assert roots["positions"].shape == (roots["count"], 3) and roots["region"]
    _same_report(roots, _command("roots", tmp_path / "scalp.vdb", "-o", tmp_path / "roots.ply", "--count", "200"),
                 ["output", "seconds"], ["positions", "normals", "tangents"])


@pytest.mark.data
def test_grow_interpolate_reports_are_the_commands(tmp_path, shared_data):
    # grow and interpolate with return_report=True: `--json`'s report (HelicoidJson.h), less the
    # command's file names and clock, on a real hairstyle's fits and roots spread over its head.
    path, head = _front_and_head(shared_data)
    hair = vdbhair.read(str(path))
    scene = vdbhair.fit(hair)
    (tmp_path / "fits.json").write_text(json.dumps(scene))
    out = tmp_path / "out.hair"

    grown, report = vdbhair.grow(scene, return_report=True)
    assert report["strands"] == len(grown) and report["guides"] == len(scene["guides"])
    _same_report(report, _command("grow", tmp_path / "fits.json", "-o", out), ["scene", "output", "seconds"])

    surface, region = vdbhair.scalp(str(head), region=hair)
    vdbhair.write_grids(str(tmp_path / "scalp.vdb"), [surface, region])
    _command("roots", tmp_path / "scalp.vdb", "-o", tmp_path / "roots.ply", "--count", "300")
    r = vdbhair.roots(str(tmp_path / "scalp.vdb"), count=300)  # the file's roots (the test above)
    for method, extra in (("points", ["--curl", "0.5", "--curl-frequency", "1"]), ("helicoid", ["--method", "helicoid"])):
        kw = {"curl": 0.5, "curl_frequency": 1.0} if method == "points" else {"method": "helicoid"}
        strands, report = vdbhair.interpolate(hair, r["positions"], normals=r["normals"], return_report=True, **kw)
        assert report["strands"] == len(strands) == len(r["positions"])
        cmd = _command("interpolate", path, "-o", out, "--roots", tmp_path / "roots.ply", *extra)
        _same_report(report, cmd, ["output", "seconds", "strands_per_second"], timings=["fit_seconds"])
