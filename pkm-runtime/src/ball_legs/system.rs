//! The forward position's equations in the platform's pose, one or two per
//! leg: the ball centre on its leg's sphere, `(Y − C)·(Y − C) = ρ²`, and
//! for a circle on its plane too, `N·(Y − C) = 0`; with the pose's
//! quaternion of unit length, `q·q = 1`. Seven polynomials in the seven
//! unknowns `x = (p, q)` (the platform frame's origin, in lengths over the
//! mechanism's size, and its rotation `R(q)`, quadratic in `q`), of degree
//! at most three.
//!
//! The rows ([`residual`]) and their slopes written out ([`with_slopes`]),
//! each once over a ring ([`Ring`]): on complex numbers for the homotopy
//! ([`super::homotopy`]), on intervals for the certificate
//! ([`super::solve`]), on `f64` for Newton's method; the slopes are
//! tested against the rows differentiated forward.

use crate::interval::Interval;
use core::ops::{Add, Mul, Neg, Sub};

/// What the equations need of a number: sums, differences, products and
/// real constants.
pub trait Ring: Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Neg<Output = Self> {
    /// A real constant.
    fn c(v: f64) -> Self;
}

impl Ring for f64 {
    #[inline]
    fn c(v: f64) -> Self {
        v
    }
}

impl Ring for nalgebra::Complex<f64> {
    #[inline]
    fn c(v: f64) -> Self {
        nalgebra::Complex::new(v, 0.0)
    }
}

impl Ring for Interval {
    #[inline]
    fn c(v: f64) -> Self {
        Interval::point(v)
    }
}

/// Which body a leg's locus is fixed in; its ball centre is fixed in the
/// other.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Body {
    /// The base: a U-P-S, R-P-S or P-R-S leg, its ball on the platform.
    Base,
    /// The platform: an S-P-R leg, its ball on the base.
    Platform,
}

/// One leg's locus, the parameters of its equations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Locus<T> {
    /// The body the locus is fixed in.
    pub on: Body,
    /// The ball centre, in the other body's frame.
    pub ball: [T; 3],
    /// The sphere's (and circle's) centre, in `on`'s frame.
    pub centre: [T; 3],
    /// A circle's plane normal, in `on`'s frame; `None`: a sphere.
    pub normal: Option<[T; 3]>,
    /// The squared radius.
    pub radius2: T,
}

impl<T: Copy> Locus<T> {
    /// The same locus with every number mapped.
    pub fn map<U>(&self, f: impl Fn(T) -> U) -> Locus<U> {
        Locus {
            on: self.on,
            ball: self.ball.map(&f),
            centre: self.centre.map(&f),
            normal: self.normal.map(|n| n.map(&f)),
            radius2: f(self.radius2),
        }
    }
}

/// How many unknowns: the platform's origin and its quaternion.
pub const UNKNOWNS: usize = 7;

/// At most this many legs (six rows and the quaternion's).
pub const LEGS: usize = UNKNOWNS - 1;

impl<T: Copy> Locus<T> {
    /// This locus and another of its kind combined number by number.
    pub fn zip_map<U>(&self, other: &Locus<T>, f: impl Fn(T, T) -> U) -> Locus<U> {
        let three = |a: [T; 3], b: [T; 3]| core::array::from_fn(|i| f(a[i], b[i]));
        Locus {
            on: self.on,
            ball: three(self.ball, other.ball),
            centre: three(self.centre, other.centre),
            normal: self.normal.zip(other.normal).map(|(a, b)| three(a, b)),
            radius2: f(self.radius2, other.radius2),
        }
    }
}

/// At most [`LEGS`] loci on the stack, and how many (no allocation where
/// the equations are evaluated many times).
pub fn on_stack<T: Ring>(legs: impl Iterator<Item = Locus<T>>) -> ([Locus<T>; LEGS], usize) {
    let zero = T::c(0.0);
    let mut at = [Locus {
        on: Body::Base,
        ball: [zero; 3],
        centre: [zero; 3],
        normal: None,
        radius2: zero,
    }; LEGS];
    let mut n = 0;
    for (slot, leg) in at.iter_mut().zip(legs) {
        *slot = leg;
        n += 1;
    }
    (at, n)
}

/// `v + v`: twice `v`, exactly (no product by a constant 2, which on
/// complex numbers is four products).
#[inline]
fn twice<T: Ring>(v: T) -> T {
    v + v
}

/// `R(q)` of a unit quaternion `q = (w, x, y, z)`.
#[inline]
pub fn rotation<T: Ring>(q: &[T; 4]) -> [[T; 3]; 3] {
    let [w, x, y, z] = *q;
    let one = T::c(1.0);
    [
        [one - twice(y * y + z * z), twice(x * y - w * z), twice(x * z + w * y)],
        [twice(x * y + w * z), one - twice(x * x + z * z), twice(y * z - w * x)],
        [twice(x * z - w * y), twice(y * z + w * x), one - twice(x * x + y * y)],
    ]
}

/// `R·v`.
#[inline]
pub(super) fn turn<T: Ring>(r: &[[T; 3]; 3], v: &[T; 3]) -> [T; 3] {
    core::array::from_fn(|i| r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2])
}

/// `a·b` (no conjugate: a polynomial on complex numbers too).
#[inline]
pub(super) fn dot<T: Ring, const N: usize>(a: &[T; N], b: &[T; N]) -> T {
    let mut sum = a[0] * b[0];
    for k in 1..N {
        sum = sum + a[k] * b[k];
    }
    sum
}

/// The rows at `x` for the loci `legs` (one per sphere, two per circle,
/// then `q·q − 1`), written into `out`; how many were written. `out` must
/// hold [`UNKNOWNS`] rows.
pub fn residual<T: Ring>(x: &[T; UNKNOWNS], legs: &[Locus<T>], out: &mut [T; UNKNOWNS]) -> usize {
    let p = [x[0], x[1], x[2]];
    let q = [x[3], x[4], x[5], x[6]];
    let r = rotation(&q);
    let mut k = 0;
    for leg in legs {
        let placed = |v: &[T; 3]| {
            let t = turn(&r, v);
            [p[0] + t[0], p[1] + t[1], p[2] + t[2]]
        };
        let (y, c, n) = match leg.on {
            Body::Base => (placed(&leg.ball), leg.centre, leg.normal),
            Body::Platform => (leg.ball, placed(&leg.centre), leg.normal.map(|n| turn(&r, &n))),
        };
        let d = [y[0] - c[0], y[1] - c[1], y[2] - c[2]];
        if k < UNKNOWNS {
            out[k] = dot(&d, &d) - leg.radius2;
        }
        k += 1;
        if let Some(n) = n {
            if k < UNKNOWNS {
                out[k] = dot(&n, &d);
            }
            k += 1;
        }
    }
    if k < UNKNOWNS {
        out[k] = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3] - T::c(1.0);
    }
    k + 1
}

/// `∂(R(q)·v)/∂q_k` for `q_k` = w, x, y, z: the slopes of [`rotation`]'s
/// polynomial (not of a normalised rotation: `q·q = 1` is a row of its
/// own), each `2·(∂R/∂q_k)/2·v` written out:
/// `∂R/∂w = 2[u]×` with `u = (x, y, z)`,
/// `∂R/∂x = 2[[0, y, z], [y, −2x, −w], [z, w, −2x]]`,
/// `∂R/∂y = 2[[−2y, x, w], [x, 0, z], [−w, z, −2y]]`,
/// `∂R/∂z = 2[[−2z, −w, x], [w, −2z, y], [x, y, 0]]`.
#[inline]
pub fn turn_slopes<T: Ring>(q: &[T; 4], v: &[T; 3]) -> [[T; 3]; 4] {
    let [w, x, y, z] = *q;
    let [a, b, c] = *v;
    let t = twice::<T>;
    [
        [t(y * c - z * b), t(z * a - x * c), t(x * b - y * a)],
        [
            t(y * b + z * c),
            t(y * a - w * c) - t(t(x * b)),
            t(z * a + w * b) - t(t(x * c)),
        ],
        [
            t(x * b + w * c) - t(t(y * a)),
            t(x * a + z * c),
            t(z * b - w * a) - t(t(y * c)),
        ],
        [
            t(x * c - w * b) - t(t(z * a)),
            t(w * a + y * c) - t(t(z * b)),
            t(x * a + y * b),
        ],
    ]
}

/// The rows (as [`residual`] writes them), their Jacobian by the unknowns
/// and their rate along a path of loci: the loci `legs` at the path's
/// point, `rates` their derivatives along it (`None`: a fixed point, rate
/// zero). Written out by the chain rule, no derivative carried through
/// the products: with `d = Y − C` (the ball centre less the locus's
/// centre, both in the locus's body), a sphere's row `d·d − ρ²` has the
/// slopes `2d·∂d`, a circle's plane row `N·d` the slopes `∂N·d + N·∂d`;
/// `∂d/∂p = ±I`, `∂d/∂q` from [`turn_slopes`].
pub fn with_slopes<T: Ring>(x: &[T; UNKNOWNS], legs: &[Locus<T>], rates: Option<&[Locus<T>]>) -> Slopes<T> {
    let zero = T::c(0.0);
    let p = [x[0], x[1], x[2]];
    let q = [x[3], x[4], x[5], x[6]];
    let r = rotation(&q);
    let mut out = Slopes {
        f: [zero; UNKNOWNS],
        j: [[zero; UNKNOWNS]; UNKNOWNS],
        ds: [zero; UNKNOWNS],
    };
    let sub = |a: [T; 3], b: [T; 3]| -> [T; 3] { [a[0] - b[0], a[1] - b[1], a[2] - b[2]] };
    let mut k = 0;
    for (i, leg) in legs.iter().enumerate() {
        let rate = rates.map(|r| &r[i]);
        // d, its slopes by p (whether +I or −I) and by q, its rate; the
        // plane's normal, its slopes by q and its rate.
        let (d, plus_p, d_q, d_s, n, n_q, n_s) = match leg.on {
            Body::Base => {
                let y = turn(&r, &leg.ball);
                let d = [
                    p[0] + y[0] - leg.centre[0],
                    p[1] + y[1] - leg.centre[1],
                    p[2] + y[2] - leg.centre[2],
                ];
                let d_s = rate.map(|v| sub(turn(&r, &v.ball), v.centre));
                (
                    d,
                    true,
                    turn_slopes(&q, &leg.ball),
                    d_s,
                    leg.normal,
                    None,
                    rate.and_then(|v| v.normal),
                )
            }
            Body::Platform => {
                let c = turn(&r, &leg.centre);
                let d = [
                    leg.ball[0] - p[0] - c[0],
                    leg.ball[1] - p[1] - c[1],
                    leg.ball[2] - p[2] - c[2],
                ];
                let d_q = turn_slopes(&q, &leg.centre).map(|v| v.map(|e| -e));
                let d_s = rate.map(|v| sub(v.ball, turn(&r, &v.centre)));
                let n = leg.normal.map(|n| turn(&r, &n));
                let n_q = leg.normal.map(|n| turn_slopes(&q, &n));
                let n_s = rate.and_then(|v| v.normal.map(|m| turn(&r, &m)));
                (d, false, d_q, d_s, n, n_q, n_s)
            }
        };
        if k < UNKNOWNS {
            out.f[k] = dot(&d, &d) - leg.radius2;
            for (slot, d_a) in out.j[k][..3].iter_mut().zip(d) {
                *slot = if plus_p { twice(d_a) } else { -twice(d_a) };
            }
            for (slot, d_m) in out.j[k][3..].iter_mut().zip(&d_q) {
                *slot = twice(dot(&d, d_m));
            }
            if let (Some(d_s), Some(v)) = (d_s, rate) {
                out.ds[k] = twice(dot(&d, &d_s)) - v.radius2;
            }
        }
        k += 1;
        if let Some(n) = n {
            if k < UNKNOWNS {
                out.f[k] = dot(&n, &d);
                for (slot, n_a) in out.j[k][..3].iter_mut().zip(n) {
                    *slot = if plus_p { n_a } else { -n_a };
                }
                for (m, (slot, d_m)) in out.j[k][3..].iter_mut().zip(&d_q).enumerate() {
                    let turned = n_q.map_or(zero, |n_q| dot(&n_q[m], &d));
                    *slot = turned + dot(&n, d_m);
                }
                if let Some(d_s) = d_s {
                    out.ds[k] = n_s.map_or(zero, |n_s| dot(&n_s, &d)) + dot(&n, &d_s);
                }
            }
            k += 1;
        }
    }
    if k < UNKNOWNS {
        out.f[k] = dot(&q, &q) - T::c(1.0);
        for (slot, q_m) in out.j[k][3..].iter_mut().zip(q) {
            *slot = twice(q_m);
        }
    }
    out
}

/// The rows at a point, their Jacobian by the unknowns and their rate
/// along a path of loci ([`with_slopes`]).
#[derive(Debug, Clone, Copy)]
pub struct Slopes<T> {
    /// The rows.
    pub f: [T; UNKNOWNS],
    /// `∂f/∂x`.
    pub j: [[T; UNKNOWNS]; UNKNOWNS],
    /// `∂f/∂s`.
    pub ds: [T; UNKNOWNS],
}

/// How many rows the loci `shape` give with the quaternion's.
pub fn rows(shape: &[(Body, bool)]) -> usize {
    shape.iter().map(|&(_, circle)| 1 + usize::from(circle)).sum::<usize>() + 1
}

/// The rows and their Jacobian enclosed over the box `b` ([`with_slopes`]
/// on intervals: any expression of the slopes, evaluated in interval
/// arithmetic rounded outward, encloses them over the box), the loci's
/// numbers as points.
pub fn enclosed(legs: &[Locus<f64>], b: &[Interval; UNKNOWNS]) -> Slopes<Interval> {
    let (at, n) = on_stack(legs.iter().map(|l| l.map(Interval::point)));
    with_slopes(b, &at[..n], None)
}

/// The rows and their Jacobian at a real point `x` ([`with_slopes`]).
pub fn at(legs: &[Locus<f64>], x: &[f64; UNKNOWNS]) -> ([f64; UNKNOWNS], [[f64; UNKNOWNS]; UNKNOWNS]) {
    let s = with_slopes(x, legs, None);
    (s.f, s.j)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interval::Enclosure;
    use crate::random::SplitMix;

    /// Forward differentiation through [`residual`] (the other way to the
    /// same slopes): point intervals carrying their derivatives by the
    /// seven unknowns and by the path's parameter `s` (slot 7).
    type Jet = Enclosure<{ UNKNOWNS + 1 }>;

    impl Ring for Jet {
        fn c(v: f64) -> Self {
            Enclosure::constant(Interval::point(v))
        }
    }

    /// The written-out slopes against forward differentiation through the
    /// rows, at random points on random loci of every kind (a sphere and a
    /// circle on each body), with random rates. Both sides are
    /// polynomials in the points and loci: equal at random real points,
    /// they are equal on complex ones too.
    #[test]
    fn written_slopes_are_the_differentiated_rows() {
        let mut rng = SplitMix::new(7);
        for trial in 0..50 {
            let kinds = [
                (Body::Base, false),
                (Body::Base, true),
                (Body::Platform, false),
                (Body::Platform, true),
            ];
            let mut legs = Vec::new();
            let mut rates = Vec::new();
            for &(on, circle) in kinds.iter().cycle().skip(trial % 4).take(3) {
                let mut locus = || Locus {
                    on,
                    ball: [rng.symmetric(), rng.symmetric(), rng.symmetric()],
                    centre: [rng.symmetric(), rng.symmetric(), rng.symmetric()],
                    normal: circle.then(|| [rng.symmetric(), rng.symmetric(), rng.symmetric()]),
                    radius2: rng.symmetric(),
                };
                legs.push(locus());
                rates.push(locus());
            }
            let x: [f64; UNKNOWNS] = core::array::from_fn(|_| rng.symmetric());
            let got = with_slopes(&x, &legs, Some(&rates));
            let vars: [Jet; UNKNOWNS] = core::array::from_fn(|k| Enclosure::variable(Interval::point(x[k]), k));
            let jets: Vec<Locus<Jet>> = legs
                .iter()
                .zip(&rates)
                .map(|(l, r)| {
                    l.zip_map(r, |v, dv| {
                        let mut e = Jet::c(v);
                        e.d[UNKNOWNS] = Interval::point(dv);
                        e
                    })
                })
                .collect();
            let mut out = [Jet::c(0.0); UNKNOWNS];
            let n = residual(&vars, &jets, &mut out).min(UNKNOWNS);
            let close = |a: f64, b: Interval| (a - b.mid()).abs() <= 1e-13 * (1.0 + b.mid().abs());
            for (r, row) in out[..n].iter().enumerate() {
                assert!(close(got.f[r], row.v), "trial {trial} row {r}");
                assert!(close(got.ds[r], row.d[UNKNOWNS]), "trial {trial} row {r} rate");
                for k in 0..UNKNOWNS {
                    assert!(close(got.j[r][k], row.d[k]), "trial {trial} row {r} column {k}");
                }
            }
        }
    }

    /// A pose, loci through it by hand (a sphere on the base, a circle on
    /// the platform), and the rows' Jacobian against central differences.
    #[test]
    fn rows_vanish_at_their_pose_and_the_jacobian_is_their_slope() {
        let (h, c, s) = (0.3f64, 0.8f64.cos(), 0.8f64.sin());
        // R about z by 0.8 rad: q = (cos 0.4, 0, 0, sin 0.4).
        let x = [0.1, -0.2, h, (0.4f64).cos(), 0.0, 0.0, (0.4f64).sin()];
        let b = [1.0, 0.0, 0.0];
        let y = [0.1 + c, -0.2 + s, h]; // p + R·b
        let sphere = Locus {
            on: Body::Base,
            ball: b,
            centre: [0.0, 0.0, 0.0],
            normal: None,
            radius2: y[0] * y[0] + y[1] * y[1] + y[2] * y[2],
        };
        // A base point (0, 0, 0) seen from the platform: Rᵀ(−p).
        let local = [-(c * 0.1 + s * -0.2), -(-s * 0.1 + c * -0.2), -h];
        let circle = Locus {
            on: Body::Platform,
            ball: [0.0, 0.0, 0.0],
            centre: [local[0] - 0.5, local[1], local[2]],
            normal: Some([0.0, 1.0, 0.0]),
            radius2: 0.25,
        };
        let legs = [sphere, circle];
        let mut out = [0.0; UNKNOWNS];
        assert_eq!(residual(&x, &legs, &mut out), 4);
        for v in &out[..4] {
            assert!(v.abs() < 1e-15, "{out:?}");
        }
        let (_, j) = at(&legs, &x);
        for k in 0..UNKNOWNS {
            let mut up = x;
            let mut down = x;
            up[k] += 1e-6;
            down[k] -= 1e-6;
            let (mut fu, mut fd) = ([0.0; UNKNOWNS], [0.0; UNKNOWNS]);
            residual(&up, &legs, &mut fu);
            residual(&down, &legs, &mut fd);
            for r in 0..4 {
                let slope = (fu[r] - fd[r]) / 2e-6;
                assert!(
                    (slope - j[r][k]).abs() < 1e-8,
                    "row {r} column {k}: {slope} {}",
                    j[r][k]
                );
            }
        }
    }
}
