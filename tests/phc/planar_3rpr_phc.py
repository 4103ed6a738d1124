#!/usr/bin/env python3
"""Every assembly of two planar 3-RPRs and a planar 3-RRR by PHCpack, for pkm's certified
forward solution to be checked against (tests/testsuite/fk_numeric.rs,
`planar_3rpr_against_phcpack`).

The forward problem is written here from the mechanisms' dimensions alone,
not from pkm: the platform's pose (x, y) and (c, s) = (cos φ, sin φ),

    c² + s² − 1 = 0,
    |(x, y) + R(φ)·b_i − a_i|² − ρ_i² = 0,  i = 1, 2, 3,

a_i the base pivots, b_i the platform pins in the platform's frame, ρ_i
the legs' lengths (the slides). A 3-RRR is the same problem once its
inputs are given: a_i is then the elbow, l1 from the base pivot at the
input angle q_i, (A_i + l1·(cos q_i, sin q_i)), and ρ_i the distal link's
length l2. PHCpack's blackbox solver (`phc -b`,
polyhedral homotopy, Debian package `phcpack`; `-0`: its fixed seed, so
the same file every run) finds every complex root;
the real ones (PHCpack's own verdict, "real regular" or "real singular")
are written, one input a row: the mechanism, its inputs (ρ1, ρ2, ρ3, or q1, q2, q3), PHCpack's count
of finite solutions (regular or singular; the rest of its 16 paths go to
infinity or fail), its count of failed paths, then each real assembly's
x, y, φ (φ in (−π, π]; PHCpack's root refined by Newton's method in 60
digits on the same equations, the inputs and dimensions as the binary
numbers they are, then rounded to double), a tag: `r` where PHCpack calls it real, `n`
where PHCpack calls it complex but every imaginary part is below 1e-6
(a root its path reached poorly: at one input of the 600 such a root
stands alone, with err 3e-4, though complex roots of real polynomials come
in conjugate pairs, and bisection on the residual finds it real), and the
condition number of the equations' Jacobian there (lengths scaled by the
size, 250 mm; 1-norm). A 3-RPR has at most six assemblies (a sextic).

The inputs: half from random platform poses (the legs' lengths that reach
them, so at least one real assembly), half random lengths in the range the
poses give (often none). Seeded: the same file every run.

    python3 tests/phc/planar_3rpr_phc.py --make   # rewrite the fixture (needs `phc`)
"""

import math
import os
import random
import subprocess
import sys
import tempfile

from polynomials import padd, pconst, pmul, pscale, pvar, text

HERE = os.path.dirname(os.path.abspath(__file__))
FIXTURE = os.path.join(HERE, "..", "fixtures", "planar_3rpr_phc.csv")

# examples/mechanisms/planar_3rpr.pkm: r = 250, p = 60, 120° apart.
def _on_circle(r, degrees):
    return (r * math.cos(math.radians(degrees)), r * math.sin(math.radians(degrees)))


MECHANISMS = {
    "planar_3rpr": {
        "a": [_on_circle(250, 210), _on_circle(250, 330), (0.0, 250.0)],
        "b": [_on_circle(60, 210), _on_circle(60, 330), (0.0, 60.0)],
        "poses": lambda rng: (rng.uniform(-80, 80), rng.uniform(-80, 80), rng.uniform(-1.0, 1.0)),
    },
    # examples/mechanisms/planar_3rpr_six.pkm.
    "planar_3rpr_six": {
        "a": [(0.0, 0.0), (159.1, 0.0), (0.0, 100.0)],
        "b": [(0.0, 0.0), (170.4, 0.0), (208.4 * math.cos(0.7), 208.4 * math.sin(0.7))],
        "poses": lambda rng: (rng.uniform(-150, 150), rng.uniform(-150, 150), rng.uniform(-math.pi, math.pi)),
    },
    # (Last, so that the 3-RPRs' inputs stay those of the first fixture.)
    # examples/mechanisms/planar_3rrr.pkm: r = 250, p = 60, l1 = 160, l2 = 140.
    "planar_3rrr": {
        "a": [_on_circle(250, 210), _on_circle(250, 330), (0.0, 250.0)],
        "b": [_on_circle(60, 210), _on_circle(60, 330), (0.0, 60.0)],
        "arms": (160.0, 140.0),
        "poses": lambda rng: (rng.uniform(-60, 60), rng.uniform(-60, 60), rng.uniform(-0.8, 0.8)),
    },
}

VARS = ("x", "y", "c", "s")


def system(m, rho):
    x, y, c, s = (pvar(i, 4) for i in range(4))
    eqs = [padd(pmul(c, c), pmul(s, s), pconst(-1.0, 4))]
    for (ax, ay), (bx, by), r in zip(m["a"], m["b"], rho):
        # (x + c·bx − s·by − ax, y + s·bx + c·by − ay)
        u = padd(x, pscale(c, bx), pscale(s, -by), pconst(-ax, 4))
        v = padd(y, pscale(s, bx), pscale(c, by), pconst(-ay, 4))
        eqs.append(padd(pmul(u, u), pmul(v, v), pconst(-r * r, 4)))
    return f"{len(eqs)}\n" + "\n".join(text(e, VARS) for e in eqs) + "\n"


def inputs_at(m, pins, rng):
    """The inputs that put the platform's pins at `pins`: the legs'
    lengths, or for a 3-RRR the base angles, each leg's elbow one of its
    two at random (`None` where a pin is out of an arm's reach)."""
    if "arms" not in m:
        return [math.hypot(px - ax, py - ay) for (ax, ay), (px, py) in zip(m["a"], pins)]
    l1, l2 = m["arms"]
    q = []
    for (ax, ay), (px, py) in zip(m["a"], pins):
        dx, dy = px - ax, py - ay
        d = math.hypot(dx, dy)
        cos_a = (l1 * l1 + d * d - l2 * l2) / (2 * l1 * d)
        if not -1.0 < cos_a < 1.0:
            return None
        q.append(math.atan2(dy, dx) + rng.choice((-1, 1)) * math.acos(cos_a))
    return q


def problem(m, given):
    """The 3-RPR problem (mechanism, lengths) the inputs pose."""
    if "arms" not in m:
        return m, given
    l1, l2 = m["arms"]
    elbows = [(ax + l1 * math.cos(q), ay + l1 * math.sin(q)) for (ax, ay), q in zip(m["a"], given)]
    return {"a": elbows, "b": m["b"], "base": m["a"], "arms": m["arms"], "q": given}, [l2, l2, l2]


SIZE = 250.0  # the mechanisms' size (mm): lengths are scaled by it for the condition number


def refined(m, rho, x0):
    """PHCpack's real root `x0` (x, y, c, s) refined by Newton's method in
    60-digit arithmetic on the same equations (the dimensions and inputs
    as the binary numbers they are), and the condition number of the
    Jacobian there, lengths scaled by SIZE (1-norm)."""
    from mpmath import mp, mpf, matrix, lu_solve, inverse, mnorm, cos, sin

    mp.dps = 60
    a = [(mpf(ax), mpf(ay)) for ax, ay in m["a"]]
    b = [(mpf(bx), mpf(by)) for bx, by in m["b"]]
    r = [mpf(v) for v in rho]
    if "arms" in m:
        l1, l2 = (mpf(v) for v in m["arms"])
        base = [(mpf(ax), mpf(ay)) for ax, ay in m["base"]]
        a = [(ax + l1 * cos(mpf(q)), ay + l1 * sin(mpf(q))) for (ax, ay), q in zip(base, m["q"])]
        r = [l2, l2, l2]

    def f(v):
        x, y, c, s = v
        out = [c * c + s * s - 1]
        for (ax, ay), (bx, by), ri in zip(a, b, r):
            u, w = x + c * bx - s * by - ax, y + s * bx + c * by - ay
            out.append(u * u + w * w - ri * ri)
        return out

    def jac(v):
        x, y, c, s = v
        rows = [[0, 0, 2 * c, 2 * s]]
        for (ax, ay), (bx, by), ri in zip(a, b, r):
            u, w = x + c * bx - s * by - ax, y + s * bx + c * by - ay
            rows.append([2 * u, 2 * w, 2 * (u * bx + w * by), 2 * (-u * by + w * bx)])
        return matrix(rows)

    v = [mpf(t) for t in x0]
    for _ in range(30):
        d = lu_solve(jac(v), matrix(f(v)))
        v = [vi - di for vi, di in zip(v, d)]
    L = mpf(SIZE)
    j = jac(v)
    js = matrix(4, 4)
    for i in range(4):
        for k in range(4):
            js[i, k] = j[i, k] * (L if k < 2 else 1) / (1 if i == 0 else L * L)
    cond = mnorm(js, 1) * mnorm(inverse(js), 1)
    x, y, c, s = v
    return float(x), float(y), float(mp.atan2(s, c)), float(cond)


def solve(m, rho):
    """PHCpack's finite solutions: (count, the real ones as (x, y, φ))."""
    with tempfile.TemporaryDirectory() as d:
        inp, out = os.path.join(d, "in"), os.path.join(d, "out")
        with open(inp, "w") as f:
            f.write(system(m, rho))
        subprocess.run(["phc", "-0", "-b", inp, out], check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        with open(out) as f:
            lines = f.read().split("THE SOLUTIONS :")[-1].splitlines()
    sols, cur, failed = [], {}, 0
    for line in lines:
        parts = line.split()
        if len(parts) == 4 and parts[0] in VARS and parts[1] == ":":
            cur[parts[0]] = (float(parts[2]), float(parts[3]))
        elif line.startswith("== err"):
            # The path's end: "real regular", "complex regular", "... singular",
            # "at infinity", "no solution" (a failed path).
            tag = line.rstrip("= ").rsplit("=", 1)[-1].strip()
            if tag.endswith("regular") or tag.endswith("singular"):
                sols.append((cur, tag))
            elif tag == "no solution":
                failed += 1
            cur = {}
    real = []
    for sol, tag in sols:
        near = all(abs(im) <= 1e-6 * max(1.0, abs(re)) for re, im in sol.values())
        if tag.startswith("real") or near:
            x, y, phi, cond = refined(m, rho, [sol[n][0] for n in VARS])
            real.append((x, y, phi, "r" if tag.startswith("real") else "n", cond))
    return len(sols), failed, real


def main():
    if "--make" not in sys.argv:
        print(__doc__)
        return
    rng = random.Random(20261129)
    rows = ["mechanism,input1,input2,input3,finite,failed,real assemblies (x y phi tag cond)..."]
    per = 300
    for name, m in MECHANISMS.items():
        reach = []
        for k in range(per):
            if k % 2 == 0 or not reach:
                x, y, phi = m["poses"](rng)
                c, s = math.cos(phi), math.sin(phi)
                pins = [(x + c * bx - s * by, y + s * bx + c * by) for bx, by in m["b"]]
                given = inputs_at(m, pins, rng)
                if given is None:
                    continue
                reach.append(given)
            elif "arms" in m:
                given = [rng.uniform(-math.pi, math.pi) for _ in range(3)]
            else:
                lo = min(min(r) for r in reach)
                hi = max(max(r) for r in reach)
                given = [rng.uniform(lo, hi) for _ in range(3)]
            finite, failed, real = solve(*problem(m, given))
            cells = [name] + [repr(r) for r in given] + [str(finite), str(failed)]
            for a in real:
                cells += [repr(v) for v in a[:3]] + [a[3], f"{a[4]:.3e}"]
            rows.append(",".join(cells))
        print(f"{name}: {per} inputs", file=sys.stderr)
    with open(FIXTURE, "w") as f:
        f.write("\n".join(rows) + "\n")


if __name__ == "__main__":
    main()
