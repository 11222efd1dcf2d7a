"""Fields: estimation, retracing, refinement, dense volumes, threads, pyopenvdb interop."""
import numpy as np
import pytest

import vdbhair
from conftest import straight_bundle, wavy_hairstyle


def test_straight_field_is_uniform(bundle):
    field = vdbhair.estimate_tangent_field(bundle, voxel_size=0.25)
    assert field.voxel_size == pytest.approx(0.25)
    coords, values = field.active_coords(), field.values()
    assert coords.dtype == np.int32 and values.dtype == np.float32
    assert coords.shape == values.shape and coords.shape[0] == field.active_voxel_count > 0
    np.testing.assert_allclose(values, np.tile([1.0, 0.0, 0.0], (len(values), 1)), atol=1e-6)
    # Every active voxel is one some strand passes: x index within the strands' span.
    assert coords[:, 0].min() >= -1 and coords[:, 0].max() <= 4.0 / 0.25 + 1


def test_straight_field_retraces_straight(bundle):
    """A bent strand retraced through the field of parallel strands comes out straight along +x."""
    field = vdbhair.estimate_tangent_field(bundle, voxel_size=0.25)
    t = np.linspace(0.0, 1.0, 11, dtype=np.float32)
    bent = np.stack([t, 0.3 * np.sin(3.0 * t), 0.2 * t * t], axis=1).astype(np.float32)
    strand = vdbhair.Strands(bent, [0, len(bent)])
    out, stats = vdbhair.retrace(strand, field, return_report=True)
    assert stats["full_length"] == 1 and stats["strands"] == 1
    p = out.positions
    length = np.linalg.norm(np.diff(bent, axis=0), axis=1).sum()
    np.testing.assert_allclose(p[:, 1:], np.tile(bent[0, 1:], (len(p), 1)), atol=1e-5)  # no sideways motion
    assert p[-1, 0] - p[0, 0] == pytest.approx(length, rel=1e-5)  # its own length, along +x
    assert np.all(np.diff(p[:, 0]) > 0)
    # The bundle's own strands retrace onto themselves.
    again = vdbhair.retrace(bundle, field)
    np.testing.assert_allclose(again.positions, bundle.positions, atol=1e-5)


def test_to_dense_layout_is_z_y_x(wavy):
    field = vdbhair.estimate_tangent_field(wavy, voxel_size=0.2)
    (i0, j0, k0), (i1, j1, k1) = field.bbox
    dense = field.to_dense()
    assert dense.shape == (k1 - k0 + 1, j1 - j0 + 1, i1 - i0 + 1, 3) and dense.dtype == np.float32
    c, v = field.active_coords(), field.values()
    np.testing.assert_array_equal(dense[c[:, 2] - k0, c[:, 1] - j0, c[:, 0] - i0], v)
    # Inactive voxels are zero: as many non-zero voxels as active non-zero values.
    assert np.count_nonzero(np.any(dense != 0, axis=-1)) == np.count_nonzero(np.any(v != 0, axis=-1))
    # A box of a chosen size (e.g. a network's input) around the hair, padded with zeros.
    box = ((i0 - 2, j0 - 1, k0), (i0 + 9, j0 + 6, k0 + 3))
    small = field.to_dense(box)
    assert small.shape == (4, 8, 12, 3)
    np.testing.assert_array_equal(small[:, 1:8, 2:12], dense[0:4, 0:7, 0:10])
    assert np.all(small[:, 0] == 0) and np.all(small[:, :, :2] == 0)
    density = field.density.to_dense(field.bbox)
    assert density.shape == dense.shape[:3] and float(density.max()) <= 1.0
    with pytest.raises(ValueError, match="bbox max"):
        field.to_dense(((0, 0, 0), (-1, 0, 0)))


def test_orientation_volume_of_a_uniform_field_is_constant():
    # Straight strands along +x filling [0, 10]^3 with voxel size 1: every voxel holds (1, 0, 0).
    line = np.stack([np.arange(11.0), np.zeros(11), np.zeros(11)], axis=1)
    positions = np.concatenate([line + (0.0, 0.5 * j, 0.5 * k) for j in range(21) for k in range(21)])
    strands = vdbhair.Strands(positions, np.arange(0, 11 * 441 + 1, 11))
    field = vdbhair.estimate_tangent_field(strands, voxel_size=1.0)
    inside = field.orientation_volume(((2, 3, 4), (8, 7, 6)), (5, 6, 7))
    assert inside.shape == (5, 6, 7, 4) and inside.dtype == np.float32
    np.testing.assert_array_equal(inside, np.broadcast_to(np.float32([1, 0, 0, 1]), inside.shape))
    # Far outside the hair: zeros; the density grid has no direction to resample.
    assert not np.any(field.orientation_volume(((20, 20, 20), (30, 30, 30)), (2, 2, 2)))
    with pytest.raises(TypeError, match="vec3s tangent grid"):
        field.density.orientation_volume(((0, 0, 0), (1, 1, 1)), (2, 2, 2))
    with pytest.raises(ValueError, match="max must be above min"):
        field.orientation_volume(((0, 0, 0), (1, 0, 1)), (2, 2, 2))


def test_one_and_two_threads_identical(wavy):
    f1 = vdbhair.estimate_tangent_field(wavy, voxel_size=0.15, threads=1)
    f2 = vdbhair.estimate_tangent_field(wavy, voxel_size=0.15, threads=2)
    np.testing.assert_array_equal(f1.active_coords(), f2.active_coords())
    np.testing.assert_array_equal(f1.values(), f2.values())
    np.testing.assert_array_equal(f1.density.values(), f2.density.values())
    r1 = vdbhair.retrace(wavy, f1, threads=1)
    r2 = vdbhair.retrace(wavy, f2, threads=2)
    np.testing.assert_array_equal(r1.positions, r2.positions)
    g1 = vdbhair.refine(wavy, voxel_size=0.15, levels=2, threads=1, measure=False)
    g2 = vdbhair.refine(wavy, voxel_size=0.15, levels=2, threads=2, measure=False)
    np.testing.assert_array_equal(g1.positions, g2.positions)
    # ... and the retrace changed something, so the comparison could fail.
    assert not np.array_equal(r1.positions, wavy.positions)


def test_levels_and_defaults(wavy):
    fields = vdbhair.estimate_tangent_field(wavy, voxel_size=0.1, levels=3)
    assert [f.voxel_size for f in fields] == pytest.approx([0.1, 0.2, 0.4])
    auto = vdbhair.estimate_tangent_field(wavy)
    assert auto.voxel_size == pytest.approx(vdbhair.suggest_voxel_size(wavy))
    assert auto.metadata["vdbhair_iterations"] == 2


def test_refine_report(wavy):
    out, report = vdbhair.refine(wavy, voxel_size=0.15, levels=2, return_report=True, measure=True)
    assert len(out) == len(wavy) and out.num_vertices == wavy.num_vertices
    assert report["mode"] == "consistent" and len(report["per_level"]) == 2
    assert [f.voxel_size for f in report["fields"]] == pytest.approx([0.15, 0.3])
    assert 0.0 <= report["coherence"]["after"] <= 1.0
    # And the output against the input, as compare() reports it (the same function, the same keys).
    assert report["compare"]["paired"] and report["compare"]["strands"] == {"a": len(wavy), "b": len(out)}
    direct = vdbhair.compare(wavy, out)
    del direct["per_strand"]
    # refine's head (a sphere fitted to the roots) is compare's too: the shares passing into it are
    # measured there, not here.
    assert report["compare"].pop("entering_head") is not None and direct.pop("entering_head") is None
    assert report["compare"] == direct
    # The measures are opt-in (as `refine --measure`): without them the report has none.
    _, plain = vdbhair.refine(wavy, voxel_size=0.15, levels=2, return_report=True)
    assert "coherence" not in plain and "compare" not in plain and plain["mode"] == "consistent"
    field_mode = vdbhair.refine(wavy, voxel_size=0.15, mode="field", head="none")
    assert not np.array_equal(field_mode.positions, out.positions)
    with pytest.raises(ValueError, match="mode"):
        vdbhair.refine(wavy, mode="sideways")


def test_argument_errors(bundle, tmp_path):
    field = vdbhair.estimate_tangent_field(bundle, voxel_size=0.25)
    with pytest.raises(vdbhair.ArgumentError, match="voxel_size -1: must be at least 0"):
        vdbhair.estimate_tangent_field(bundle, voxel_size=-1.0)
    with pytest.raises(ValueError, match="integrator"):
        vdbhair.retrace(bundle, field, integrator="rk5")
    with pytest.raises(vdbhair.LimitError):
        vdbhair.estimate_tangent_field(bundle, voxel_size=1e-4, max_voxels=1000)
    with pytest.raises(ValueError, match=r"^threads -1: must be at least 0$"):
        vdbhair.retrace(bundle, field, threads=-1)
    with pytest.raises(TypeError, match="field must be a vdbhair.TangentField or a vdbhair.Grid"):
        vdbhair.retrace(bundle, "field.vdb")
    path = str(tmp_path / "f.vdb")
    field.write(path)
    with pytest.raises(vdbhair.GridTypeError):
        vdbhair.retrace(bundle, vdbhair.read_grid(path, "density"))
    with pytest.raises(LookupError) as info:
        vdbhair.read_grid(path, "nothing")
    assert isinstance(info.value, vdbhair.NotFoundError) and "tangent" in str(info.value)


def test_write_and_read_back(tmp_path, wavy):
    field = vdbhair.estimate_tangent_field(wavy, voxel_size=0.2)
    path = str(tmp_path / "field.vdb")
    field.write(path)
    grids = vdbhair.read_grids(path)
    assert sorted(grids) == ["coherence", "density", "hair_length", "spread", "tangent"]
    np.testing.assert_array_equal(grids["tangent"].values(), field.values())
    np.testing.assert_array_equal(grids["hair_length"].values(), field.hair_length.values())
    assert grids["tangent"].metadata["creator"].startswith("vdbhair")
    report = vdbhair.inspect(path)
    assert [r["name"] for r in report] == list(grids)  # file order, both
    tangent = next(r for r in report if r["name"] == "tangent")
    assert tangent["active_voxels"] == field.active_voxel_count
    assert tangent["unit_share"] > 0.9
    world = field.index_to_world([[1, 2, 3]])
    np.testing.assert_allclose(world, [[0.2, 0.4, 0.6]], atol=1e-12)
    np.testing.assert_allclose(field.world_to_index(world), [[1, 2, 3]], atol=1e-12)


def test_progress_callback_and_its_exception(wavy):
    calls = []
    vdbhair.estimate_tangent_field(wavy, voxel_size=0.2, progress=lambda *a: calls.append(a))
    assert calls and all(len(c) == 4 for c in calls)
    assert isinstance(calls[0][0], str) and calls[0][1] == 0

    def stop(*_):
        raise RuntimeError("stop here")
    with pytest.raises(RuntimeError, match="stop here"):
        vdbhair.retrace(wavy, vdbhair.estimate_tangent_field(wavy, voxel_size=0.2), progress=stop)


def test_ctrl_c_raises_keyboard_interrupt(wavy):
    """SIGINT during the work (sent from the progress callback, so the timing is certain) stops it
    with KeyboardInterrupt, and Python's own handler is back afterwards."""
    import os
    import signal
    field = vdbhair.estimate_tangent_field(wavy, voxel_size=0.2)
    with pytest.raises(KeyboardInterrupt, match="interrupted"):
        vdbhair.retrace(wavy, field, progress=lambda *a: os.kill(os.getpid(), signal.SIGINT))
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    assert len(vdbhair.retrace(wavy, field)) == len(wavy)  # later calls are not interrupted


def test_pyopenvdb_reads_what_vdbhair_writes(tmp_path, wavy):
    openvdb = pytest.importorskip("pyopenvdb", reason="pyopenvdb (Debian's python3-openvdb) is not installed")
    field = vdbhair.estimate_tangent_field(wavy, voxel_size=0.2)
    path = str(tmp_path / "field.vdb")
    field.write(path)
    grid = openvdb.read(path, "tangent")
    assert isinstance(grid, openvdb.Vec3SGrid)
    assert grid.activeVoxelCount() == field.active_voxel_count
    assert grid.transform.voxelSize()[0] == pytest.approx(0.2)
    acc = grid.getConstAccessor()
    got = np.array([acc.getValue(tuple(int(x) for x in c)) for c in field.active_coords()], dtype=np.float32)
    np.testing.assert_array_equal(got, field.values())
    # pyopenvdb's dense copy agrees with to_dense (its array is [x][y][z], ours [z][y][x]).
    (i0, j0, k0), (i1, j1, k1) = field.bbox
    theirs = np.zeros((i1 - i0 + 1, j1 - j0 + 1, k1 - k0 + 1, 3), dtype=np.float32)
    grid.copyToArray(theirs, ijk=(i0, j0, k0))
    np.testing.assert_array_equal(theirs.transpose(2, 1, 0, 3), field.to_dense())


def test_vdbhair_reads_what_pyopenvdb_writes(tmp_path):
    openvdb = pytest.importorskip("pyopenvdb", reason="pyopenvdb (Debian's python3-openvdb) is not installed")
    # A uniform field along the unit diagonal, made and written by pyopenvdb alone.
    direction = np.array([1.0, 1.0, 0.0]) / np.sqrt(2.0)
    dense = np.tile(direction.astype(np.float32), (24, 24, 24, 1))
    grid = openvdb.Vec3SGrid()
    grid.copyFromArray(dense, ijk=(-4, -4, -4))
    grid.name = "flow"
    grid.transform = openvdb.createLinearTransform(voxelSize=0.25)
    path = str(tmp_path / "pyopenvdb.vdb")
    openvdb.write(path, grids=[grid])

    flow = vdbhair.read_grid(path, "flow")
    assert flow.value_type == "vec3s" and flow.voxel_size == pytest.approx(0.25)
    assert flow.active_voxel_count == 24 ** 3
    np.testing.assert_allclose(flow.values(), np.tile(direction, (24 ** 3, 1)), atol=1e-7)
    # Strands traced through it run straight along the diagonal.
    t = np.linspace(0.0, 1.0, 5, dtype=np.float32)
    s = vdbhair.Strands(np.stack([t, np.zeros_like(t), np.zeros_like(t)], axis=1), [0, 5])
    out = vdbhair.retrace(s, flow)
    np.testing.assert_allclose(out.positions, t[:, None] * direction[None, :], atol=1e-5)


def test_refine_report_is_the_commands(wavy, tmp_path):
    import json
    import pathlib
    import subprocess
    # One report whichever front end ran it: refine(return_report=True) is `refine --json`'s, less
    # the command's output path, plus the fields (and compare() with measure=True, as the command).
    cli = pathlib.Path(vdbhair.__file__).resolve().parents[1] / "bin" / "vdbhair"
    if not cli.exists():
        pytest.skip(f"no command-line vdbhair at {cli}")
    hair = tmp_path / "wavy.hair"
    vdbhair.write(wavy, str(hair))
    for extra in ([], ["--measure"]):
        run = subprocess.run([str(cli), "refine", str(hair), "--voxel-size", "0.15", "--levels", "2", "--head", "none", "-o",
                              str(tmp_path / "out.hair"), "--json", *extra], check=True, capture_output=True, text=True)
        command = json.loads(run.stdout)
        _, report = vdbhair.refine(vdbhair.read(str(hair)), voxel_size=0.15, levels=2, head="none", measure=bool(extra),
                                   return_report=True)
        del command["output"]
        del report["fields"]
        # The memory the machine had free at that moment is the one figure that may differ.
        del command["memory"]["available_bytes"], report["memory"]["available_bytes"]
        assert report == command


def test_scalp_space_matches_the_command(wavy, tmp_path):
    import pathlib
    import subprocess
    # The same field as `vdbhair field --space scalp`, value for value (the sphere fitted to the roots).
    field = vdbhair.estimate_tangent_field(wavy, space="scalp")
    assert field.metadata["vdbhair_space"] == "scalp"
    cli = pathlib.Path(vdbhair.__file__).resolve().parents[1] / "bin" / "vdbhair"
    if not cli.exists():
        pytest.skip(f"no command-line vdbhair at {cli}")
    hair = tmp_path / "wavy.hair"
    vdbhair.write(wavy, str(hair))
    subprocess.run([str(cli), "field", str(hair), "--space", "scalp", "-o", str(tmp_path / "f.vdb"), "-q"], check=True)
    grid = vdbhair.read_grid(str(tmp_path / "f.vdb"), "tangent")
    assert np.array_equal(field.active_coords(), grid.active_coords())
    assert np.array_equal(field.values(), grid.values())
    # A given sphere is used as given; scalp= is refused in world space.
    given = vdbhair.estimate_tangent_field(wavy, space="scalp", scalp=(0.0, 0.0, 0.0, 1.0))
    assert given.metadata["vdbhair_scalp_radius"] == 1.0
    with pytest.raises(ValueError, match="scalp= is for space='scalp'"):
        vdbhair.estimate_tangent_field(wavy, scalp=(0.0, 0.0, 0.0, 1.0))
    with pytest.raises(ValueError, match="r > 0"):
        vdbhair.estimate_tangent_field(wavy, space="scalp", scalp=(0.0, 0.0, 0.0, 0.0))


def test_scalp_space_over_a_measured_head(tmp_path):
    # Hair standing on an ellipsoid head (semi-axes 1.3, 1, 1): over the head measured as a level
    # set, every root is at w = 0; over the sphere fitted to the roots, w spreads with the shape.
    rng = np.random.default_rng(4)
    strands = []
    for _ in range(400):
        h = rng.uniform(0.2, 0.95)
        a = rng.uniform(0.0, 2.0 * np.pi)
        r = np.sqrt(1.0 - h * h)
        root = np.array([1.3 * r * np.cos(a), h, r * np.sin(a)])
        n = np.array([root[0] / 1.69, root[1], root[2]])
        n /= np.linalg.norm(n)
        strands.append(root + np.linspace(0.0, 0.4, 12)[:, None] * n)
    hair = vdbhair.Strands(np.concatenate(strands).astype(np.float32), np.arange(0, 12 * 401, 12))
    # The head: a mesh of the ellipsoid, written as PLY.
    rings, segs = 40, 80
    verts = []
    for i in range(rings + 1):
        t = np.pi * i / rings
        for j in range(segs):
            p = 2.0 * np.pi * j / segs
            verts.append((1.3 * np.sin(t) * np.cos(p), np.cos(t), np.sin(t) * np.sin(p)))
    faces = []
    for i in range(rings):
        for j in range(segs):
            a, b = i * segs + j, i * segs + (j + 1) % segs
            c, d = a + segs, b + segs
            faces += [(a, c, b), (b, c, d)]
    head = tmp_path / "ellipsoid.ply"
    with open(head, "w") as f:
        f.write(f"ply\nformat ascii 1.0\nelement vertex {len(verts)}\nproperty float x\nproperty float y\nproperty float z\n"
                f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n")
        f.writelines(f"{x} {y} {z}\n" for x, y, z in verts)
        f.writelines(f"3 {a} {b} {c}\n" for a, b, c in faces)

    measured = vdbhair.estimate_tangent_field(hair, 0.05, space="scalp", scalp=str(head))
    meta = measured.metadata
    assert meta["vdbhair_scalp_resolution"] == 64
    table = np.array(meta["vdbhair_scalp_distance"].split(), dtype=np.float32)
    assert table.shape == (64 * 64,)
    # d, in radii of the sphere fitted to the roots, from the centre of that sphere: not constant
    # (the head is not that sphere), every ray hit it.
    assert np.all(np.isfinite(table)) and table.min() > 0.0 and table.max() / table.min() > 1.1
    assert len(meta["vdbhair_scalp_distance"]) > 30000
    # The grids' (u, v, w) lattice: the lowest active w layer holds the roots, at w = 0 over the
    # measured head; over the sphere the roots reach several voxels below and above it.
    sphere = vdbhair.estimate_tangent_field(hair, 0.05, space="scalp")
    lowest = measured.active_coords()[:, 2].min()
    assert lowest >= -1
    assert sphere.active_coords()[:, 2].min() < lowest - 2
    # Retraced, the strands stand along the normals they were made along.
    out = vdbhair.retrace(hair, measured)
    assert len(out) == 400
    with pytest.raises(ValueError, match="not inside the scalp surface"):
        far = vdbhair.Strands(hair.positions + np.float32([5.0, 0.0, 0.0]), hair.offsets)
        vdbhair.estimate_tangent_field(far, 0.05, space="scalp", scalp=str(head))


def test_refine_in_scalp_space_over_a_head(tmp_path):
    # refine(space="scalp", scalp=HEAD) as `vdbhair refine --space scalp --scalp HEAD`: the fields
    # carry the measured scalp and the head is the obstacle.
    surface, _ = vdbhair.scalp(sphere=(0.0, 0.0, 0.0, 1.0), voxel_size=0.02)
    head = str(tmp_path / "ball.vdb")
    vdbhair.write_grids(head, [surface])
    rng = np.random.default_rng(2)
    strands = []
    for _ in range(300):
        d = rng.normal(size=3)
        d[1] = abs(d[1]) + 0.3
        d /= np.linalg.norm(d)
        strands.append(d * 1.01 + np.linspace(0.0, 0.5, 10)[:, None] * d)
    hair = vdbhair.Strands(np.concatenate(strands).astype(np.float32), np.arange(0, 10 * 301, 10))
    out, report = vdbhair.refine(hair, voxel_size=0.05, space="scalp", scalp=head, return_report=True)
    assert len(out) == 300
    assert report["head"].startswith("level set")
    meta = report["fields"][0].metadata
    assert meta["vdbhair_space"] == "scalp" and meta["vdbhair_scalp_resolution"] == 64
    with pytest.raises(ValueError, match="scalp= is for space='scalp'"):
        vdbhair.refine(hair, scalp=head)
