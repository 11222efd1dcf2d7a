#!/usr/bin/env python3
"""docs/interpolation.md's tables: `vdbhair interpolate` and `reconstruct` from guides on the real
grooms of ../shared/data that have a head, measured independently of vdbhair (NumPy and
pyopenvdb only read what the command wrote).

    /usr/bin/python3 scripts/guides_table.py [--vdbhair build/bin/vdbhair] [--render DIR] [--only NAME]
                                             [--args "--method helicoid ..."]

For each groom: 10 % of its strands (seeded) become guides; `interpolate` regrows hair at every
root of the groom (--roots the groom) and at 20,000 roots spread over the head's scalp
(`vdbhair scalp` + `--scalp --count`). Measures, per output:
- leaves: share of strands with a point (vertices, and points at most half a voxel apart) outside
  the guides' hair volume: the voxels the guides' segments pass, dilated by one voxel, at the
  guides' suggested voxel size. The groom's own rate against the same volume is the baseline.
- head: share of strands with a vertex after the root more than half a voxel inside the head and
  deeper than its root by as much, by the scalp .vdb's level set (trilinear; a strand lying on the
  scalp is within that of it). The guides' own rate is the baseline.
- error (regrown at the groom's roots): discrete Frechet distance to the groom's strand at the
  same root, both resampled to 32 points by arc length, over that strand's length; and the same
  for the nearest guide alone.
"""
import argparse
import json
import os
import shlex
import subprocess
import sys
import tempfile

import numpy as np
import pyopenvdb as vdb

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.path.join(os.path.dirname(ROOT), "shared", "data")
sys.path.insert(0, os.path.join(ROOT, "build", "python"))
import vdbhair  # noqa: E402  (reading strand files and the voxel size suggestion only)

# (name, hair, head mesh, up axis of the head's frame)
GROOMS = [
    ("straight", "hair/cyhair/straight.hair", "scalp/cem_yuksel/woman_head.ply", "z"),
    ("ruby_long", "hair/tressfx/ascii_v2/ruby_long_hair_16_guide.tfx", "scalp/tressfx/ruby_head.obj", "y"),
    ("ruby_short", "hair/tressfx/ascii_v2/ruby_short_hair_16_guide.tfx", "scalp/tressfx/ruby_head.obj", "y"),
    ("ponytail_free", "hair/tressfx/ascii_v2/hair_free_16_guide.tfx", "scalp/tressfx/head_max4.obj", "y"),
    ("sintel", "hair/tressfx/binary_v4/GEO-sintel_hair_emit.001-sintel_hair.tfx", "scalp/sintel/sintel.obj", "y"),
    ("bangs_100", "hair/cyhair/Bangs_100.hair", "scalp/ct2hair/Bangs_head.ply", "y"),
    ("hairnet", "hair/hairnet_convdata/strands00014_00035_00010.convdata", "scalp/usc_hairsalon/head_model.ply", "y"),
]


def strands_of(s):
    pos = np.asarray(s.positions, dtype=np.float64)
    off = np.asarray(s.offsets)
    return [pos[off[i]:off[i + 1]] for i in range(len(off) - 1)]


def make_strands(strands):
    off = np.concatenate([[0], np.cumsum([len(p) for p in strands])]).astype(np.uint32)
    return vdbhair.Strands(np.concatenate(strands).astype(np.float32), off)


def resample(p, n=32):
    seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    if s[-1] <= 0:
        return np.repeat(p[:1], n, axis=0), 0.0
    t = np.linspace(0.0, s[-1], n)
    return np.stack([np.interp(t, s, p[:, k]) for k in range(3)], axis=1), s[-1]


def frechet(a, b):
    d = np.linalg.norm(a[:, None, :] - b[None, :, :], axis=2)
    n, m = d.shape
    ca = np.full((n, m), np.inf)
    ca[0, 0] = d[0, 0]
    for i in range(1, n):
        ca[i, 0] = max(ca[i - 1, 0], d[i, 0])
    for j in range(1, m):
        ca[0, j] = max(ca[0, j - 1], d[0, j])
    for i in range(1, n):
        for j in range(1, m):
            ca[i, j] = max(min(ca[i - 1, j], ca[i - 1, j - 1], ca[i, j - 1]), d[i, j])
    return ca[-1, -1]


def dense_points(p, h):
    """Vertices and points at most h/2 apart on every segment."""
    out = [p]
    for a, b in zip(p[:-1], p[1:]):
        k = int(np.ceil(np.linalg.norm(b - a) / (0.5 * h)))
        if k > 1:
            t = np.arange(1, k)[:, None] / k
            out.append(a + (b - a) * t)
    return np.concatenate(out)


class Volume:
    def __init__(self, strands, h):
        self.h = h
        vox = set()
        for p in strands:
            for c in np.unique(np.round(dense_points(p, h) / h).astype(np.int64), axis=0):
                vox.add(tuple(c))
        offsets = [(i, j, k) for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1)]
        self.vox = {(a + i, b + j, c + k) for (a, b, c) in vox for (i, j, k) in offsets}

    def leaves(self, p):
        for c in np.round(dense_points(p, self.h) / self.h).astype(np.int64):
            if tuple(c) not in self.vox:
                return True
        return False


class Head:
    """The scalp .vdb's level set, copied into a dense array and sampled trilinearly."""

    def __init__(self, path):
        grid = vdb.read(path, "surface")
        (i0, j0, k0), (i1, j1, k1) = grid.evalActiveVoxelBoundingBox()
        self.lo = np.array([i0, j0, k0]) - 1
        self.arr = np.full((i1 - i0 + 3, j1 - j0 + 3, k1 - k0 + 3), grid.background, dtype=np.float32)
        grid.copyToArray(self.arr, ijk=tuple(int(x) for x in self.lo))
        self.h = grid.transform.voxelSize()[0]
        self.origin = np.array(grid.transform.indexToWorld((0, 0, 0)))
        self.background = grid.background

    def dist(self, pts):
        x = (np.asarray(pts) - self.origin) / self.h - self.lo
        f = np.floor(x).astype(np.int64)
        t = x - f
        out = np.zeros(len(x))
        inside = np.all((f >= 0) & (f + 1 < np.array(self.arr.shape)), axis=1)
        fi, ti = f[inside], t[inside]
        acc = np.zeros(len(fi))
        for dx in (0, 1):
            for dy in (0, 1):
                for dz in (0, 1):
                    w = (ti[:, 0] if dx else 1 - ti[:, 0]) * (ti[:, 1] if dy else 1 - ti[:, 1]) * (ti[:, 2] if dz else 1 - ti[:, 2])
                    acc += w * self.arr[fi[:, 0] + dx, fi[:, 1] + dy, fi[:, 2] + dz]
        out[inside] = acc
        out[~inside] = self.background
        return out

    def enters(self, p):
        tol = 0.5 * self.h
        d = self.dist(p)
        return bool(np.any((d[1:] < -tol) & (d[1:] < d[0] - tol)))


def share(flags):
    return 100.0 * float(np.mean(flags)) if len(flags) else 0.0


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(" ".join(cmd) + "\n" + r.stderr)
    return r.stdout


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--vdbhair", default=os.path.join(ROOT, "build", "bin", "vdbhair"))
    ap.add_argument("--render")
    ap.add_argument("--only")
    ap.add_argument("--args", default="", help="extra options for interpolate")
    ap.add_argument("--share", type=float, default=0.10)
    ap.add_argument("--count", type=int, default=20000)
    args = ap.parse_args()
    extra = shlex.split(args.args)
    tmp = tempfile.mkdtemp()
    print("| groom | guides | at the groom's roots: leaves (groom) / head (guides) / error mean (nearest guide) | on the scalp: leaves / head |")
    print("| --- | --- | --- | --- |")
    rng = np.random.default_rng(0)
    for name, rel, head_rel, up in GROOMS:
        if args.only and name != args.only:
            continue
        hair_path, head_path = os.path.join(DATA, rel), os.path.join(DATA, head_rel)
        if not os.path.exists(hair_path) or not os.path.exists(head_path):
            print("| %s | (missing) |" % name)
            continue
        groom = vdbhair.read(hair_path)
        S = len(groom)
        idx = np.sort(rng.choice(S, max(1, int(round(args.share * S))), replace=False))
        keep = np.zeros(S, dtype=bool)
        keep[idx] = True
        strands = strands_of(groom)
        guides = [strands[i] for i in idx]
        guide_file = os.path.join(tmp, name + "_guides.hair")
        guide_set = make_strands(guides)
        guide_set.write(guide_file)
        scalp = os.path.join(tmp, name + "_scalp.vdb")
        run([args.vdbhair, "scalp", head_path, "-o", scalp, "--region", hair_path, "--quiet"])
        head = Head(scalp)
        h = vdbhair.suggest_voxel_size(guide_set)
        vol = Volume(guides, h)
        base_leave = share([vol.leaves(p) for p in strands])
        base_head = share([head.enters(p) for p in guides])
        # Regrown at the groom's roots.
        out1 = os.path.join(tmp, name + "_at_roots.hair")
        head_opt = [] if "--head" in extra else ["--head", scalp]
        # The groom's roots have no normals: surface frames apply on the scalp only.
        at_roots = [a for i, a in enumerate(extra) if not ("--frames" in extra[i - 1:i + 1] and "surface" in extra[i:i + 2])]
        run([args.vdbhair, "interpolate", guide_file, "--roots", hair_path, "-o", out1, "--up", up, "--quiet"] + head_opt + at_roots)
        new1 = strands_of(vdbhair.read(out1))
        groots = np.array([g[0] for g in guides])
        errs, near = [], []
        for i in range(S):
            if keep[i]:
                continue
            a, L = resample(strands[i])
            if L <= 0:
                continue
            b, _ = resample(new1[i])
            errs.append(frechet(a, b) / L)
            g = guides[int(np.argmin(np.linalg.norm(groots - strands[i][0], axis=1)))]
            c, _ = resample(g - g[0] + strands[i][0])
            near.append(frechet(a, c) / L)
        leave1 = share([vol.leaves(p) for p in new1])
        head1 = share([head.enters(p) for p in new1])
        # On the scalp.
        out2 = os.path.join(tmp, name + "_scalp.hair")
        run([args.vdbhair, "interpolate", guide_file, "--scalp", scalp, "--count", str(args.count), "-o", out2, "--up", up, "--quiet"] + extra)
        new2 = strands_of(vdbhair.read(out2))
        leave2 = share([vol.leaves(p) for p in new2])
        head2 = share([head.enters(p) for p in new2])
        print("| %s | %d of %d | %.1f %% (%.1f %%) / %.1f %% (%.1f %%) / %.1f %% (%.1f %%) | %.1f %% / %.1f %% |" % (
            name, len(idx), S, leave1, base_leave, head1, base_head, 100 * np.mean(errs), 100 * np.mean(near), leave2, head2))
        sys.stdout.flush()
        if args.render:
            os.makedirs(args.render, exist_ok=True)
            for tag, f in (("groom", hair_path), ("guides", guide_file), ("at_roots", out1), ("scalp", out2)):
                run([args.vdbhair, "render", f, "-o", os.path.join(args.render, "%s_%s.png" % (name, tag)), "--head", head_path,
                     "--up", up, "--view", "three-quarter", "--quiet"])


if __name__ == "__main__":
    main()
