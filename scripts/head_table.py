#!/usr/bin/env python3
"""The head in the generative verbs (issue 49): `synth`, `transfer` and `comb` on every groom of
../shared/data that has a head, measured by NumPy from the files the command wrote.

    PYTHONPATH=build/python /usr/bin/python3 scripts/head_table.py [--vdbhair build/bin/vdbhair]
        [--only NAME] [--render DIR] [--out DIR]

Per run:
- inside: share of vertices inside the head, by refine --head's rule (the head mesh's level set as
  `vdbhair scalp` makes it, trilinear, distance < 0), of the input (the example, or the hair
  combed) and of the output;
- kinks: share of strands with a turn over 45 degrees between two consecutive edges; for comb, the
  share of the moved strands that gain one ("new");
- time: wall seconds of the command (one run; speed is measured with paired runs elsewhere).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.environ.get("VDBHAIR_SHARED_DATA", os.path.join(os.path.dirname(ROOT), "shared", "data"))
import vdbhair  # noqa: E402  (reading strand files and grids only)

# name: (hair, head mesh, up axis)
GROOMS = {
    "straight": ("hair/cyhair/straight.hair", "scalp/cem_yuksel/woman_head.ply", "z"),
    "ruby_long": ("hair/tressfx/ascii_v2/ruby_long_hair_16_guide.tfx", "scalp/tressfx/ruby_head.obj", "y"),
    "ruby_short": ("hair/tressfx/ascii_v2/ruby_short_hair_16_guide.tfx", "scalp/tressfx/ruby_head.obj", "y"),
    "ponytail_free": ("hair/tressfx/ascii_v2/hair_free_16_guide.tfx", "scalp/tressfx/head_max4.obj", "y"),
    "sintel": ("hair/tressfx/binary_v4/GEO-sintel_hair_emit.001-sintel_hair.tfx", "scalp/sintel/sintel.obj", "y"),
    "hairnet": ("hair/hairnet_convdata/strands00014_00035_00010.convdata", "scalp/usc_hairsalon/head_model.ply", "y"),
}

# (verb, name, options: HEAD, UP, STROKE and DETAILS are substituted)
RUNS = [
    ("synth", "ruby_short", ["--head", "HEAD"]),
    ("synth", "ruby_short", ["--scalp", "HEAD"]),
    ("synth", "ruby_long", ["--head", "HEAD"]),
    ("synth", "ponytail_free", ["--head", "HEAD"]),
    ("synth", "ponytail_free", ["--scalp", "HEAD"]),
    ("synth", "straight", ["--head", "HEAD", "--up", "z"]),
    ("synth", "sintel", ["--head", "HEAD"]),
    ("synth", "hairnet", ["--head", "HEAD"]),
    ("transfer", "straight", ["hair/ply/Curly_100.ply", "--scalp", "HEAD"]),
    ("transfer", "ruby_long", ["hair/tressfx/ascii_v2/ruby_short_hair_16_guide.tfx", "--scalp", "HEAD"]),
    ("transfer", "ruby_short", ["hair/tressfx/ascii_v2/ruby_long_hair_16_guide.tfx", "--scalp", "HEAD"]),
    ("comb", "ruby_long", ["sweep"]),
    ("comb", "ruby_long", ["press"]),
    ("comb", "straight", ["sweep"]),
    ("comb", "straight", ["press"]),
    ("comb", "ponytail_free", ["sweep"]),
    ("comb", "ponytail_free", ["press"]),
    ("comb", "hairnet", ["sweep"]),
    ("comb", "hairnet", ["press"]),
    ("comb", "ruby_short", ["press"]),
]


class Head:
    """The head's level set (`vdbhair scalp HEAD`'s 'surface'), dense, sampled trilinearly."""

    def __init__(self, path):
        g = vdbhair.read_grid(path, "surface")
        (i0, j0, k0), (i1, j1, k1) = g.bbox
        self.lo = np.array([i0 - 1, j0 - 1, k0 - 1])
        hi = np.array([i1 + 1, j1 + 1, k1 + 1])
        self.arr = g.to_dense(((int(self.lo[0]), int(self.lo[1]), int(self.lo[2])), (int(hi[0]), int(hi[1]), int(hi[2]))))  # [z][y][x]
        self.grid = g
        self.background = float(abs(self.arr.max()))
        self.h = g.voxel_size

    def dist(self, pts):
        x = np.asarray(self.grid.world_to_index(np.asarray(pts, dtype=np.float64))) - self.lo
        f = np.floor(x).astype(np.int64)
        t = x - f
        shape = np.array(self.arr.shape[::-1])  # x, y, z
        ok = np.all((f >= 0) & (f + 1 < shape), axis=1)
        out = np.full(len(x), self.background)
        fi, ti = f[ok], t[ok]
        acc = np.zeros(len(fi))
        for dx in (0, 1):
            for dy in (0, 1):
                for dz in (0, 1):
                    w = (ti[:, 0] if dx else 1 - ti[:, 0]) * (ti[:, 1] if dy else 1 - ti[:, 1]) * (ti[:, 2] if dz else 1 - ti[:, 2])
                    acc += w * self.arr[fi[:, 2] + dz, fi[:, 1] + dy, fi[:, 0] + dx]
        out[ok] = acc
        return out


def load(path):
    s = vdbhair.read(path)
    return np.asarray(s.positions, dtype=np.float64), np.asarray(s.offsets, dtype=np.int64)


def max_turn_deg(pos, off):
    """Largest angle between consecutive edges of each strand, degrees."""
    e = np.diff(pos, axis=0)
    n = np.linalg.norm(e, axis=1)
    u = e / np.maximum(n, 1e-30)[:, None]
    c = np.einsum("ij,ij->i", u[:-1], u[1:])
    ang = np.degrees(np.arccos(np.clip(c, -1, 1)))
    # edge k joins vertex k, k+1; the pair (k, k+1) is inside a strand when k+1 < off[s+1]-1 for its strand
    strand_of_edge = np.searchsorted(off, np.arange(len(e)), side="right") - 1
    valid = (strand_of_edge[:-1] == strand_of_edge[1:]) & (n[:-1] > 0) & (n[1:] > 0)
    # the edge between the last vertex of a strand and the first of the next is not an edge
    last = off[1:] - 1
    bad = np.zeros(len(e), dtype=bool)
    bad[last[last < len(e)]] = True
    valid &= ~bad[:-1] & ~bad[1:]
    worst = np.zeros(len(off) - 1)
    np.maximum.at(worst, strand_of_edge[:-1][valid], ang[valid])
    return worst


def inside_share(head, pos):
    return 100.0 * float(np.mean(head.dist(pos) < 0.0))


def head_box(head, up):
    """The centre of the head mesh's level-set box, a quarter of its smallest side, and the unit
    up axis: the scale strokes are made at."""
    (i0, j0, k0), (i1, j1, k1) = head.grid.bbox
    lo = np.array(head.grid.index_to_world(np.array([[i0, j0, k0]], dtype=np.float64)))[0]
    hi = np.array(head.grid.index_to_world(np.array([[i1, j1, k1]], dtype=np.float64)))[0]
    upv = np.zeros(3)
    upv[{"x": 0, "y": 1, "z": 2}[up]] = 1.0
    return 0.5 * (lo + hi), 0.25 * float(np.min(hi - lo)), upv


def strokes_for(kind, head, up):
    """A sweep across the back at the head's lower half and a press into the back of the head,
    from the head mesh's level-set box."""
    c, R, upv = head_box(head, up)
    side = np.array([1.0, 0.0, 0.0])
    back = np.cross(side, upv)  # -z for y-up, +y for z-up
    if up == "y":
        back = -np.array([0.0, 0.0, 1.0])
    if kind == "sweep":
        pts = [c - 1.6 * R * side + 1.6 * R * back - 0.8 * R * upv, c + 1.8 * R * back - 0.8 * R * upv, c + 1.6 * R * side + 1.6 * R * back - 0.8 * R * upv]
        return {"vdbhair": "strokes/1", "strokes": [{"points": [list(map(float, p)) for p in pts], "radius": 0.8 * R, "strength": 0.8}]}
    pts = [c + 3.0 * R * back + 1.0 * R * upv, c + 0.5 * R * back]
    return {"vdbhair": "strokes/1", "strokes": [{"points": [list(map(float, p)) for p in pts], "radius": 1.2 * R, "strength": 1.0}]}


def run(cmd):
    t = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(" ".join(cmd) + "\n" + r.stderr)
    return time.perf_counter() - t, r.stdout


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--vdbhair", default=os.path.join(ROOT, "build", "bin", "vdbhair"))
    ap.add_argument("--only", help="a verb or a groom name")
    ap.add_argument("--out", help="keep outputs here")
    ap.add_argument("--render", help="render inputs and outputs with the head into this folder")
    ap.add_argument("--json", help="write the rows here")
    args = ap.parse_args()
    tmp = args.out or tempfile.mkdtemp()
    os.makedirs(tmp, exist_ok=True)
    heads = {}
    rows = []
    print("| verb | groom | options | inside: input → output | kinks > 45°: input → output (new) | time |")
    print("| --- | --- | --- | --- | --- | ---: |")
    for verb, name, opts in RUNS:
        if args.only and args.only not in (verb, name):
            continue
        hair_rel, head_rel, up = GROOMS[name]
        hair, head_mesh = os.path.join(DATA, hair_rel), os.path.join(DATA, head_rel)
        if not (os.path.exists(hair) and os.path.exists(head_mesh)):
            print("| %s | %s | (missing data) |" % (verb, name))
            continue
        if name not in heads:
            scalp = os.path.join(tmp, name + "_head.vdb")
            if not os.path.exists(scalp):
                run([args.vdbhair, "scalp", head_mesh, "-o", scalp, "--quiet"])
            heads[name] = Head(scalp)
        head = heads[name]
        tag = "%s_%s_%s" % (verb, name, "_".join(o.replace("/", "").replace("-", "").replace(".", "") for o in opts if o not in ("HEAD",))[:40])
        out = os.path.join(tmp, tag + ".hair")
        o = [head_mesh if x == "HEAD" else x for x in opts]
        if verb == "synth":
            cmd = [args.vdbhair, "synth", hair, "-o", out, "--quiet", "--seed", "0"] + o
            ref = hair
        elif verb == "transfer":
            details = os.path.join(DATA, o[0])
            cmd = [args.vdbhair, "transfer", details, hair, "-o", out, "--quiet"] + o[1:]
            ref = hair
        else:
            stroke = os.path.join(tmp, "%s_%s.json" % (name, o[0]))
            with open(stroke, "w") as f:
                json.dump(strokes_for(o[0], head, up), f)
            cmd = [args.vdbhair, "comb", hair, "--stroke", stroke, "-o", out, "--quiet", "--head", head_mesh]
            ref = hair
        try:
            secs, _ = run(cmd)
        except RuntimeError as e:
            print("| %s | %s | %s | failed: %s |" % (verb, name, " ".join(opts), str(e).splitlines()[-1]))
            continue
        pin, oin = load(ref)
        pout, oout = load(out)
        kin, kout = max_turn_deg(pin, oin), max_turn_deg(pout, oout)
        row = {"verb": verb, "groom": name, "options": " ".join(opts), "inside_in": inside_share(head, pin),
               "inside_out": inside_share(head, pout), "kinks_in": 100.0 * float(np.mean(kin > 45)),
               "kinks_out": 100.0 * float(np.mean(kout > 45)), "seconds": secs}
        new = ""
        if verb == "comb" and len(oin) == len(oout):
            moved = np.array([not np.array_equal(pin[oin[i]:oin[i + 1]], pout[oout[i]:oout[i + 1]]) for i in range(len(oin) - 1)])
            gained = (kout > 45) & ~(kin > 45)
            row["moved"] = int(moved.sum())
            row["new_kinks"] = 100.0 * float(gained[moved].mean()) if moved.any() else 0.0
            new = " (new %.1f %% of %d moved)" % (row["new_kinks"], row["moved"])
        rows.append(row)
        print("| %s | %s | %s | %.1f %% → %.1f %% | %.1f %% → %.1f %%%s | %.1f s |" % (
            verb, name, " ".join(opts), row["inside_in"], row["inside_out"], row["kinks_in"], row["kinks_out"], new, secs))
        sys.stdout.flush()
        if args.render:
            os.makedirs(args.render, exist_ok=True)
            for t, f in (("in", ref), ("out", out)):
                png = os.path.join(args.render, "%s_%s.png" % (tag, t))
                if t == "in" and os.path.exists(png):
                    continue
                view = "back" if verb == "comb" else "three-quarter"
                facing = ["--facing", "y"] if up == "z" else []  # cyHair models face +y
                run([args.vdbhair, "render", f, "-o", png, "--head", head_mesh, "--up", up, "--view", view, "--quiet",
                     "--width", "600", "--height", "600"] + facing)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
