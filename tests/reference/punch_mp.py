#!/usr/bin/env python3
"""Seed 003's punch beside its change points, to 16 digits: the reference
that tests/testsuite/seed003_dynamics.rs holds pkm's inverse dynamics to.

Written by hand from the paper's geometry (Table 1, as
examples/mechanisms/seed003_punch.pkm declares it, with the file's
corrections; docs/dynamics.md), sharing no code with pkm:

- Kinematics in closed form on second-order jets (value, d/dt, d²/dt²)
  over mpmath numbers: the crank angle φ(t) = φ0 + ω t + α t²/2 carried
  through every formula gives every point's position, velocity and
  acceleration exactly (to the working precision).
- Newton–Euler on all seven moving links at once: 21 balances
  (Σ reactions + m g = m a_c, Σ moments about the origin = I θ̈ + c × m a_c)
  and 9 joint conditions (a passive revolute's moment is 0, a slider's
  force along its guide is 0), one 30 × 30 solve.

Conventions, pkm's (docs/dynamics.md): H at the origin, slider 6 on the x
axis, A = (m, n), slider 3 on x = m, φ from +x. A joint's reaction is the
force and moment (about the joint's point; a slider's point is its
slider's) that its first link exerts on its second, the base first where
a joint is on it: A = R(base, 1), B = R(1, 2), C = R(2, 3), P1 = P(base, 3),
D = R(2, 4), G = R(7, 4), G.2 = R(7, 5), F = R(5, 6), P2 = P(base, 6),
H = R(base, 7). Forces in N, moments and the crank torque in N·mm. The
branches are pkm's plan's, in its order (the first choice varies fastest)
and with its signs:

- C (slider 3 on its line, |BC| = l2): + above B, − below
  (y_C = y_B ± √(l2² − (m − x_B)²));
- G (|DG| = l4, |HG| = l7): + to the right of H→D, − to its left
  (G = a û ∓ h û⊥, û = D/|D|, û⊥ = û turned +90°);
- F (slider 6 on the x axis, |GF| = l5): x_F = x_G ± √(l5² − y_G²).

tests/testsuite/seed003_dynamics.rs checks these against the points `pkm` solves.
With l5 = l7 and |HG| = l7, l5² − y_G² = x_G², so F's roots are H itself
and 2 x_G: they cross where x_G = 0 (on G's − branch), the change points φ*
where F passes through H, found here to the working precision. F's + root
is 2 x_G on one side of φ* and H on the other.

Rows: both change points, φ* ± 3, 2, 1.5, 1, 0.3 and 10^-k degrees for k = 1 … 10
(the crank angle is the double nearest, which pkm is given; the reference
is computed at that double exactly), every branch of the plan (8; those
that do not assemble are rows with `reaches` 0), at three crank states
(ω, α): at rest (0, 0), the issue's (1 rad/s, 0) and a fast (10 rad/s,
50 rad/s²). Columns: the crank torque, every joint's force (N), the
sliders' moments (N·mm; a revolute's is 0 by its condition, A's is the
torque), x_F and y_C with their rates and accelerations (mm, s), and G.
Every number is computed with 60 digits (the accelerations lose about
3 log10(1/c) of them, c the relative distance of F's two roots, 2.6e-13 at
1e-10°: the same ε/c³ that pkm's doubles show) and written to 16; --write
checks them against 100 digits (within 3e-23 of each row's largest number).

Usage: python3 tests/reference/punch_mp.py [--write | --check]
  --write  writes tests/fixtures/seed003_change_points.csv
  --check  recomputes and compares with that file (CI; the default)
Without mpmath (the pinned version) installed, it makes a venv under target/ and installs it there.
"""

import csv
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
FIXTURE = ROOT / "tests" / "fixtures" / "seed003_change_points.csv"
MPMATH = "mpmath==1.3.0"


sys.path.insert(0, str(ROOT / "tests"))
from check_venv import enter  # noqa: E402

enter("reference-venv", [MPMATH])

from mpmath import mp, mpf  # noqa: E402

# Table 1 (mm, kg, kg·mm²) as the example file declares them; every value
# is the double pkm reads (mpf of a float is exact).
P = dict(m=235.0, n=205.0, l1=40.0, l2=117.0, l8=80.0, l4=170.0, l5=108.96, l7=108.96)
MASS = {1: 0.00118, 2: 0.01703, 3: 0.00629, 4: 0.004, 5: 0.00277, 6: 0.00608, 7: 0.00277}
G_Y = -9.80665  # m/s²
JOINTS = ["A", "B", "C", "P1", "D", "G", "G.2", "F", "P2", "H"]
# (ω, α) of the crank: at rest, the 1 rad/s, and a fast turn.
STATES = [(0.0, 0.0), (1.0, 0.0), (10.0, 50.0)]
# φ − φ* in degrees, each on both sides.
OFFSETS = [3.0, 2.0, 1.5, 1.0, 0.3] + [10.0**-k for k in range(1, 11)]
SIGNS = ["+", "-"]
# The working precision (decimal digits): next to a change point the
# accelerations lose about 3 log10(1/c) digits, c ≈ 1e-13 at 1e-10°.
DIGITS = 60


def check_parameters():
    """The file's parameters are the ones above (a guard against drift)."""
    text = (ROOT / "examples" / "mechanisms" / "seed003_punch.pkm").read_text()
    block = re.search(r"parameters\s*\{([^}]*)\}", text).group(1)
    declared = {k: float(v) for k, v in re.findall(r"(\w+)\s*=\s*([-0-9.eE]+)\s*;", block)}
    assert declared == P, f"seed003_punch.pkm's parameters changed: {declared}"


class Jet:
    """x(t) to second order: value, first and second derivative in t."""

    __slots__ = ("v", "d", "dd")

    def __init__(self, v, d=0, dd=0):
        self.v, self.d, self.dd = mpf(v), mpf(d), mpf(dd)

    @staticmethod
    def of(x):
        return x if isinstance(x, Jet) else Jet(x)

    def __add__(self, o):
        o = Jet.of(o)
        return Jet(self.v + o.v, self.d + o.d, self.dd + o.dd)

    __radd__ = __add__

    def __neg__(self):
        return Jet(-self.v, -self.d, -self.dd)

    def __sub__(self, o):
        return self + (-Jet.of(o))

    def __rsub__(self, o):
        return Jet.of(o) - self

    def __mul__(self, o):
        o = Jet.of(o)
        return Jet(self.v * o.v, self.d * o.v + self.v * o.d, self.dd * o.v + 2 * self.d * o.d + self.v * o.dd)

    __rmul__ = __mul__

    def recip(self):
        v = self.v
        return Jet(1 / v, -self.d / v**2, (2 * self.d**2 - v * self.dd) / v**3)

    def __truediv__(self, o):
        return self * Jet.of(o).recip()

    def __rtruediv__(self, o):
        return Jet.of(o) * self.recip()


def sqrt(a):
    if a.v < 0:
        raise ValueError("no real root")
    s = mp.sqrt(a.v)
    d = a.d / (2 * s)
    return Jet(s, d, (a.dd - 2 * d**2) / (2 * s))


def sin(u):
    s, c = mp.sin(u.v), mp.cos(u.v)
    return Jet(s, c * u.d, -s * u.d**2 + c * u.dd)


def cos(u):
    s, c = mp.sin(u.v), mp.cos(u.v)
    return Jet(c, -s * u.d, -c * u.d**2 - s * u.dd)


def atan2(y, x):
    """The angle of (x, y): θ' = (x y' − y x') / (x² + y²), and its derivative."""
    n = x.v * y.d - y.v * x.d
    q = x.v**2 + y.v**2
    dn = x.v * y.dd - y.v * x.dd
    dq = 2 * (x.v * x.d + y.v * y.d)
    return Jet(mp.atan2(y.v, x.v), n / q, (dn * q - n * dq) / q**2)


def rotate(theta, local):
    """A link-frame vector turned by the jet angle θ."""
    c, s = cos(theta), sin(theta)
    return (c * local[0] - s * local[1], s * local[0] + c * local[1])


def configuration(phi, signs, upto_g=False):
    """Every point and link angle as jets on branch `signs` (C, G, F), or
    None where it does not assemble; only G with `upto_g`."""
    p = {k: mpf(v) for k, v in P.items()}
    s_c, s_g, s_f = (1 if s == "+" else -1 for s in signs)
    A = (Jet(p["m"]), Jet(p["n"]))
    B = (A[0] + p["l1"] * cos(phi), A[1] + p["l1"] * sin(phi))
    dx = p["m"] - B[0]
    if p["l2"] ** 2 - dx.v**2 < 0:
        return None
    C = (Jet(p["m"]), B[1] + s_c * sqrt(p["l2"] ** 2 - dx * dx))
    # Link 2's frame: C at the origin, B along x; D = (l2/2, h) in it.
    theta2 = atan2(B[1] - C[1], B[0] - C[0])
    h2 = mp.sqrt(p["l8"] ** 2 - (p["l2"] / 2) ** 2)
    e = rotate(theta2, (p["l2"] / 2, h2))
    D = (C[0] + e[0], C[1] + e[1])
    # G on the circles |G − D| = l4 and |G − H| = l7, H the origin.
    dd = D[0] * D[0] + D[1] * D[1]
    d = sqrt(dd)
    a = (p["l7"] ** 2 - p["l4"] ** 2 + dd) / (2 * d)
    if p["l7"] ** 2 - a.v**2 < 0:
        return None
    h = sqrt(p["l7"] ** 2 - a * a)
    u = (D[0] / d, D[1] / d)
    perp = (-u[1], u[0])
    G = (a * u[0] - s_g * h * perp[0], a * u[1] - s_g * h * perp[1])
    if upto_g:
        return G
    if p["l5"] ** 2 - G[1].v ** 2 < 0:
        return None
    F = (G[0] + s_f * sqrt(p["l5"] ** 2 - G[1] * G[1]), Jet(0))
    H = (Jet(0), Jet(0))
    theta = {
        1: phi,
        2: theta2,
        3: Jet(0),
        4: atan2(G[1] - D[1], G[0] - D[0]),
        5: atan2(F[1] - G[1], F[0] - G[0]),
        6: Jet(0),
        7: atan2(G[1], G[0]),
    }
    origin = {1: A, 2: C, 3: C, 4: D, 5: G, 6: F, 7: H}
    return dict(A=A, B=B, C=C, D=D, G=G, F=F, H=H, theta=theta, origin=origin, h2=h2)


def bodies(cfg):
    """Per moving link: mass (kg), centroid (jets, mm), centroidal inertia (kg·mm²)."""
    p = {k: mpf(v) for k, v in P.items()}
    local = {
        1: (p["l1"] / 2, 0),
        2: (p["l2"] / 2, cfg["h2"] / 3),
        3: (0, 0),
        4: (p["l4"] / 2, 0),
        5: (p["l5"] / 2, 0),
        6: (0, 0),
        7: (p["l7"] / 2, 0),
    }
    m = {k: mpf(v) for k, v in MASS.items()}
    inertia = {
        1: mpf(0.631) - m[1] * (p["l1"] / 2) ** 2,
        2: mpf(12.534),
        3: mpf(0),
        4: mpf(9.63),
        5: mpf(2.75),
        6: mpf(0),
        7: mpf(11) - m[7] * (p["l7"] / 2) ** 2,
    }
    out = {}
    for k in range(1, 8):
        r = rotate(cfg["theta"][k], local[k])
        o = cfg["origin"][k]
        out[k] = (m[k], (o[0] + r[0], o[1] + r[1]), inertia[k])
    return out


# Each joint: (first link, second link, its point, kind); 0 is the base,
# always first.
def joints(cfg):
    return [
        (0, 1, cfg["A"], "actuated"),
        (1, 2, cfg["B"], "R"),
        (2, 3, cfg["C"], "R"),
        (0, 3, cfg["C"], (0, 1)),  # P1: slider 3's point, its guide along y
        (2, 4, cfg["D"], "R"),
        (7, 4, cfg["G"], "R"),
        (7, 5, cfg["G"], "R"),
        (5, 6, cfg["F"], "R"),
        (0, 6, cfg["F"], (1, 0)),  # P2: slider 6's point, its guide along x
        (0, 7, cfg["H"], "R"),
    ]


def matrix(cfg):
    """The 30 × 30 system: 21 balances, then 9 joint conditions (positions only)."""
    js = joints(cfg)
    n = 3 * len(js)
    rows = []
    for link in range(1, 8):
        fx, fy, mz = [0] * n, [0] * n, [0] * n
        for j, (first, second, point, _) in enumerate(js):
            s = 1 if second == link else -1 if first == link else 0
            if s == 0:
                continue
            px, py = point[0].v, point[1].v
            fx[3 * j] += s
            fy[3 * j + 1] += s
            # M_j + p × F about the origin.
            mz[3 * j + 2] += s
            mz[3 * j] += -s * py
            mz[3 * j + 1] += s * px
        rows += [fx, fy, mz]
    for j, (_, _, _, kind) in enumerate(js):
        row = [0] * n
        if kind == "R":
            row[3 * j + 2] = 1
        elif isinstance(kind, tuple):
            row[3 * j], row[3 * j + 1] = kind
        else:
            continue
        rows.append(row)
    assert len(rows) == n, len(rows)
    return mp.matrix(rows)


def newton_euler(a, cfg):
    """The crank torque and every joint's (Fx, Fy, M) in N and N·mm, `a` the system of `cfg`'s position."""
    g = (mpf(0), mpf(G_Y) * 1000)  # mm/s²
    rhs = []
    for link, (mass, c, inertia) in bodies(cfg).items():
        need = (mass * (c[0].dd - g[0]), mass * (c[1].dd - g[1]))
        alpha = cfg["theta"][link].dd
        rhs += [need[0], need[1], inertia * alpha + c[0].v * need[1] - c[1].v * need[0]]
    rhs += [mpf(0)] * (a.rows - len(rhs))
    x = mp.lu_solve(a, mp.matrix(rhs))
    # kg·mm/s² to N, kg·mm²/s² to N·mm.
    k = mpf(1) / 1000
    reactions = [(x[3 * j] * k, x[3 * j + 1] * k, x[3 * j + 2] * k) for j in range(len(JOINTS))]
    return reactions[0][2], reactions


def g_x(phi):
    """x_G on the crossing branch (C −, G −) at a number φ."""
    return configuration(Jet(phi), "--+", upto_g=True)[0].v


def change_points():
    """φ* where x_G = 0 on G's − branch: F's two roots meet at H."""
    return [mp.findroot(g_x, mp.radians(guess), tol=mpf(10) ** (-mp.dps + 5)) for guess in (154.5189, 234.6346)]


def branches():
    """The plan's branches in its order: the first choice varies fastest."""
    return [SIGNS[i & 1] + SIGNS[i >> 1 & 1] + SIGNS[i >> 2 & 1] for i in range(8)]


HEADER = (
    ["point", "degrees", "side", "q", "offset_deg", "omega", "alpha", "signs", "reaches", "torque"]
    + [f"{j}_{c}" for j in JOINTS for c in ("fx", "fy")]
    + ["P1_m", "P2_m", "x_F", "v_F", "a_F", "y_C", "v_C", "a_C", "x_G", "y_G"]
)


def rows(dps):
    """Every row of the fixture as mpmath numbers (or None for a branch that does not assemble)."""
    mp.dps = dps
    stars = change_points()
    out = []
    for point, star in enumerate(stars, 1):
        for degrees in OFFSETS:
            for side in (-1, 1):
                q = float(star + side * mp.radians(mpf(degrees)))
                offset = mp.degrees(mpf(q) - star)
                for signs in branches():
                    a = None
                    for omega, alpha in STATES:
                        key = [point, degrees, side, repr(q), offset, omega, alpha, signs]
                        cfg = configuration(Jet(q, omega, alpha), signs)
                        if cfg is None:
                            out.append((key, None))
                            continue
                        # The positions, and so the system, are the same at every state.
                        a = a or matrix(cfg)
                        torque, reactions = newton_euler(a, cfg)
                        numbers = [torque] + [x for r in reactions for x in r[:2]]
                        numbers += [reactions[JOINTS.index("P1")][2], reactions[JOINTS.index("P2")][2]]
                        for j in (cfg["F"][0], cfg["C"][1]):
                            numbers += [j.v, j.d, j.dd]
                        numbers += [cfg["G"][0].v, cfg["G"][1].v]
                        out.append((key, numbers))
    # Grouped by state, then branch.
    out.sort(key=lambda r: (r[0][0], OFFSETS.index(r[0][1]), r[0][2], STATES.index((r[0][5], r[0][6]))))
    return stars, out


def compare(a_rows, b_rows, tol, what):
    """Every number of two computations within tol of the larger of its row."""
    assert len(a_rows) == len(b_rows), what
    worst = 0
    for (ka, na), (kb, nb) in zip(a_rows, b_rows):
        assert [str(x) for x in ka[:4]] == [str(x) for x in kb[:4]] and ka[7] == kb[7], f"{what}: {ka} against {kb}"
        assert (na is None) == (nb is None), f"{what}: {ka}"
        if na is None:
            continue
        scale = max(abs(mpf(x)) for x in na)
        for x, y in zip(na, nb):
            worst = max(worst, abs(mpf(x) - mpf(y)) / scale)
    assert worst <= tol, f"{what}: {worst}"
    return worst


def text(x):
    """A number to 16 digits, 0 for what is zero to the working precision."""
    return "0" if abs(x) < mpf(10) ** -40 else mp.nstr(x, 16)


def main():
    check_parameters()
    mode = sys.argv[1] if len(sys.argv) > 1 else "--check"
    if mode not in ("--write", "--check"):
        sys.exit(__doc__)
    stars, computed = rows(DIGITS)
    mp.dps = 50
    print("change points: " + ", ".join(f"{mp.nstr(s, 20)} rad = {mp.nstr(mp.degrees(s), 20)}°" for s in stars))
    if mode == "--write":
        # What the working precision leaves: the same rows with 40 more digits.
        _, finer = rows(DIGITS + 40)
        worst = compare(computed, finer, mpf(10) ** -20, f"{DIGITS} against {DIGITS + 40} digits")
        print(f"{DIGITS} and {DIGITS + 40} digits agree within {mp.nstr(worst, 3)} of each row's largest number")
    lines = [HEADER]
    for key, numbers in computed:
        point, degrees, side, q, offset, omega, alpha, signs = key
        head = [point, repr(degrees), side, q, mp.nstr(offset, 6), repr(omega), repr(alpha), signs]
        lines.append([str(x) for x in head] + (["1"] + [text(x) for x in numbers] if numbers else ["0"]))
    if mode == "--write":
        FIXTURE.parent.mkdir(parents=True, exist_ok=True)
        with open(FIXTURE, "w", newline="") as f:
            f.write("# Seed 003's punch beside its change points, exact to 16 digits: tests/reference/punch_mp.py\n")
            csv.writer(f, lineterminator="\n").writerows(lines)
        print(f"wrote {FIXTURE.relative_to(ROOT)}: {len(lines) - 1} rows")
        return
    with open(FIXTURE, newline="") as f:
        stored = [r for r in csv.reader(line for line in f if not line.startswith("#"))]
    assert stored[0] == HEADER, "the fixture's columns changed"
    assert len(stored) == len(lines), f"{len(stored)} rows stored, {len(lines)} computed"
    worst = 0
    for s, c in zip(stored[1:], lines[1:]):
        assert s[:9] == c[:9], f"{s[:9]} against {c[:9]}"
        if s[8] == "1":
            numbers = [(mpf(a), mpf(b)) for a, b in zip(s[9:], c[9:])]
            scale = max(abs(b) for _, b in numbers)
            worst = max([worst] + [abs(a - b) / scale for a, b in numbers])
    assert worst < 1e-14, f"the fixture differs from the computation by {worst}"
    print(f"{FIXTURE.relative_to(ROOT)}: {len(lines) - 1} rows as computed (within {mp.nstr(worst, 3)})")


if __name__ == "__main__":
    main()
