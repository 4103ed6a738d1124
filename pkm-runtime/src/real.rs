//! The scalar the model's kinematics are generic over.
//!
//! [`Real`] is deliberately tiny: the operations that
//! [`crate::kinematics`]'s link poses and loop residual (through
//! [`crate::kinematics::Kinematics`]) and `reference.rs`'s Newton iteration
//! use, so that the same code runs in `f64` (for
//! [`crate::newton`]) and in a higher precision without a numeric-tower
//! dependency. It is implemented here for `f64`, and for the 237-bit `f256`
//! in `pkm_runtime::reference` (feature `high-precision`, for the
//! work-precision reference only). The plan steps' kernels are generic over
//! another trait, [`crate::scalar::Scalar`], which the code generator's
//! symbolic scalar implements too.
//!
//! Comparisons (`PartialOrd`) are meant to choose a branch or classify a
//! case, never to compute a value; a dual number should therefore compare by
//! its primal (value) part.

use core::ops::{Add, Div, Mul, Neg, Sub};

/// A real scalar: `f64`, or later a dual number wrapping one.
///
/// All methods mirror the inherent `f64` methods of the same name.
///
/// # Example
///
/// A function written once for every `Real`:
///
/// ```
/// use pkm_runtime::real::Real;
///
/// fn hyp<T: Real>(a: T, b: T) -> T {
///     (a * a + b * b).sqrt()
/// }
/// assert_eq!(hyp(3.0_f64, 4.0), 5.0);
/// assert_eq!(<f64 as Real>::from_f64(2.5), 2.5);
/// ```
pub trait Real:
    Copy
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// Converts a constant (e.g. a tolerance) into this scalar type.
    fn from_f64(x: f64) -> Self;

    /// The additive identity, `0`.
    fn zero() -> Self {
        Self::from_f64(0.0)
    }

    /// The multiplicative identity, `1`.
    fn one() -> Self {
        Self::from_f64(1.0)
    }

    /// Square root (of non-negative arguments).
    fn sqrt(self) -> Self;

    /// Absolute value.
    fn abs(self) -> Self;

    /// Sine (argument in radians).
    fn sin(self) -> Self;

    /// Cosine (argument in radians).
    fn cos(self) -> Self;

    /// Four-quadrant arctangent of `self / x` (`self` is the ordinate `y`), in `[-π, π]`.
    fn atan2(self, x: Self) -> Self;

    /// `true` if the value is neither infinite nor NaN (for a dual number: all of its parts).
    fn is_finite(self) -> bool;
}

impl Real for f64 {
    #[inline]
    fn from_f64(x: f64) -> Self {
        x
    }

    #[inline]
    fn zero() -> Self {
        0.0
    }

    #[inline]
    fn one() -> Self {
        1.0
    }

    #[inline]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }

    #[inline]
    fn abs(self) -> Self {
        f64::abs(self)
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
        f64::atan2(self, x)
    }

    #[inline]
    fn is_finite(self) -> bool {
        f64::is_finite(self)
    }
}

#[cfg(test)]
mod tests {
    use super::Real;

    fn generic_ops<T: Real>(x: T) -> [T; 2] {
        [x.sqrt(), (-x).abs()]
    }

    #[test]
    fn f64_impl_matches_inherent_methods() {
        assert_eq!(generic_ops(4.0_f64), [2.0, 4.0]);
        assert_eq!(<f64 as Real>::zero(), 0.0);
        assert_eq!(<f64 as Real>::one(), 1.0);
        assert_eq!(Real::atan2(1.0_f64, 1.0), core::f64::consts::FRAC_PI_4);
        assert_eq!(Real::sin(0.0_f64), 0.0);
        assert_eq!(Real::cos(0.0_f64), 1.0);
        assert!(!Real::is_finite(f64::NAN));
        assert!(!Real::is_finite(f64::INFINITY));
        assert!(Real::is_finite(1.0_f64));
    }
}
