"""vdbhair.Strands: arrays, checks, iteration, and round trips through every writable format."""
import os
import pathlib
import re
import subprocess

import numpy as np
import pytest

import vdbhair
from conftest import SOURCE_DIR, straight_bundle, wavy_hairstyle


def two_strands():
    positions = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 2, 0], [0, 3, 1]], dtype=np.float32)
    return positions, np.array([0, 2, 5])


def test_arrays_and_views():
    positions, offsets = two_strands()
    s = vdbhair.Strands(positions, offsets)
    assert len(s) == 2 and s.num_vertices == 5
    assert s.positions.dtype == np.float32 and s.positions.shape == (5, 3)
    assert s.offsets.dtype == np.int64 and list(s.offsets) == [0, 2, 5]
    assert list(s.counts) == [2, 3]
    np.testing.assert_array_equal(s.positions, positions)
    # positions is a view of the C++ storage (no copy): two reads share memory, and it is read-only.
    assert np.shares_memory(s.positions, s.positions)
    assert not s.positions.flags.writeable
    with pytest.raises(ValueError):
        s.positions[0, 0] = 5.0
    # The view keeps the strands alive.
    view = vdbhair.Strands(positions, offsets).positions
    np.testing.assert_array_equal(view, positions)
    assert s.thickness is None and s.color is None and s.root_uv is None and s.strand_id is None


def test_iteration_and_indexing():
    positions, offsets = two_strands()
    s = vdbhair.Strands(positions, offsets)
    items = list(s)
    assert [a.shape for a in items] == [(2, 3), (3, 3)]
    np.testing.assert_array_equal(items[1], positions[2:5])
    np.testing.assert_array_equal(s[-1], positions[2:5])
    with pytest.raises(IndexError):
        s[2]


def test_attributes():
    positions, offsets = two_strands()
    s = vdbhair.Strands(positions, offsets, thickness=np.arange(5) * 0.1, color=np.full((5, 3), 0.25),
                        root_uv=[[0.1, 0.2], [0.3, 0.4]], strand_id=[7, 9])
    np.testing.assert_allclose(s.thickness, np.arange(5) * 0.1, rtol=1e-6)
    assert s.color.shape == (5, 3) and s.color.dtype == np.float32
    assert list(s.strand_id) == [7, 9] and s.strand_id.dtype == np.int32
    np.testing.assert_allclose(s.root_uv, [[0.1, 0.2], [0.3, 0.4]], rtol=1e-6)


@pytest.mark.parametrize("kwargs, message", [
    (dict(positions=np.zeros((5, 2)), offsets=[0, 2, 5]), "Strands(positions): shape (5, 2); must be (V, 3)"),
    (dict(positions=np.array([["a", "b", "c"]] * 5), offsets=[0, 2, 5]), "Strands(positions): dtype <U1; must hold real numbers"),
    (dict(positions=np.zeros((5, 3)), offsets=[0, 1, 5]), "Strands(offsets): strand 0 has 1 vertices (offsets[0] = 0, offsets[1] = 1); a strand needs at least 2"),
    (dict(positions=np.zeros((5, 3)), offsets=[1, 3, 5]), "Strands(offsets): offsets[0] = 1; must be 0"),
    (dict(positions=np.zeros((5, 3)), offsets=[0, 2, 4]), "Strands(offsets): the last offset is 4 but positions has 5 rows; it must equal the vertex count"),
    (dict(positions=np.zeros((5, 3)), offsets=[0.0, 2.0, 5.0]), "Strands(offsets): dtype float64; must hold integers"),
    (dict(positions=np.zeros((5, 3)), offsets=[0, 2, 5], thickness=np.ones(4)), "Strands(thickness): shape (4,); must be (V,)"),
    (dict(positions=np.zeros((5, 3)), offsets=[0, 2, 5], strand_id=[1, 2**40]), "Strands(strand_id): strand 1 has id 1099511627776; ids must fit in 32 bits"),
])
def test_bad_arrays_rejected_with_their_message(kwargs, message):
    with pytest.raises(ValueError) as info:
        vdbhair.Strands(**kwargs)
    assert str(info.value) == message
    assert isinstance(info.value, vdbhair.Error)


def test_non_finite_position_named():
    positions, offsets = two_strands()
    positions[3, 1] = np.nan
    with pytest.raises(ValueError, match=r"^Strands\(positions\): vertex 3 has a non-finite coordinate \(0, nan, 0\); coordinates must be finite$"):
        vdbhair.Strands(positions, offsets)


# Binary formats keep float32 exactly; text formats (.obj, .usda, ascii .ply) to float32 rounding.
@pytest.mark.parametrize("ext, exact", [(".hair", True), (".data", True), (".ply", True), (".vdb", False), (".obj", False), (".usda", False)])
def test_round_trip_every_writable_format(tmp_path, ext, exact):
    s = wavy_hairstyle(count=40, vertices=12)
    path = str(tmp_path / ("hair" + ext))
    vdbhair.write(s, path)
    back = vdbhair.read(path)
    assert len(back) == len(s)
    np.testing.assert_array_equal(back.offsets, s.offsets)
    if exact:
        np.testing.assert_array_equal(back.positions, s.positions)
    else:
        scale = float(np.abs(s.positions).max())
        np.testing.assert_allclose(back.positions, s.positions, rtol=0, atol=1e-6 * scale)
    # The method writes the same file.
    path2 = str(tmp_path / ("again" + ext))
    s.write(path2)
    np.testing.assert_array_equal(vdbhair.read(path2).positions, back.positions)


def test_ascii_ply_and_polyline_obj(tmp_path):
    s = straight_bundle(count=3)
    vdbhair.write(s, str(tmp_path / "a.ply"), ply_encoding="ascii")
    assert (tmp_path / "a.ply").read_bytes().startswith(b"ply\nformat ascii")
    vdbhair.write(s, str(tmp_path / "p.obj"), obj_lines="polylines")
    assert sum(1 for line in (tmp_path / "p.obj").read_text().splitlines() if line.startswith("l ")) == len(s)
    with pytest.raises(ValueError, match="^write: ply_encoding 'big': must be one of binary, ascii$"):
        vdbhair.write(s, str(tmp_path / "b.ply"), ply_encoding="big")


def test_read_errors_are_typed(tmp_path):
    with pytest.raises(OSError) as info:
        vdbhair.read(str(tmp_path / "missing.hair"))
    assert isinstance(info.value, vdbhair.IoError) and "missing.hair" in str(info.value)
    bad = tmp_path / "bad.hair"
    bad.write_bytes(b"NOPE" + bytes(200))
    with pytest.raises(vdbhair.FormatError) as info:
        vdbhair.read(str(bad))
    assert "bad.hair" in str(info.value) and isinstance(info.value, ValueError)
    with pytest.raises(vdbhair.ArgumentError, match="tfx"):
        vdbhair.write(straight_bundle(), str(tmp_path / "out.tfx"))
    assert not (tmp_path / "out.tfx").exists()


def test_ply_points_in_runs_and_obj_curves_take_keywords(tmp_path):
    # A PLY of points only, 3 strands of 4 points (NeuralHaircut's layout), written here.
    pts = np.arange(36, dtype=np.float32).reshape(12, 3)
    path = tmp_path / "runs.ply"
    path.write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 12\nproperty float x\nproperty float y\n"
                     b"property float z\nend_header\n" + pts.tobytes())
    s = vdbhair.read(str(path), points_per_strand=4)
    assert len(s) == 3 and np.array_equal(s[1], pts[4:8])
    with pytest.raises(vdbhair.FormatError, match="read it with points_per_strand=N"):
        vdbhair.read(str(path))
    with pytest.raises(vdbhair.FormatError, match="not a multiple of points_per_strand=5"):
        vdbhair.read(str(path), points_per_strand=5)
    with pytest.raises(ValueError, match=r"^read: points_per_strand -1: must be at least 0$"):
        vdbhair.read(str(path), points_per_strand=-1)
    # A cubic Bezier curve, sampled at 7 points on request.
    obj = tmp_path / "curve.obj"
    obj.write_text("v 0 0 0\nv 1 2 0\nv 3 2 0\nv 4 0 0\ncstype bezier\ndeg 3\ncurv 0 1 -4 -3 -2 -1\nend\n")
    c = vdbhair.read(str(obj), curve_samples=7)
    assert len(c) == 1 and c[0].shape == (7, 3)
    assert np.allclose(c[0][3], [2.0, 1.5, 0.0])  # the Bezier's middle: (P0 + 3 P1 + 3 P2 + P3) / 8
    with pytest.raises(ValueError, match=r"^curve_samples 1: must be 0 \(automatic\) or 2 or more$"):
        vdbhair.read(str(obj), curve_samples=1)


def test_short_strands_dropped_with_a_warning_or_rejected(tmp_path):
    # A .data file with a strand of one vertex between two good ones.
    path = tmp_path / "short.data"
    body = [np.int32(3).tobytes()]
    for n in (2, 1, 2):
        body.append(np.int32(n).tobytes())
        body.append(np.arange(3 * n, dtype=np.float32).tobytes())
    path.write_bytes(b"".join(body))
    with pytest.warns(UserWarning, match="dropped 1 strand"):
        s = vdbhair.read(str(path))
    assert len(s) == 2
    with pytest.raises(vdbhair.FormatError, match="strand 1 has 1 vertices"):
        vdbhair.read(str(path), strict=True)


@pytest.mark.data
def test_real_file_counts(shared_data):
    s = vdbhair.read(str(shared_data / "hair/cyhair/straight.hair"))
    assert (len(s), s.num_vertices) == (10000, 160000)
    assert np.all(s.counts == 16)
    # The same 100 strands in four formats read alike.
    base = vdbhair.read(str(shared_data / "hair/cyhair/Bangs_100.hair"))
    assert (len(base), base.num_vertices) == (100, 1165)
    for rel in ("usc_data/Bangs_100.data", "ct2hair_bin/Bangs_100.bin", "ply/Bangs_100_binary.ply"):
        other = vdbhair.read(str(shared_data / "hair" / rel))
        np.testing.assert_array_equal(other.offsets, base.offsets, err_msg=rel)
        np.testing.assert_allclose(other.positions, base.positions, rtol=0, atol=1e-3, err_msg=rel)


@pytest.mark.data
def test_real_data_file_as_numpy_would_read_it(shared_data):
    """A .data file read by vdbhair matches numpy.fromfile plus the offsets a user would compute."""
    path = shared_data / "hair/usc_data/harolongo.data"
    raw = np.fromfile(path, dtype=np.uint8)
    count = int(raw[:4].view(np.int32)[0])
    pos, offsets, cursor = [], [0], 4
    for _ in range(count):
        n = int(raw[cursor:cursor + 4].view(np.int32)[0])
        pos.append(raw[cursor + 4:cursor + 4 + 12 * n].view(np.float32).reshape(n, 3))
        cursor += 4 + 12 * n
        offsets.append(offsets[-1] + n)
    s = vdbhair.read(str(path))
    assert len(s) == count == 7905
    np.testing.assert_array_equal(s.offsets, offsets)
    np.testing.assert_array_equal(s.positions, np.concatenate(pos))


def hair_on_sphere(count=64, vertices=12, radius=10.0, seed=3):
    """Strands rooted on the upper half of a sphere, leaving along the normal and falling to -y."""
    rng = np.random.default_rng(seed)
    points = []
    for _ in range(count):
        phi, cos_t = rng.uniform(0, 2 * np.pi), rng.uniform(0.1, 1.0)
        n = np.array([np.sqrt(1 - cos_t**2) * np.cos(phi), cos_t, np.sqrt(1 - cos_t**2) * np.sin(phi)])
        p, length = radius * n, radius * rng.uniform(0.5, 2.5)
        for k in range(vertices):
            points.append(p.copy())
            t = k / (vertices - 1)
            d = (1 - t) * n + t * np.array([0.0, -1.0, 0.0])
            p += length / (vertices - 1) * d / np.linalg.norm(d)
    return vdbhair.Strands(np.array(points, dtype=np.float32), np.arange(count + 1) * vertices)


def test_read_roots_last_and_auto(tmp_path):
    hair = hair_on_sphere()
    path = tmp_path / "rooted.hair"
    hair.write(path)
    tip_first = vdbhair.read(path, roots="last")
    np.testing.assert_array_equal(tip_first[0], hair[0][::-1])
    tip_first.write(tmp_path / "tip_first.hair")
    with pytest.warns(UserWarning, match=r"roots=auto reversed 100 % of the strands \(64 of 64\)"):
        back = vdbhair.read(tmp_path / "tip_first.hair", roots="auto")
    np.testing.assert_array_equal(back.positions, hair.positions)
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # hair rooted first: kept, without a word
        np.testing.assert_array_equal(vdbhair.read(path, roots="auto").positions, hair.positions)
    with pytest.raises(vdbhair.ArgumentError, match="^read: roots 'tip': must be one of first, last, auto$"):
        vdbhair.read(path, roots="tip")


def test_paths_may_be_pathlib(tmp_path):
    hair = hair_on_sphere(count=4)
    vdbhair.write(hair, tmp_path / "a.ply")
    hair.write(tmp_path / "b.obj")
    assert len(vdbhair.read(tmp_path / "a.ply")) == 4
    assert len(vdbhair.read(str(tmp_path / "b.obj"))) == 4
    field = vdbhair.estimate_tangent_field(hair, voxel_size=2.0)
    field.write(tmp_path / "f.vdb")
    assert "tangent" in vdbhair.read_grids(tmp_path / "f.vdb")
    assert vdbhair.inspect(tmp_path / "f.vdb")


def test_write_takes_the_cli_write_options(tmp_path):
    hair = hair_on_sphere(count=4)
    out = tmp_path / "h.usda"
    vdbhair.write(hair, out, usd_up="z", meters_per_unit=1.0, width=0.25)
    text = out.read_text()
    assert 'upAxis = "Z"' in text and "metersPerUnit = 1\n" in text
    assert 'float[] widths = [0.25] (\n        interpolation = "constant"' in text
    again = vdbhair.read(out)
    again.write(tmp_path / "h2.usda")  # USD to USD keeps the unit and the axis
    text2 = (tmp_path / "h2.usda").read_text()
    assert 'upAxis = "Z"' in text2 and "metersPerUnit = 1\n" in text2
    hair.write(tmp_path / "h.vdb", codec="fixed8")
    assert np.abs(vdbhair.read(tmp_path / "h.vdb").positions - hair.positions).max() < 0.5
    with pytest.raises(vdbhair.ArgumentError, match="^write: codec 'zip': must be one of float, fixed16, fixed8$"):
        hair.write(tmp_path / "x.vdb", codec="zip")
    with pytest.raises(vdbhair.ArgumentError, match="^write: usd_up 'x': must be one of auto, y, z$"):
        vdbhair.write(hair, out, usd_up="x")
    with pytest.raises(vdbhair.ArgumentError, match="^write: meters_per_unit -1: must be at least 0 metres$"):
        vdbhair.write(hair, out, meters_per_unit=-1)
    with pytest.raises(vdbhair.ArgumentError, match="^write: voxel_size -2: must be at least 0 world units$"):
        vdbhair.write(hair, tmp_path / "x.vdb", voxel_size=-2)


def cli():
    """The `vdbhair` command of the same build (VDBHAIR_CLI, else bin/ next to the module's python/)."""
    path = os.environ.get("VDBHAIR_CLI") or str(pathlib.Path(vdbhair.__file__).resolve().parents[1] / "bin" / "vdbhair")
    assert os.access(path, os.X_OK), f"no vdbhair command at {path} (set VDBHAIR_CLI)"
    return path


def test_write_keywords_are_converts_declared_options_and_write_the_same_bytes(tmp_path):
    """write()'s keywords are writeParameters(), which `vdbhair convert` takes as options: the same
    names, and the same values write the same file from a real hairstyle."""
    signature = vdbhair.write.__doc__.splitlines()[0]
    keywords = re.findall(r"(\w+): [^,]+? = ", signature)
    assert keywords == ["ply_encoding", "obj_lines", "codec", "voxel_size", "usd_up", "meters_per_unit", "width"]
    shown = subprocess.run([cli(), "convert", "--help"], capture_output=True, text=True, check=True).stdout
    for keyword in keywords:
        assert re.search(r"^\s+--" + keyword.replace("_", "-") + r"\b", shown, re.M), f"convert --help has no --{keyword}"
    source = SOURCE_DIR / "scenes" / "default" / "ponytail.hair"
    hair = vdbhair.read(source)
    cases = [("a.usda", dict(usd_up="z", meters_per_unit=1.0, width=0.1), ["--usd-up", "z", "--meters-per-unit", "1", "--width", "0.1"]),
             ("b.usda", dict(usd_up="auto"), []),
             ("a.ply", dict(ply_encoding="ascii"), ["--ply-encoding", "ascii"]),
             ("a.obj", dict(obj_lines="polylines"), ["--obj-lines", "polylines"])]
    for name, keywords, flags in cases:
        vdbhair.write(hair, tmp_path / ("python_" + name), **keywords)
        subprocess.run([cli(), "convert", str(source), str(tmp_path / ("cli_" + name)), "--quiet", *flags], check=True)
        assert (tmp_path / ("python_" + name)).read_bytes() == (tmp_path / ("cli_" + name)).read_bytes(), name


def test_units_declared_and_converted(tmp_path):
    positions, offsets = two_strands()
    s = vdbhair.Strands(positions, offsets)
    assert s.meters_per_unit is None and s.up_axis is None
    with pytest.raises(ValueError, match="declare no unit to convert from"):
        s.convert_units("m")
    s.meters_per_unit = 0.01  # declares centimetres; nothing moves
    np.testing.assert_array_equal(s.positions, positions)
    s.convert_units("mm")
    assert s.meters_per_unit == 0.001
    np.testing.assert_allclose(s.positions, positions * 10.0, rtol=1e-6)
    s.convert_units(1.0)  # metres, as a number
    np.testing.assert_allclose(s.positions, positions * 0.01, rtol=1e-6)
    s.write(tmp_path / "m.usda")
    again = vdbhair.read(tmp_path / "m.usda")
    assert again.meters_per_unit == 1.0 and again.up_axis == "Y"
    with pytest.raises(ValueError, match="'furlong': expected mm, cm, dm, m, in"):
        s.convert_units("furlong")
    with pytest.raises(ValueError, match="meters_per_unit=-1"):
        s.meters_per_unit = -1.0
    assert s.meters_per_unit == 1.0  # a refused value changes nothing


def test_defaults_settable_and_written_to_hair(tmp_path):
    # A cyHair header's defaults carried by strands built from arrays (the Blender add-on's export).
    positions, offsets = two_strands()
    s = vdbhair.Strands(positions, offsets)
    assert s.defaults == {"thickness": 1.0, "transparency": 0.0, "color": (0.5, 0.5, 0.5)}
    s.defaults = {"thickness": 0.25, "color": (1.0, 0.5, 0.0)}  # some keys: the others kept
    assert s.defaults == {"thickness": 0.25, "transparency": 0.0, "color": (1.0, 0.5, 0.0)}
    s.write(tmp_path / "d.hair")
    assert vdbhair.read(tmp_path / "d.hair").defaults == s.defaults
    with pytest.raises(ValueError, match="unknown key 'width'; the keys are thickness, transparency, color"):
        s.defaults = {"thickness": 2.0, "width": 1.0}
    with pytest.raises(ValueError, match="transparency = nan; must be a finite number"):
        s.defaults = {"transparency": float("nan")}
    with pytest.raises(ValueError, match="color has 2 values; must be"):
        s.defaults = {"color": (1.0, 0.0)}
    assert s.defaults["thickness"] == 0.25  # a refused dict changes nothing
