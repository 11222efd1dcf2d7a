#!/usr/bin/env python3
"""Every vdbhair verb end to end, as a shell user runs it: two builds of the `vdbhair` command
(A and B) in turn on the same inputs, a warm-up and RUNS counted runs each, median wall time and
peak resident memory (wait4), and the ratio B/A. Prints a Markdown table (docs/performance.md).

    scripts/verb_timings.py A_PROGRAM B_PROGRAM [--runs 5] [--dir /tmp/vdbhair_verbs] [--only RE]

The inputs are made once with program A: the bundled default scene (scenes/default), a hairstyle
of 100,000 strands x 64 vertices (jittered copies of its ponytail, 77 MB as .data) and what the
verbs chain (a field, a scalp, roots). Standard library only.
"""
import argparse
import os
import random
import re
import shutil
import statistics
import struct
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = os.path.join(ROOT, "scenes")


def read_hair(path):
    """Yuksel's .hair as a list of strands (lists of (x, y, z)): its segments and points arrays."""
    with open(path, "rb") as f:
        data = f.read()
    magic, nstrands, npoints, bits, dsegs = struct.unpack_from("<4sIIII", data, 0)
    assert magic == b"HAIR" and bits & 2, path
    off = 128
    if bits & 1:  # a segments array, else every strand has the default count
        segs = struct.unpack_from("<%dH" % nstrands, data, off)
        off += 2 * nstrands
    else:
        segs = [dsegs] * nstrands
    pts = struct.unpack_from("<%df" % (3 * npoints), data, off)
    strands, at = [], 0
    for s in segs:
        n = s + 1
        strands.append([pts[3 * (at + i):3 * (at + i) + 3] for i in range(n)])
        at += n
    return strands


def resample(strand, n):
    """A polyline resampled to n vertices evenly by arc length."""
    lengths = [0.0]
    for a, b in zip(strand, strand[1:]):
        lengths.append(lengths[-1] + sum((b[k] - a[k]) ** 2 for k in range(3)) ** 0.5)
    total, out, j = lengths[-1], [], 0
    for i in range(n):
        s = total * i / (n - 1)
        while j < len(strand) - 2 and lengths[j + 1] < s:
            j += 1
        seg = lengths[j + 1] - lengths[j]
        t = 0.0 if seg <= 0 else min(1.0, max(0.0, (s - lengths[j]) / seg))
        out.append(tuple(strand[j][k] + t * (strand[j + 1][k] - strand[j][k]) for k in range(3)))
    return out


def write_big_data(path, count, vertices, seed=7):
    """USC .data: int32 strand count, then per strand int32 vertex count and float32 x y z."""
    base = [resample(s, vertices) for s in read_hair(os.path.join(SCENES, "default", "ponytail.hair"))]
    rng = random.Random(seed)
    with open(path, "wb") as f:
        f.write(struct.pack("<i", count))
        for i in range(count):
            s = base[i % len(base)]
            dx, dy, dz = (rng.uniform(-0.3, 0.3) for _ in range(3))
            flat = [c for p in s for c in (p[0] + dx, p[1] + dy, p[2] + dz)]
            f.write(struct.pack("<i", vertices))
            f.write(struct.pack("<%df" % len(flat), *flat))


def run(cmd, cwd):
    start = time.perf_counter()
    proc = subprocess.Popen(cmd, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    err = proc.stderr.read().decode(errors="replace")
    proc.stderr.close()
    proc.returncode = os.waitstatus_to_exitcode(status)
    return wall, usage.ru_maxrss / 1024.0, proc.returncode, err


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--dir", default="/tmp/vdbhair_verbs")
    ap.add_argument("--only", default="", help="run only the verbs whose name matches this regular expression")
    args = ap.parse_args()
    a, b = os.path.abspath(args.a), os.path.abspath(args.b)
    d = args.dir
    os.makedirs(d, exist_ok=True)
    big = os.path.join(d, "big.data")
    if not os.path.exists(big):
        print("making %s (100,000 strands x 64 vertices) ..." % big, file=sys.stderr)
        write_big_data(big, 100000, 64)
    pony = os.path.join(SCENES, "default", "ponytail.hair")
    head = os.path.join(SCENES, "default", "head.json")
    small_head = os.path.join(d, "small_head.json")
    with open(head) as f:
        text = f.read()
    with open(small_head, "w") as f:
        f.write(text.replace('"count":124', '"count":16'))
    prep = [
        [a, "convert", big, "big.vdb"],
        [a, "field", big, "-o", "field.vdb"],
        [a, "scalp", "--sphere", "0,88,7,34", "-o", "scalp.vdb", "--voxel-size", "0.5", "--region", pony],
        [a, "roots", "scalp.vdb", "-o", "roots.ply", "--count", "20000"],
        [a, "grow", small_head, "-o", "head.hair"],
    ]
    for cmd in prep:
        if subprocess.run(cmd, cwd=d, stdout=subprocess.DEVNULL).returncode != 0:
            sys.exit("verb_timings.py: preparing failed: " + " ".join(cmd))
    # (name, arguments after the program)
    verbs = [
        ("--help", ["--help"]),
        ("info .data", ["info", big]),
        ("info .vdb", ["info", "big.vdb"]),
        ("convert .data → .vdb", ["convert", big, "o.vdb"]),
        ("convert .vdb → .hair", ["convert", "big.vdb", "o.hair"]),
        ("field", ["field", big, "-o", "o_field.vdb"]),
        ("retrace", ["retrace", big, "--field", "field.vdb", "-o", "o_retrace.data"]),
        ("refine", ["refine", big, "-o", "o_refine.data"]),
        ("grow", ["grow", head, "-o", "o_grow.hair"]),
        ("fit", ["fit", pony, "-o", "o_fit.json"]),
        ("scalp", ["scalp", "--sphere", "0,88,7,34", "-o", "o_scalp.vdb", "--voxel-size", "0.5", "--region", pony]),
        ("roots", ["roots", "scalp.vdb", "-o", "o_roots.ply", "--count", "20000"]),
        ("interpolate", ["interpolate", small_head, "--roots", "roots.ply", "-o", "o_interp.hair"]),
        ("reconstruct", ["reconstruct", "head.hair", "-o", "o_rec.hair", "--guides", "10%"]),
        ("synth", ["synth", pony, "-o", "o_synth.hair"]),
        ("transfer", ["transfer", pony, pony, "-o", "o_transfer.hair"]),
        # The stroke is in the default head scene's frame (head.hair is grown from it); on
        # ponytail.hair it reaches no wisp and the comb does nothing.
        ("comb", ["comb", "head.hair", "--stroke", os.path.join(SCENES, "comb", "sweep_ponytail.json"), "-o", "o_comb.hair"]),
        ("inspect", ["inspect", "field.vdb"]),
        ("render", ["render", pony, "-o", "o_render.png"]),
        ("demo", ["demo", head, "-o", "o_demo"]),
        ("batch", ["batch", os.path.join(SCENES, "batch", "field.json"), "-o", "o_batch", "--quiet"]),
    ]
    only = re.compile(args.only) if args.only else None
    print("| verb | A: wall, peak | B: wall, peak | B/A wall (min-max) |")
    print("| --- | --- | --- | --- |")
    for name, rest in verbs:
        if only and not only.search(name):
            continue
        walls = {a: [], b: []}
        peaks = {a: [], b: []}
        ratios = []
        for r in range(-1, args.runs):
            pair = {}
            for prog in (a, b):
                if name in ("demo", "batch"):
                    shutil.rmtree(os.path.join(d, rest[3]), ignore_errors=True)
                wall, peak, code, err = run([prog] + rest, d)
                if code != 0:
                    sys.exit("verb_timings.py: %s failed (%d): %s" % (" ".join([prog] + rest), code, err.strip()[-400:]))
                pair[prog] = wall
                if r >= 0:
                    walls[prog].append(wall)
                    peaks[prog].append(peak)
            if r >= 0:
                ratios.append(pair[b] / pair[a])
        print("| %s | %.3f s, %.0f MiB | %.3f s, %.0f MiB | %.2f (%.2f-%.2f) |" % (
            name, statistics.median(walls[a]), statistics.median(peaks[a]), statistics.median(walls[b]),
            statistics.median(peaks[b]), statistics.median(ratios), min(ratios), max(ratios)))
        sys.stdout.flush()


if __name__ == "__main__":
    main()
