#!/usr/bin/env python3
"""Writes scenes/default/head.json: vdbhair's bundled full-head helicoid scene.

About 200 guides rooted on a spherical scalp (radius 10, centre at the origin, +y up, the face
towards +z), each a two-piece p-helicoid (Piuze et al. 2011, §3.4): the first piece wraps around
the head towards the nape (kT = 1 / (R + 0.5), the normal pointing at the centre, so its circle hugs the scalp),
the second falls with a little random curl and twist; gentle waviness (Eq. 4) and a wisp of 250
streamlines per guide (§3.3). 200 x 251 = 50,200 strands. The hair is combed back and gathered at the nape into a low ponytail. Deterministic (seeded); stdlib only.

usage: make_default_head.py OUT.json
"""
import json
import math
import random
import sys

R = 10.0
GUIDES = 200
WISP = 250
rng = random.Random(20261122)


def normalize(v):
    n = math.sqrt(sum(c * c for c in v))
    return [c / n for c in v]


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def scalp_roots(count):
    """Fibonacci points on the sphere, kept on the scalp: above y = -0.15 R, away from the face."""
    roots, i, n = [], 0, count * 4
    while len(roots) < count and i < n:
        y = 1.0 - 2.0 * (i + 0.5) / n
        r = math.sqrt(1.0 - y * y)
        a = math.pi * (3.0 - math.sqrt(5.0)) * i
        u = [r * math.cos(a), y, r * math.sin(a)]
        i += 1
        if u[1] < -0.15:
            continue
        if u[2] > 0.45 and u[1] < 0.55:  # the face and forehead
            continue
        roots.append(u)
    return roots


guides = []
for u in scalp_roots(GUIDES):
    root = [R * c for c in u]
    # Combed back: along the great circle towards the nape point m (behind and below).
    m = normalize([0.0, -0.3, -1.0])
    um = dot(u, m)
    d = [m[k] - um * u[k] for k in range(3)]
    if math.sqrt(dot(d, d)) < 1e-3:
        d = [0.0, -1.0, 0.0]
    d = normalize(d)
    tangent = normalize([0.12 * u[k] + d[k] for k in range(3)])  # lifted a little off the scalp
    normal = [-c for c in u]  # towards the centre: the first piece's circle hugs the head
    # First piece: around the head towards the nape, stopping short of it.
    wrap = max(1.5, (R + 0.5) * (math.acos(max(-1.0, min(1.0, um))) - 0.35))
    kT = 1.0 / (R + 0.5)
    fall = 9.0 + 4.0 * rng.random()
    guides.append({
        "root": [round(c, 5) for c in root],
        "frame": {"tangent": [round(c, 6) for c in tangent], "normal": [round(c, 6) for c in normal]},
        "pieces": [
            {"k": [round(kT, 6), 0.0, round(rng.uniform(-0.01, 0.01), 5), 0.0], "length": round(wrap, 4)},
            {"k": [round(rng.uniform(-0.08, 0.08), 5), round(rng.uniform(-0.02, 0.02), 5),
                   round(rng.uniform(-0.05, 0.05), 5), round(rng.uniform(-0.2, 0.2), 4)],
             "length": round(fall, 4), "roll": round(rng.uniform(-0.3, 0.3), 4)},
        ],
        "waviness": {"amplitude": 0.1, "frequency": round(rng.uniform(1.6, 2.4), 4), "phase": round(rng.uniform(0, 6.28), 4),
                     "noise": 0.01},
        "wisp": {"count": WISP, "radius": 0.9, "fanning": 0.05},
    })

with open(sys.argv[1], "w") as f:
    f.write('{"vdbhair": "scene/1", "seed": 11, "step": 0.4,\n "guides": [\n')
    f.write(",\n".join("  " + json.dumps(g, separators=(",", ":")) for g in guides))
    f.write("\n ]}\n")
print("wrote %s: %d guides, %d strands" % (sys.argv[1], len(guides), len(guides) * (WISP + 1)))
