//! Closed-form geometric primitives: small named subproblems that generated
//! kinematics solvers are composed from (in the style of the IK-Geo
//! subproblems and the Paden–Kahan subproblems).
//!
//! # Conventions
//!
//! * **Scalars** are generic over [`Real`] (`f64` today, a dual number later).
//! * **Points and vectors** are plain arrays: `[T; 2]` = `(x, y)` in the plane,
//!   `[T; 3]` = `(x, y, z)` in space. Arrays keep the primitives free of any
//!   trait bound beyond [`Real`]; with nalgebra use `Vector3::from(a)` and
//!   `v.into()` to convert.
//! * **Directions** (line directions, rotation axes, plane normals) need not be
//!   unit length; they are normalised internally and a zero-length one is a
//!   [`Error::Degenerate`]. Line parameters `t` are always measured in length
//!   units along the *normalised* direction.
//! * **Angles** are in radians, right-handed (counter-clockwise in the plane,
//!   right-hand rule about a 3D axis), and returned in `[-π, π]`.
//! * **Results** never panic and never allocate. A primitive with two assembly
//!   branches returns `Result<`[`Roots2`]`<S>, `[`Error`]`<T>>`; one with a single
//!   solution returns `Result<S, Error<T>>`. Non-finite inputs (and non-finite
//!   results from overflow) are reported as [`Error::Degenerate`], never as a
//!   silent NaN.
//! * **Branches** are named by a [`Sign`]: each primitive documents what its
//!   `Plus` and `Minus` branch are, and `Roots2::branches()[0]` is always
//!   `Plus`, so callers can enumerate assembly modes in a fixed order.
//! * **Tolerances** are relative to the scale of the subproblem and are the
//!   two documented constants [`TANGENCY_TOL`] and [`PARALLEL_TOL`].
//!
//! # Families
//!
//! * [`scalar`]: [`trig_equation`], [`stable_quadratic`].
//! * [`spatial`]: [`line_plane`], [`line_sphere`], [`trilaterate`],
//!   [`rotate_to_distance`], [`circle_to_distance`].
//! * [`paden_kahan`]: [`pk1`], [`pk2`], [`pk3`].

use crate::real::Real;

pub mod paden_kahan;
pub mod scalar;
pub mod spatial;
#[cfg(test)]
mod testing;
mod vec;

pub use paden_kahan::{pk1, pk2, pk3};
pub use scalar::{stable_quadratic, trig_equation, QuadraticRoots};
pub use spatial::{circle_to_distance, line_plane, line_sphere, rotate_to_distance, trilaterate};

/// Relative tolerance for tangency (double roots) and for data consistency.
///
/// When a primitive's existence condition has the form `x ≤ y` (e.g. the
/// centre distance of two circles `d ≤ r1 + r2`, or `|c| ≤ hypot(a, b)`), an
/// excess `x − y` of at most `TANGENCY_TOL · scale` — `scale` being the
/// largest length (or coefficient magnitude) of that condition, documented per
/// primitive — is treated as rounding: the radicand is clamped to zero and the
/// result is [`Roots2::Tangent`]. A larger excess is an
/// [`Error::Unreachable`] whose `by` is the excess. The same tolerance decides
/// whether data that must agree exactly (e.g. `|p| = |q|` in [`pk1`]) agree.
///
/// `1e-9` is far above the rounding error of the formulas (a few ulps,
/// ≈ `1e-15` relative) and far below any mechanically meaningful gap
/// (a nanometre on a one-metre mechanism).
pub const TANGENCY_TOL: f64 = 1e-9;

/// Smallest `|sin(angle)|` between two directions that are *not* parallel.
///
/// Line–line, line–plane, axis–axis and collinearity tests compare the sine
/// of the angle between unit directions with this constant; at or below it
/// the configuration is an [`Error::Degenerate`]. Just above it the result is
/// valid but ill-conditioned: its relative accuracy is about `ε / |sin|`.
pub const PARALLEL_TOL: f64 = 1e-12;

/// A point on a line, with its line parameter.
///
/// `point = line_point + t · unit(line_dir)`: `t` is the signed distance along
/// the normalised direction from the line's given point.
///
/// # Example
///
/// ```
/// use pkm_runtime::primitives::{line_plane, LinePoint};
///
/// let hit = line_plane([0.0, 0.0, 0.0], [0.0, 0.0, 2.0], [0.0, 0.0, 3.0], [0.0, 0.0, 1.0]);
/// assert_eq!(hit, Ok(LinePoint { t: 3.0, point: [0.0, 0.0, 3.0] }));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinePoint<T, const N: usize> {
    /// Signed distance from the line's given point along the unit direction.
    pub t: T,
    /// The point itself.
    pub point: [T; N],
}

/// Which sign a `±` choice took: names one of the two branches of a [`Roots2`].
///
/// # Example
///
/// ```
/// use pkm_runtime::primitives::Sign;
///
/// assert_eq!(Sign::ALL, [Sign::Plus, Sign::Minus]);
/// assert_eq!(Sign::Minus.index(), 1);
/// assert_eq!(Sign::Minus.value::<f64>(), -1.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Sign {
    /// The `+` branch (index 0).
    Plus,
    /// The `−` branch (index 1).
    Minus,
}

impl Sign {
    /// Both signs in the fixed enumeration order: `[Plus, Minus]`.
    pub const ALL: [Sign; 2] = [Sign::Plus, Sign::Minus];

    /// Position of this branch in [`Roots2::branches`]: `Plus` → 0, `Minus` → 1.
    ///
    /// ```
    /// use pkm_runtime::primitives::Sign;
    /// assert_eq!(Sign::Plus.index(), 0);
    /// ```
    pub fn index(self) -> usize {
        match self {
            Sign::Plus => 0,
            Sign::Minus => 1,
        }
    }

    /// The sign as a scalar: `+1` or `−1`.
    ///
    /// ```
    /// use pkm_runtime::primitives::Sign;
    /// assert_eq!(Sign::Plus.value::<f64>(), 1.0);
    /// ```
    pub fn value<T: Real>(self) -> T {
        match self {
            Sign::Plus => T::one(),
            Sign::Minus => -T::one(),
        }
    }
}

/// The successful outcome of a primitive with two assembly branches.
///
/// `S` is the solution type (an angle, a point, a pair of angles, ...).
///
/// # Example
///
/// ```
/// use pkm_runtime::primitives::{Roots2, Sign};
///
/// let two = Roots2::Two { branches: [1.0, -1.0] };
/// assert_eq!(two.branch(Sign::Minus), -1.0);
/// assert_eq!(two.count(), 2);
/// let tangent = Roots2::Tangent { value: 0.5 };
/// assert_eq!(tangent.branches(), [0.5, 0.5]);
/// assert_eq!(tangent.count(), 1);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Roots2<S> {
    /// Two distinct solutions; `branches[Sign::Plus.index()]` is the `Plus` branch.
    Two {
        /// `[plus, minus]`.
        branches: [S; 2],
    },
    /// A double root: the two branches coincide (tangency). Reported when the
    /// radicand is exactly zero, or negative by no more than [`TANGENCY_TOL`]
    /// (it is then clamped to zero).
    Tangent {
        /// The common value of both branches.
        value: S,
    },
}

impl<S: Copy> Roots2<S> {
    /// The solution of the branch `sign` (for `Tangent`, the common value).
    ///
    /// ```
    /// use pkm_runtime::primitives::{Roots2, Sign};
    /// assert_eq!(Roots2::Two { branches: [3, 4] }.branch(Sign::Plus), 3);
    /// ```
    pub fn branch(&self, sign: Sign) -> S {
        match *self {
            Roots2::Two { branches } => branches[sign.index()],
            Roots2::Tangent { value } => value,
        }
    }

    /// Both branches in the order `[Plus, Minus]` (a tangent value is repeated).
    ///
    /// ```
    /// use pkm_runtime::primitives::Roots2;
    /// assert_eq!(Roots2::Tangent { value: 7 }.branches(), [7, 7]);
    /// ```
    pub fn branches(&self) -> [S; 2] {
        match *self {
            Roots2::Two { branches } => branches,
            Roots2::Tangent { value } => [value, value],
        }
    }

    /// Number of distinct solutions: 2 or 1.
    ///
    /// ```
    /// use pkm_runtime::primitives::Roots2;
    /// assert_eq!(Roots2::Two { branches: [0, 1] }.count(), 2);
    /// ```
    pub fn count(&self) -> usize {
        match self {
            Roots2::Two { .. } => 2,
            Roots2::Tangent { .. } => 1,
        }
    }

    /// `true` for a double root.
    ///
    /// ```
    /// use pkm_runtime::primitives::Roots2;
    /// assert!(Roots2::Tangent { value: 0.0 }.is_tangent());
    /// ```
    pub fn is_tangent(&self) -> bool {
        matches!(self, Roots2::Tangent { .. })
    }

    /// Applies `f` to every solution, keeping the branch structure.
    ///
    /// ```
    /// use pkm_runtime::primitives::Roots2;
    /// let r = Roots2::Two { branches: [1, 2] }.map(|x| 10 * x);
    /// assert_eq!(r, Roots2::Two { branches: [10, 20] });
    /// ```
    pub fn map<U, F: FnMut(S) -> U>(self, mut f: F) -> Roots2<U> {
        match self {
            Roots2::Two { branches: [p, m] } => Roots2::Two { branches: [f(p), f(m)] },
            Roots2::Tangent { value } => Roots2::Tangent { value: f(value) },
        }
    }

    /// Applies a fallible `f` to every solution (plus branch first); the first
    /// error is returned.
    ///
    /// ```
    /// use pkm_runtime::primitives::Roots2;
    /// let r: Result<_, &str> = Roots2::Tangent { value: 4 }.try_map(|x| Ok(x + 1));
    /// assert_eq!(r, Ok(Roots2::Tangent { value: 5 }));
    /// ```
    pub fn try_map<U, E, F: FnMut(S) -> Result<U, E>>(self, mut f: F) -> Result<Roots2<U>, E> {
        Ok(match self {
            Roots2::Two { branches: [p, m] } => Roots2::Two {
                branches: [f(p)?, f(m)?],
            },
            Roots2::Tangent { value } => Roots2::Tangent { value: f(value)? },
        })
    }
}

/// Why a primitive has no (finite, isolated) solution.
///
/// # Example
///
/// ```
/// use pkm_runtime::primitives::{line_sphere, Error};
///
/// // The x axis and the unit sphere about (0, 3, 0): out of reach by 2.
/// match line_sphere([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 3.0, 0.0], 1.0) {
///     Err(Error::Unreachable { by, .. }) => assert!((by - 2.0_f64).abs() < 1e-15),
///     other => panic!("{other:?}"),
/// }
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Error<T> {
    /// The data violate an existence condition by more than the tolerance.
    Unreachable {
        /// The violated condition, e.g. `"centre distance <= r1 + r2"`.
        constraint: &'static str,
        /// How far out of reach, in the units documented by the primitive
        /// (usually a length: the excess distance). Never negative.
        by: T,
    },
    /// The problem is singular: no isolated solutions exist (e.g. coincident
    /// circle centres, parallel lines, a zero-length axis, non-finite input).
    Degenerate {
        /// What is degenerate.
        what: &'static str,
    },
}

impl<T: core::fmt::Display> core::fmt::Display for Error<T> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Error::Unreachable { constraint, by } => {
                write!(f, "unreachable: `{constraint}` violated by {by}")
            }
            Error::Degenerate { what } => write!(f, "degenerate: {what}"),
        }
    }
}

impl<T: core::fmt::Display + core::fmt::Debug> std::error::Error for Error<T> {}

/// The error for non-finite input data.
pub(crate) fn non_finite_input<T>() -> Error<T> {
    Error::Degenerate {
        what: "non-finite input",
    }
}

/// The error for a non-finite result (overflow of an intermediate).
pub(crate) fn non_finite_result<T>() -> Error<T> {
    Error::Degenerate {
        what: "non-finite result (overflow)",
    }
}

/// `Err(non-finite input)` unless every listed scalar is finite.
pub(crate) fn ensure_finite<T: Real>(xs: &[T]) -> Result<(), Error<T>> {
    if xs.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(non_finite_input())
    }
}

/// Checks that every solution is finite (`ok` tells for one solution).
pub(crate) fn ensure_finite_roots<S: Copy, T>(
    roots: Roots2<S>,
    ok: impl Fn(&S) -> bool,
) -> Result<Roots2<S>, Error<T>> {
    if roots.branches().iter().all(ok) {
        Ok(roots)
    } else {
        Err(non_finite_result())
    }
}

/// The common tangency test: `excess = x − y` of a condition `x ≤ y` at scale
/// `scale`. Returns `Ok(true)` when it is a tangency (excess within
/// tolerance), `Ok(false)` when the condition holds strictly, and the
/// `Unreachable` error otherwise.
pub(crate) fn classify_excess<T: Real>(excess: T, scale: T, constraint: &'static str) -> Result<bool, Error<T>> {
    if excess < T::zero() {
        Ok(false)
    } else if excess <= T::from_f64(TANGENCY_TOL) * scale {
        Ok(true)
    } else {
        Err(Error::Unreachable { constraint, by: excess })
    }
}

/// Half-chord of a circle/sphere of radius `r` cut by a line at distance
/// `e ≥ 0` from its centre: `±sqrt(r² − e²)`, computed as
/// `sqrt((r − e)(r + e))` (no cancellation). `Plus` is `+sqrt`; the tangency
/// scale is `e`.
pub(crate) fn half_chord<T: Real>(e: T, r: T, constraint: &'static str) -> Result<Roots2<T>, Error<T>> {
    if classify_excess(e - r, e, constraint)? {
        return Ok(Roots2::Tangent { value: T::zero() });
    }
    let s = ((r - e) * (r + e)).sqrt();
    Ok(Roots2::Two { branches: [s, -s] })
}

/// Foot and height of a triangle with base `d > 0` and the other two sides
/// `r1` (from the base's start) and `r2` (from its end), both `≥ 0`.
///
/// Returns `(x, h)`: the apex is at `x` along the base and `h ≥ 0` away from
/// it (as `Roots2<T>` of `±h`, `Plus` = `+h`). The height uses Kahan's stable
/// formula for the area of a needle-like triangle: with the sides sorted
/// `a ≥ b ≥ c`,
/// `area = ¼·sqrt((a + (b + c))·(c − (a − b))·(c + (a − b))·(a + (b − c)))`,
/// parentheses exactly as written; only `c − (a − b)` can be negative, and its
/// negation is the excess reported as `Unreachable` (`outside` when the base
/// is the longest side, i.e. the circles are too far apart; `inside` when a
/// radius is, i.e. one circle contains the other). The tangency scale is `a`.
pub(crate) fn triangle_apex<T: Real>(
    d: T,
    r1: T,
    r2: T,
    outside: &'static str,
    inside: &'static str,
) -> Result<(T, Roots2<T>), Error<T>> {
    // Sort the three sides, remembering whether the base is the longest.
    let (mut a, mut b, mut c) = (d, r1, r2);
    let mut base_longest = true;
    if b > a {
        core::mem::swap(&mut a, &mut b);
        base_longest = false;
    }
    if c > a {
        core::mem::swap(&mut a, &mut c);
        base_longest = false;
    }
    if c > b {
        core::mem::swap(&mut b, &mut c);
    }
    let two = T::from_f64(2.0);
    // Foot of the apex on the base: (d² + r1² − r2²) / 2d without forming squares of d.
    let x = (d + (r1 - r2) * (r1 + r2) / d) / two;
    let neck = c - (a - b);
    let constraint = if base_longest { outside } else { inside };
    if classify_excess(-neck, a, constraint)? {
        return Ok((x, Roots2::Tangent { value: T::zero() }));
    }
    // sqrt of the product taken as two square roots of pairs: no overflow below ~1e154.
    let h = ((a + (b + c)) * (a + (b - c))).sqrt() * (neck * (c + (a - b))).sqrt() / (two * d);
    Ok((x, Roots2::Two { branches: [h, -h] }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roots2_accessors() {
        let r = Roots2::Two { branches: [1, 2] };
        assert_eq!(Sign::ALL.map(|s| r.branch(s)), [1, 2]);
        assert!(!r.is_tangent());
        assert_eq!(r.try_map(|x| if x > 1 { Err(x) } else { Ok(x) }), Err(2));
    }

    #[test]
    fn error_display() {
        let e: Error<f64> = Error::Unreachable {
            constraint: "x <= y",
            by: 0.5,
        };
        assert_eq!(e.to_string(), "unreachable: `x <= y` violated by 0.5");
        let d: Error<f64> = non_finite_input();
        assert_eq!(d.to_string(), "degenerate: non-finite input");
    }

    #[test]
    fn classify_excess_cases() {
        assert_eq!(classify_excess(-1.0, 1.0, "c"), Ok(false));
        assert_eq!(classify_excess(0.0, 1.0, "c"), Ok(true));
        assert_eq!(classify_excess(1e-10, 1.0, "c"), Ok(true));
        assert_eq!(
            classify_excess(1e-6, 1.0, "c"),
            Err(Error::Unreachable {
                constraint: "c",
                by: 1e-6
            })
        );
    }

    #[test]
    fn kahan_needle_triangle() {
        // 3-4-5 triangle on base 5: foot 3.2 (= 16/5), height 2.4 (= 12/5).
        let (x, h) = triangle_apex(5.0, 4.0, 3.0, "o", "i").unwrap();
        assert!((x - 3.2_f64).abs() < 1e-15);
        assert!((h.branch(Sign::Plus) - 2.4_f64).abs() < 1e-15);
        // Needle: base 2 − 1e-12 under two unit sides; 2 − d is exact, so is the reference.
        let d = 2.0 - 1e-12;
        let expected = ((2.0 - d) * (2.0 + d)).sqrt() / 2.0;
        let (_, h) = triangle_apex(d, 1.0, 1.0, "o", "i").unwrap();
        let got = h.branch(Sign::Plus);
        assert!((got - expected).abs() <= 1e-14 * expected, "{got} vs {expected}");
    }
}
