#!/usr/bin/python3
"""Issue 19, part 1: does a fit depend on the step it was traced with?

For each real hairstyle: resample to 30 vertices (`vdbhair convert --resample 30`), keep an evenly
strided subset, fit it (`vdbhair fit --json`), then regrow the scene with every guide's `step`
divided by 1, 4 and 16 (`vdbhair grow`), and measure each regrown strand against its input strand:

    discrete Frechet distance between the input densified to the fit's step h (each segment cut
    into ceil(length / h) equal parts, as `fit` measures) and the regrown strand resampled by arc
    length at the same spacing h (so that the three steps are compared on the same footing),
    relative to the input strand's length.

Prints the issue's table: the mean error `fit` reported, the mean error regrown at h, h/4, h/16,
the share of strands flagged: at h/4 or h/16 more than twice the error `fit` reported for it, or
more than 10 % of its length; the largest error at h/4 or h/16 and the largest ratio of it to
the strand's reported error; the mean step convergence `fit --json` reports; and fit strands/s
(wall clock of `vdbhair fit`, all threads: the benchmark's fit section is the speed measure).

    /usr/bin/python3 scripts/fit_step_table.py [--strands 2000] [--vertices 30|0] [--styles wavy,...] [--vdbhair build/bin/vdbhair]
"""
import argparse
import json
import os
import struct
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.path.join(os.path.dirname(ROOT), "shared", "data", "hair")

STYLES = [
    ("harolongo (wavy)", os.path.join(DATA, "usc_data", "harolongo.data")),
    ("straight", os.path.join(DATA, "cyhair", "straight.hair")),
    ("Curly_100", os.path.join(DATA, "ply", "Curly_100.ply")),
    ("Ratboy mohawk", os.path.join(DATA, "tressfx", "binary_v4", "Ratboy_mohawk.tfx")),
    ("ponytail (scenes/default)", os.path.join(ROOT, "scenes", "default", "ponytail.hair")),
]
FACTORS = (1, 4, 16)


def read_data(path):
    """USC-HairSalon .data: int32 strand count; per strand int32 vertex count and float32 xyz."""
    buf = open(path, "rb").read()
    (n,) = struct.unpack_from("<i", buf, 0)
    off, out = 4, []
    for _ in range(n):
        (m,) = struct.unpack_from("<i", buf, off)
        off += 4
        out.append(np.frombuffer(buf, dtype="<f4", count=3 * m, offset=off).reshape(m, 3).astype(np.float64))
        off += 12 * m
    return out


def write_data(path, strands):
    with open(path, "wb") as f:
        f.write(struct.pack("<i", len(strands)))
        for s in strands:
            f.write(struct.pack("<i", len(s)))
            f.write(np.asarray(s, dtype="<f4").tobytes())


def densify(p, h):
    """Each segment cut into ceil(len / h) equal parts."""
    out = [p[:1]]
    for a, b in zip(p[:-1], p[1:]):
        n = max(1, int(np.ceil(np.linalg.norm(b - a) / h - 1e-9)))
        t = (np.arange(1, n + 1) / n)[:, None]
        out.append(a + t * (b - a))
    return np.concatenate(out)


def resample(p, h):
    """Points at arc lengths 0, h, 2h, ... and the end."""
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])
    n = max(1, int(np.ceil(s[-1] / h - 1e-9)))
    t = np.minimum(np.arange(n + 1) * h, s[-1])
    return np.stack([np.interp(t, s, p[:, c]) for c in range(3)], axis=1)


def frechet_batch(P, Q):
    """Discrete Frechet distances of many pairs at once, by anti-diagonals. Sequences are padded by
    repeating their last point, which does not change the distance."""
    S = len(P)
    N = max(len(p) for p in P)
    M = max(len(q) for q in Q)
    A = np.empty((S, N, 3))
    B = np.empty((S, M, 3))
    for i, (p, q) in enumerate(zip(P, Q)):
        A[i, :len(p)] = p
        A[i, len(p):] = p[-1]
        B[i, :len(q)] = q
        B[i, len(q):] = q[-1]
    D = np.sqrt(((A[:, :, None, :] - B[:, None, :, :]) ** 2).sum(-1))
    C = np.full((S, N, M), np.inf)
    C[:, 0, 0] = D[:, 0, 0]
    for d in range(1, N + M - 1):
        i = np.arange(max(0, d - M + 1), min(N, d + 1))
        j = d - i
        best = np.full((S, len(i)), np.inf)
        m = i > 0
        best[:, m] = np.minimum(best[:, m], C[:, i[m] - 1, j[m]])
        m = j > 0
        best[:, m] = np.minimum(best[:, m], C[:, i[m], j[m] - 1])
        m = (i > 0) & (j > 0)
        best[:, m] = np.minimum(best[:, m], C[:, i[m] - 1, j[m] - 1])
        C[:, i, j] = np.maximum(D[:, i, j], best)
    return C[:, N - 1, M - 1]


def frechet_all(P, Q, chunk=200):
    # Group by size so that padding stays small.
    order = sorted(range(len(P)), key=lambda k: (len(P[k]), len(Q[k])))
    out = np.empty(len(P))
    for c in range(0, len(order), chunk):
        idx = order[c:c + chunk]
        out[idx] = frechet_batch([P[k] for k in idx], [Q[k] for k in idx])
    return out


def run(cmd):
    return subprocess.run(cmd, check=True, capture_output=True, text=True).stdout


def style_row(name, path, args, tmp):
    tag = "".join(ch for ch in name.split()[0].lower() if ch.isalnum())
    r30 = os.path.join(tmp, tag + "_30.data")
    run([args.vdbhair, "convert", path, "-o", r30, "--quiet"] + (["--resample", str(args.vertices)] if args.vertices > 0 else []))
    strands = read_data(r30)
    stride = max(1, -(-len(strands) // args.strands)) if args.strands > 0 else 1
    strands = strands[::stride]
    sub = os.path.join(tmp, tag + "_sub.data")
    write_data(sub, strands)
    fits = os.path.join(tmp, tag + "_fits.json")
    t0 = time.time()
    rep = json.loads(run([args.vdbhair, "fit", sub, "-o", fits, "--json", "--quiet"]))
    scene = json.load(open(fits))
    guides = scene["guides"]
    idx = [g["fit"]["strand"] for g in guides]
    targets = [strands[k] for k in idx]
    lengths = np.array([np.linalg.norm(np.diff(p, axis=0), axis=1).sum() for p in targets])
    steps = np.array([g.get("step", scene["step"]) for g in guides])
    reported = np.array([g["fit"]["frechet"] for g in guides]) / lengths
    dense = [densify(p, h) for p, h in zip(targets, steps)]
    errs = {}
    for f in FACTORS:
        sc = json.loads(json.dumps(scene))
        for g in sc["guides"]:
            g["step"] = g.get("step", scene["step"]) / f
        sp = os.path.join(tmp, "%s_h%d.json" % (tag, f))
        json.dump(sc, open(sp, "w"))
        out = os.path.join(tmp, "%s_h%d.data" % (tag, f))
        run([args.vdbhair, "grow", sp, "-o", out, "--quiet"])
        grown = read_data(out)
        assert len(grown) == len(guides), (len(grown), len(guides))
        g = [resample(p, h) for p, h in zip(grown, steps)]
        errs[f] = frechet_all(dense, g) / lengths
    fine = np.maximum(errs[4], errs[16])
    flagged = (fine > 2.0 * reported) | (fine > 0.10)
    conv = rep.get("step_convergence")
    ratio = fine / np.maximum(reported, 1e-12)
    row = "| %s | %d | %.2f %% | %.2f %% | %.2f %% | %.2f %% | %.2f %% (%d) | %.2f %% | %.2f %% | %.2fx | %s | %.0f |" % (
        name, len(guides), 100 * reported.mean(), 100 * errs[1].mean(), 100 * errs[4].mean(), 100 * errs[16].mean(),
        100 * flagged.mean(), flagged.sum(), 100 * np.median(fine[flagged]) if flagged.any() else 0.0,
        100 * fine.max(), ratio.max(), "%.3f %%" % (100 * conv["mean"]) if conv else "-", rep["strands_per_second"])
    if args.details and flagged.any():
        for k in np.nonzero(flagged)[0][:args.details]:
            print("  flagged strand %d: reported %.3f %%, h %.3f %%, h/4 %.3f %%, h/16 %.3f %%" % (
                idx[k], 100 * reported[k], 100 * errs[1][k], 100 * errs[4][k], 100 * errs[16][k]), file=sys.stderr)
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--strands", type=int, default=1000, help="most strands per style (an evenly strided subset; 0: all)")
    ap.add_argument("--vdbhair", default=os.path.join(ROOT, "build", "bin", "vdbhair"))
    ap.add_argument("--styles", default="", help="comma-separated name prefixes (default: all)")
    ap.add_argument("--vertices", type=int, default=30, help="resample every strand to this many vertices (0: as stored)")
    ap.add_argument("--details", type=int, default=0, help="print up to N flagged strands per style on stderr")
    args = ap.parse_args()
    print("| style (%s vertices) | strands | reported | grow @h | @h/4 | @h/16 | flagged strands | flagged: median error | worst @h/4, h/16 | worst / reported | fit's step convergence | fit strands/s |" % (args.vertices or "stored"))
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    want = [s.strip().lower() for s in args.styles.split(",") if s.strip()]
    with tempfile.TemporaryDirectory() as tmp:
        for name, path in STYLES:
            if want and not any(name.lower().startswith(w) for w in want):
                continue
            if not os.path.exists(path):
                print("| %s | (missing: %s) |" % (name, path))
                continue
            print(style_row(name, path, args, tmp))
            sys.stdout.flush()


if __name__ == "__main__":
    main()
