"""Speed of the Python module against the C++ calls it wraps (issue 18, "Speed"). Not a test.

Makes the benchmark's 100,000-strand set (jittered copies of scenes/default/ponytail.hair, 64
vertices a strand: 77 MB as .data), then times on the same files, best of --reps:
  - vdbhair.estimate_tangent_field and vdbhair.retrace against estimateTangentField and
    retraceStrands called from C++ (build/bin/vdbhair_python_speed), same parameters;
  - vdbhair.read of the .data file against numpy.fromfile plus the offsets loop a user writes.
The C++ program runs before and after the Python calls (the machine's speed drifts).

    PYTHONPATH=build/python /usr/bin/python3 python/bench/speed.py [--strands N] [--reps R] [--threads T]
"""
import argparse
import json
import os
import pathlib
import subprocess
import tempfile
import time

import numpy as np

import vdbhair

ROOT = pathlib.Path(__file__).resolve().parents[2]


def best(reps, f):
    times = []
    for _ in range(reps):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return min(times)


def jittered_copies(base, count, vertices, jitter, seed=1):
    """count strands of `vertices` vertices, resampled by arc length from base's strands in turn,
    each moved by a normal offset of standard deviation `jitter` (world units)."""
    rng = np.random.default_rng(seed)
    resampled = []
    for strand in base:
        seg = np.linalg.norm(np.diff(strand, axis=0), axis=1)
        s = np.concatenate([[0.0], np.cumsum(seg)])
        t = np.linspace(0.0, s[-1], vertices)
        resampled.append(np.stack([np.interp(t, s, strand[:, a]) for a in range(3)], axis=1))
    resampled = np.stack(resampled)  # (S, vertices, 3)
    pick = np.arange(count) % len(resampled)
    pos = resampled[pick] + rng.normal(0.0, jitter, (count, 1, 3))
    return vdbhair.Strands(pos.reshape(-1, 3).astype(np.float32), np.arange(count + 1, dtype=np.int64) * vertices)


def numpy_read_data(path):
    """What a user writes for a USC-HairSalon .data file: fromfile, then walk the counts."""
    raw = np.fromfile(path, dtype=np.uint8)
    count = int(raw[:4].view(np.int32)[0])
    counts = np.empty(count, dtype=np.int64)
    starts = np.empty(count, dtype=np.int64)
    cursor = 4
    for i in range(count):
        n = int(raw[cursor:cursor + 4].view(np.int32)[0])
        counts[i], starts[i] = n, cursor + 4
        cursor += 4 + 12 * n
    positions = np.concatenate([raw[a:a + 12 * n].view(np.float32) for a, n in zip(starts, counts)]).reshape(-1, 3)
    offsets = np.concatenate([[0], np.cumsum(counts)])
    return positions, offsets


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--strands", type=int, default=100000)
    ap.add_argument("--vertices", type=int, default=64)
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--cpp", default=str(ROOT / "build/bin/vdbhair_python_speed"))
    args = ap.parse_args()

    base = vdbhair.read(str(ROOT / "scenes/default/ponytail.hair"))
    strands = jittered_copies(base, args.strands, args.vertices, 0.3)
    voxel = vdbhair.suggest_voxel_size(strands)
    with tempfile.TemporaryDirectory() as tmp:
        data = os.path.join(tmp, "set.data")  # float32 kept exactly
        vdbhair.write(strands, data)
        print(f"{len(strands)} strands x {args.vertices} vertices, voxel size {voxel:.4g}, .data {os.path.getsize(data) / 1e6:.1f} MB, "
              f"best of {args.reps}, threads {args.threads or 'all'}")

        def cpp():
            out = subprocess.run([args.cpp, data, repr(voxel), str(args.reps), str(args.threads)], check=True,
                                 capture_output=True, text=True).stdout
            return json.loads(out)

        c1 = cpp()
        s = vdbhair.read(data)
        field = [None]
        t_field = best(args.reps, lambda: field.__setitem__(0, vdbhair.estimate_tangent_field(s, voxel, threads=args.threads)))
        t_retrace = best(args.reps, lambda: vdbhair.retrace(s, field[0], threads=args.threads))
        c2 = cpp()
        t_read = best(args.reps, lambda: vdbhair.read(data))
        t_numpy = best(args.reps, lambda: numpy_read_data(data))
        p, o = numpy_read_data(data)
        r = vdbhair.read(data)
        assert np.array_equal(p, r.positions) and np.array_equal(o, r.offsets)

    for name, py in (("field", t_field), ("retrace", t_retrace)):
        cpp_best = min(c1[name], c2[name])
        print(f"{name:8s} python {py:.3f} s   C++ {c1[name]:.3f} / {c2[name]:.3f} s (before / after)   "
              f"python / best C++ {py / cpp_best:.3f}")
    print(f"read .data  vdbhair.read {t_read:.3f} s   numpy.fromfile + offsets loop {t_numpy:.3f} s   numpy / vdbhair {t_numpy / t_read:.2f}x")
    print(f"read .data  C++ readStrands {c1['read']:.3f} / {c2['read']:.3f} s (before / after)")


if __name__ == "__main__":
    main()
