//! Interval arithmetic, and intervals carrying their derivatives: the
//! [`Scalar`] on which a plan's steps enclose every value they can take
//! over a box of given values, with the enclosure of its partial
//! derivatives (what [`crate::certify`] proves roots with).
//!
//! An [`Interval`] `[lo, hi]` holds every real value the f64 path can
//! compute for any point of the box: each operation rounds its bounds
//! outward (one ulp for the arithmetic and the square root, which IEEE
//! rounds correctly; two for the sine, cosine and arctangent, which the
//! system's library computes within one). An empty interval (NaN bounds) is
//! a value undefined at every point of the box (the square root of a
//! negative interval), as the f64 path's NaN is; an unbounded one
//! (`[−∞, ∞]`, a division by an interval holding zero) is defined but
//! unknown.
//!
//! [`Enclosure`] is an interval with the intervals of its `N` partial
//! derivatives (forward mode, as [`crate::hyper_dual`] does on points):
//! every value the steps compute over the box, and every derivative, by
//! the chain rule on intervals.
//!
//! A decision a kernel takes on values ([`Scalar::require`],
//! [`Scalar::if_less`], a square root's or an absolute value's argument
//! across zero, an angle whose box holds the origin) may go both ways over
//! a box. The enclosure then holds both outcomes (a requirement is taken
//! as met, a selection is the hull of its two values), which is still an
//! enclosure of every value on the part of the box where the f64 path is
//! defined, so it can prove that a box holds no root; but the function
//! may be undefined, or not differentiable, somewhere in the box, so it
//! cannot prove one. Such a decision marks the values that depend on it
//! ([`Enclosure::doubt`]: a selection, a square root, an angle), or, a
//! requirement having no value, the whole evaluation ([`watch`]); a box
//! whose residual is in doubt is never certified: it is split until every
//! decision is taken one way, or reported as possible. A decision that
//! no row of the residual depends on (a passive joint's angle at a
//! half-turn, say) does not stand in the way.

use crate::primitives::{Error as GeomError, Sign};
use crate::scalar::{Failure, Scalar};
use core::cell::Cell;
use core::ops::{Add, Div, Mul, Neg, Sub};

thread_local! {
    static UNDECIDED: Cell<bool> = const { Cell::new(false) };
}

/// Records a decision that went both ways over the box being enclosed
/// (read by [`watch`]).
pub(crate) fn undecided() {
    UNDECIDED.with(|u| u.set(true));
}

/// Runs `f` and says whether a decision in it went both ways over the
/// box (see the module's text).
pub fn watch<R>(f: impl FnOnce() -> R) -> (R, bool) {
    let before = UNDECIDED.with(|u| u.replace(false));
    let r = f();
    let took = UNDECIDED.with(|u| u.replace(before));
    (r, took)
}

/// A closed interval of reals, rounded outward; NaN bounds: empty.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    /// The lower bound.
    pub lo: f64,
    /// The upper bound.
    pub hi: f64,
}

#[inline]
fn down(x: f64) -> f64 {
    if x.is_nan() {
        x
    } else {
        x.next_down()
    }
}

#[inline]
fn up(x: f64) -> f64 {
    if x.is_nan() {
        x
    } else {
        x.next_up()
    }
}

impl Interval {
    /// The empty interval.
    pub const EMPTY: Interval = Interval {
        lo: f64::NAN,
        hi: f64::NAN,
    };
    /// Every real.
    pub const ENTIRE: Interval = Interval {
        lo: f64::NEG_INFINITY,
        hi: f64::INFINITY,
    };

    /// `[lo, hi]` (empty where `lo > hi` or either is NaN).
    #[inline]
    pub fn new(lo: f64, hi: f64) -> Self {
        if lo <= hi {
            Interval { lo, hi }
        } else {
            Self::EMPTY
        }
    }

    /// The point `x`.
    #[inline]
    pub fn point(x: f64) -> Self {
        Interval { lo: x, hi: x }
    }

    /// Whether it holds no value.
    #[inline]
    pub fn is_empty(self) -> bool {
        self.lo.is_nan() || self.hi.is_nan()
    }

    /// Whether it is exactly zero.
    #[inline]
    pub fn is_zero(self) -> bool {
        self.lo == 0.0 && self.hi == 0.0
    }

    /// Whether it holds `x`.
    #[inline]
    pub fn contains(self, x: f64) -> bool {
        self.lo <= x && x <= self.hi
    }

    /// Whether every value of `self` is inside `other`, strictly.
    #[inline]
    pub fn inside(self, other: Interval) -> bool {
        other.lo < self.lo && self.hi < other.hi
    }

    /// `hi − lo`.
    #[inline]
    pub fn width(self) -> f64 {
        self.hi - self.lo
    }

    /// The midpoint (finite where both bounds are).
    #[inline]
    pub fn mid(self) -> f64 {
        0.5 * self.lo + 0.5 * self.hi
    }

    /// The larger of `|lo|` and `|hi|`.
    #[inline]
    pub fn mag(self) -> f64 {
        self.lo.abs().max(self.hi.abs())
    }

    /// The smallest interval holding both.
    #[inline]
    pub fn hull(self, o: Interval) -> Interval {
        match (self.is_empty(), o.is_empty()) {
            (true, _) => o,
            (_, true) => self,
            _ => Interval {
                lo: self.lo.min(o.lo),
                hi: self.hi.max(o.hi),
            },
        }
    }

    /// The common part (empty where none).
    #[inline]
    pub fn meet(self, o: Interval) -> Interval {
        Interval::new(self.lo.max(o.lo), self.hi.min(o.hi))
    }

    /// Widened outward by one ulp at each end.
    #[inline]
    fn out(lo: f64, hi: f64) -> Interval {
        Interval {
            lo: down(lo),
            hi: up(hi),
        }
    }

    /// Widened outward by two ulps (the library's transcendentals).
    #[inline]
    fn out2(lo: f64, hi: f64) -> Interval {
        Interval {
            lo: down(down(lo)),
            hi: up(up(hi)),
        }
    }

    /// The product's four bound products, `0·∞ = 0` (bounds are limits,
    /// not members).
    #[inline]
    fn mul_bounds(self, o: Interval) -> Interval {
        // By signs where both are finite and of one sign (the usual case):
        // two products.
        if self.lo >= 0.0 && o.lo >= 0.0 && self.hi.is_finite() && o.hi.is_finite() {
            return Interval::out(self.lo * o.lo, self.hi * o.hi);
        }
        if self.hi <= 0.0 && o.hi <= 0.0 && self.lo.is_finite() && o.lo.is_finite() {
            return Interval::out(self.hi * o.hi, self.lo * o.lo);
        }
        let p = |a: f64, b: f64| if a == 0.0 || b == 0.0 { 0.0 } else { a * b };
        let (a, b, c, d) = (p(self.lo, o.lo), p(self.lo, o.hi), p(self.hi, o.lo), p(self.hi, o.hi));
        Interval::out(a.min(b).min(c.min(d)), a.max(b).max(c.max(d)))
    }

    /// `1/self`; unbounded where it holds zero.
    #[inline]
    pub fn recip(self) -> Interval {
        if self.is_empty() {
            return self;
        }
        if self.contains(0.0) {
            return Self::ENTIRE;
        }
        Interval::out(1.0 / self.hi, 1.0 / self.lo)
    }

    /// The square root of the part at or above zero; empty where none is.
    #[inline]
    pub fn sqrt(self) -> Interval {
        if self.is_empty() || self.hi < 0.0 {
            return Self::EMPTY;
        }
        let lo = self.lo.max(0.0).sqrt();
        Interval {
            lo: if lo == 0.0 { 0.0 } else { down(lo) },
            hi: up(self.hi.sqrt()),
        }
    }

    /// The sine.
    #[inline]
    pub fn sin(self) -> Interval {
        (self - Interval::point(core::f64::consts::FRAC_PI_2)).cos()
    }

    /// The cosine: the ends' values, and ±1 where a multiple of π lies
    /// between them (looked for with a margin, so that π's rounding
    /// cannot hide one).
    #[inline]
    pub fn cos(self) -> Interval {
        use core::f64::consts::PI;
        if self.is_empty() {
            return self;
        }
        if self.width().is_nan() || self.width() >= 2.0 * PI {
            return Interval::new(-1.0, 1.0);
        }
        let (a, b) = (self.lo.cos(), self.hi.cos());
        let (mut lo, mut hi) = (a.min(b), a.max(b));
        let margin = 1e-15 * (1.0 + self.mag());
        // Even multiples of π: 1; odd: −1.
        let first = ((self.lo - margin) / PI).ceil();
        let last = ((self.hi + margin) / PI).floor();
        let mut k = first;
        while k <= last {
            if (k as i64).rem_euclid(2) == 0 {
                hi = 1.0;
            } else {
                lo = -1.0;
            }
            k += 1.0;
        }
        let r = Interval::out2(lo, hi);
        Interval {
            lo: r.lo.max(-1.0),
            hi: r.hi.min(1.0),
        }
    }

    /// The absolute value.
    #[inline]
    pub fn abs(self) -> Interval {
        if self.is_empty() || self.lo >= 0.0 {
            self
        } else if self.hi <= 0.0 {
            -self
        } else {
            Interval {
                lo: 0.0,
                hi: self.mag(),
            }
        }
    }
}

impl Add for Interval {
    type Output = Interval;
    #[inline]
    fn add(self, o: Interval) -> Interval {
        if self.is_empty() || o.is_empty() {
            return Interval::EMPTY;
        }
        // Exact: adding an exact zero.
        if o.is_zero() {
            return self;
        }
        if self.is_zero() {
            return o;
        }
        let lo = self.lo + o.lo;
        let hi = self.hi + o.hi;
        Interval::out(
            if lo.is_nan() { f64::NEG_INFINITY } else { lo },
            if hi.is_nan() { f64::INFINITY } else { hi },
        )
    }
}

impl Sub for Interval {
    type Output = Interval;
    #[inline]
    fn sub(self, o: Interval) -> Interval {
        self + (-o)
    }
}

impl Neg for Interval {
    type Output = Interval;
    #[inline]
    fn neg(self) -> Interval {
        Interval {
            lo: -self.hi,
            hi: -self.lo,
        }
    }
}

impl Mul for Interval {
    type Output = Interval;
    #[inline]
    fn mul(self, o: Interval) -> Interval {
        if self.is_empty() || o.is_empty() {
            return Interval::EMPTY;
        }
        // Exact: by an exact zero or one (a constant coordinate, a
        // derivative's seed).
        if self.is_zero() || o.is_zero() {
            return Interval::point(0.0);
        }
        if self == Interval::point(1.0) {
            return o;
        }
        if o == Interval::point(1.0) {
            return self;
        }
        self.mul_bounds(o)
    }
}

impl Div for Interval {
    type Output = Interval;
    #[inline]
    fn div(self, o: Interval) -> Interval {
        if self.is_empty() || o.is_empty() {
            return Interval::EMPTY;
        }
        if o.contains(0.0) {
            return if self.lo == 0.0 && self.hi == 0.0 {
                self
            } else {
                Interval::ENTIRE
            };
        }
        // Quotients of the bounds, rounded outward.
        let c = [self.lo / o.lo, self.lo / o.hi, self.hi / o.lo, self.hi / o.hi];
        let lo = c.iter().copied().filter(|x| !x.is_nan()).fold(f64::INFINITY, f64::min);
        let hi = c
            .iter()
            .copied()
            .filter(|x| !x.is_nan())
            .fold(f64::NEG_INFINITY, f64::max);
        Interval::out(lo, hi)
    }
}

/// The four-quadrant arctangent of `y/x` over a box, in (−π, π] as the
/// f64 path's [`crate::scalar::angle`], or, where the box crosses the
/// negative x-axis, in [0, 2π) (the same angles a turn apart: every use
/// of a joint's angle is periodic, a sine, a cosine, a wrapped
/// difference). A box holding the origin gives the whole turn (its
/// enclosure in doubt, [`Enclosure`]'s `atan2`).
#[inline]
fn atan2(y: Interval, x: Interval) -> Interval {
    use core::f64::consts::PI;
    if y.is_empty() || x.is_empty() {
        return Interval::EMPTY;
    }
    if y.contains(0.0) && x.contains(0.0) {
        return Interval::new(-PI, PI);
    }
    let across = x.lo < 0.0 && y.contains(0.0) && !(y.lo == 0.0 && y.hi == 0.0 && x.hi < 0.0);
    let at = |yy: f64, xx: f64| {
        let a = crate::scalar::angle(yy, xx);
        if across && a < 0.0 {
            a + 2.0 * PI
        } else {
            a
        }
    };
    let c = [at(y.lo, x.lo), at(y.lo, x.hi), at(y.hi, x.lo), at(y.hi, x.hi)];
    let lo = c.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = c.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    Interval::out2(lo, hi)
}

/// An interval with the intervals of its `N` partial derivatives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Enclosure<const N: usize> {
    /// The values.
    pub v: Interval,
    /// The partial derivatives.
    pub d: [Interval; N],
    /// Whether a decision this value depends on went both ways over the
    /// box (a selection switching inside it, a square root or an angle
    /// undefined on part of it): the value is enclosed, the derivatives
    /// are not those of one smooth function, and no certificate may rest
    /// on it. A value that does not depend on such a decision keeps its
    /// certificate though another in the same run took one.
    pub doubt: bool,
}

impl<const N: usize> Enclosure<N> {
    /// The `k`-th variable over `x`.
    #[inline]
    pub fn variable(x: Interval, k: usize) -> Self {
        Enclosure {
            v: x,
            d: core::array::from_fn(|i| Interval::point(if i == k { 1.0 } else { 0.0 })),
            doubt: false,
        }
    }

    /// A value constant over the box.
    #[inline]
    pub fn constant(x: Interval) -> Self {
        Enclosure {
            v: x,
            d: [Interval::point(0.0); N],
            doubt: false,
        }
    }

    /// `f(self)` with `f(v)` and `f'(v)` given.
    #[inline]
    fn chain(self, f: Interval, df: Interval) -> Self {
        Enclosure {
            v: f,
            d: self.d.map(|d| df * d),
            doubt: self.doubt,
        }
    }
}

impl<const N: usize> Add for Enclosure<N> {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        Enclosure {
            v: self.v + o.v,
            d: core::array::from_fn(|i| self.d[i] + o.d[i]),
            doubt: self.doubt || o.doubt,
        }
    }
}

impl<const N: usize> Sub for Enclosure<N> {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        Enclosure {
            v: self.v - o.v,
            d: core::array::from_fn(|i| self.d[i] - o.d[i]),
            doubt: self.doubt || o.doubt,
        }
    }
}

impl<const N: usize> Neg for Enclosure<N> {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        Enclosure {
            v: -self.v,
            d: self.d.map(|d| -d),
            doubt: self.doubt,
        }
    }
}

#[allow(clippy::suspicious_arithmetic_impl)] // the product rule
impl<const N: usize> Mul for Enclosure<N> {
    type Output = Self;
    #[inline]
    fn mul(self, o: Self) -> Self {
        Enclosure {
            v: self.v * o.v,
            d: core::array::from_fn(|i| self.d[i] * o.v + self.v * o.d[i]),
            doubt: self.doubt || o.doubt,
        }
    }
}

#[allow(clippy::suspicious_arithmetic_impl)] // the quotient rule
impl<const N: usize> Div for Enclosure<N> {
    type Output = Self;
    #[inline]
    fn div(self, o: Self) -> Self {
        let q = self.v / o.v;
        let inv = o.v.recip();
        Enclosure {
            v: q,
            d: core::array::from_fn(|i| (self.d[i] - q * o.d[i]) * inv),
            doubt: self.doubt || o.doubt,
        }
    }
}

/// `then` where every `a` is below every `b`, `otherwise` where none is
/// (or either is empty: NaN compares false in the f64 path); both ways,
/// the hull of the two values and of their derivatives, recorded as
/// undecided unless the selection is `continuous` where it switches (its
/// hull then holds the generalised gradient).
#[inline]
fn select<const N: usize>(
    a: Enclosure<N>,
    b: Enclosure<N>,
    then: Enclosure<N>,
    otherwise: Enclosure<N>,
    continuous: bool,
) -> Enclosure<N> {
    if a.v.is_empty() || b.v.is_empty() || a.v.lo >= b.v.hi {
        otherwise
    } else if a.v.hi < b.v.lo {
        then
    } else {
        Enclosure {
            v: then.v.hull(otherwise.v),
            d: core::array::from_fn(|i| then.d[i].hull(otherwise.d[i])),
            doubt: !continuous || then.doubt || otherwise.doubt,
        }
    }
}

impl<const N: usize> Scalar for Enclosure<N> {
    type Choice = Sign;

    #[inline]
    fn c(x: f64) -> Self {
        Self::constant(Interval::point(x))
    }
    #[inline]
    fn sqrt(self) -> Self {
        // Undefined on part of the box: the edge of its real values. (At
        // zero itself the derivative's enclosure is unbounded, which no
        // certificate passes.)
        let edge = self.v.lo < 0.0 && self.v.hi >= 0.0;
        let r = self.v.sqrt();
        let mut e = self.chain(r, (r + r).recip());
        e.doubt |= edge;
        e
    }
    #[inline]
    fn sin(self) -> Self {
        self.chain(self.v.sin(), self.v.cos())
    }
    #[inline]
    fn cos(self) -> Self {
        self.chain(self.v.cos(), -self.v.sin())
    }
    #[inline]
    fn atan2(self, x: Self) -> Self {
        // A box holding the origin: every angle, no derivative.
        let origin = self.v.contains(0.0) && x.v.contains(0.0);
        let v = atan2(self.v, x.v);
        let r2 = x.v * x.v + self.v * self.v;
        Enclosure {
            v,
            d: core::array::from_fn(|i| (x.v * self.d[i] - self.v * x.d[i]) / r2),
            doubt: origin || self.doubt || x.doubt,
        }
    }
    #[inline]
    fn abs(self) -> Self {
        if self.v.is_empty() || self.v.lo >= 0.0 {
            self
        } else if self.v.hi <= 0.0 {
            -self
        } else {
            // Continuous (Lipschitz) across zero: the hull of ±d holds
            // its generalised gradient.
            Enclosure {
                v: self.v.abs(),
                d: self.d.map(|d| d.hull(-d)),
                doubt: self.doubt,
            }
        }
    }
    #[inline]
    fn if_less(a: Self, b: Self, then: Self, otherwise: Self) -> Self {
        select(a, b, then, otherwise, false)
    }
    #[inline]
    fn if_less_continuous(a: Self, b: Self, then: Self, otherwise: Self) -> Self {
        select(a, b, then, otherwise, true)
    }
    #[inline]
    fn require(a: Self, b: Self, failure: Failure<Self>, _site: [usize; 2]) -> Result<(), GeomError<f64>> {
        if a.v.is_empty() || b.v.is_empty() || a.v.lo >= b.v.hi {
            Err(failure.map(|x| x.v.mid()).error())
        } else {
            if a.v.hi >= b.v.lo {
                undecided();
            }
            Ok(())
        }
    }
    #[inline]
    fn pick(choice: Sign, plus: Self, minus: Self) -> Self {
        choice.pick(plus, minus)
    }
    #[inline]
    fn choice(signs: &[Sign], k: Option<usize>) -> Sign {
        Sign::nth(signs, k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::SplitMix;

    fn uniform(rng: &mut SplitMix) -> f64 {
        0.5 * (rng.symmetric() + 1.0)
    }

    /// Every operation's enclosure holds the f64 path's value at random
    /// points of random boxes, and the derivative's holds a central
    /// difference's (to its error).
    #[test]
    fn enclosures_hold_the_points() {
        let mut rng = SplitMix::new(7);
        type E = Enclosure<1>;
        type Case = (&'static str, fn(E) -> E, fn(f64) -> f64);
        let fs: [Case; 8] = [
            ("x·x − 3x", |x| x * x - E::c(3.0) * x, |x| x * x - 3.0 * x),
            ("sin", |x| x.sin(), f64::sin),
            ("cos 5x", |x| (E::c(5.0) * x).cos(), |x| (5.0 * x).cos()),
            ("sqrt(x²+1)", |x| (x * x + E::c(1.0)).sqrt(), |x| (x * x + 1.0).sqrt()),
            ("1/(x+4)", |x| E::c(1.0) / (x + E::c(4.0)), |x| 1.0 / (x + 4.0)),
            (
                "atan2(x, −1)",
                |x| x.atan2(E::c(-1.0)),
                |x| crate::scalar::angle(x, -1.0),
            ),
            ("atan2(1, x)", |x| E::c(1.0).atan2(x), |x| crate::scalar::angle(1.0, x)),
            ("|x − 0.1|", |x| (x - E::c(0.1)).abs(), |x| (x - 0.1).abs()),
        ];
        for (name, f, g) in fs {
            for _ in 0..2000 {
                let c = 3.0 * rng.symmetric();
                let w = 10f64.powf(-6.0 * uniform(&mut rng)) * uniform(&mut rng);
                let b = Interval::new(c - w, c + w);
                let e = f(E::variable(b, 0));
                for _ in 0..5 {
                    let x = b.lo + (b.hi - b.lo) * uniform(&mut rng);
                    let y = g(x);
                    // Angles a turn apart are one (see `atan2`).
                    let held = e.v.contains(y) || e.v.contains(y + 2.0 * core::f64::consts::PI);
                    assert!(held, "{name} over {b:?} at {x}: {y} not in {:?}", e.v);
                    let h = 1e-6;
                    if b.contains(x - h) && b.contains(x + h) {
                        let fd = (g(x + h) - g(x - h)) / (2.0 * h);
                        let d = e.d[0];
                        assert!(
                            d.lo - 1e-6 <= fd && fd <= d.hi + 1e-6,
                            "{name}' over {b:?} at {x}: {fd} vs {d:?}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn edges_and_decisions() {
        // A square root of a negative interval is empty; across zero,
        // undecided.
        let r = Enclosure::<1>::variable(Interval::new(-2.0, -1.0), 0).sqrt();
        assert!(r.v.is_empty() && !r.doubt);
        let r = Enclosure::<1>::variable(Interval::new(-1.0, 4.0), 0).sqrt();
        assert!(r.v.lo == 0.0 && r.v.hi >= 2.0 && r.doubt);
        let r = Enclosure::<1>::variable(Interval::new(1.0, 4.0), 0).sqrt();
        assert!(!r.doubt);
        // The doubt follows the values that depend on the decision, and
        // only those.
        let x = Enclosure::<1>::variable(Interval::new(-1.0, 4.0), 0);
        let (both, took) = watch(|| (x.sqrt() * x, x * x + Enclosure::c(1.0)));
        assert!(both.0.doubt && !both.1.doubt && !took);
        // An angle over a box holding the origin.
        let o = Enclosure::<1>::variable(Interval::new(-1.0, 1.0), 0);
        assert!(o.atan2(o).doubt && !x.atan2(Enclosure::c(1.0)).doubt);
        // A requirement met on part of the box marks the whole evaluation.
        let (_, took) = watch(|| Enclosure::<1>::require(Enclosure::c(0.0), x, Failure::Degenerate("test"), [0, 0]));
        assert!(took);
        // Division by an interval holding zero: unbounded, not empty.
        let q = Interval::point(1.0) / Interval::new(-1.0, 1.0);
        assert_eq!(q, Interval::ENTIRE);
        let z = q * Interval::point(0.0);
        assert!(z.contains(0.0) && z.width() <= 1e-300, "{z:?}");
        // The cosine over [3, 3.3] holds −1 (π inside).
        assert_eq!(Interval::new(3.0, 3.3).cos().lo, -1.0);
        assert!(Interval::new(0.1, 0.2).cos().hi < 1.0);
        // An undecided selection is the hull.
        type E = Enclosure<1>;
        let a = E::variable(Interval::new(-1.0, 1.0), 0);
        let s = E::if_less(a, E::c(0.0), E::c(2.0), E::c(5.0));
        assert!(s.doubt && s.v.lo <= 2.0 && s.v.hi >= 5.0);
        // A continuous one (a maximum) is not in doubt; one decided is the
        // arm taken, with its own doubt.
        assert!(!E::if_less_continuous(a, E::c(0.0), E::c(2.0), E::c(5.0)).doubt);
        assert!(!E::if_less(E::c(-2.0), a, E::c(2.0), a.sqrt()).doubt);
    }
}
