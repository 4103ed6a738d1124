#!/usr/bin/env python3
"""Every real pose of random parallel mechanisms with ball-jointed legs by
PHCpack, for pkm's forward solution of ball legs (pkm-runtime's
ball_legs) to be checked against: tests/fixtures/ball_legs_phc.jsonl.

The problem is written here from the instance's numbers alone, not from
pkm.  Unknowns: the platform's position p = (p1, p2, p3) and a unit
quaternion q = (w, x, y, z), R(q) the usual rotation matrix.  An instance
is a list of legs ("loci"), each {on, ball, centre, normal, radius2}:

    on = "base":     Y = p + R·ball,  C = centre,        N = normal
    on = "platform": Y = ball,        C = p + R·centre,  N = R·normal

    (Y − C)·(Y − C) − radius2 = 0,   and N·(Y − C) = 0 where normal is not null,
    w² + x² + y² + z² − 1 = 0:

seven equations in the seven unknowns for every instance here (three
circles, or six spheres).  q and −q are one pose: each real pose is
written once, q's component of largest magnitude positive.

Four kinds (lengths about 1), seeded per (kind, id), so the same file
every run and an instance does not depend on how many are made:

  rps  (3-RPS-like) three circles on the base: leg i at θi = 120°·i ± 15°,
       centre a_i = r_a·(cos θi, sin θi, 0), r_a ∈ U(0.8, 1.2) (each leg its
       own), normal (−sin θi', cos θi', 0), θi' = θi ± 20°; the ball on the
       platform b_i = r_b·(cos φi, sin φi, U(−0.1, 0.1)), φi = 120°·i ± 15°,
       r_b ∈ U(0.5, 0.8) (each leg its own).
  prs  (3-PRS-like) as rps, the circle's centre moved up a slide:
       a_i + s·d_i, d_i a unit vector tilted U(−30°, 30°) from vertical in
       the leg's vertical plane, s ∈ U(0.5, 1.5) (each leg its own).
  spr  (3-SPR-like) three circles on the platform: ball a_i on the base (as
       rps's a_i), the circle's centre r_b·(cos φi, sin φi, 0) in the
       platform's frame, its normal the platform circle's tangent ± 20°.
  ups  (general 6-6 Stewart-Gough) six spheres: centres on the base at
       60°·i ± 25°, radius U(0.8, 1.2), z ∈ U(−0.15, 0.15); balls on the
       platform likewise, radius U(0.4, 0.7).

Each instance draws a pose (p = (U(−0.2, 0.2), U(−0.2, 0.2), U(0.6, 1.2)),
R a rotation about a random axis by U(0, 0.4) rad), moves each circle's
centre along its normal onto the pose's plane (in the circle's own body's
frame) and sets every radius2 so that the pose is a root.  Even ids stop
there (at least one real pose: the drawn one, and each is checked to be
found).  Odd ids then multiply each radius (not squared) by U(0.9, 1.1),
except prs, whose odd ids take one link length L ∈ U(0.6, 1.2) for the
three legs (radius2 = L²); these often have fewer real poses or none.
Every number of an instance is rounded to 12 significant digits before
solving: the fixture's decimals are the instance.

PHCpack's blackbox solver (`phc -b`, polyhedral homotopy, Debian package
`phcpack`; `-0`: its fixed seed, so the same file every run) solves an
equivalent system with each pose once (no ±q pair):

  - three circles (rps, prs, spr): leg i's ball on its circle,
    Y_i = C_i + c_i·u_i + s_i·v_i (u_i, v_i of the circle's radius,
    orthogonal to each other and to its normal), c_i² + s_i² = 1, and
    |Y_i − Y_j|² = |P_i − P_j|² for the three pairs, P_i the legs' other
    points (the balls on the platform, or for spr the balls on the base,
    the circles then in the platform's frame).  16 paths, 16 finite
    solutions for a generic instance.  A real (c, s) gives the pose
    that takes the P triangle onto the Y triangle (congruent, so one proper
    rigid motion).
  - six spheres (ups): Study's parameters, q (not normalised) and h, with
    p = 2·vec(h·q̄)/|q|²: the Study quadric q·h = 0, a fixed real
    normalisation (1, 0.31, −0.23, 0.17)·q = 1, leg 1's equation times
    |q|² (a quadric: 4|h|² + 4 Re(h·b̄·q̄) + |q|²(|b|² + |a|² − r²)
    − 4a·vec(h·q̄) − 2a·(q·b·q̄) = 0) and legs 2..6's less leg 1's (no
    |h|²).  84 paths (the mixed volume): 40 finite solutions, the other 44
    diverge and PHCpack calls them failures ("no solution", their h about
    1e4).  A solution with |q|² = 0 would have no pose: it is counted as
    "spurious" in "phc" (the key is absent where there is none).

Each line: {"kind", "id", "legs": [{"on", "ball", "centre", "normal" (null
for a sphere), "radius2"}], "phc": {"paths": PHCpack's paths, "finite":
its finite solutions (regular or singular; each pose once, as above),
"complex": the finite ones that are not a real pose, "failed": its "no
solution" ends (for ups, the diverging paths), "seconds": its wall-clock
time, all its runs}, "real": [{"p", "q", "tag", "cond"}]}.  p and q: the root refined by
Newton's method in 50 digits on the seven equations above (the fixture's
decimals as the numbers, residual below 1e-40, else not written), rounded
to double; tag "r": PHCpack calls it real; "n": PHCpack calls it complex
but each imaginary part is at most 1e-6·max(1, |real part|) and its real
part refines by Newton in 50 digits to a real root of the equations (one
that does not is counted complex); two of PHCpack's roots that refine to
one pose are written once.  Where Newton from PHCpack's point fails or
reaches a pose already found, the point is taken for the middle of two
close roots (a near double root: PHCpack calls both "singular" and gives
the same point twice, and Newton from it reaches one of them or a third
root): Newton starts again from the point moved both ways by 1e-5 to
1e-2 along the Jacobian's near-null direction, and the new roots within
0.05 of the point are written (ups 98: its drawn pose and a second root
3.7e-5 from it, cond 7.9e5 each, missed without this).  cond: the 1-norm condition number of the
equations' 7×7 Jacobian (rows in the order above: per leg the sphere then
the plane, the unit quaternion last; columns p then q) at the root,
4 significant digits.

Where a run of PHCpack ends with fewer finite solutions than 16 (three
circles) or 40 (ups), it is run again (at most three runs in all) with the
legs' order turned by one more (another system, so other paths with the same
seed); the first run with all of them is written, else the one with the
most (then the most real poses), and "phc" has "tries" (the runs made) and
"chosen" (which one is written; its numbers, the seconds those of all the
runs).  (A lost path can be a real pose: spr 71's first run ends with 15
finite and 3 real poses, its second with 16 and 4.)

Instances: 1000 of each kind (ids 0..999): about 0.25 s each for the
three-circle kinds, 4 s for ups (3.9 s of it PHCpack's), about 75
minutes in all on one core; the fixture is about 7.5 MB (a line, nearly
always 4-8 real poses, is about 2 kB).  Instances are seeded by their id,
so `--from N` makes ids N.. alone, to be added to the fixture (its rows
by kind, then id).

    python3 tests/phc/ball_legs_phc.py --make   # rewrite the fixture (needs `phc`)
    python3 tests/phc/ball_legs_phc.py --make --count 6 --out /tmp/t.jsonl   # a trial
    python3 tests/phc/ball_legs_phc.py --make --kinds ups --from 300 --out /tmp/ups.jsonl   # ids 300..999
    python3 tests/phc/ball_legs_phc.py --dietmaier tests/fixtures/dietmaier_40_phc.txt   # PHCpack's input for the coupled bench
"""

import json
import math
import os
import random
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
FIXTURE = ROOT / "tests" / "fixtures" / "ball_legs_phc.jsonl"
MPMATH = "mpmath==1.3.0"


sys.path.insert(0, str(ROOT / "tests"))
from check_venv import enter  # noqa: E402

enter("phc-venv", [MPMATH])

from mpmath import mp, mpf, matrix, lu_solve, inverse, mnorm  # noqa: E402
from polynomials import padd, pconst, pdot, pmul, pscale, pvar, text  # noqa: E402

KINDS = ("rps", "prs", "spr", "ups")
PER_KIND = {"rps": 1000, "prs": 1000, "spr": 1000, "ups": 1000}
SEED = 20261129
DPS = 50

# ---------------------------------------------------------------- geometry (double)


def rot(q):
    w, x, y, z = q
    return [
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ]


def mv(m, v):
    return [sum(m[i][k] * v[k] for k in range(3)) for i in range(3)]


def mtv(m, v):
    return [sum(m[k][i] * v[k] for k in range(3)) for i in range(3)]


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def vadd(a, b, k=1.0):
    return [x + k * y for x, y in zip(a, b)]


def r12(v):
    """`v` rounded to 12 significant digits (the fixture's number is this)."""
    return float(f"{v:.12g}")


def polar(r, deg, z=0.0):
    t = math.radians(deg)
    return [r * math.cos(t), r * math.sin(t), z]


def random_pose(rng):
    p = [rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.2), rng.uniform(0.6, 1.2)]
    axis = [rng.gauss(0.0, 1.0) for _ in range(3)]
    n = math.sqrt(dot(axis, axis))
    angle = rng.uniform(0.0, 0.4)
    s = math.sin(angle / 2)
    q = [math.cos(angle / 2)] + [s * a / n for a in axis]
    return p, q


def instance(kind, ident):
    """The legs of instance `ident` of `kind` (numbers rounded to 12
    significant digits) and the pose drawn for it."""
    rng = random.Random(f"{SEED}-{kind}-{ident}")
    legs = []
    if kind == "ups":
        for i in range(6):
            a = polar(rng.uniform(0.8, 1.2), 60 * i + rng.uniform(-25, 25), rng.uniform(-0.15, 0.15))
            b = polar(rng.uniform(0.4, 0.7), 60 * i + rng.uniform(-25, 25), rng.uniform(-0.15, 0.15))
            legs.append({"on": "base", "ball": b, "centre": a, "normal": None})
    else:
        link = rng.uniform(0.6, 1.2)  # prs: the three legs' link length
        for i in range(3):
            th = 120 * i + rng.uniform(-15, 15)
            a = polar(rng.uniform(0.8, 1.2), th)
            th_u = th + rng.uniform(-20, 20)
            u = [-math.sin(math.radians(th_u)), math.cos(math.radians(th_u)), 0.0]
            phi = 120 * i + rng.uniform(-15, 15)
            rb = rng.uniform(0.5, 0.8)
            if kind == "rps":
                b = polar(rb, phi, rb * rng.uniform(-0.1, 0.1))
                legs.append({"on": "base", "ball": b, "centre": a, "normal": u})
            elif kind == "prs":
                b = polar(rb, phi, rb * rng.uniform(-0.1, 0.1))
                tilt = math.radians(rng.uniform(-30, 30))
                t = math.radians(th)
                d = [math.sin(tilt) * math.cos(t), math.sin(tilt) * math.sin(t), math.cos(tilt)]
                c = vadd(a, d, rng.uniform(0.5, 1.5))
                legs.append({"on": "base", "ball": b, "centre": c, "normal": u})
            else:  # spr
                c = polar(rb, phi)
                ph_u = phi + rng.uniform(-20, 20)
                n = [-math.sin(math.radians(ph_u)), math.cos(math.radians(ph_u)), 0.0]
                legs.append({"on": "platform", "ball": a, "centre": c, "normal": n})
    p, q = random_pose(rng)
    R = rot(q)
    for leg in legs:
        b, c, n = leg["ball"], leg["centre"], leg["normal"]
        if leg["on"] == "base":
            y = vadd(p, mv(R, b))
            if n is not None:
                c = vadd(c, n, dot(n, vadd(y, c, -1)) / dot(n, n))
            d = vadd(y, c, -1)
        else:
            y_body = mtv(R, vadd(b, p, -1))  # the ball in the platform's frame
            c = vadd(c, n, dot(n, vadd(y_body, c, -1)) / dot(n, n))
            d = vadd(y_body, c, -1)
        leg["centre"] = c
        leg["radius2"] = dot(d, d)
    if ident % 2 == 1:
        for leg in legs:
            if kind == "prs":
                leg["radius2"] = link * link
            else:
                leg["radius2"] = (math.sqrt(leg["radius2"]) * rng.uniform(0.9, 1.1)) ** 2
    for leg in legs:
        for key in ("ball", "centre", "normal"):
            if leg[key] is not None:
                leg[key] = [r12(v) for v in leg[key]]
        leg["radius2"] = r12(leg["radius2"])
    return legs, (p, q)


# ---------------------------------------------------------------- polynomials for PHCpack
# polynomials.py: {exponent tuple: coefficient}.


# ---------------------------------------------------------------- three circles: 16 paths
# Leg i's ball on its circle, Y_i = C_i + c_i·u_i + s_i·v_i (u_i, v_i
# orthogonal, of the circle's radius, both orthogonal to its normal), in
# the base's frame (circles on the base) or the platform's (circles on the
# platform); c_i² + s_i² = 1 and the three distances |Y_i − Y_j| those of
# the partner points (the platform's balls, or the base's balls).

CIRCLE_NAMES = ("c1", "s1", "c2", "s2", "c3", "s3")


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def unit(v):
    n = math.sqrt(dot(v, v))
    return [x / n for x in v]


def circles(legs):
    out = []
    for leg in legs:
        n = unit(leg["normal"])
        r = math.sqrt(leg["radius2"])
        e1 = unit(cross(n, [1.0, 0.0, 0.0] if abs(n[0]) < 0.6 else [0.0, 1.0, 0.0]))
        e2 = cross(n, e1)
        out.append((leg["centre"], [r * x for x in e1], [r * x for x in e2]))
    return out


def circle_system(legs):
    nv = 6
    V = [pvar(i, nv) for i in range(nv)]
    cir = circles(legs)
    eqs = [padd(pmul(V[2 * i], V[2 * i]), pmul(V[2 * i + 1], V[2 * i + 1]), pconst(-1.0, nv)) for i in range(3)]
    for i, j in ((0, 1), (1, 2), (0, 2)):
        (ci, ui, vi), (cj, uj, vj) = cir[i], cir[j]
        d = vadd(ci, cj, -1)
        bb = vadd(legs[i]["ball"], legs[j]["ball"], -1)
        yi = ((V[2 * i], ui), (V[2 * i + 1], vi))
        yj = ((V[2 * j], uj), (V[2 * j + 1], vj))
        terms = [pconst(dot(d, d) + dot(ui, ui) + dot(uj, uj) - dot(bb, bb), nv)]
        terms += [pscale(m, 2 * dot(d, w)) for m, w in yi]
        terms += [pscale(m, -2 * dot(d, w)) for m, w in yj]
        terms += [pscale(pmul(m1, m2), -2 * dot(w1, w2)) for m1, w1 in yi for m2, w2 in yj]
        eqs.append(padd(*terms))
    return eqs


def rot_to_quat(R):
    """The unit quaternion of the rotation matrix R (Shepperd)."""
    t = R[0][0] + R[1][1] + R[2][2]
    cands = [1 + t, 1 + 2 * R[0][0] - t, 1 + 2 * R[1][1] - t, 1 + 2 * R[2][2] - t]
    k = max(range(4), key=lambda i: cands[i])
    s = math.sqrt(max(cands[k], 1e-300)) * 2  # 4·|q_k|
    if k == 0:
        q = [s / 4, (R[2][1] - R[1][2]) / s, (R[0][2] - R[2][0]) / s, (R[1][0] - R[0][1]) / s]
    elif k == 1:
        q = [(R[2][1] - R[1][2]) / s, s / 4, (R[0][1] + R[1][0]) / s, (R[0][2] + R[2][0]) / s]
    elif k == 2:
        q = [(R[0][2] - R[2][0]) / s, (R[0][1] + R[1][0]) / s, s / 4, (R[1][2] + R[2][1]) / s]
    else:
        q = [(R[1][0] - R[0][1]) / s, (R[0][2] + R[2][0]) / s, (R[1][2] + R[2][1]) / s, s / 4]
    return q


def frame(p1, p2, p3):
    e1 = unit(vadd(p2, p1, -1))
    e3 = unit(cross(vadd(p2, p1, -1), vadd(p3, p1, -1)))
    e2 = cross(e3, e1)
    return [e1, e2, e3]  # rows


def pose_from_points(body, world):
    """The rigid motion (p, q) taking the three `body` points nearest to `world`."""
    fb, fw = frame(*body), frame(*world)
    R = [[sum(fw[k][i] * fb[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    p = vadd(world[0], mv(R, body[0]), -1)
    return p, rot_to_quat(R)


def circle_pose(legs, x):
    """The pose of the circles' real point x = (c1, s1, c2, s2, c3, s3)."""
    ys = [vadd(vadd(c, u, x[2 * i]), v, x[2 * i + 1]) for i, (c, u, v) in enumerate(circles(legs))]
    balls = [leg["ball"] for leg in legs]
    if legs[0]["on"] == "base":
        return pose_from_points(balls, ys)
    return pose_from_points(ys, balls)


# ---------------------------------------------------------------- Stewart-Gough: Study's parameters, 84 paths
# q (4, a quaternion not normalised) and h (4): p = 2·vec(h·q̄)/|q|²,
# R = R(q/|q|); the Study quadric q·h = 0, the normalisation L·q = 1
# (L real and fixed), leg 1's sphere times |q|²,
#   4|h|² + 4·Re(h·b̄·q̄) + |q|²(|b|² + |a|² − r²) − 2a·(2·vec(h·q̄)) − 2a·(q·b·q̄) = 0,
# and legs 2..6's spheres less leg 1's (no |h|²).  Each pose once.

STUDY_NAMES = ("q0", "q1", "q2", "q3", "h0", "h1", "h2", "h3")
NORMALISATION = (1.0, 0.31, -0.23, 0.17)


def qmul(a, b):
    a0, av, b0, bv = a[0], a[1:], b[0], b[1:]
    s = padd(pmul(a0, b0), *(pscale(pmul(x, y), -1.0) for x, y in zip(av, bv)))
    cr = [
        padd(pmul(av[1], bv[2]), pscale(pmul(av[2], bv[1]), -1.0)),
        padd(pmul(av[2], bv[0]), pscale(pmul(av[0], bv[2]), -1.0)),
        padd(pmul(av[0], bv[1]), pscale(pmul(av[1], bv[0]), -1.0)),
    ]
    return [s] + [padd(pmul(a0, bv[i]), pmul(b0, av[i]), cr[i]) for i in range(3)]


def study_system(legs):
    nv = 8
    Q = [pvar(i, nv) for i in range(4)]
    H = [pvar(4 + i, nv) for i in range(4)]
    Qc = [Q[0]] + [pscale(x, -1.0) for x in Q[1:]]
    pure = lambda v: [{}] + [pconst(x, nv) for x in v]  # noqa: E731
    delta = padd(*(pmul(x, x) for x in Q))
    hh = padd(*(pmul(x, x) for x in H))
    P = [pscale(x, 2.0) for x in qmul(H, Qc)[1:]]
    spheres = []
    for leg in legs:
        b, a = leg["ball"], leg["centre"]
        Rb = qmul(qmul(Q, pure(b)), Qc)[1:]
        hbq = qmul(qmul(H, pure([-x for x in b])), Qc)[0]
        spheres.append(
            padd(
                pscale(hh, 4.0),
                pscale(hbq, 4.0),
                pscale(delta, dot(b, b) + dot(a, a) - leg["radius2"]),
                pscale(pdot(a, P), -2.0),
                pscale(pdot(a, Rb), -2.0),
            )
        )
    eqs = [padd(*(pmul(x, y) for x, y in zip(Q, H))), spheres[0]]
    for s in spheres[1:]:
        eqs.append(padd(s, pscale(spheres[0], -1.0)))  # |h|²'s coefficient 0.0: not written
    eqs.append(padd(pdot(NORMALISATION, Q), pconst(-1.0, nv)))
    return eqs


def study_pose(x):
    q, h = x[:4], x[4:]
    delta = dot(q, q)
    hq = [h[0] * q[0] + dot(h[1:], q[1:])] + [
        -h[0] * q[i] + q[0] * h[i] - (cross(h[1:], q[1:])[i - 1]) for i in range(1, 4)
    ]  # h·q̄
    p = [2 * v / delta for v in hq[1:]]
    n = math.sqrt(delta)
    return p, [v / n for v in q]


# ---------------------------------------------------------------- PHCpack


def phc(eqs, names):
    """PHCpack's blackbox on `eqs`: (paths, [(values, tag)], failed, seconds)."""
    with tempfile.TemporaryDirectory() as d:
        inp, out = os.path.join(d, "in"), os.path.join(d, "out")
        with open(inp, "w") as f:
            f.write(f"{len(eqs)} {len(names)}\n" + "\n".join(text(e, names) for e in eqs) + "\n")
        t0 = time.perf_counter()
        subprocess.run(["phc", "-0", "-b", inp, out], check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        seconds = time.perf_counter() - t0
        with open(out) as f:
            lines = f.read().split("THE SOLUTIONS :")[-1].splitlines()
    paths = None
    sols, cur, failed = [], {}, 0
    for line in lines:
        parts = line.split()
        if paths is None and len(parts) == 2 and parts[0].isdigit():
            paths = int(parts[0])
        if len(parts) == 4 and parts[0] in names and parts[1] == ":":
            cur[parts[0]] = complex(float(parts[2]), float(parts[3]))
        elif line.startswith("== err"):
            # The path's end: "real regular", "complex regular", "... singular",
            # "at infinity", "no solution" (a failed path).
            tag = line.rstrip("= ").rsplit("=", 1)[-1].strip()
            if tag.endswith("regular") or tag.endswith("singular"):
                sols.append(([cur[n] for n in names], tag))
            elif tag == "no solution":
                failed += 1
            cur = {}
    return paths, sols, failed, seconds


# ---------------------------------------------------------------- the equations, 50 digits


def mrot(q):
    w, x, y, z = q
    R = [
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ]
    dR = [
        [[0, -2 * z, 2 * y], [2 * z, 0, -2 * x], [-2 * y, 2 * x, 0]],
        [[0, 2 * y, 2 * z], [2 * y, -4 * x, -2 * w], [2 * z, 2 * w, -4 * x]],
        [[-4 * y, 2 * x, 2 * w], [2 * x, 0, 2 * z], [-2 * w, 2 * z, -4 * y]],
        [[-4 * z, -2 * w, 2 * x], [2 * w, -4 * z, 2 * y], [2 * x, 2 * y, 0]],
    ]
    return R, dR


def mlegs(legs):
    """The legs' numbers as the decimals the fixture writes, in mpf."""
    conv = lambda v: None if v is None else [mpf(repr(x)) for x in v]  # noqa: E731
    return [(leg["on"], conv(leg["ball"]), conv(leg["centre"]), conv(leg["normal"]), mpf(repr(leg["radius2"]))) for leg in legs]


def equations(ml, v, jacobian=True):
    """The 7 equations at v = (p1, p2, p3, w, x, y, z), and their Jacobian."""
    p, q = v[:3], v[3:]
    R, dR = mrot(q)
    mvm = lambda m, u: [sum(m[i][k] * u[k] for k in range(3)) for i in range(3)]  # noqa: E731
    f, J = [], []
    for on, ball, centre, normal, r2 in ml:
        if on == "base":
            Rb = mvm(R, ball)
            D = [p[i] + Rb[i] - centre[i] for i in range(3)]
            dD = [[1 if i == k else 0 for i in range(3)] for k in range(3)] + [mvm(m, ball) for m in dR]
            N, dN = normal, None
        else:
            Rc = mvm(R, centre)
            D = [ball[i] - p[i] - Rc[i] for i in range(3)]
            dD = [[-1 if i == k else 0 for i in range(3)] for k in range(3)] + [[-x for x in mvm(m, centre)] for m in dR]
            if normal is not None:
                N = mvm(R, normal)
                dN = [[0, 0, 0]] * 3 + [mvm(m, normal) for m in dR]
            else:
                N = None
        f.append(sum(d * d for d in D) - r2)
        J.append([2 * sum(D[i] * col[i] for i in range(3)) for col in dD])
        if N is not None:
            f.append(sum(N[i] * D[i] for i in range(3)))
            row = [sum(N[i] * dD[k][i] for i in range(3)) for k in range(7)]
            if dN is not None:
                row = [row[k] + sum(dN[k][i] * D[i] for i in range(3)) for k in range(7)]
            J.append(row)
    f.append(sum(x * x for x in q) - 1)
    J.append([0, 0, 0] + [2 * x for x in q])
    return f, J


def refine(ml, p, q):
    """Newton's method in 50 digits from the double pose (p, q): the real
    root, its residual and the Jacobian's 1-norm condition number, or None
    where it does not converge."""
    v = [mpf(x) for x in list(p) + list(q)]
    tiny = mpf(10) ** (-DPS + 3)
    for it in range(40):
        f, J = equations(ml, v)
        try:
            d = lu_solve(matrix(J), matrix(f))
        except ZeroDivisionError:
            return None
        v = [a - b for a, b in zip(v, d)]
        step = max(abs(x) for x in d)
        if step < tiny:
            break
        if step > 10 or max(abs(x) for x in v) > 1e6:
            return None
    f, J = equations(ml, v)
    res = max(abs(x) for x in f)
    if res > mpf(10) ** -40:
        return None
    Jm = matrix(J)
    try:
        cond = mnorm(Jm, 1) * mnorm(inverse(Jm), 1)
    except ZeroDivisionError:
        cond = mpf("inf")
    q = v[3:]
    k = max(range(4), key=lambda i: abs(q[i]))
    if q[k] < 0:
        v = v[:3] + [-x for x in q]
    return v, res, cond


def known(real, v):
    return any(max(abs(a - b) for a, b in zip(v, w[0])) < mpf(10) ** -30 for w in real)


def split(ml, real, x0):
    """The roots not yet in `real` that Newton reaches from x0 moved both
    ways along the Jacobian's near-null direction (inverse iteration), by
    1e-5 to 1e-2."""
    v0 = [mpf(t) for t in x0]
    _, J = equations(ml, v0)
    J = matrix(J)
    d = matrix([mpf(1), mpf("0.3"), mpf("-0.7"), mpf("0.2"), mpf("0.5"), mpf("-0.4"), mpf("0.9")])
    try:
        for _ in range(4):
            d = lu_solve(J, d)
            d = d / mnorm(d, 1)
    except ZeroDivisionError:
        return []
    out = []
    for step in (1e-5, 3e-5, 1e-4, 3e-4, 1e-3, 3e-3, 1e-2):
        for sign in (1, -1):
            start = [v0[i] + sign * step * d[i] for i in range(7)]
            r = refine(ml, start[:3], start[3:])
            if r is None or known(real, r[0]) or known(out, r[0]):
                continue
            if max(abs(a - b) for a, b in zip(r[0], v0)) < 0.05 or max(abs(a + b) for a, b in zip(r[0][3:], v0[3:])) < 0.05 and max(abs(a - b) for a, b in zip(r[0][:3], v0[:3])) < 0.05:
                out.append(r)
    return out


# ---------------------------------------------------------------- one instance


def near_real(x):
    return all(abs(z.imag) <= 1e-6 * max(1.0, abs(z.real)) for z in x)


TRIES = 3  # PHCpack's runs at most, the legs' order turned by one each time
EXPECTED = {"rps": 16, "prs": 16, "spr": 16, "ups": 40}


def one_try(kind, legs, ml, stats):
    """PHCpack on the instance with the legs in this order: (its numbers,
    the real roots refined, how many of its solutions refined to one)."""
    if kind == "ups":
        eqs, names, to_pose = study_system(legs), STUDY_NAMES, study_pose
    else:
        eqs, names, to_pose = circle_system(legs), CIRCLE_NAMES, lambda x: circle_pose(legs, x)
    paths, sols, failed, seconds = phc(eqs, names)
    real, finite, spurious, to_real = [], 0, 0, 0
    for x, tag in sols:
        if kind == "ups" and abs(sum(z * z for z in x[:4])) < 1e-8:
            spurious += 1  # |q|² = 0: no pose
            continue
        finite += 1
        if not (tag.startswith("real") or near_real(x)):
            continue
        p, q = to_pose([z.real for z in x])
        found = []
        r = refine(ml, p, q)
        if r is not None and not known(real, r[0]):
            found = [r]
        else:
            # No root, or one already found: PHCpack's point is likely the
            # middle of two close roots (a near double root, which it calls
            # singular, and Newton from the middle reaches only one of them).
            found = split(ml, real, list(p) + list(q))
            stats["split" if found else ("duplicate" if r is not None else "no_newton")] += 1
        if found or r is not None:
            to_real += 1  # PHCpack's solution is a real pose
        for v, res, cond in found:
            stats["max_residual"] = max(stats["max_residual"], float(res))
            real.append((v, "r" if tag.startswith("real") else "n", cond))
    numbers = {"paths": paths, "finite": finite, "complex": finite - to_real, "failed": failed, "seconds": seconds}
    if spurious:
        numbers["spurious"] = spurious
    return numbers, real


def solve(kind, ident, stats):
    legs, (p0, q0) = instance(kind, ident)
    ml = mlegs(legs)
    best, seconds = None, 0.0
    for k in range(TRIES):
        numbers, real = one_try(kind, legs[k:] + legs[:k], ml, stats)
        seconds += numbers["seconds"]
        if best is None or (numbers["finite"], len(real)) > (best[0]["finite"], len(best[1])):
            best = (numbers, real, k + 1)
        if numbers["finite"] >= EXPECTED[kind]:
            break
    numbers, real, chosen = best
    numbers["seconds"] = round(seconds, 3)
    if k > 0:
        numbers["tries"] = k + 1
        numbers["chosen"] = chosen
        stats["retried"].append((ident, k + 1, chosen, numbers["finite"]))
    if ident % 2 == 0:
        k = max(range(4), key=lambda i: abs(q0[i]))
        qs = [x if q0[k] > 0 else -x for x in q0]
        target = list(p0) + qs
        if not any(max(abs(float(a) - b) for a, b in zip(v, target)) < 1e-6 for v, _, _ in real):
            stats["posed_missing"].append(ident)
            print(f"{kind} {ident}: the posed root is not among the real roots", file=sys.stderr)
    row = {
        "kind": kind,
        "id": ident,
        "legs": [{"on": l["on"], "ball": l["ball"], "centre": l["centre"], "normal": l["normal"], "radius2": l["radius2"]} for l in legs],
        "phc": numbers,
        "real": [
            {"p": [float(x) for x in v[:3]], "q": [float(x) for x in v[3:]], "tag": t, "cond": float(f"{float(c):.4g}")}
            for v, t, c in real
        ],
    }
    return row, seconds


# ---------------------------------------------------------------- the fixture


def dietmaier_input(out):
    """PHCpack's input for Dietmaier's 6-6 platform
    (tests/fixtures/dietmaier_40.txt: |R·plat_i + p − base_i| = L_i) in the
    Study parameters above, for `cargo bench --bench coupled` to time
    PHCpack on: its 40 real roots are the 40 real poses."""
    pts = {"base": {}, "plat": {}, "len": {}}
    for line in (ROOT / "tests" / "fixtures" / "dietmaier_40.txt").read_text().splitlines():
        f = line.split()
        if f and f[0] in pts:
            pts[f[0]][int(f[1])] = [float(v) for v in f[2:]]
    legs = [
        {"on": "base", "ball": pts["plat"][i], "centre": pts["base"][i], "normal": None, "radius2": pts["len"][i][0] ** 2}
        for i in range(1, 7)
    ]
    eqs = study_system(legs)
    Path(out).write_text(f"{len(eqs)} {len(STUDY_NAMES)}\n" + "\n".join(text(e, STUDY_NAMES) for e in eqs) + "\n")


def main():
    if "--dietmaier" in sys.argv:
        dietmaier_input(sys.argv[sys.argv.index("--dietmaier") + 1])
        return
    if "--make" not in sys.argv:
        print(__doc__)
        return
    mp.dps = DPS
    args = sys.argv[1:]
    counts = dict(PER_KIND)
    if "--count" in args:  # a trial: N instances of each kind
        counts = {k: min(v, int(args[args.index("--count") + 1])) for k, v in counts.items()}
    kinds = args[args.index("--kinds") + 1].split(",") if "--kinds" in args else KINDS
    first = int(args[args.index("--from") + 1]) if "--from" in args else 0
    out = Path(args[args.index("--out") + 1]) if "--out" in args else FIXTURE
    part = out.with_suffix(out.suffix + ".part")
    with open(part, "w") as f:
        for kind in kinds:
            stats = {"no_newton": 0, "duplicate": 0, "split": 0, "max_residual": 0.0, "posed_missing": [], "retried": []}
            reals, finites, failed, tags, phc_s = Counter(), Counter(), 0, Counter(), 0.0
            t0 = time.perf_counter()
            for ident in range(first, counts[kind]):
                row, seconds = solve(kind, ident, stats)
                f.write(json.dumps(row, separators=(",", ":")) + "\n")
                f.flush()
                reals[len(row["real"])] += 1
                finites[row["phc"]["finite"]] += 1
                failed += row["phc"]["failed"]
                tags.update(r["tag"] for r in row["real"])
                phc_s += seconds
            total = time.perf_counter() - t0
            n = max(1, counts[kind] - first)
            print(
                f"{kind}: {n} instances, {total / n:.3f} s each ({phc_s / n:.3f} s PHCpack); "
                f"real roots {dict(sorted(reals.items()))}; finite {dict(sorted(finites.items()))}; "
                f"failed paths {failed}; tags {dict(tags)}; {stats}",
                file=sys.stderr,
                flush=True,
            )
    os.replace(part, out)


if __name__ == "__main__":
    main()
