"""`vdbhair field --dense` read by NumPy: a uniform field gives a constant orientation volume.

    check_dense.py VDBHAIR WORKDIR
    check_dense.py --npy PATH D H W     (a volume's shape, type, occupancy range and unit directions)

Straight strands along +x fill the cube [0, 10]^3 (0.5 apart), so with voxel size 1 every voxel
of the cube holds the tangent (1, 0, 0). The orientation volume over a box inside the cube is
(1, 0, 0, 1) at every sample; over a box reaching beyond it, samples a voxel or more outside hold
(0, 0, 0, 0). Prints "ok: ..." when NumPy reads the shape and the values.
"""
import os
import subprocess
import sys

import numpy

if sys.argv[1] == "--npy":  # check_dense.py --npy PATH D H W: a (D, H, W, 4) float32 volume, partly occupied
    a = numpy.load(sys.argv[2])
    shape = tuple(int(n) for n in sys.argv[3:6]) + (4,)
    assert a.shape == shape and a.dtype == numpy.float32, (a.shape, a.dtype)
    assert 0 < a[..., 3].mean() < 1 and numpy.all((a[..., 3] >= 0) & (a[..., 3] <= 1)), a[..., 3].mean()
    norms = numpy.linalg.norm(a[..., :3], axis=-1)
    assert numpy.allclose(norms[a[..., 3] > 0.01], 1, atol=1e-5), "directions must be unit where occupied"
    print("ok: shape", a.shape, f"occupied {numpy.count_nonzero(a[..., 3])} samples")
    sys.exit(0)

cli, work = sys.argv[1], sys.argv[2]
os.makedirs(work, exist_ok=True)
obj = os.path.join(work, "uniform.obj")
with open(obj, "w") as f:
    n = 0
    for j in range(21):
        for k in range(21):
            for i in range(11):
                f.write(f"v {float(i)} {j * 0.5} {k * 0.5}\n")
            f.write("l " + " ".join(str(n + i + 1) for i in range(11)) + "\n")
            n += 11


def dense(name, box, size):
    out = os.path.join(work, name)
    subprocess.run([cli, "field", obj, "-o", os.path.join(work, name + ".vdb"), "--voxel-size", "1", "--quiet",
                    "--dense", out, "--dense-box", ",".join(map(str, box)), "--dense-size", ",".join(map(str, size))], check=True)
    return numpy.load(out)


inside = dense("inside.npy", (2, 3, 4, 8, 7, 6), (5, 6, 7))
assert inside.shape == (5, 6, 7, 4) and inside.dtype == numpy.float32, (inside.shape, inside.dtype)
assert numpy.array_equal(inside, numpy.broadcast_to(numpy.float32([1, 0, 0, 1]), inside.shape)), inside.reshape(-1, 4)[:4]

# x from -10 to 20 in 30 cells of 1: sample i at x = i - 9.5; the cube's voxels are x = 0..10.
# y and z from 4 to 6 (inside). Axis order (D, H, W) = (z, y, x).
wide = dense("wide.npy", (-10, 4, 4, 20, 6, 6), (2, 2, 30))
assert wide.shape == (2, 2, 30, 4), wide.shape
x = numpy.arange(30) - 9.5
row = wide[0, 0]
outside = (x < -1) | (x > 11)
core = (x >= 0) & (x <= 10)
assert numpy.all(row[outside] == 0), row[outside]
assert numpy.all(row[core] == numpy.float32([1, 0, 0, 1])), row[core]
edge = row[(x > -1) & (x < 0)]
assert numpy.all((edge[:, 3] > 0) & (edge[:, 3] < 1)) and numpy.all(edge[:, 0] == 1), edge
print(f"ok: numpy reads {inside.shape} and {wide.shape} float32 volumes; a uniform field is (1, 0, 0, 1) inside, "
      f"0 a voxel outside, occupancy {edge[0, 3]:.2f} half a voxel out")
