#!/usr/bin/env python3
"""Comb with strokes drawn at random around each groom's head (issue 49: comb makes no new kink).

    PYTHONPATH=build/python /usr/bin/python3 scripts/comb_strokes.py [--vdbhair build/bin/vdbhair]
        [--strokes 8] [--seed 1] [--only ruby_long,hairnet] [--out DIR]

For every groom of scripts/head_table.py, --strokes strokes, each a press (from 2-3.5 quarter
head-boxes out, 0-1.5 above, to 0.2-1 out at a height of -1 to 0.8) or a sweep (three points
across the head's side at that height), about a direction drawn around the up axis, with a radius
of 0.5-1.5 quarter head-boxes and a strength of 0.4-1 (points rounded to four decimals, as a user
types them). `vdbhair comb --head MESH` runs each; the output's strands are measured with NumPy:
a strand has a new kink when it turns by over 45 degrees between two edges and did not before.
Prints one line per stroke and the number of strokes that made any new kink.
"""
import argparse
import json
import os
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import head_table as ht  # noqa: E402  (the grooms, the head's level set, the kink measure)


def stroke(rng, c, R, upv, side):
    az = rng.uniform(0, 2 * np.pi)
    fwd = np.cross(upv, side)
    d = np.cos(az) * fwd + np.sin(az) * side
    across = np.cross(upv, d)
    kind = "press" if rng.uniform() < 0.5 else "sweep"
    h = rng.uniform(-1.0, 0.8)
    if kind == "press":
        pts = [c + rng.uniform(2, 3.5) * R * d + rng.uniform(0, 1.5) * R * upv, c + rng.uniform(0.2, 1.0) * R * d + h * R * upv]
    else:
        pts = [c - 1.6 * R * across + 1.6 * R * d + h * R * upv, c + 1.8 * R * d + h * R * upv, c + 1.6 * R * across + 1.6 * R * d + h * R * upv]
    pts = [[round(float(x), 4) for x in p] for p in pts]
    return kind, {"vdbhair": "strokes/1", "strokes": [{"points": pts, "radius": float(rng.uniform(0.5, 1.5) * R), "strength": float(rng.uniform(0.4, 1.0))}]}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--vdbhair", default=os.path.join(ht.ROOT, "build", "bin", "vdbhair"))
    ap.add_argument("--strokes", type=int, default=8, help="strokes per groom")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--only", help="comma-separated groom names")
    ap.add_argument("--out", help="keep strokes and outputs here")
    args = ap.parse_args()
    tmp = args.out or tempfile.mkdtemp()
    os.makedirs(tmp, exist_ok=True)
    rng = np.random.default_rng(args.seed)
    names = args.only.split(",") if args.only else ["ruby_long", "ruby_short", "ponytail_free", "hairnet", "sintel", "straight"]
    total = bad = 0
    for name in names:
        hair_rel, head_rel, up = ht.GROOMS[name]
        hair, mesh = os.path.join(ht.DATA, hair_rel), os.path.join(ht.DATA, head_rel)
        if not (os.path.exists(hair) and os.path.exists(mesh)):
            print(name, "(missing data)")
            continue
        scalp = os.path.join(tmp, name + "_head.vdb")
        if not os.path.exists(scalp):
            ht.run([args.vdbhair, "scalp", mesh, "-o", scalp, "--quiet"])
        head = ht.Head(scalp)
        pin, oin = ht.load(hair)
        turn_in = ht.max_turn_deg(pin, oin)
        c, R, upv = ht.head_box(head, up)
        side = np.array([1.0, 0.0, 0.0]) - upv * upv[0]
        side /= np.linalg.norm(side)
        for t in range(args.strokes):
            kind, st = stroke(rng, c, R, upv, side)
            sf, out = os.path.join(tmp, "%s_%d.json" % (name, t)), os.path.join(tmp, "%s_%d.hair" % (name, t))
            with open(sf, "w") as f:
                json.dump(st, f)
            ht.run([args.vdbhair, "comb", hair, "--stroke", sf, "-o", out, "--quiet", "--head", mesh])
            po, oo = ht.load(out)
            turn_out = ht.max_turn_deg(po, oo)
            new = np.where((turn_out > 45) & (turn_in <= 45))[0]
            total += 1
            bad += len(new) > 0
            detail = " strands %s turns %s" % (new[:5].tolist(), np.round(turn_out[new[:5]], 1).tolist()) if len(new) else ""
            print("%s %d %s: new kinks %d%s" % (name, t, kind, len(new), detail), flush=True)
    print("%d of %d strokes made a new kink over 45 degrees" % (bad, total))


if __name__ == "__main__":
    main()
