"""Sparse polynomials for PHCpack's input, shared by the scripts that write
PHCpack's systems (planar_3rpr_phc.py, ball_legs_phc.py).

A polynomial is a dict {exponent tuple: coefficient}; `text` writes it in
PHCpack's syntax with every coefficient to 17 digits.
"""


def pconst(v, nv):
    return {(0,) * nv: v} if v != 0.0 else {}


def pvar(i, nv):
    e = [0] * nv
    e[i] = 1
    return {tuple(e): 1.0}


def padd(*ps):
    out = {}
    for p in ps:
        for e, v in p.items():
            out[e] = out.get(e, 0.0) + v
    return out


def pscale(p, k):
    return {e: v * k for e, v in p.items()}


def pmul(p, q):
    out = {}
    for e1, v1 in p.items():
        for e2, v2 in q.items():
            e = tuple(a + b for a, b in zip(e1, e2))
            out[e] = out.get(e, 0.0) + v1 * v2
    return out


def pdot(a, b):
    """Σ a_i·b_i, `a` numbers, `b` polynomials."""
    return padd(*(pscale(y, x) for x, y in zip(a, b)))


def text(p, names):
    terms = []
    for e, v in sorted(p.items()):
        if v == 0.0:
            continue
        mono = "*".join(f"{n}^{k}" if k > 1 else n for n, k in zip(names, e) if k > 0)
        coef = f"{v:+.17E}"
        terms.append(f"{coef}*{mono}" if mono else coef)
    return " ".join(terms) + ";"
