//! The step kernels' shared vocabulary: which root of a `±` choice a solve
//! takes ([`Sign`]), why a kernel has no solution ([`Error`]), and the
//! tolerance that tells a tangency from a miss ([`TANGENCY_TOL`]).
//!
//! The kernels themselves are written once, generic over
//! [`crate::scalar::Scalar`], in [`crate::subproblems`] (one file each,
//! with its equation and its tests); a point carried across a joint at its
//! given value stays with its step ([`crate::steps::beyond::carried`]).
//!
//! Generated code names `::pkm::runtime::primitives::Sign` and
//! `::pkm::runtime::primitives::Error`, so the module keeps its path.

/// Relative tolerance for tangency (double roots) and for data consistency.
///
/// When a kernel's existence condition has the form `x ≤ y` (`|c| ≤
/// √(a² + b²)` in [`crate::subproblems::trig::trig_turns`], the distance of a
/// sphere's centre from a line `≤` its radius in
/// [`crate::subproblems::line_sphere::line_distance`]), an excess `x − y` of at most
/// `TANGENCY_TOL · scale` — `scale` being the largest length (or coefficient
/// magnitude) of that condition, documented per kernel — is treated as
/// rounding: the kernel returns the double root. A larger excess is an
/// [`Error::Unreachable`] whose `by` is the excess. The verification of a
/// solve ([`crate::consistency::VERIFY_TOL`]) is a tenth of it.
///
/// `1e-9` is far above the rounding error of the formulas (a few ulps,
/// ≈ `1e-15` relative) and far below any mechanically meaningful gap
/// (a nanometre on a one-metre mechanism).
pub const TANGENCY_TOL: f64 = 1e-9;

/// Which sign a `±` choice took: names one of the two roots of a step that
/// branches (each kernel documents which root is its `Plus`).
///
/// # Example
///
/// ```
/// use pkm_runtime::primitives::Sign;
///
/// assert_eq!(Sign::Plus.index(), 0);
/// assert_eq!(Sign::Minus.index(), 1);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Sign {
    /// The `+` root (index 0).
    Plus,
    /// The `−` root (index 1).
    Minus,
}

impl Sign {
    /// `plus` or `minus`, the root this sign names: [`crate::scalar::Scalar::pick`]
    /// of every scalar that holds a value.
    #[inline]
    pub fn pick<T>(self, plus: T, minus: T) -> T {
        match self {
            Sign::Plus => plus,
            Sign::Minus => minus,
        }
    }

    /// Choice `k` of `signs`, `Plus` where the step has none (`k` is
    /// `None`): [`crate::scalar::Scalar::choice`] of every scalar that
    /// holds a value.
    #[inline]
    pub fn nth(signs: &[Sign], k: Option<usize>) -> Sign {
        k.map_or(Sign::Plus, |k| signs[k])
    }

    /// The position of this root in a `[plus, minus]` pair: `Plus` → 0, `Minus` → 1.
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
}

/// Why a kernel has no (finite, isolated) solution.
///
/// # Example
///
/// ```
/// use pkm_runtime::primitives::Error;
/// use pkm_runtime::subproblems::line_sphere::line_distance;
///
/// // The x axis and the sphere of radius 1 about (0, 3, 0): out of reach by 2.
/// match line_distance([0.0; 3], [1.0, 0.0, 0.0], [0.0, 3.0, 0.0], 1.0, [0, 0]) {
///     Err(Error::Unreachable { by, .. }) => assert_eq!(by, 2.0),
///     other => panic!("{other:?}"),
/// }
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Error<T> {
    /// The data violate an existence condition by more than the tolerance.
    Unreachable {
        /// The violated condition, e.g. `"|c| <= hypot(a, b)"`.
        constraint: &'static str,
        /// How far out of reach, in the units documented by the kernel
        /// (usually a length: the excess distance). Never negative.
        by: T,
    },
    /// The problem is singular: no isolated solutions exist (e.g. a point
    /// on the turning axis, a slide parallel to the plane it must reach).
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn error_display() {
        let e: Error<f64> = Error::Unreachable {
            constraint: "x <= y",
            by: 0.5,
        };
        assert_eq!(e.to_string(), "unreachable: `x <= y` violated by 0.5");
        let d: Error<f64> = Error::Degenerate {
            what: "non-finite input",
        };
        assert_eq!(d.to_string(), "degenerate: non-finite input");
    }
}
