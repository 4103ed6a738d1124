//! Every root of `N` equations in `N` unknowns over a box, each proven or
//! reported: interval branch-and-prune with Krawczyk's operator.
//!
//! The residual is given as an enclosure over a box ([`Enclosed`]: the
//! intervals of its values and of its Jacobian's entries there, as the
//! plan's steps compute them on [`crate::interval::Enclosure`]). A box is
//!
//! - **dropped** where the residual is undefined at every point (a step
//!   has no real solution anywhere in it) or some component's interval
//!   excludes zero: no root there, proven;
//! - **certified** where Krawczyk's operator
//!   `K(X) = m − Y·f(m) + (I − Y·J(X))·(X − m)`, with `m` the box's middle,
//!   `J(X)` the Jacobian's enclosure and `Y ≈ mid(J)⁻¹`, lies strictly
//!   inside it and every decision the steps took went one way over the
//!   box: then `X` holds exactly one root, and `K(X)` too (Krawczyk 1969,
//!   Moore 1977; Neumaier, *Interval methods for systems of equations*,
//!   §5.1). The box is then narrowed by `X ← K(X) ∩ X` while that
//!   shrinks it, and the root is its middle: the certificate is the final
//!   box, a few ulps wide at a well-conditioned root;
//! - narrowed to `K(X) ∩ X` (no root outside it), or **split** in two
//!   across its widest side (measured against the search box's);
//! - reported **possible** where it is narrower than
//!   [`Limits::resolution`] of the search box and still neither dropped nor
//!   certified: a root may be there that the method cannot prove, because
//!   the Jacobian is singular or nearly so at it (a double root, a fold
//!   where two assemblies meet: Merlet's distinction between a solution
//!   proven and one only not excluded), or because a step's decision
//!   changes there (the edge of a branch's real solutions). Touching
//!   possible boxes are one report. Where the search exhausts
//!   [`Limits::boxes`], every box left is reported possible too: nothing
//!   is dropped unproven.

use crate::interval::Interval;

/// The residual's enclosure over a box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Enclosed<const N: usize> {
    /// The values' intervals.
    pub f: [Interval; N],
    /// The Jacobian's, `j[row][column]`.
    pub j: [[Interval; N]; N],
    /// Every decision of the steps went one way over the box (see
    /// [`crate::interval`]).
    pub decided: bool,
}

/// Why a root is only possible.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Doubt {
    /// The Jacobian is singular, or too ill-conditioned to prove, over
    /// the smallest box: a double root, or two roots closer than the
    /// resolution.
    Singular,
    /// A step's decision changes inside the smallest box: the edge of the
    /// branch's real solutions (where two branches meet) or a degenerate
    /// configuration of a step.
    Edge,
    /// The search's box budget ran out before this box was decided.
    Budget,
}

impl Doubt {
    /// In words.
    pub fn text(self) -> &'static str {
        match self {
            Doubt::Singular => "singular: the Jacobian may vanish here (a double root or a fold), not provable",
            Doubt::Edge => "at the edge of the branch's real solutions (where two branches meet), not provable",
            Doubt::Budget => "the search's box budget ran out before this box was decided",
        }
    }
}

/// A root found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Root<const N: usize> {
    /// Where: the certificate's middle, or the possible box's point of
    /// least residual.
    pub x: [f64; N],
    /// The box: for a certified root, proven to hold it and no other.
    pub cert: [Interval; N],
    /// `None`: certified; otherwise why it is only possible.
    pub doubt: Option<Doubt>,
}

/// What the search may spend.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// Boxes examined at most.
    pub boxes: usize,
    /// A box narrower than this fraction of the search box on every side
    /// is not split again.
    pub resolution: f64,
    /// Parts each side of the search box is first split into (a little
    /// off equal parts, as every split: [`SPLIT`]).
    pub initial: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            boxes: 200_000,
            resolution: 1e-11,
            initial: 1,
        }
    }
}

/// What [`roots`] did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Stats {
    /// Boxes whose residual was enclosed.
    pub boxes: usize,
}

/// The inverse of a point matrix by Gauss–Jordan with partial pivoting;
/// `None` where a pivot vanishes.
fn inverse<const N: usize>(a: [[f64; N]; N]) -> Option<[[f64; N]; N]> {
    let mut m = a;
    let mut inv = [[0.0; N]; N];
    for (i, row) in inv.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for c in 0..N {
        let p = (c..N).max_by(|&x, &y| m[x][c].abs().total_cmp(&m[y][c].abs()))?;
        if m[p][c] == 0.0 || !m[p][c].is_finite() {
            return None;
        }
        m.swap(c, p);
        inv.swap(c, p);
        let d = m[c][c];
        for k in 0..N {
            m[c][k] /= d;
            inv[c][k] /= d;
        }
        for r in 0..N {
            if r != c {
                let f = m[r][c];
                for k in 0..N {
                    m[r][k] -= f * m[c][k];
                    inv[r][k] -= f * inv[c][k];
                }
            }
        }
    }
    inv.iter().flatten().all(|x| x.is_finite()).then_some(inv)
}

/// What Krawczyk's operator needs of a box's enclosure: `Y ≈ mid(J)⁻¹`,
/// `C = I − Y·J(X)` and `‖C‖∞`. The operator can lie inside `X` only where
/// that norm is below 1, so the middle's residual is not computed elsewhere.
struct Preconditioned<const N: usize> {
    y: [[f64; N]; N],
    c: [[Interval; N]; N],
    norm: f64,
}

fn preconditioner<const N: usize>(e: &Enclosed<N>) -> Option<Preconditioned<N>> {
    let mid_j: [[f64; N]; N] = core::array::from_fn(|r| core::array::from_fn(|c| e.j[r][c].mid()));
    let y = inverse(mid_j)?;
    let c: [[Interval; N]; N] = core::array::from_fn(|r| {
        core::array::from_fn(|col| {
            let mut a = Interval::point(if r == col { 1.0 } else { 0.0 });
            for (l, yl) in y[r].iter().enumerate() {
                a = a - Interval::point(*yl) * e.j[l][col];
            }
            a
        })
    });
    let norm = c
        .iter()
        .map(|row| row.iter().map(|a| a.mag()).sum::<f64>())
        .fold(0.0f64, f64::max);
    norm.is_finite().then_some(Preconditioned { y, c, norm })
}

/// Krawczyk's operator `m − Y·f(m) + C·(X − m)` on `x` (see the module's
/// text); `None` where it cannot be formed.
fn krawczyk<const N: usize>(
    x: &[Interval; N],
    p: &Preconditioned<N>,
    at_mid: &Enclosed<N>,
    m: &[f64; N],
) -> Option<[Interval; N]> {
    let mut k = [Interval::point(0.0); N];
    for (r, kr) in k.iter_mut().enumerate() {
        let mut acc = Interval::point(m[r]);
        for (yc, fc) in p.y[r].iter().zip(&at_mid.f) {
            acc = acc - Interval::point(*yc) * *fc;
        }
        for (c, xc) in x.iter().enumerate() {
            acc = acc + p.c[r][c] * (*xc - Interval::point(m[c]));
        }
        *kr = acc;
    }
    k.iter().all(|i| !i.is_empty()).then_some(k)
}

/// +1 or −1 where every value of `f` has that sign, 0 where it holds
/// zero (or nothing).
fn sign(f: Interval) -> i8 {
    if f.lo > 0.0 {
        1
    } else if f.hi < 0.0 {
        -1
    } else {
        0
    }
}

fn widest<const N: usize>(x: &[Interval; N], scale: &[f64; N]) -> (usize, f64) {
    (0..N)
        .map(|i| (i, x[i].width() / scale[i]))
        .fold((0, f64::NEG_INFINITY), |a, b| if b.1 > a.1 { b } else { a })
}

/// Every root of the residual in the box `start`, each certified or
/// possible (see the module's text), in the order found; and what the
/// search did. `enclose(x)` is `None` where the residual is undefined at
/// every point of `x`.
pub fn roots<const N: usize>(
    start: [Interval; N],
    limits: &Limits,
    mut enclose: impl FnMut(&[Interval; N]) -> Option<Enclosed<N>>,
) -> (Vec<Root<N>>, Stats) {
    let scale: [f64; N] = start.map(|i| i.width().max(f64::MIN_POSITIVE));
    let mut stats = Stats::default();
    let mut out: Vec<Root<N>> = Vec::new();
    let mut doubtful: Vec<([Interval; N], Doubt)> = Vec::new();
    // The first split, each side into `initial` parts.
    let parts = limits.initial.max(1);
    let mut stack = vec![start];
    for i in 0..N {
        stack = stack
            .into_iter()
            .flat_map(|b| {
                let w = b[i].width() / parts as f64;
                let cut = move |k: usize| match k {
                    0 => b[i].lo,
                    k if k == parts => b[i].hi,
                    k => b[i].lo + w * (k as f64 - 1.0 + 2.0 * SPLIT),
                };
                (0..parts).map(move |k| {
                    let mut c = b;
                    c[i] = Interval::new(cut(k), cut(k + 1));
                    c
                })
            })
            .collect();
    }
    // The widest box first (a budget spent at one hard place, a fold where
    // two roots nearly meet, leaves the rest of the range explored and
    // only boxes narrower than any explored one undecided; under the
    // budget the order changes nothing: every box is decided by itself).
    let mut pending = Pending::default();
    for x in stack {
        pending.push(x, &scale);
    }
    let excludes = |e: &Enclosed<N>| e.f.iter().any(|f| f.is_empty() || !f.contains(0.0));
    while let Some(mut x) = pending.pop() {
        if stats.boxes >= limits.boxes {
            doubtful.push((x, Doubt::Budget));
            continue;
        }
        stats.boxes += 1;
        let Some(e) = enclose(&x) else { continue };
        if excludes(&e) {
            continue;
        }
        // One unknown, monotone over the box: the residual's range is
        // between its values at the ends, which decide the box.
        if N == 1 && e.decided && !e.j[0][0].contains(0.0) {
            stats.boxes += 2;
            let end = |t: f64, enclose: &mut dyn FnMut(&[Interval; N]) -> Option<Enclosed<N>>| {
                enclose(&[Interval::point(t); N])
                    .filter(|a| a.decided)
                    .map(|a| sign(a.f[0]))
            };
            match (end(x[0].lo, &mut enclose), end(x[0].hi, &mut enclose)) {
                (Some(a), Some(b)) if a != 0 && a == b => continue,
                (Some(a), Some(b)) if a != 0 && a == -b => {
                    out.push(refine(x, &mut enclose, &mut stats));
                    continue;
                }
                _ => {}
            }
        }
        // The centred form: f(X) ⊂ f(m) + J(X)·(X − m), where every
        // decision went one way (the residual is smooth on the box). Where
        // the residual's slope is a small difference of large terms (a
        // flat residual of a mechanism near a singular pose), the
        // enclosure of f itself is many times too wide, and this one
        // excludes boxes that it cannot.
        let m: [f64; N] = x.map(|i| i.mid());
        let mut at_mid = None;
        if e.decided && e.j.iter().flatten().all(|j| j.lo.is_finite() && j.hi.is_finite()) {
            stats.boxes += 1;
            at_mid = enclose(&m.map(Interval::point));
            if let Some(a) = &at_mid {
                let centred_excludes = (0..N).any(|r| {
                    let mut acc = a.f[r];
                    for c in 0..N {
                        acc = acc + e.j[r][c] * (x[c] - Interval::point(m[c]));
                    }
                    !acc.is_empty() && !acc.contains(0.0)
                });
                if centred_excludes {
                    continue;
                }
            }
        }
        if let Some(p) = preconditioner(&e) {
            if p.norm < 1.0 {
                let a = match at_mid {
                    Some(a) => Some(a),
                    None => {
                        stats.boxes += 1;
                        enclose(&m.map(Interval::point))
                    }
                };
                let k = a.and_then(|a| krawczyk(&x, &p, &a, &m));
                if let Some(k) = k {
                    if e.decided && (0..N).all(|i| k[i].inside(x[i])) {
                        out.push(refine(k, &mut enclose, &mut stats));
                        continue;
                    }
                    let met: [Interval; N] = core::array::from_fn(|i| k[i].meet(x[i]));
                    if met.iter().any(|i| i.is_empty()) {
                        continue;
                    }
                    // Narrowed well: look again.
                    if (0..N).all(|i| met[i].width() <= 0.7 * x[i].width()) {
                        pending.push(met, &scale);
                        continue;
                    }
                    x = met;
                }
            }
        }
        let (i, w) = widest(&x, &scale);
        if w <= limits.resolution {
            // A root on the box's side cannot be strictly inside it: try
            // the box inflated about its middle (ε-inflation).
            if e.decided {
                if let Some(root) = inflated(&x, &mut enclose, &mut stats) {
                    out.push(root);
                    continue;
                }
            }
            let doubt = if e.decided { Doubt::Singular } else { Doubt::Edge };
            doubtful.push((x, doubt));
            continue;
        }
        // Off the middle, so that a root at a round number (a middle of
        // the search box) is not on a side.
        let c = x[i].lo + SPLIT * x[i].width();
        let (mut a, mut b) = (x, x);
        a[i] = Interval::new(x[i].lo, c);
        b[i] = Interval::new(c, x[i].hi);
        pending.push(a, &scale);
        pending.push(b, &scale);
    }
    // A root certified twice (from both sides of a split) once.
    let mut unique: Vec<Root<N>> = Vec::new();
    for r in out {
        let same =
            |o: &Root<N>| (0..N).all(|i| o.cert[i].contains(r.x[i])) || (0..N).all(|i| r.cert[i].contains(o.x[i]));
        if !unique.iter().any(same) {
            unique.push(r);
        }
    }
    // A possible box holding a certified root is that root.
    let doubtful: Vec<_> = doubtful
        .into_iter()
        .filter(|(b, _)| !unique.iter().any(|r| (0..N).all(|i| b[i].contains(r.x[i]))))
        .collect();
    unique.extend(merge(doubtful, &mut enclose, &mut stats));
    (unique, stats)
}

/// The boxes [`roots`] has still to look at, the widest first (its widest
/// side over the search box's), then the first pushed.
struct Pending<const N: usize> {
    heap: std::collections::BinaryHeap<Waiting<N>>,
    pushed: usize,
}

impl<const N: usize> Default for Pending<N> {
    fn default() -> Self {
        Pending {
            heap: std::collections::BinaryHeap::new(),
            pushed: 0,
        }
    }
}

struct Waiting<const N: usize> {
    width: f64,
    order: usize,
    x: [Interval; N],
}

impl<const N: usize> PartialEq for Waiting<N> {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == core::cmp::Ordering::Equal
    }
}

impl<const N: usize> Eq for Waiting<N> {}

impl<const N: usize> PartialOrd for Waiting<N> {
    fn partial_cmp(&self, o: &Self) -> Option<core::cmp::Ordering> {
        Some(self.cmp(o))
    }
}

impl<const N: usize> Ord for Waiting<N> {
    fn cmp(&self, o: &Self) -> core::cmp::Ordering {
        self.width.total_cmp(&o.width).then(o.order.cmp(&self.order))
    }
}

impl<const N: usize> Pending<N> {
    fn push(&mut self, x: [Interval; N], scale: &[f64; N]) {
        self.heap.push(Waiting {
            width: widest(&x, scale).1,
            order: self.pushed,
            x,
        });
        self.pushed += 1;
    }

    fn pop(&mut self) -> Option<[Interval; N]> {
        self.heap.pop().map(|w| w.x)
    }
}

/// Why [`near`] could not prove the root it tracked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Lost {
    /// Newton's method from the start did not converge inside the region.
    Diverged,
    /// The box from the start to the root found holds another root, or
    /// one the search cannot decide (a fold near), or none it can prove.
    NotAlone,
}

/// The root nearest a known point, proven to be the only one between
/// them: Newton's method from `from` (steps kept inside `region`), then
/// [`roots`] over the box spanning `from` and the point reached, widened
/// by the last step and a margin of `margin` of each side of `region`.
/// Where that box holds exactly one root, certified, and nothing
/// possible, the root is returned with its certificate: no other root
/// lies between the start and it, so a path of roots followed in small
/// steps this way does not jump to another root without the search
/// seeing it (it would have to lie in the box).
///
/// # Errors
/// [`Lost`]: Newton's method failed, or the box holds more than that one
/// root or undecided boxes.
pub fn near<const N: usize>(
    from: [f64; N],
    region: &[Interval; N],
    margin: f64,
    limits: &Limits,
    mut enclose: impl FnMut(&[Interval; N]) -> Option<Enclosed<N>>,
) -> Result<Root<N>, Lost> {
    let (p, step) = newton(from, region, &mut enclose).ok_or(Lost::Diverged)?;
    let span: [Interval; N] = core::array::from_fn(|i| {
        let pad = 8.0 * step[i] + margin * region[i].width();
        Interval::new(from[i].min(p[i]) - pad, from[i].max(p[i]) + pad).meet(region[i])
    });
    // One Krawczyk test on the whole span first (a short, well-conditioned
    // step passes it); the search where it does not.
    let mut stats = Stats::default();
    if let Some(k) = certified(&span, &span.map(|i| i.mid()), &mut enclose, &mut stats) {
        return Ok(refine(k, &mut enclose, &mut stats));
    }
    let (found, _) = roots(span, limits, &mut enclose);
    match found[..] {
        [one] if one.doubt.is_none() => Ok(one),
        _ => Err(Lost::NotAlone),
    }
}

/// Newton's method from `from` on the residual's values and Jacobian at
/// points (their enclosures' middles), every step kept inside `region`:
/// where the steps fall to 10⁻¹² of the region's sides, the point and the
/// last step's size; `None` where a step leaves the region, the Jacobian
/// is singular, or 40 steps do not converge.
pub fn newton<const N: usize>(
    from: [f64; N],
    region: &[Interval; N],
    enclose: &mut impl FnMut(&[Interval; N]) -> Option<Enclosed<N>>,
) -> Option<([f64; N], [f64; N])> {
    let mut p = from;
    for _ in 0..40 {
        let (f, j) = enclose.at(&p)?;
        let y = inverse(j)?;
        let d: [f64; N] = core::array::from_fn(|r| -(0..N).map(|c| y[r][c] * f[c]).sum::<f64>());
        p = core::array::from_fn(|i| p[i] + d[i]);
        if !(0..N).all(|i| region[i].contains(p[i])) {
            return None;
        }
        let step = d.map(f64::abs);
        if (0..N).all(|i| step[i] <= 1e-12 * region[i].width()) {
            return Some((p, step));
        }
    }
    None
}

/// The root near `x`, proven alone in a small box about it: Newton's
/// method from `x` (at most 8 steps, the residual and the Jacobian at
/// points), then Krawczyk's operator on boxes about the point reached,
/// from 128 ulps of `x`'s size (plus one) wide, each 8 times the last, up
/// to 10⁻⁴ of it; the first that passes is the certificate (narrowed
/// where it is wider than 10⁻¹² of the size or does not hold the point:
/// Newton's method inside it and a box about where that stops). `None`
/// where none does: a root too ill-conditioned or singular to prove, or
/// none.
pub fn isolate<const N: usize>(
    x: [f64; N],
    enclose: &mut impl FnMut(&[Interval; N]) -> Option<Enclosed<N>>,
) -> Option<Root<N>> {
    isolate_with(x, enclose)
}

/// [`isolate`] on a [`Residual`] that gives its values at points in plain
/// floats (Newton's steps); the proofs on its enclosures alike.
pub fn isolate_with<const N: usize>(x: [f64; N], enclose: &mut impl Residual<N>) -> Option<Root<N>> {
    let mut p = x;
    let mut last = f64::INFINITY;
    for _ in 0..8 {
        let Some(d) = newton_step(&p, enclose) else { break };
        if d.iter().any(|v| !v.is_finite()) {
            break;
        }
        // Not half the last step: rounding, Newton's convergence is over.
        let size = d.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if size > 0.5 * last {
            break;
        }
        last = size;
        p = core::array::from_fn(|i| p[i] + d[i]);
        if d.iter()
            .zip(&p)
            .all(|(d, p)| d.abs() <= 4.0 * f64::EPSILON * (1.0 + p.abs()))
        {
            break;
        }
    }
    let size = 1.0 + p.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut stats = Stats::default();
    let mut w = 128.0 * f64::EPSILON * size;
    while w <= 1e-4 * size {
        let b: [Interval; N] = p.map(|v| Interval::new(v - w, v + w));
        if let Some(k) = certified(&b, &p, enclose, &mut stats) {
            // A box a few hundred ulps wide that holds Newton's point is
            // the certificate already; a wider one is narrowed.
            if w <= 1e-12 * size && (0..N).all(|i| k[i].contains(p[i])) {
                return Some(Root {
                    x: p,
                    cert: k,
                    doubt: None,
                });
            }
            return Some(refine(k, enclose, &mut stats));
        }
        w *= 8.0;
    }
    None
}

/// Newton's step at the point `p`: `−J⁻¹·f` with the residual and its
/// Jacobian at `p` (their enclosures' middles); `None` where they cannot
/// be enclosed or the Jacobian is singular.
fn newton_step<const N: usize>(p: &[f64; N], enclose: &mut impl Residual<N>) -> Option<[f64; N]> {
    let (f, j) = enclose.at(p)?;
    let y = inverse(j)?;
    Some(core::array::from_fn(|r| -(0..N).map(|c| y[r][c] * f[c]).sum::<f64>()))
}

/// A residual of `N` unknowns: its enclosure with its Jacobian's over a
/// box (what a proof needs), and its value and Jacobian at a point (what
/// Newton's steps need; by default the enclosure of the point's middles,
/// but a residual written over a ring gives them in plain floats, at a
/// twentieth of the cost). Every `FnMut` from boxes to enclosures is one.
pub trait Residual<const N: usize> {
    /// The enclosures over `x`; `None` where the residual is undefined.
    fn enclose(&mut self, x: &[Interval; N]) -> Option<Enclosed<N>>;

    /// The value and Jacobian at `p`; `None` where undefined.
    fn at(&mut self, p: &[f64; N]) -> Option<([f64; N], [[f64; N]; N])> {
        let e = self.enclose(&p.map(Interval::point))?;
        let f = e.f.map(|f| f.mid());
        f.iter().all(|v| v.is_finite()).then_some(())?;
        Some((f, core::array::from_fn(|r| core::array::from_fn(|c| e.j[r][c].mid()))))
    }
}

impl<const N: usize, F: FnMut(&[Interval; N]) -> Option<Enclosed<N>>> Residual<N> for F {
    fn enclose(&mut self, x: &[Interval; N]) -> Option<Enclosed<N>> {
        self(x)
    }
}

/// Where a box is split: a little off its middle.
const SPLIT: f64 = 0.498_730_158_2;

/// `x` inflated to four times its width about its middle and certified
/// there, if it can be.
fn inflated<const N: usize>(x: &[Interval; N], enclose: &mut impl Residual<N>, stats: &mut Stats) -> Option<Root<N>> {
    let wide: [Interval; N] = x.map(|i| {
        let (m, w) = (i.mid(), 2.0 * i.width().max(f64::EPSILON * i.mag()));
        Interval::new(m - w, m + w)
    });
    let k = certified(&wide, &wide.map(|i| i.mid()), enclose, stats)?;
    Some(refine(k, enclose, stats))
}

/// Krawczyk's operator on `x` about `m`, where it lies strictly inside
/// `x` and every decision went one way: then `x` holds exactly one root,
/// and the operator's box too.
fn certified<const N: usize>(
    x: &[Interval; N],
    m: &[f64; N],
    enclose: &mut impl Residual<N>,
    stats: &mut Stats,
) -> Option<[Interval; N]> {
    stats.boxes += 2;
    let e = enclose.enclose(x)?;
    let p = preconditioner(&e)?;
    let a = enclose.enclose(&m.map(Interval::point))?;
    let k = krawczyk(x, &p, &a, m)?;
    (e.decided && (0..N).all(|i| k[i].inside(x[i]))).then(|| core::array::from_fn(|i| k[i].meet(x[i])))
}

/// A root in the certified box `x`, and a narrower certificate: Newton's
/// method from the middle (the residual and the Jacobian at points),
/// then Krawczyk's operator on a small box about where it stops, the box
/// inflated until it passes (a box inside `x` holds `x`'s one root).
/// Where none passes, `x` stays the certificate and the root is Newton's
/// last point inside `x`.
fn refine<const N: usize>(x: [Interval; N], enclose: &mut impl Residual<N>, stats: &mut Stats) -> Root<N> {
    let mut p: [f64; N] = x.map(|i| i.mid());
    let mut step = x.map(|i| i.width());
    if N == 1 {
        // A bracket of one unknown: Newton's steps kept in it, halved
        // where one would leave it (the sign at the ends tells which half).
        let x0 = safe_newton(x[0], &mut |t: f64| {
            stats.boxes += 1;
            enclose.at(&[t; N]).map(|(f, j)| (f[0], j[0][0]))
        });
        if let Some((t, d)) = x0 {
            p = [t; N];
            step = [d; N];
        }
    }
    let mut last = f64::INFINITY;
    for _ in 0..16 {
        stats.boxes += 1;
        let Some(d) = newton_step(&p, enclose) else { break };
        let next: [f64; N] = core::array::from_fn(|i| p[i] + d[i]);
        if !(0..N).all(|i| x[i].contains(next[i])) {
            break;
        }
        // A step not half the last: Newton's convergence is over, what is
        // left is rounding (a component at zero never meets a tolerance
        // relative to itself).
        let size = d.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if size > 0.5 * last {
            break;
        }
        let done = (0..N).all(|i| d[i].abs() <= 4.0 * f64::EPSILON * next[i].abs().max(f64::MIN_POSITIVE));
        p = next;
        step = d.map(f64::abs);
        last = size;
        if done {
            break;
        }
    }
    let mut radius: [f64; N] =
        core::array::from_fn(|i| (8.0 * step[i]).max(16.0 * f64::EPSILON * p[i].abs()).max(1e-300));
    for _ in 0..6 {
        let small: [Interval; N] =
            core::array::from_fn(|i| Interval::new(p[i] - radius[i], p[i] + radius[i]).meet(x[i]));
        if small.iter().any(|i| i.is_empty()) {
            break;
        }
        if let Some(k) = certified(&small, &p, enclose, stats) {
            return Root {
                x: p,
                cert: k,
                doubt: None,
            };
        }
        radius = radius.map(|r| 16.0 * r);
    }
    Root {
        x: p,
        cert: x,
        doubt: None,
    }
}

/// A root of `f` (its value and derivative at a point) in `x`, where
/// `f` has opposite signs at the ends: Newton's steps, each kept inside
/// the shrinking bracket or replaced by halving it (rtsafe, Press et al.
/// §9.4); the root and the last step's size. `None` where the ends have
/// one sign or are undefined.
fn safe_newton(x: Interval, f: &mut impl FnMut(f64) -> Option<(f64, f64)>) -> Option<(f64, f64)> {
    let (fa, _) = f(x.lo)?;
    let (fb, _) = f(x.hi)?;
    if fa == 0.0 {
        return Some((x.lo, 0.0));
    }
    if fb == 0.0 {
        return Some((x.hi, 0.0));
    }
    if fa.signum() == fb.signum() {
        return None;
    }
    // `lo` where f < 0.
    let (mut lo, mut hi) = if fa < 0.0 { (x.lo, x.hi) } else { (x.hi, x.lo) };
    let mut t = x.mid();
    let mut step = (hi - lo).abs();
    for _ in 0..100 {
        let Some((ft, dt)) = f(t) else {
            t = 0.5 * (lo + hi);
            continue;
        };
        if ft == 0.0 {
            return Some((t, 0.0));
        }
        if ft < 0.0 {
            lo = t;
        } else {
            hi = t;
        }
        let newton = t - ft / dt;
        let inside = (newton - lo) * (newton - hi) < 0.0;
        let next = if inside && dt.is_finite() && dt != 0.0 {
            newton
        } else {
            0.5 * (lo + hi)
        };
        step = (next - t).abs();
        if next == t || step <= 2.0 * f64::EPSILON * t.abs() || (lo - hi).abs() <= 2.0 * f64::EPSILON * t.abs() {
            t = next;
            break;
        }
        t = next;
    }
    Some((t, step))
}

/// Possible boxes that touch are one report, at the point of the group's
/// boxes' middles with the least residual.
fn merge<const N: usize>(
    mut boxes: Vec<([Interval; N], Doubt)>,
    enclose: &mut impl FnMut(&[Interval; N]) -> Option<Enclosed<N>>,
    stats: &mut Stats,
) -> Vec<Root<N>> {
    let touch = |a: &[Interval; N], b: &[Interval; N]| (0..N).all(|i| a[i].lo <= b[i].hi && b[i].lo <= a[i].hi);
    let mut groups: Vec<Vec<([Interval; N], Doubt)>> = Vec::new();
    while let Some(b) = boxes.pop() {
        let mut group = vec![b];
        let mut k = 0;
        while k < group.len() {
            let here = group[k].0;
            let (near, far): (Vec<_>, Vec<_>) = boxes.into_iter().partition(|o| touch(&o.0, &here));
            boxes = far;
            group.extend(near);
            k += 1;
        }
        groups.push(group);
    }
    groups
        .into_iter()
        .map(|group| {
            let hull: [Interval; N] =
                core::array::from_fn(|i| group.iter().fold(Interval::EMPTY, |h, b| h.hull(b.0[i])));
            // The most telling doubt: a budget, then an edge, then a singularity.
            let doubt = group
                .iter()
                .map(|b| b.1)
                .max_by_key(|d| match d {
                    Doubt::Budget => 2,
                    Doubt::Edge => 1,
                    Doubt::Singular => 0,
                })
                .unwrap_or(Doubt::Singular);
            let size = |m: &[f64; N], e: &mut dyn FnMut(&[Interval; N]) -> Option<Enclosed<N>>| {
                e(&m.map(Interval::point)).map_or(f64::INFINITY, |e| e.f.iter().fold(0.0f64, |s, f| s.max(f.mag())))
            };
            let mut best = (hull.map(|i| i.mid()), f64::INFINITY);
            for b in &group {
                let m = b.0.map(|i| i.mid());
                stats.boxes += 1;
                let s = size(&m, enclose);
                if s < best.1 {
                    best = (m, s);
                }
            }
            Root {
                x: best.0,
                cert: hull,
                doubt: Some(doubt),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interval::{watch, Enclosure};
    use crate::scalar::Scalar;

    /// The residual `f` (over [`Enclosure`]) as [`roots`] reads it.
    fn enclosed<const N: usize>(
        f: impl Fn([Enclosure<N>; N]) -> Option<[Enclosure<N>; N]>,
    ) -> impl FnMut(&[Interval; N]) -> Option<Enclosed<N>> {
        move |x| {
            let v: [Enclosure<N>; N] = core::array::from_fn(|i| Enclosure::variable(x[i], i));
            let (r, took) = watch(|| f(v));
            let r = r?;
            Some(Enclosed {
                f: r.map(|e| e.v),
                j: r.map(|e| e.d),
                decided: !took && r.iter().all(|e| !e.doubt),
            })
        }
    }

    fn one(lo: f64, hi: f64, f: impl Fn(Enclosure<1>) -> Option<Enclosure<1>>) -> Vec<Root<1>> {
        let (mut r, _) = roots(
            [Interval::new(lo, hi)],
            &Limits::default(),
            enclosed(move |[x]| f(x).map(|y| [y])),
        );
        r.sort_by(|a, b| a.x[0].total_cmp(&b.x[0]));
        r
    }

    #[test]
    fn simple_roots_are_certified_to_the_ulp() {
        type E = Enclosure<1>;
        // (x − 0.3)(x + 0.7)(x − 0.301): three simple roots, two of them
        // 1e-3 apart.
        let r = one(-1.0, 1.0, |x| {
            Some((x - E::c(0.3)) * (x + E::c(0.7)) * (x - E::c(0.301)))
        });
        let want = [-0.7, 0.3, 0.301];
        assert_eq!(r.len(), 3, "{r:?}");
        for (r, w) in r.iter().zip(want) {
            assert_eq!(r.doubt, None);
            assert!(r.cert[0].contains(w), "{r:?}");
            assert!(r.cert[0].width() <= 1e-15, "{r:?}");
        }
        // sin(5x) on [−1, 1]: 0, ±π/5.
        let r = one(-1.0, 1.0, |x| Some((E::c(5.0) * x).sin()));
        assert_eq!(r.len(), 3);
        assert!(r.iter().all(|r| r.doubt.is_none()));
        assert!(r[2].cert[0].contains(std::f64::consts::PI / 5.0));
    }

    #[test]
    fn double_roots_and_edges_are_possible() {
        type E = Enclosure<1>;
        // (x − 0.31)²: one possible root, singular.
        let r = one(-1.0, 1.0, |x| Some((x - E::c(0.31)) * (x - E::c(0.31))));
        assert_eq!(r.len(), 1, "{r:?}");
        assert_eq!(r[0].doubt, Some(Doubt::Singular));
        assert!((r[0].x[0] - 0.31).abs() <= 1e-6);
        // A minimum 1e-6 above zero: no root, proven.
        assert!(one(-1.0, 1.0, |x| Some((x - E::c(0.31)) * (x - E::c(0.31)) + E::c(1e-6))).is_empty());
        // Two roots 1e-9 apart: both certified.
        let r = one(-1.0, 1.0, |x| Some((x - E::c(0.5)) * (x - E::c(0.5 + 1e-9))));
        assert_eq!(r.len(), 2, "{r:?}");
        assert!(r.iter().all(|r| r.doubt.is_none()));
        // A branch ending at its root: √(0.4 − x)·… meets zero at its edge.
        let r = one(-1.0, 1.0, |x| {
            let s = E::c(0.4) - x;
            Some(s.sqrt() - E::c(0.0))
        });
        assert_eq!(r.len(), 1, "{r:?}");
        assert_eq!(r[0].doubt, Some(Doubt::Edge));
        // Undefined everywhere: nothing.
        assert!(one(-1.0, 1.0, |_| None).is_empty());
    }

    #[test]
    fn two_unknowns() {
        type E = Enclosure<2>;
        // The unit circle meets the hyperbola x·y = 0.25 four times.
        let (r, stats) = roots(
            [Interval::new(-2.0, 2.0), Interval::new(-2.0, 2.0)],
            &Limits::default(),
            enclosed(|[x, y]| Some([x * x + y * y - E::c(1.0), x * y - E::c(0.25)])),
        );
        assert_eq!(r.len(), 4, "{r:?}");
        let a = ((2.0 + 3f64.sqrt()) / 4.0).sqrt();
        let b = ((2.0 - 3f64.sqrt()) / 4.0).sqrt();
        for root in &r {
            assert_eq!(root.doubt, None);
            let [x, y] = root.x;
            assert!(
                ((x.abs() - a).abs() <= 1e-15 && (y.abs() - b).abs() <= 1e-15)
                    || ((x.abs() - b).abs() <= 1e-15 && (y.abs() - a).abs() <= 1e-15),
                "{root:?}"
            );
        }
        assert!(stats.boxes < 5000, "{stats:?}");
    }

    /// Tracking: Newton's root from a start, proven alone between them;
    /// a Newton step that jumps over other roots is caught (sin x from
    /// 1.5: Newton lands near −4π, past −π, −2π, −3π and 0), a start where
    /// the Jacobian vanishes or a step leaves the region diverges.
    #[test]
    fn near_proves_the_root_it_reaches_alone() {
        let region = [Interval::new(-20.0, 20.0)];
        let square = |[x]: [Enclosure<1>; 1]| Some([x * x - Enclosure::c(1.0)]);
        let r = near([0.9], &region, 1e-6, &Limits::default(), enclosed(square)).unwrap();
        assert!(
            r.doubt.is_none() && r.cert[0].contains(1.0) && (r.x[0] - 1.0).abs() <= 1e-15,
            "{r:?}"
        );
        assert_eq!(
            near([0.0], &region, 1e-6, &Limits::default(), enclosed(square)),
            Err(Lost::Diverged)
        );
        let sine = |[x]: [Enclosure<1>; 1]| Some([x.sin()]);
        assert_eq!(
            near([1.5], &region, 1e-6, &Limits::default(), enclosed(sine)),
            Err(Lost::NotAlone)
        );
        let r = near([0.3], &region, 1e-6, &Limits::default(), enclosed(sine)).unwrap();
        assert!(r.x[0].abs() <= 1e-15 && r.cert[0].contains(0.0), "{r:?}");
        let narrow = [Interval::new(-0.5, 2.0)];
        assert_eq!(
            near([0.1], &narrow, 1e-6, &Limits::default(), enclosed(square)),
            Err(Lost::Diverged)
        );
    }
}
