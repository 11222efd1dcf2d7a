"""vdbhair.prepare and vdbhair.strand_statistics: the command line's dataset toolbox in Python."""
import json
import subprocess

import numpy as np
import pytest

import vdbhair
from conftest import straight_bundle
from test_defaults import cli


def sphere_mesh(path, scale=1.0, shift=(0.0, 0.0, 0.0), rings=10, segments=14):
    """A lumpy UV sphere as an OBJ (vertices moved by scale and shift; the same triangles)."""
    lines = []
    for i in range(rings + 1):
        t = np.pi * i / rings
        for j in range(segments):
            f = 2.0 * np.pi * j / segments
            p = np.array([0.8 * np.sin(t) * np.cos(f), np.cos(t) + 0.2 * np.sin(t) * np.sin(f) ** 2, np.sin(t) * np.sin(f)])
            p = p * scale + np.array(shift)
            lines.append("v %.9f %.9f %.9f" % tuple(p))
    for i in range(rings):
        for j in range(segments):
            a, b = i * segments + j + 1, i * segments + (j + 1) % segments + 1
            lines.append(f"f {a} {a + segments} {b}")
            lines.append(f"f {b} {a + segments} {b + segments}")
    path.write_text("\n".join(lines) + "\n")
    return str(path)


def test_prepare_counts_alignment_and_the_command_lines_report(tmp_path):
    hair = straight_bundle(count=6, vertices=9, length=2.0, spacing=0.1)  # 36 strands
    head = sphere_mesh(tmp_path / "head.obj")
    target = sphere_mesh(tmp_path / "target.obj", scale=0.5, shift=(0.0, 1.7, 0.0))
    out, report = vdbhair.prepare(hair, points=20, count=10, head=head, align_to=target)
    assert len(out) == 10 and report["strands"] == 10 and report["vertices"] == 200
    assert np.all(np.diff(out.offsets) == 20)
    assert report["align"]["method"] == "correspondence"
    assert report["align"]["scale"] == pytest.approx(0.5, rel=1e-6)
    assert report["align"]["translation"] == pytest.approx([0.0, 1.7, 0.0], abs=1e-6)
    assert report["align"]["residual_rms"] < 1e-6
    assert report["subsample"]["min_root_spacing"] >= report["subsample"]["coverage_radius"]
    assert len(hair) == 36  # the input is not changed
    # The same run on the command line reports the same figures.
    vdbhair.write(hair, str(tmp_path / "in.hair"))
    line = subprocess.run([cli(), "prepare", str(tmp_path / "in.hair"), str(tmp_path / "out.hair"), "--points", "20", "--strands", "10",
                           "--head", head, "--align-to", target, "--json"], capture_output=True, text=True, check=True).stdout
    command = json.loads(line)
    for key in ("input", "output", "head", "align_to"):
        del command[key]
    assert report == command
    written = vdbhair.read(str(tmp_path / "out.hair"))
    assert np.allclose(written.positions, out.positions)


def test_prepare_fixes_penetration_of_a_sphere_and_refuses_bad_arguments():
    # Strands rooted on top of the unit sphere, aimed through it.
    hair = straight_bundle(count=3, vertices=12, length=3.0, spacing=0.01, direction=(1.0, -0.8, 0.0))  # 9 strands
    hair = vdbhair.Strands(hair.positions + np.float32([0.0, 1.05, 0.0]), hair.offsets)
    out, report = vdbhair.prepare(hair, fix_penetration=(0.0, 0.0, 0.0, 1.0))
    assert report["fix_penetration"]["entering_before"] == 9
    assert report["fix_penetration"]["entering_after"] == 0
    assert np.linalg.norm(out.positions, axis=1).min() > 1.0 - 1e-5
    with pytest.raises(vdbhair.Error, match="prepare: points 1: a strand needs at least 2 vertices"):
        vdbhair.prepare(hair, points=1)
    with pytest.raises(vdbhair.Error, match="align_to needs head="):
        vdbhair.prepare(hair, align_to="x.obj")


def test_strand_statistics_histograms():
    hair = straight_bundle(count=5, vertices=9, length=4.0)  # 25 strands
    stats = vdbhair.strand_statistics(hair, bins=4)
    assert sum(stats["length"]["counts"]) == 25
    assert stats["turning_deg"]["range"]["max"] == 0.0
    assert sum(stats["curvature"]["histogram"]["counts"]) + stats["curvature"]["histogram"]["above"] == 225


@pytest.mark.data
def test_prepare_a_usc_guide_set(shared_data):
    data = shared_data
    hair = vdbhair.read(str(data / "hair/usc_data/hairnet_cstrands/cstrands00001.data"))
    head = str(data / "scalp/usc_hairsalon/head_model.ply")
    out, report = vdbhair.prepare(hair, points=100, count=4, head=head, align_to=head, fix_penetration=head)
    assert len(out) == 4 and report["vertices"] == 400
    assert report["align"]["scale"] == pytest.approx(1.0, abs=1e-9)
    assert report["fix_penetration"]["entering_after"] == 0
