"""vdbhair.compare: the command line's report as a dict, per-strand values as NumPy arrays."""
import json
import subprocess

import numpy as np
import pytest

import vdbhair
from conftest import straight_bundle
from test_defaults import cli


def test_compare_against_itself_and_a_shift():
    a = straight_bundle(count=4, vertices=17, length=4.0, spacing=1.0)
    same = vdbhair.compare(a, a, unit="cm")
    assert [m["f1"] for m in same["oriented_points"]] == [1.0] * 4
    assert same["chamfer"]["mean"] == 0.0 and same["position_error"] == 0.0 and same["frechet"]["max"] == 0.0
    # The bundle moved 0.1 across its strands: Chamfer 0.1 each way, the root-aligned error 0,
    # each strand's Frechet distance 0.1 over its length 4.
    b = vdbhair.Strands(a.positions + np.float32([0.0, 0.0, 0.1]), a.offsets)
    r = vdbhair.compare(a, b, threshold=["0.05:20", "0.15:20"])  # no unit: file units
    assert r["chamfer"]["a_to_b"] == pytest.approx(0.1, rel=1e-5)
    assert r["position_error"] == pytest.approx(0.0, abs=1e-6)
    assert np.allclose(r["per_strand"]["frechet"], 0.1 / 4.0, rtol=1e-4)
    assert r["per_strand"]["chamfer"].shape == (len(a),)
    assert [m["f1"] for m in r["oriented_points"]] == [0.0, 1.0]
    assert r["meters_per_unit"] is None


def test_compare_is_the_command_lines_report(tmp_path):
    a = straight_bundle(count=3, vertices=9)
    b = straight_bundle(count=3, vertices=9, direction=(1.0, 0.1, 0.0))
    vdbhair.write(a, str(tmp_path / "a.hair"))
    vdbhair.write(b, str(tmp_path / "b.hair"))
    python = vdbhair.compare(vdbhair.read(str(tmp_path / "a.hair")), vdbhair.read(str(tmp_path / "b.hair")), unit="cm")
    line = subprocess.run([cli(), "compare", str(tmp_path / "a.hair"), str(tmp_path / "b.hair"), "--unit", "cm", "--json"],
                          capture_output=True, text=True, check=True).stdout
    command = json.loads(line)
    del python["per_strand"], command["a"], command["b"]
    assert python == command


def test_compare_bad_arguments():
    a = straight_bundle(count=2, vertices=5)
    with pytest.raises(ValueError, match="compare: samples 2"):
        vdbhair.compare(a, a, samples=2)
    with pytest.raises(ValueError, match="^compare: unit '-1': expected mm, cm, dm, m, in"):
        vdbhair.compare(a, a, unit="-1")
    with pytest.raises(ValueError, match=r"^compare: threshold '1:200': expected DISTANCE:ANGLE, .* an angle in \[0, 180\] degrees"):
        vdbhair.compare(a, a, threshold="1:200")


def test_compare_older_keywords_still_work_with_a_warning():
    a = straight_bundle(count=4, vertices=17, length=4.0, spacing=1.0)
    b = vdbhair.Strands(a.positions + np.float32([0.0, 0.0, 0.25]), a.offsets)
    new = vdbhair.compare(a, b, unit="cm", threshold=["2:20", "3:30"])
    with pytest.warns(DeprecationWarning, match=r"compare\(meters_per_unit=\.\.\.\) is deprecated: use unit="):
        old = vdbhair.compare(a, b, meters_per_unit=0.01, thresholds=[(0.002, 20.0), (0.003, 30.0)])  # metres
    assert [m["f1"] for m in old["oriented_points"]] == [m["f1"] for m in new["oriented_points"]] == [0.0, 1.0]
    assert [m["distance_mm"] for m in old["oriented_points"]] == pytest.approx([2.0, 3.0])
