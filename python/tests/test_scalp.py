"""scalp, roots and reconstruct: analytic oracles (a sphere), the command's results value for value,
thread independence and the argument errors."""
import pathlib
import subprocess

import numpy as np
import pytest

import vdbhair
from conftest import straight_bundle


def cli_or_skip():
    cli = pathlib.Path(vdbhair.__file__).resolve().parents[1] / "bin" / "vdbhair"
    if not cli.exists():
        pytest.skip(f"no command-line vdbhair at {cli}")
    return cli


def fibonacci_sphere(n, radius=1.0):
    i = np.arange(n) + 0.5
    z = 1.0 - 2.0 * i / n
    r = np.sqrt(1.0 - z * z)
    phi = np.pi * (3.0 - np.sqrt(5.0)) * i
    unit = np.stack([r * np.cos(phi), z, r * np.sin(phi)], axis=1)
    return radius * unit, unit


def read_roots_ply(path):
    """x y z nx ny nz tx ty tz as float32, binary little-endian (what `vdbhair roots` writes)."""
    data = pathlib.Path(path).read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode()
    assert "binary_little_endian" in header and "property float tz" in header
    return np.frombuffer(data[end:], dtype="<f4").reshape(-1, 9)


def test_scalp_sphere_is_a_signed_distance():
    surface, region = vdbhair.scalp(sphere=(1.0, 2.0, 3.0, 2.0), voxel_size=0.1)
    assert region is None
    assert surface.name == "surface" and surface.grid_class == "level set" and surface.value_type == "float"
    world = surface.active_coords() * surface.voxel_size
    exact = np.linalg.norm(world - [1.0, 2.0, 3.0], axis=1) - 2.0
    # A narrow band of half width 3 voxels, its values the distance to the sphere (world units).
    assert np.abs(surface.values()).max() <= 3 * 0.1 + 1e-6
    near = np.abs(exact) < 0.25
    assert near.sum() > 1000
    assert np.abs(surface.values()[near] - exact[near]).max() < 0.02


def test_scalp_from_points_and_strands():
    pts, normals = fibonacci_sphere(300, radius=1.0)
    surface, _ = vdbhair.scalp(pts, normals=normals, voxel_size=0.05)
    world = surface.active_coords() * surface.voxel_size
    exact = np.linalg.norm(world, axis=1) - 1.0
    near = np.abs(exact) < 0.05
    assert np.abs(surface.values()[near] - exact[near]).max() < 0.02  # Turk & O'Brien's implicit through the sphere
    # A Strands: its roots with their first segments as normals (hair growing outward from the sphere).
    positions = np.concatenate([np.stack([p, p * 1.2]) for p in pts]).astype(np.float32)
    hair = vdbhair.Strands(positions, np.arange(len(pts) + 1, dtype=np.int64) * 2)
    from_hair, _ = vdbhair.scalp(hair, voxel_size=0.05)
    assert np.array_equal(from_hair.active_coords(), surface.active_coords())
    assert np.allclose(from_hair.values(), surface.values(), atol=1e-4)  # normals from float32 segments
    with pytest.raises(ValueError, match="points need normals="):
        vdbhair.scalp(pts)
    with pytest.raises(ValueError, match="2 normals for 300 points"):
        vdbhair.scalp(pts, normals=normals[:2])
    with pytest.raises(ValueError, match="give one of source"):
        vdbhair.scalp()
    with pytest.raises(ValueError, match="4 constraint points"):
        vdbhair.scalp(pts[:4], normals=normals[:4])


def test_scalp_and_roots_match_the_commands(tmp_path):
    cli = cli_or_skip()
    # The region from roots around the north pole, then follicles on it; the same as the commands.
    pole = straight_bundle(count=5, vertices=3, length=0.2, spacing=0.1, direction=(0.0, 1.0, 0.0))
    shifted = vdbhair.Strands(pole.positions + np.array([0.0, 1.0, 0.0], dtype=np.float32), pole.offsets)
    hair = tmp_path / "pole.hair"
    vdbhair.write(shifted, str(hair))
    surface, region = vdbhair.scalp(sphere=(0.0, 0.0, 0.0, 1.0), voxel_size=0.05, region=shifted)
    assert region is not None and region.name == "region" and region.value_type == "bool"
    scalp_vdb = tmp_path / "scalp.vdb"
    subprocess.run([str(cli), "scalp", "--sphere", "0,0,0,1", "--voxel-size", "0.05", "--region", str(hair),
                    "-o", str(scalp_vdb), "-q"], check=True)
    theirs = vdbhair.read_grid(str(scalp_vdb), "surface")
    assert np.array_equal(surface.active_coords(), theirs.active_coords())
    assert np.array_equal(surface.values(), theirs.values())

    ours = vdbhair.roots(surface, count=40, region=region, seed=3)
    from_file = vdbhair.roots(str(scalp_vdb), count=40, seed=3)  # the file's region is used
    assert from_file["region"] and ours["region"]
    subprocess.run([str(cli), "roots", str(scalp_vdb), "--count", "40", "--seed", "3", "-o", str(tmp_path / "r.ply"), "-q"],
                   check=True)
    ply = read_roots_ply(tmp_path / "r.ply")
    for r in (ours, from_file):
        assert np.array_equal(r["positions"], ply[:, 0:3])
        assert np.array_equal(r["normals"], ply[:, 3:6])
        assert np.array_equal(r["tangents"], ply[:, 6:9])
    # On the sphere, near the pole (the region), normals outward.
    p = ours["positions"]
    assert np.abs(np.linalg.norm(p, axis=1) - 1.0).max() < 0.01
    bundle = shifted.positions[shifted.offsets[:-1]]
    projected = bundle / np.linalg.norm(bundle, axis=1)[:, None]
    nearest = np.linalg.norm(p[:, None, :] - projected[None, :, :], axis=2).min(axis=1)
    radius = 2 * 0.1  # the default: twice the roots' mean spacing
    assert nearest.max() <= radius + 0.05 * np.sqrt(3)  # within a voxel of the region's discs
    assert np.abs(np.einsum("ij,ij->i", ours["normals"], p / np.linalg.norm(p, axis=1)[:, None]) - 1.0).max() < 1e-3


def test_roots_over_a_whole_sphere():
    surface, _ = vdbhair.scalp(sphere=(0.0, 0.0, 0.0, 1.0), voxel_size=0.05)
    r = vdbhair.roots(surface, count=300, threads=1)
    assert r["positions"].shape == (300 - r["removed"], 3) and r["positions"].dtype == np.float32
    assert r["area"] == pytest.approx(4.0 * np.pi, rel=0.03)
    assert r["spacing"]["cv"] < 0.1  # evenly spread
    assert np.array_equal(vdbhair.roots(surface, count=300, threads=2)["positions"], r["positions"])
    # A spacing instead of a count; the errors.
    assert vdbhair.roots(surface, spacing=0.3)["spacing"]["mean"] == pytest.approx(0.3, rel=0.15)
    # Fission from a quarter of the count reaches it.
    grown = vdbhair.roots(surface, count=300, initial_fraction=0.25)
    assert grown["initial"] == 75 and grown["fissions"] >= 200
    assert abs(len(grown["positions"]) - 300) <= 6 and grown["spacing"]["cv"] < 0.1
    assert grown["contour"] == 0  # no region, no rim
    with pytest.raises(ValueError, match=r"^roots: initial_fraction 0: must be above 0 and at most 4$"):
        vdbhair.roots(surface, count=10, initial_fraction=0.0)
    with pytest.raises(ValueError, match="give one of count= and spacing="):
        vdbhair.roots(surface)
    with pytest.raises(ValueError, match=r"^roots: spacing -1: must be at least 0 world units$"):
        vdbhair.roots(surface, spacing=-1.0)
    with pytest.raises(TypeError, match="not a float level set"):
        vdbhair.roots(vdbhair.estimate_tangent_field(straight_bundle()).density, count=10)


def test_reconstruct_straight_hair():
    hair = straight_bundle(count=6, vertices=12, length=3.0, spacing=0.2)
    helicoid, points, report = vdbhair.reconstruct(hair, guides=0.25, seed=1)
    assert len(helicoid) == len(points) == len(hair)
    assert len(report["guide_strands"]) == report["guides"] == 9  # round(0.25 * 36)
    for method, out in (("helicoid", helicoid), ("points", points)):
        assert report["per_strand"][method].shape == (36,)
        # Straight parallel hair is rebuilt straight: the fits are within 0.9 % of these strands,
        # and the arcs reconstruction blends them (1.1 %).
        assert report["frechet_relative"][method]["mean"] < 0.015, method
        for i in range(len(out)):
            assert np.allclose(out[i][0], hair[i][0], atol=1e-4), method  # every root kept
    # The paper's blend of the fits' own pieces, on request; a blend that does not exist is refused.
    fitted = vdbhair.reconstruct(hair, guides=0.25, seed=1, blend="fitted")[2]
    assert fitted["frechet_relative"]["helicoid"]["mean"] < 0.015
    assert fitted["frechet_relative"]["points"]["mean"] == report["frechet_relative"]["points"]["mean"]
    with pytest.raises(ValueError, match=r"^reconstruct: blend 'sideways': must be one of arcs, fitted$"):
        vdbhair.reconstruct(hair, blend="sideways")
    # Every strand a guide: the points way returns the strands themselves.
    _, same, everything = vdbhair.reconstruct(hair, guides=1.0, meters_per_unit=0.01)
    assert everything["frechet_relative"]["points"]["mean"] == 0.0
    assert np.array_equal(same.positions, hair.positions)
    # As papers measure: the strands themselves match every oriented point, at no position error.
    assert report["measures"]["points"]["oriented_points"] is None  # no unit: not measured
    measured = everything["measures"]["points"]
    assert [m["distance_mm"] for m in measured["oriented_points"]] == pytest.approx([2.0, 3.0, 4.0, 4.0])
    assert all(m["f1"] == 1.0 and m["strand_consistency"] == 1.0 for m in measured["oriented_points"])
    assert measured["perm_position"] == 0.0 and measured["perm_curvature"] == 0.0
    assert report["measures"]["nearest"]["perm_position"] >= 0.0
    # Parallel straight hair stays inside its guides' volume; a head sphere across the strands'
    # middles is entered by as many rebuilt strands (points) as original ones.
    leaving = report["leaving_guide_volume"]
    assert leaving["original"] == 0.0 and leaving["points"] == 0.0 and leaving["voxel"] > 0.0
    assert report["entering_head"] is None  # no head: not measured
    entering = vdbhair.reconstruct(hair, guides=0.25, seed=1, head=(1.5, 0.0, 0.0, 0.3))[2]["entering_head"]
    assert 0.0 < entering["original"] <= 1.0
    assert entering["points"] == pytest.approx(entering["original"])
    with pytest.raises(ValueError, match=r"^reconstruct: meters_per_unit -1: must be at least 0$"):
        vdbhair.reconstruct(hair, meters_per_unit=-1.0)
    h1 = vdbhair.reconstruct(hair, guides=0.25, seed=1, threads=1)[0]
    assert np.array_equal(h1.positions, helicoid.positions)
    with pytest.raises(ValueError, match=r"^reconstruct: guides 0: must be above 0 and at most 1$"):
        vdbhair.reconstruct(hair, guides=0.0)
    with pytest.raises(ValueError, match=r"^reconstruct: select 'grid': must be one of random, cluster$"):
        vdbhair.reconstruct(hair, select="grid")
    with pytest.raises(ValueError, match=r"^reconstruct: max_error 0: must be above 0$"):
        vdbhair.reconstruct(hair, max_error=0.0)


def test_scalp_region_painted_on_vertices(tmp_path):
    # An octahedron of radius 10, its top vertex painted red: the region is around the top, as the command makes it.
    ply = tmp_path / "painted.ply"
    ply.write_text("ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\nproperty float z\n"
                   "property uchar red\nelement face 8\nproperty list uchar int vertex_indices\nend_header\n"
                   "10 0 0 0\n-10 0 0 0\n0 10 0 255\n0 -10 0 0\n0 0 10 0\n0 0 -10 0\n"
                   "3 0 2 4\n3 4 2 1\n3 1 2 5\n3 5 2 0\n3 0 4 3\n3 4 1 3\n3 1 5 3\n3 5 0 3\n")
    surface, region = vdbhair.scalp(str(ply), voxel_size=0.5, region_vertex="red")
    assert region.metadata["vdbhair_region_kind"] == "vertex"
    y = region.active_coords()[:, 1] * region.voxel_size
    assert y.min() > 0.0 and y.max() > 9.0  # the upper half's painted apex, none of the lower half
    cli = cli_or_skip()
    subprocess.run([str(cli), "scalp", str(ply), "--voxel-size", "0.5", "--region-vertex", "red", "-o", str(tmp_path / "p.vdb"), "-q"],
                   check=True)
    assert np.array_equal(region.active_coords(), vdbhair.read_grid(str(tmp_path / "p.vdb"), "region").active_coords())
    with pytest.raises(ValueError, match="no scalar property 'hair'"):
        vdbhair.scalp(str(ply), region_vertex="hair")
    with pytest.raises(ValueError, match="the source is not a .ply path"):
        vdbhair.scalp(sphere=(0.0, 0.0, 0.0, 1.0), region_vertex="red")
