#!/usr/bin/python3
"""`vdbhair inspect --json` against pyopenvdb (OpenVDB's own Python binding) on the same file.

usage: check_inspect.py VDBHAIR FILE.vdb       compare on an existing file
       check_inspect.py VDBHAIR --make OUT.vdb  first write a file with tiles, several value types
                                                and metadata through pyopenvdb, then compare

Per voxel grid: active voxel count, leaf count, the active index bounding box, memory, the
metadata pyopenvdb reads, and the value statistics recomputed here from pyopenvdb's iterators
(tiles weighted by their voxel count): min, max, mean, standard deviation, for vectors the
lengths and the share of unit vectors. Point grids are skipped: pyopenvdb cannot read them.
"""
import json
import math
import subprocess
import sys

import pyopenvdb as vdb


def fail(what):
    print("FAIL:", what)
    sys.exit(1)


def check(cond, what):
    if not cond:
        fail(what)


def close(a, b, rel=1e-6, abs_=1e-9):
    return abs(a - b) <= max(abs_, rel * max(abs(a), abs(b)))


def make(path):
    f = vdb.FloatGrid()
    f.name = "blob"
    f.gridClass = vdb.GridClass.FOG_VOLUME
    f.fill((0, 0, 0), (63, 31, 15), 0.5)          # whole 8^3 leaves become tiles
    acc = f.getAccessor()
    for i in range(40):
        acc.setValueOn((70 + i, 3, -2), 0.01 * i * i - 1.0)
    f.transform = vdb.createLinearTransform(voxelSize=0.25)
    f.updateMetadata({"note": "made by check_inspect.py", "count": 7})
    v = vdb.Vec3SGrid()
    v.name = "wind"
    v.fill((-8, -8, -8), (7, 7, 7), (0.0, 0.0, 1.0))
    vacc = v.getAccessor()
    for i in range(30):
        vacc.setValueOn((20 + i, 0, 0), (0.1 * i, 0.0, 0.0))
    n = vdb.BoolGrid()
    n.name = "mask"
    nacc = n.getAccessor()
    for i in range(100):
        nacc.setValueOn((i % 10, i // 10, 0), i % 7 == 0)
    vdb.write(path, grids=[f, v, n])


def stats(grid, vector):
    n = 0
    total = 0.0
    lo, hi = math.inf, -math.inf
    values = []
    unit = 0
    for item in grid.citerOnValues():
        x = item.value
        if vector:
            x = math.sqrt(sum(float(c) * float(c) for c in x))
            if abs(x - 1.0) <= 1e-3:
                unit += item.count
        x = float(x)
        n += item.count
        total += x * item.count
        lo, hi = min(lo, x), max(hi, x)
        values.append((x, item.count))
    mean = total / n if n else 0.0
    var = sum(c * (x - mean) ** 2 for x, c in values) / n if n else 0.0
    return {"count": n, "min": lo, "max": hi, "mean": mean, "stddev": math.sqrt(var), "unit_share": unit / n if n else 0.0}


binary, path = sys.argv[1], sys.argv[2]
if path == "--make":
    path = sys.argv[3]
    make(path)
out = subprocess.run([binary, "inspect", path, "--json"], capture_output=True, text=True)
check(out.returncode == 0, "vdbhair inspect exited %d: %s" % (out.returncode, out.stderr.strip()))
report = json.loads(out.stdout)
ours = {g["name"]: g for g in report["grids"]}
try:
    metas = vdb.readAllGridMetadata(path)
except TypeError as e:  # a point grid: pyopenvdb reads none of the file
    print("SKIPPED: pyopenvdb cannot read %s (%s)" % (path, e))
    sys.exit(0)
check(len(metas) == len(report["grids"]), "grid count %d vs pyopenvdb %d" % (len(report["grids"]), len(metas)))
compared = 0
for meta in metas:
    name = meta.name
    check(name in ours, "grid '%s' missing from inspect" % name)
    g = ours[name]
    if g["value_type"].startswith("ptdataidx"):
        continue
    grid = vdb.read(path, name)
    check(g["active_voxels"] == grid.activeVoxelCount(), "%s active voxels %d vs %d" % (name, g["active_voxels"], grid.activeVoxelCount()))
    check(g["leaf_nodes"] == grid.leafCount(), "%s leaves %d vs %d" % (name, g["leaf_nodes"], grid.leafCount()))
    # pyopenvdb delays loading leaf buffers, so its memUsage() is smaller than a loaded grid's;
    # the file records the loaded size its writer measured (file_mem_bytes).
    written = grid.metadata.get("file_mem_bytes")
    check(written is not None, "%s: no file_mem_bytes to compare the memory with" % name)
    check(g["memory_bytes"] == written, "%s memory %d vs file_mem_bytes %d" % (name, g["memory_bytes"], written))
    lo, hi = grid.evalActiveVoxelBoundingBox()
    check(g["index_bbox"] == [list(lo), list(hi)], "%s index bbox %s vs %s" % (name, g["index_bbox"], (lo, hi)))
    check(g["class"] == grid.gridClass, "%s class %s vs %s" % (name, g["class"], grid.gridClass))
    for key, value in grid.metadata.items():
        if key in ("name", "class", "vector_type") or key.startswith("file_"):
            continue
        check(key in g["metadata"], "%s metadata %s missing" % (name, key))
        mine = g["metadata"][key]
        if isinstance(value, (tuple, list)):
            check(all(close(a, b) for a, b in zip(mine, value)), "%s metadata %s %s vs %s" % (name, key, mine, value))
        elif isinstance(value, float):
            check(close(mine, value), "%s metadata %s %s vs %s" % (name, key, mine, value))
        else:
            check(mine == value, "%s metadata %s %s vs %s" % (name, key, mine, value))
    vector = grid.valueTypeName.startswith("vec3")
    ref = stats(grid, vector)
    s = g["length"] if vector else g["values"]
    check(s["count"] == ref["count"], "%s value count %d vs %d" % (name, s["count"], ref["count"]))
    for k in ("min", "max", "mean", "stddev"):
        check(close(s[k], ref[k], 1e-5, 1e-6), "%s %s %r vs %r" % (name, k, s[k], ref[k]))
    check(s["min"] <= s["p01"] <= s["median"] <= s["p99"] <= s["max"], "%s quantiles ordered" % name)
    if vector:
        check(close(g["unit_share"], ref["unit_share"]), "%s unit share %r vs %r" % (name, g["unit_share"], ref["unit_share"]))
    tiles = sum(1 for item in grid.citerOnValues() if item.count > 1)
    check(g["active_tiles"] == tiles, "%s active tiles %d vs %d" % (name, g["active_tiles"], tiles))
    compared += 1
check(compared > 0, "no voxel grid compared")
print("ok: %d grid(s) of %s agree with pyopenvdb" % (compared, path))
