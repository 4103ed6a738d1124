//! The forward position's equations in the platform's pose, one or two per
//! leg: the ball centre on its leg's sphere, `(Y − C)·(Y − C) = ρ²`, and
//! for a circle on its plane too, `N·(Y − C) = 0`; with the pose's
//! quaternion of unit length, `q·q = 1`. Seven polynomials in the seven
//! unknowns `x = (p, q)` (the platform frame's origin, in lengths over the
//! mechanism's size, and its rotation `R(q)`, quadratic in `q`), of degree
//! at most three.
//!
//! Written once over a ring ([`Ring`]): run on complex numbers carrying
//! their derivatives for the homotopy ([`super::homotopy`]), on
//! enclosures for the certificate ([`super::solve`]).

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

impl<const N: usize> Ring for crate::interval::Enclosure<N> {
    #[inline]
    fn c(v: f64) -> Self {
        crate::interval::Enclosure::constant(crate::interval::Interval::point(v))
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

/// `R(q)` of a unit quaternion `q = (w, x, y, z)`.
#[inline]
pub fn rotation<T: Ring>(q: &[T; 4]) -> [[T; 3]; 3] {
    let [w, x, y, z] = *q;
    let one = T::c(1.0);
    let two = T::c(2.0);
    [
        [
            one - two * (y * y + z * z),
            two * (x * y - w * z),
            two * (x * z + w * y),
        ],
        [
            two * (x * y + w * z),
            one - two * (x * x + z * z),
            two * (y * z - w * x),
        ],
        [
            two * (x * z - w * y),
            two * (y * z + w * x),
            one - two * (x * x + y * y),
        ],
    ]
}

#[inline]
fn turn<T: Ring>(r: &[[T; 3]; 3], v: &[T; 3]) -> [T; 3] {
    core::array::from_fn(|i| r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2])
}

#[inline]
fn dot<T: Ring>(a: &[T; 3], b: &[T; 3]) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
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

/// How many rows the loci `shape` give with the quaternion's.
pub fn rows(shape: &[(Body, bool)]) -> usize {
    shape.iter().map(|&(_, circle)| 1 + usize::from(circle)).sum::<usize>() + 1
}

/// The rows and their Jacobian at a real point `x` (on enclosures of
/// width zero: each the rounded value's enclosure's middle).
pub fn at(legs: &[Locus<f64>], x: &[f64; UNKNOWNS]) -> ([f64; UNKNOWNS], [[f64; UNKNOWNS]; UNKNOWNS]) {
    use crate::interval::{Enclosure, Interval};
    let vars: [Enclosure<UNKNOWNS>; UNKNOWNS] = core::array::from_fn(|k| Enclosure::variable(Interval::point(x[k]), k));
    let legs: Vec<Locus<Enclosure<UNKNOWNS>>> = legs.iter().map(|l| l.map(Enclosure::c)).collect();
    let mut out = [Enclosure::c(0.0); UNKNOWNS];
    residual(&vars, &legs, &mut out);
    (
        out.map(|r| r.v.mid()),
        core::array::from_fn(|r| out[r].d.map(|d| d.mid())),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

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
