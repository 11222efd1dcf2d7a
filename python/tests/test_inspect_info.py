"""vdbhair.inspect and vdbhair.strand_statistics take their keywords from the declarations
`vdbhair inspect`'s and `vdbhair info`'s options come from (sliceParameters(),
strandStatsParameters()), inspect with the command's grid, slice and output: the same names, and
the same results as the command line."""
import inspect
import json
import re
import subprocess

import pytest

import vdbhair
from conftest import wavy_hairstyle
from test_defaults import cli

# What every verb takes (apps/Cli.cc's addCommonOptions, addReadOptions): Python's threads and
# progress stand for them.
COMMON = {"help", "threads", "no_clobber", "json", "quiet", "points_per_strand", "curve_samples", "roots"}


def cli_options(verb):
    """The long options `vdbhair VERB --help` lists, as Python spells keywords."""
    text = subprocess.run([cli(), verb, "--help"], capture_output=True, text=True, check=True).stdout
    flags = re.findall(r"^\s+(?:-\w,)?--([\w-]+)", text, re.M)
    return {f.replace("-", "_") for f in flags} - COMMON


def keywords(function):
    return set(inspect.signature(function).parameters) - {"threads", "progress"}


@pytest.fixture(scope="module")
def field_vdb(tmp_path_factory):
    path = tmp_path_factory.mktemp("inspect") / "field.vdb"
    vdbhair.estimate_tangent_field(wavy_hairstyle(), voxel_size=0.2).write(str(path))
    return path


def test_inspect_keywords_are_the_commands_options():
    assert keywords(vdbhair.inspect) - {"path"} == cli_options("inspect")


def test_inspect_is_the_command_lines_report(field_vdb, tmp_path):
    python = vdbhair.inspect(field_vdb)
    command = json.loads(subprocess.run([cli(), "inspect", str(field_vdb), "--json"], capture_output=True, text=True, check=True).stdout)
    assert [g["name"] for g in python] == [g["name"] for g in command["grids"]]
    # One record of a grid for both (gridReportJson()): the same keys, the same values.
    for p, c in zip(python, command["grids"]):
        assert sorted(p) == sorted(c)
        assert p == c
    # One grid by name, as --grid.
    only = vdbhair.inspect(field_vdb, grid="density")
    assert [g["name"] for g in only] == ["density"]
    with pytest.raises(vdbhair.NotFoundError, match=r"no grid named 'nope' \(the file has: "):
        vdbhair.inspect(field_vdb, grid="nope")


def test_inspect_slice_is_the_command_lines_image(field_vdb, tmp_path):
    grids, drawn = vdbhair.inspect(field_vdb, slice="z=0.4", output=tmp_path / "py.png", hsv=True, streamlines=40, width=200)
    line = subprocess.run([cli(), "inspect", str(field_vdb), "--slice", "z=0.4", "-o", str(tmp_path / "cli.png"), "--hsv",
                           "--streamlines", "40", "--width", "200", "--json"], capture_output=True, text=True, check=True).stdout
    command = json.loads(line)
    assert (tmp_path / "py.png").read_bytes() == (tmp_path / "cli.png").read_bytes()
    assert drawn["grid"] == "tangent" and drawn["streamlines"] > 0
    del drawn["output"], command["slice"]["output"]
    assert drawn == command["slice"]
    assert grids == command["grids"]


def test_inspect_bad_keywords_name_the_keyword_value_and_rule(field_vdb, tmp_path):
    with pytest.raises(ValueError, match=r"^inspect: width 15: must be between 16 and 16384 pixels$"):
        vdbhair.inspect(field_vdb, slice="z=0", output=tmp_path / "a.png", width=15)
    with pytest.raises(ValueError, match=r"^inspect: streamlines 100001: must be between 0 and 100000$"):
        vdbhair.inspect(field_vdb, slice="z=0", output=tmp_path / "a.png", streamlines=100001)
    with pytest.raises(ValueError, match=r"^inspect: slice w=3: expected AXIS=WORLD"):
        vdbhair.inspect(field_vdb, slice="w=3", output=tmp_path / "a.png")
    with pytest.raises(ValueError, match=r"^inspect: slice z=0: needs output, the slice image's path"):
        vdbhair.inspect(field_vdb, slice="z=0")
    with pytest.raises(ValueError, match=r"^inspect: output \S+a.png: an image is drawn only of a slice: add slice AXIS=WORLD$"):
        vdbhair.inspect(field_vdb, output=tmp_path / "a.png")
    with pytest.raises(ValueError, match=r"^inspect: slice z=abc: expected AXIS=WORLD"):
        vdbhair.inspect(field_vdb, slice="z=abc", output=tmp_path / "a.png")
    with pytest.raises(ValueError, match=r"^inspect: hsv and streamlines draw on a slice"):
        vdbhair.inspect(field_vdb, hsv=True)
    with pytest.raises(vdbhair.ArgumentTypeError, match=r"^inspect: width must be an integer"):
        vdbhair.inspect(field_vdb, width="wide")
    assert not (tmp_path / "a.png").exists()


def test_strand_statistics_keywords_are_info_options():
    # info's other options (--strict, --grid, --stats) choose what is read and whether to count.
    assert keywords(vdbhair.strand_statistics) - {"strands"} == {"bins"}
    assert "bins" in cli_options("info")


def test_strand_statistics_is_info_stats(tmp_path):
    path = tmp_path / "wavy.hair"
    vdbhair.write(wavy_hairstyle(), str(path))
    python = vdbhair.strand_statistics(vdbhair.read(str(path)), bins=7)
    line = subprocess.run([cli(), "info", str(path), "--stats", "--bins", "7", "--json"], capture_output=True, text=True, check=True).stdout
    assert python == json.loads(line)["stats"]
    assert len(python["length"]["counts"]) == 7
    with pytest.raises(ValueError, match=r"^strand_statistics: bins 0: must be between 1 and 10000$"):
        vdbhair.strand_statistics(vdbhair.read(str(path)), bins=0)
    with pytest.raises(ValueError, match=r"^strand_statistics: bins -1: must be at least 1$"):
        vdbhair.strand_statistics(vdbhair.read(str(path)), bins=-1)
