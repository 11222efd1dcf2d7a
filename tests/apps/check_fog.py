"""Checks with pyopenvdb that a vdbhair field's 'density' is a true fog volume (values in [0, 1],
class 'fog volume', the rule and reference in its metadata) and that 'hair_length' keeps the raw
summed length (class 'unknown'):  python3 check_fog.py FIELD.vdb"""
import sys

import pyopenvdb as vdb

path = sys.argv[1]
density = vdb.read(path, "density")
length = vdb.read(path, "hair_length")
lo, hi = density.evalMinMax()
print("density: class %s, values %g .. %g, reference %g" % (density.gridClass, lo, hi, density["vdbhair_density_reference"]))
print("hair_length: class %s, values up to %g" % (length.gridClass, length.evalMinMax()[1]))
if density.gridClass != "fog volume" or not (0.0 <= lo and hi <= 1.0):
    raise SystemExit("FAIL: density is not a fog volume in [0, 1]")
if length.gridClass != "unknown" or length.activeVoxelCount() != density.activeVoxelCount():
    raise SystemExit("FAIL: hair_length should be class unknown with density's voxels")
if not density["vdbhair_density_reference"] > 0:
    raise SystemExit("FAIL: no vdbhair_density_reference")
print("ok: density in [0, 1], hair_length the raw sum")
