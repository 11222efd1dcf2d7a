#!/usr/bin/env python3
"""Pictures of interpolate's groom controls (docs/interpolation.md, "Controls on the new hair"):
Ruby's long hair from ../shared/data (TressFX, on its own head), 10 % of its strands as guides
(seed 0), 20,000 new hairs spread over the scalp where it grows, once at the defaults and once per
control; masks are made here with pyopenvdb. Run with Debian's /usr/bin/python3 after a build:

    /usr/bin/python3 scripts/groom_pictures.py [--out docs/groom]
"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np
import pyopenvdb as vdb

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "build", "python"))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import vdbhair  # noqa: E402
from guides_table import DATA, make_strands, strands_of  # noqa: E402

HAIR = "hair/tressfx/ascii_v2/ruby_long_hair_16_guide.tfx"
HEAD = "scalp/tressfx/ruby_head.obj"


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(" ".join(cmd) + "\n" + r.stderr)
    return r.stdout


def mask(path, name, lo, hi, voxel, value):
    """A float grid `name` over the box [lo, hi] whose value at each voxel centre is value(x, y, z)."""
    n = np.ceil((np.asarray(hi) - np.asarray(lo)) / voxel).astype(int) + 1
    ijk0 = np.floor(np.asarray(lo) / voxel).astype(int)
    idx = np.indices(n).reshape(3, -1).T + ijk0
    x, y, z = (idx * voxel).T
    dense = value(x, y, z).reshape(n).astype(np.float32)
    grid = vdb.FloatGrid(0.0)
    grid.copyFromArray(dense, ijk=tuple(int(v) for v in ijk0))
    grid.transform = vdb.createLinearTransform(voxelSize=voxel)
    grid.name = name
    vdb.write(path, grids=[grid])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--vdbhair", default=os.path.join(ROOT, "build", "bin", "vdbhair"))
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "groom"))
    args = ap.parse_args()
    hair, head = os.path.join(DATA, HAIR), os.path.join(DATA, HEAD)
    if not os.path.exists(hair) or not os.path.exists(head):
        print("skipped: %s or %s not found" % (hair, head))
        return
    os.makedirs(args.out, exist_ok=True)
    tmp = tempfile.mkdtemp()
    groom = vdbhair.read(hair)
    rng = np.random.default_rng(0)
    idx = np.sort(rng.choice(len(groom), len(groom) // 10, replace=False))
    strands = strands_of(groom)
    guides = os.path.join(tmp, "guides.hair")
    make_strands([strands[i] for i in idx]).write(guides)
    scalp = os.path.join(tmp, "scalp.vdb")
    run([args.vdbhair, "scalp", head, "-o", scalp, "--region", hair, "--quiet"])
    lo, hi = groom.positions.min(axis=0) - 10, groom.positions.max(axis=0) + 10
    # Length: a layered cut, the front hair at 40 % of its length rising to all of it at the back
    # (the face looks along +z); density: a centre parting, bare within 2 units of x = 0.
    length = os.path.join(tmp, "length.vdb")
    mask(length, "length", lo, hi, 2.0, lambda x, y, z: np.clip(0.4 + 0.6 * (20.0 - z) / 60.0, 0.4, 1.0))
    density = os.path.join(tmp, "density.vdb")
    mask(density, "density", lo, hi, 1.0, lambda x, y, z: (np.abs(x) > 2.0).astype(float))
    cases = [
        ("defaults", []),
        ("clumps", ["--clump-radius", "5", "--clump-tightness", "0.85"]),
        ("clumps_tip", ["--clump-radius", "5", "--clump-tightness", "0.85", "--clump-profile", "3"]),
        ("curl", ["--curl", "2.5", "--curl-frequency", "0.4"]),
        ("frizz", ["--frizz", "2"]),
        ("length", ["--length", length]),
        ("density", ["--density", density]),
        ("all", ["--length", length, "--clump-radius", "5", "--curl", "1.5", "--curl-frequency", "0.4", "--frizz", "0.8"]),
    ]
    for name, extra in cases:
        out = os.path.join(tmp, name + ".hair")
        report = run([args.vdbhair, "interpolate", guides, "--scalp", scalp, "--count", "20000", "--up", "y", "-o", out] + extra)
        print("## %s: %s" % (name, " ".join(extra)))
        print(report.strip())
        # The parting of the density mask shows from the back.
        view = "back" if name == "density" else "three-quarter"
        run([args.vdbhair, "render", out, "-o", os.path.join(args.out, name + ".png"), "--head", head, "--view", view,
             "--width", "768", "--height", "768", "--quiet"])


if __name__ == "__main__":
    main()
