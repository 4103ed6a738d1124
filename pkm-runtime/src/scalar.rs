//! The scalar a solver's steps compute with.
//!
//! The steps of a plan ([`crate::steps`]) are written once, generic over
//! [`Scalar`]. With `f64` they are the plan interpreter. With the code
//! generator's symbolic scalar (in pkm-dsl) the same steps record every
//! operation instead of doing it, and what they record becomes the generated
//! straight-line solver: one source for both, so the two agree by
//! construction and the interpreter stays the oracle.
//!
//! The closed-form kernels are traced too: where they branch on values (a
//! tangency, which root) they say so through [`Scalar::require`],
//! [`Scalar::if_less`] and [`Scalar::pick`], which generated code writes as
//! guards and selects.

use crate::primitives::{Error as GeomError, Sign};
use core::ops::{Add, Div, Mul, Neg, Sub};

/// Arithmetic, the elementary functions the steps use, and their decisions.
///
/// # Example
///
/// ```
/// use pkm_runtime::scalar::Scalar;
///
/// fn norm<T: Scalar>(v: [T; 3]) -> T {
///     (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
/// }
/// assert_eq!(norm([3.0, 0.0, 4.0]), 5.0);
/// ```
pub trait Scalar:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self> + Neg<Output = Self>
{
    /// How a step's ± choice is given: a [`Sign`] when it runs, a sign or
    /// "the caller's k-th sign" when code is generated.
    type Choice: Copy;

    /// A constant.
    fn c(x: f64) -> Self;
    /// Square root.
    fn sqrt(self) -> Self;
    /// Sine.
    fn sin(self) -> Self;
    /// Cosine.
    fn cos(self) -> Self;
    /// Four-quadrant arctangent of `self / x`, in (−π, π] ([`angle`]).
    fn atan2(self, x: Self) -> Self;
    /// Absolute value.
    fn abs(self) -> Self;
    /// `then` where `a < b`, else `otherwise` (decided once, where it depends
    /// on the geometry only).
    fn if_less(a: Self, b: Self, then: Self, otherwise: Self) -> Self;
    /// [`Scalar::if_less`] where the two choices agree at `a = b` (a
    /// maximum, a sort, a clamp): a continuous selection, which an interval
    /// that holds both outcomes encloses by their hull without doubt
    /// ([`crate::interval`]). Every other scalar computes it as `if_less`.
    fn if_less_continuous(a: Self, b: Self, then: Self, otherwise: Self) -> Self {
        Self::if_less(a, b, then, otherwise)
    }
    /// `Ok` where `a < b`; otherwise (NaN included) the kernel fails with
    /// `failure`. `site` is the step and the joint it solves.
    fn require(a: Self, b: Self, failure: Failure<Self>, site: [usize; 2]) -> Result<(), GeomError<f64>>;
    /// The root `choice` picks of two.
    fn pick(choice: Self::Choice, plus: Self, minus: Self) -> Self;
    /// Names the value (generated code's variable names); no effect on numbers.
    fn named(self, _name: &dyn Fn() -> String) -> Self {
        self
    }
    /// The given value's sign choice number `k` of `signs` at run time.
    fn choice(signs: &[Self::Choice], k: Option<usize>) -> Self::Choice;
}

impl Scalar for f64 {
    type Choice = Sign;

    #[inline]
    fn c(x: f64) -> Self {
        x
    }
    #[inline]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline]
    fn sin(self) -> Self {
        f64::sin(self)
    }
    #[inline]
    fn cos(self) -> Self {
        f64::cos(self)
    }
    #[inline]
    fn atan2(self, x: Self) -> Self {
        angle(self, x)
    }
    #[inline]
    fn abs(self) -> Self {
        f64::abs(self)
    }
    #[inline]
    fn if_less(a: Self, b: Self, then: Self, otherwise: Self) -> Self {
        if a < b {
            then
        } else {
            otherwise
        }
    }
    #[inline]
    fn require(a: Self, b: Self, failure: Failure<Self>, _site: [usize; 2]) -> Result<(), GeomError<f64>> {
        if a < b {
            Ok(())
        } else {
            Err(failure.error())
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

/// A [`Scalar`] that holds a value and is ordered: `f64` and the 70-digit
/// `f256` of `reference.rs` (feature `high-precision`), not the code
/// generator's symbols. What computes with
/// values that it compares (the model's link poses and loop residual,
/// [`crate::kinematics`], and the reference Newton iteration) is written
/// over it; its arithmetic and functions are [`Scalar`]'s, so that the
/// two are one set of operations.
///
/// Comparisons (`PartialOrd`) choose a branch or classify a case, never
/// compute a value.
///
/// ```
/// use pkm_runtime::scalar::{Real, Scalar};
///
/// fn hyp<T: Real>(a: T, b: T) -> T {
///     if a == T::c(0.0) { b.abs() } else { (a * a + b * b).sqrt() }
/// }
/// assert_eq!(hyp(3.0_f64, 4.0), 5.0);
/// ```
pub trait Real: Scalar + PartialOrd {
    /// Neither infinite nor NaN (for a dual number: every part).
    fn is_finite(self) -> bool;
}

impl Real for f64 {
    #[inline]
    fn is_finite(self) -> bool {
        f64::is_finite(self)
    }
}

/// The angle of `(x, y)` in (−π, π]: `atan2(y, x)`, but π where `y` is a
/// negative zero and `x < 0` (where atan2 gives −π). Folding a sum with an
/// exact zero may turn +0 into −0, so the code generator and the
/// interpreter agree on the angle only where ±0 name one angle.
///
/// ```
/// use pkm_runtime::scalar::angle;
///
/// assert_eq!(angle(-0.0, -1.0), std::f64::consts::PI);
/// assert_eq!(angle(1.0, 0.0), std::f64::consts::FRAC_PI_2);
/// ```
#[inline]
pub fn angle(y: f64, x: f64) -> f64 {
    let a = f64::atan2(y, x);
    if a == -core::f64::consts::PI {
        core::f64::consts::PI
    } else {
        a
    }
}

/// Why a kernel fails, with the values its error reports.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Failure<T> {
    /// No solution is determined (a point on an axis, parallel lines).
    Degenerate(&'static str),
    /// The named constraint fails by the value.
    Unreachable(&'static str, T),
    /// A circle's point cannot reach distance `d` from a point: farther than
    /// the largest distance `dmax`, or nearer than the smallest `dmin`.
    Distance {
        /// The distance asked for.
        d: T,
        /// The largest distance.
        dmax: T,
        /// The smallest distance.
        dmin: T,
    },
}

impl<T: Copy> Failure<T> {
    /// The same failure with its values mapped by `f` (to `f64`, to report).
    pub fn map(self, f: impl Fn(T) -> f64) -> Failure<f64> {
        match self {
            Failure::Degenerate(what) => Failure::Degenerate(what),
            Failure::Unreachable(constraint, by) => Failure::Unreachable(constraint, f(by)),
            Failure::Distance { d, dmax, dmin } => Failure::Distance {
                d: f(d),
                dmax: f(dmax),
                dmin: f(dmin),
            },
        }
    }
}

impl Failure<f64> {
    /// The error it is.
    pub fn error(self) -> GeomError<f64> {
        match self {
            Failure::Degenerate(what) => GeomError::Degenerate { what },
            Failure::Unreachable(constraint, by) => GeomError::Unreachable { constraint, by },
            Failure::Distance { d, dmax, dmin } => unreachable_distance(d, dmax, dmin),
        }
    }
}

/// The error of a circle's point that cannot reach distance `d` from a
/// point (see [`Failure::Distance`]).
#[cold]
pub fn unreachable_distance(d: f64, dmax: f64, dmin: f64) -> GeomError<f64> {
    if d > dmax {
        GeomError::Unreachable {
            constraint: "d <= largest distance from q to the circle",
            by: d - dmax,
        }
    } else {
        GeomError::Unreachable {
            constraint: "d >= smallest distance from q to the circle",
            by: (dmin - d).max(0.0),
        }
    }
}

/// The larger of two values (the first where equal).
#[inline]
pub fn max<T: Scalar>(a: T, b: T) -> T {
    T::if_less_continuous(a, b, b, a)
}

/// `a · b` of two 3-vectors.
#[inline]
pub fn dot<T: Scalar>(a: [T; 3], b: [T; 3]) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a × b`.
#[inline]
pub fn cross<T: Scalar>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `a + b`.
#[inline]
pub fn add<T: Scalar>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `a − b`.
#[inline]
pub fn sub<T: Scalar>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `s · a`.
#[inline]
pub fn scale<T: Scalar>(s: T, a: [T; 3]) -> [T; 3] {
    [s * a[0], s * a[1], s * a[2]]
}

/// `|a|`.
#[inline]
pub fn norm<T: Scalar>(a: [T; 3]) -> T {
    dot(a, a).sqrt()
}

/// `a / |a|` (a zero vector gives NaN: callers normalise geometry the
/// planner has checked, never a value that can vanish at run time).
#[inline]
pub fn unit<T: Scalar>(a: [T; 3]) -> [T; 3] {
    let n = norm(a);
    [a[0] / n, a[1] / n, a[2] / n]
}

/// `a` with its component along unit `k` removed.
#[inline]
pub fn reject<T: Scalar>(a: [T; 3], k: [T; 3]) -> [T; 3] {
    sub(a, scale(dot(k, a), k))
}

/// Constants as a vector.
#[inline]
pub fn constant<T: Scalar>(a: [f64; 3]) -> [T; 3] {
    a.map(T::c)
}

#[cfg(test)]
mod tests {
    use super::{Real, Scalar};

    fn generic_ops<T: Real>(x: T) -> [T; 2] {
        [x.sqrt(), (-x).abs()]
    }

    /// `f64`'s `Scalar` and `Real` are its own functions (atan2 but for
    /// its −π, `angle`).
    #[test]
    fn f64_impl_matches_inherent_methods() {
        assert_eq!(generic_ops(4.0_f64), [2.0, 4.0]);
        assert_eq!(<f64 as Scalar>::c(0.0), 0.0);
        assert_eq!(<f64 as Scalar>::c(1.0), 1.0);
        assert_eq!(Scalar::atan2(1.0_f64, 1.0), core::f64::consts::FRAC_PI_4);
        assert_eq!(Scalar::sin(0.0_f64), 0.0);
        assert_eq!(Scalar::cos(0.0_f64), 1.0);
        assert!(!Real::is_finite(f64::NAN));
        assert!(!Real::is_finite(f64::INFINITY));
        assert!(Real::is_finite(1.0_f64));
    }
}
