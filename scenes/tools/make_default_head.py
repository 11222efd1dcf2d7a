#!/usr/bin/env python3
"""Writes scenes/default/head.json: vdbhair's bundled full-head helicoid scene, a ponytail.

A spherical head (radius 10, centre at the origin, +y up, the face towards +z; the scene's "head"
record) with 400 guides rooted area-uniformly (a Fibonacci lattice) over a scalp region that runs
down to the nape and the temples and leaves the face and the ears bare. Each guide is a p-helicoid
(Piuze et al. 2011, §3.4) of kT-only pieces (circles) and a last curly one, combed back and gathered
into a ponytail:

0. off the scalp: the hair leaves the scalp at up to 0.2 rad and lies down again over up to 3
   units (a quarter of the way to the tie at most, bending with kT <= 0.2), ending tangent to the
   sphere through its end;
1. along the scalp to the tie: the circle from there, in the plane of the root and the tie, through
   the guide's own point on the tie (a ring of radius 0.4 about a point 0.9 above the back of the
   head, on the side the root is); kT and the length are solved in closed form from the chord (a
   circle through two points with a given start tangent), so the circle lies outside the head and
   rises off it steadily. Roots just under the tie, whose hair would have to bend sharply outwards,
   instead leave the scalp as steeply as needed for one circle bending outwards with kT <= 0.3;
2. the turn at the tie: a circle of radius 2.5 from the direction the guide arrives in to the
   ponytail's common direction G (back and down), its roll chosen so it turns towards G;
3. the ponytail's fall: the same circle for every guide, bending from G towards straight down;
4. the hanging end: a small random curl and twist per guide.

The end frame of each piece is computed in closed form (a kT-only piece rotates its frame about
E_B by kT·length), and the scene is grown with RK4 so the traced guides follow those circles.
Every wisp (124 strands, §3.3) has its roots in the scalp's tangent plane ("normal": the radial
direction) and 2 % strays; gentle waviness (Eq. 4; no noise, which would move roots off the scalp). 400 x 125 = 50,000 strands.
Deterministic (seeded); stdlib only.

usage: make_default_head.py OUT.json
"""
import json
import math
import random
import sys

R = 10.0                # head radius
GUIDES = 400
WISP = 124              # wisp strands per guide (plus the guide)
WISP_RADIUS = 0.7       # covers the scalp: 400 disks of this radius are ~80 % of the region's area
STEP = 0.4
TIE_DIR = None          # set below: where the ponytail is tied, seen from the centre
TIE_HEIGHT = 0.9        # the tie's centre above the scalp
TIE_RING = 0.4         # guides end on a ring of this radius about it, on the side they come from
TURN_RADIUS = 2.5       # piece 2
LIFT, LIFT_LENGTH = 0.2, 3.0   # piece 0: how steeply hair leaves the scalp, and over what length it lies down again
MAX_OUTWARD = 0.3       # 1 / the tightest outward bend, well above the wisp's radius
FALL_KT, FALL_LENGTH = 0.13, 7.0  # piece 3
FANNING = 0.0
STRAYS = 0.02
rng = random.Random(20261201)


def add(a, b):
    return [x + y for x, y in zip(a, b)]


def sub(a, b):
    return [x - y for x, y in zip(a, b)]


def mul(s, a):
    return [s * x for x in a]


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def norm(a):
    return math.sqrt(dot(a, a))


def normalize(a):
    n = norm(a)
    return [x / n for x in a]


def perp(v, n):
    """The part of v perpendicular to unit n."""
    return sub(v, mul(dot(v, n), n))


TIE_DIR = normalize([0.0, 0.22, -1.0])
TIE = mul(R + TIE_HEIGHT, TIE_DIR)
G = normalize([0.0, -0.55, -1.0])   # the ponytail leaves the tie back and down
DOWN = [0.0, -1.0, 0.0]


def hairline(a):
    """The lowest y (unit sphere) of the scalp at azimuth a (0: the face, +-pi: the back)."""
    a = abs(a)
    if a < math.pi / 2:   # forehead (0.5) down to the temples and sideburns (-0.25)
        return -0.25 + 0.75 * math.cos(a) ** 1.5
    return -0.25 - 0.3 * math.sin(a - math.pi / 2) ** 2   # sides down to the nape (-0.55)


def on_scalp(u):
    if u[1] < hairline(math.atan2(u[0], u[2])):
        return False
    # The ears: bare patches on the sides, just above the hairline there.
    for side in (1.0, -1.0):
        ear = normalize([side, -0.12, -0.05])
        if dot(u, ear) > math.cos(0.28):
            return False
    return True


def fibonacci(n):
    golden = math.pi * (3.0 - math.sqrt(5.0))
    for i in range(n):
        y = 1.0 - 2.0 * (i + 0.5) / n
        r = math.sqrt(1.0 - y * y)
        yield [r * math.cos(golden * i), y, r * math.sin(golden * i)]


def scalp_roots(count):
    """Area-uniform roots: the Fibonacci lattice of the whole sphere whose scalp part has `count` points."""
    best = None
    for n in range(count, count * 4):
        roots = [u for u in fibonacci(n) if on_scalp(u)]
        if len(roots) == count:
            return roots, n
        if best is None or abs(len(roots) - count) < abs(len(best[0]) - count):
            best = (roots, n)
    return best


def rotate_frame(t, n, b, angle):
    """The frame of a kT-only piece after turning by angle (radians) about b."""
    c, s = math.cos(angle), math.sin(angle)
    return add(mul(c, t), mul(s, n)), add(mul(-s, t), mul(c, n)), b


def roll_towards(t, n, b, target):
    """The roll (n' = cos n + sin b) that points n at target's part perpendicular to t, and the angle from t to target."""
    roll = math.atan2(dot(target, b), dot(target, n))
    angle = math.acos(max(-1.0, min(1.0, dot(t, target))))
    c, s = math.cos(roll), math.sin(roll)
    n2 = add(mul(c, n), mul(s, b))
    return roll, angle, n2, cross(t, n2)


def r(x, d=6):
    return round(x, d)


def rv(v, d=6):
    return [round(x, d) for x in v]


def circle_to(p, t, n, b, target):
    """The kT-only piece from p (frame t, n, b) through target: its roll (n' = cos n + sin b, towards
    the chord), kT, length and end frame. In (t, n') coordinates the chord is
    (sin psi, 1 - cos psi) / kT, so psi / 2 = atan2(c_n, c_t) and kT = 2 c_n / |c|^2."""
    chord = sub(target, p)
    roll = math.atan2(dot(chord, b), dot(chord, n))
    c, s = math.cos(roll), math.sin(roll)
    n2 = add(mul(c, n), mul(s, b))
    b2 = cross(t, n2)
    ct, cn = dot(chord, t), dot(chord, n2)
    psi = 2.0 * math.atan2(cn, ct)
    kT = 2.0 * cn / dot(chord, chord)
    length = psi / kT if kT > 1e-9 else norm(chord)
    t2, n3, b3 = rotate_frame(t, n2, b2, psi)
    return roll, kT, length, (t2, n3, b3)


def arc_point(p, t, n, kT, length):
    psi = kT * length
    if abs(kT) < 1e-12:
        return add(p, mul(length, t))
    return add(p, add(mul(math.sin(psi) / kT, t), mul((1.0 - math.cos(psi)) / kT, n)))


def make_guide(u):
    root = mul(R, u)
    # The guide's point on the tie ring: on the side its root is.
    w = perp(u, TIE_DIR)
    w = normalize(w) if norm(w) > 1e-6 else normalize(perp(DOWN, TIE_DIR))
    target = add(TIE, mul(TIE_RING, w))
    chord = sub(target, root)
    d = perp(chord, u)
    d = normalize(d) if norm(d) > 1e-6 else normalize(perp(DOWN, u))
    pieces = []
    phase = math.pi  # the first quarter wave (Eq. 4: a sin(phase + b s) E_N) moves away from the scalp, E_N pointing into it
    # Piece 0: the hair leaves the scalp at LIFT radians and turns back over LIFT_LENGTH until it
    # runs along the scalp again (tangent to the sphere through its end: solved by bisection).
    # (At most a quarter of the way to the tie, so that hair rooted near it does not overshoot.)
    # Its bend stays gentle next to the wisp's radius (kT0 = (lift + length / R) / length <= 0.2):
    # a shorter piece leaves the scalp less steeply.
    lift_length = min(LIFT_LENGTH, 0.25 * norm(chord))
    lift = min(LIFT, lift_length * (0.2 - 1.0 / R))
    t0 = add(mul(math.cos(lift), d), mul(math.sin(lift), u))
    n0 = add(mul(-math.cos(lift), u), mul(math.sin(lift), d))
    b0 = cross(t0, n0)
    lo, hi = 0.0, lift + 2.0 * lift_length / R
    for _ in range(60):
        psi = 0.5 * (lo + hi)
        end = arc_point(root, t0, n0, psi / lift_length, lift_length)
        if dot(rotate_frame(t0, n0, b0, psi)[0], end) > 0.0:
            lo = psi
        else:
            hi = psi
    kT0 = psi / lift_length
    p1 = arc_point(root, t0, n0, kT0, lift_length)
    f1 = rotate_frame(t0, n0, b0, psi)
    # Piece 1: along the scalp to the tie, the circle from there through the target.
    roll1, kT1, length1, f2 = circle_to(p1, f1[0], f1[1], f1[2], target)
    frame = {"tangent": rv(t0), "normal": rv(n0)}
    if dot(f1[1], sub(target, p1)) < 0.0 and kT1 > MAX_OUTWARD:
        # Roots close under the tie: the hair would lie down and then bend sharply outwards to
        # reach it (tighter than the wisp is wide). Leave the scalp as steeply as needed instead,
        # one circle bending outwards with kT = MAX_OUTWARD (the start tangent at asin(kT |c| / 2)
        # from the chord, in the plane of the chord and the scalp normal).
        chord_angle = math.atan2(dot(chord, u), dot(chord, d))
        lift = max(0.15, chord_angle - math.asin(min(1.0, MAX_OUTWARD * norm(chord) / 2.0)))
        t0 = add(mul(math.cos(lift), d), mul(math.sin(lift), u))
        n0 = normalize(perp(chord, t0))
        b0 = cross(t0, n0)
        roll1, kT1, length1, f2 = circle_to(root, t0, n0, b0, target)
        frame = {"tangent": rv(t0), "normal": rv(n0)}
        pieces.append({"k": [r(kT1), 0.0, 0.0, 0.0], "length": r(length1, 4)})
        phase = 0.0  # E_N points out of the scalp here
    else:
        pieces.append({"k": [r(kT0), 0.0, 0.0, 0.0], "length": r(lift_length, 4)})
        pieces.append({"k": [r(kT1), 0.0, 0.0, 0.0], "length": r(length1, 4), "roll": r(roll1)})
    t1, n1, b1 = f2
    if kT1 * pieces[-1]["length"] > 0.75 * math.pi:
        raise SystemExit("guide rooted at %s: its way to the tie turns by %.2f rad" % (rv(root, 3), kT1 * pieces[-1]["length"]))
    # Piece 2: the turn towards G at the tie.
    roll2, turn, n1r, b1r = roll_towards(t1, n1, b1, G)
    length2 = TURN_RADIUS * turn
    t2, n2, b2 = rotate_frame(t1, n1r, b1r, turn)
    pieces.append({"k": [r(1.0 / TURN_RADIUS), 0.0, 0.0, 0.0], "length": r(length2, 4), "roll": r(roll2)})
    # Piece 3: the fall, the same bend for every guide, from G towards straight down.
    roll3, _, n2r, b2r = roll_towards(t2, n2, b2, DOWN)
    pieces.append({"k": [FALL_KT, 0.0, 0.0, 0.0], "length": FALL_LENGTH, "roll": r(roll3)})
    # Piece 4: the hanging end, with a little curl of its own.
    curl = [rng.uniform(-0.02, 0.02), rng.uniform(-0.01, 0.01), rng.uniform(-0.03, 0.03), rng.uniform(-0.1, 0.1)]
    pieces.append({"k": [r(c, 5) for c in curl], "length": r(rng.uniform(6.0, 9.0), 4), "roll": r(rng.uniform(-0.3, 0.3), 4)})
    return {
        "root": rv(root, 5),
        "frame": frame,
        "pieces": pieces,
        "waviness": {"amplitude": 0.06, "frequency": r(rng.uniform(1.6, 2.4), 4), "phase": r(phase, 4)},
        "wisp": {"count": WISP, "radius": WISP_RADIUS, "fanning": FANNING, "normal": rv(u), "strays": STRAYS},
    }


def main():
    roots, lattice = scalp_roots(GUIDES)
    guides = [make_guide(u) for u in roots]
    with open(sys.argv[1], "w") as f:
        f.write('{"vdbhair": "scene/1", "seed": 11, "step": %g, "integrator": "rk4", "head": {"sphere": [0, 0, 0, %g]},\n'
                ' "guides": [\n' % (STEP, R))
        f.write(",\n".join("  " + json.dumps(g, separators=(",", ":")) for g in guides))
        f.write("\n ]}\n")
    print("wrote %s: %d guides (of a %d-point Fibonacci lattice), %d strands"
          % (sys.argv[1], len(guides), lattice, len(guides) * (WISP + 1)))


if __name__ == "__main__":
    main()
