#!/usr/bin/python3
"""Interop check: a field .vdb written by vdbhair, read back by pyopenvdb (OpenVDB's own Python
binding, Debian's python3-openvdb). Checks grid names, classes, vector types, the metadata that
explains how the grid was made, and that tangent values are unit vectors where density > 0.

usage: check_pyopenvdb.py FIELD.vdb VOXEL_SIZE [GRID_SUFFIX]
"""
import math
import sys

import pyopenvdb as vdb

path, voxel = sys.argv[1], float(sys.argv[2])
suffix = sys.argv[3] if len(sys.argv) > 3 else ""
grids, _ = vdb.readAll(path)
byname = {g.name: g for g in grids}
tangent, density = byname["tangent" + suffix], byname["density" + suffix]


def check(cond, what):
    if not cond:
        print("FAIL:", what)
        sys.exit(1)


check(tangent.valueTypeName == "vec3s", "tangent is vec3s, got %s" % tangent.valueTypeName)
check(tangent.gridClass == "unknown", "tangent class unknown, got %s" % tangent.gridClass)
check(tangent.vectorType == "contravariant relative", "tangent vector type, got %s" % tangent.vectorType)
check(density.valueTypeName == "float", "density is float")
check(density.gridClass == "fog volume", "density class fog volume, got %s" % density.gridClass)
for g in (tangent, density):
    m = g.metadata
    check(m.get("creator", "").startswith("vdbhair "), "%s creator" % g.name)
    check(abs(m["vdbhair_voxel_size"] - voxel) < 1e-9 * voxel, "%s vdbhair_voxel_size" % g.name)
    check(m["vdbhair_iterations"] == 2, "%s vdbhair_iterations" % g.name)
    check(m["vdbhair_space"] == "world", "%s vdbhair_space" % g.name)
    check(m["vdbhair_strand_count"] > 0, "%s vdbhair_strand_count" % g.name)
    check(abs(g.transform.voxelSize()[0] - voxel) < 1e-9 * voxel, "%s transform voxel size" % g.name)
check(tangent.activeVoxelCount() == density.activeVoxelCount(), "same active voxels")
dacc = density.getConstAccessor()
units = 0
for item in tangent.citerOnValues():
    ijk, value = item.min, item.value
    d = dacc.getValue(ijk)
    check(d > 0, "density > 0 at active voxel %s" % (ijk,))
    n = math.sqrt(sum(c * c for c in value))
    check(n == 0 or abs(n - 1) < 1e-5, "unit tangent at %s (length %g)" % (ijk, n))
    units += n > 0
check(units > 0, "some non-zero tangents")
print("ok: %d tangent voxels read by pyopenvdb with class, vector type and metadata" % units)
