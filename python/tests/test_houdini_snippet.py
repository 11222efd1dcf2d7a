"""docs/houdini_strands_to_curves.py (the Houdini Python SOP that turns a strands.vdb into polylines),
run on the points of a vdbhair strands.vdb as Convert VDB Points gives them: every attribute of every
point in the grid's own order (Grid.point_attributes()), behind a stand-in for the few `hou` calls
the snippet makes. The polylines must be the strands vdbhair reads from the same file."""
import pathlib
import types

import numpy as np
import pytest

import vdbhair
from conftest import wavy_hairstyle

SNIPPET = pathlib.Path(__file__).resolve().parents[2] / "docs" / "houdini_strands_to_curves.py"


class _Point:
    def __init__(self, number, position):
        self.number, self.position = number, position


class _Geometry:
    """The hou.Geometry calls the snippet uses, over Grid.point_attributes()."""

    def __init__(self, columns, int_attributes):
        self.columns, self.ints, self.polygons = columns, int_attributes, []
        self._points = [_Point(i, p) for i, p in enumerate(columns["P"])]

    def findPointAttrib(self, name):
        if name not in self.columns:
            return None
        kind = hou.attribData.Int if name in self.ints else hou.attribData.Float
        return types.SimpleNamespace(dataType=lambda: kind)

    def pointIntAttribValues(self, name):
        return tuple(int(v) for v in self.columns[name])

    def pointFloatAttribValues(self, name):
        return tuple(float(v) for v in self.columns[name])

    def points(self):
        return tuple(self._points)

    def createPolygons(self, point_lists, is_closed=True):
        assert is_closed is False
        self.polygons.extend([list(p) for p in point_lists])


class _NodeError(Exception):
    pass


hou = types.SimpleNamespace(attribData=types.SimpleNamespace(Int="Int", Float="Float"), NodeError=_NodeError)


def run_snippet(geometry):
    hou.pwd = lambda: types.SimpleNamespace(geometry=lambda: geometry)
    exec(compile(SNIPPET.read_text(), str(SNIPPET), "exec"), {"hou": hou})
    return geometry.polygons


@pytest.mark.parametrize("float_ids", [False, True])
def test_snippet_rebuilds_vdbhair_strands(tmp_path, float_ids):
    hair = wavy_hairstyle()
    path = tmp_path / "strands.vdb"
    hair.write(path)
    columns = vdbhair.read_grids(path)["strands"].point_attributes()
    assert set(columns) >= {"P", "strand", "vertex", "root"}
    n = hair.num_vertices
    assert columns["P"].shape == (n, 3) and columns["strand"].dtype == np.int64 and columns["root"].dtype == bool
    # Spatial order, not strand order: the snippet has work to do.
    assert not np.all(np.diff(columns["strand"]) >= 0)
    ints = {"strand", "vertex"}
    if float_ids:  # Houdini's own points may carry them as floats
        columns = dict(columns, strand=columns["strand"].astype(np.float64), vertex=columns["vertex"].astype(np.float64))
        ints = set()
    polylines = run_snippet(_Geometry(columns, ints))
    expected = vdbhair.read(path)
    assert len(polylines) == expected.num_strands == hair.num_strands
    for i, line in enumerate(polylines):
        got = np.array([p.position for p in line], dtype=np.float32)
        np.testing.assert_array_equal(got, expected[i])
        # The root is the first point of each polyline.
        assert columns["root"][line[0].number] and not any(columns["root"][p.number] for p in line[1:])


def test_snippet_says_what_is_missing(tmp_path):
    hair = wavy_hairstyle()
    hair.write(tmp_path / "strands.vdb")
    columns = vdbhair.read_grids(tmp_path / "strands.vdb")["strands"].point_attributes()
    del columns["vertex"]
    with pytest.raises(_NodeError, match="no point attribute 'vertex': unpack a vdbhair strands.vdb with Convert VDB Points"):
        run_snippet(_Geometry(columns, {"strand"}))


def test_point_attributes_refuses_voxel_grids(tmp_path):
    field = vdbhair.estimate_tangent_field(wavy_hairstyle(), voxel_size=1.0)
    with pytest.raises(vdbhair.GridTypeError, match="holds vec3s voxels, not points"):
        field.tangent.point_attributes()
