//! Allocation-free helpers on `[T; N]` points and vectors (crate-private).

use super::Error;
use crate::real::Real;

/// `a − b`.
pub(crate) fn sub<T: Real, const N: usize>(a: [T; N], b: [T; N]) -> [T; N] {
    core::array::from_fn(|i| a[i] - b[i])
}

// Fused multiply-adds: a software call on baseline x86-64, but the planar
// dyads' round trips (tests/round_trips.rs, 10⁵ draws) are up to 1.6× worse
// without them (five-bar fk∘ik 5.3e-12 → 8.6e-12, Watt ik∘fk 1.2e-10 →
// 1.5e-10). The traced spatial steps do not use these helpers.

/// `a + s · b`, one fused operation per component.
pub(crate) fn axpy<T: Real, const N: usize>(a: [T; N], s: T, b: [T; N]) -> [T; N] {
    core::array::from_fn(|i| s.mul_add(b[i], a[i]))
}

/// Dot product, accumulated with fused multiply-adds.
pub(crate) fn dot<T: Real, const N: usize>(a: [T; N], b: [T; N]) -> T {
    a.iter()
        .zip(b.iter())
        .fold(T::zero(), |acc, (&x, &y)| x.mul_add(y, acc))
}

/// Euclidean norm. The square root of the sum of squares is within a few
/// ulps and several times faster than `hypot`; only when that sum leaves
/// [1e-280, 1e280] (lengths beyond 1e±140, or zero, where a dual number's
/// `sqrt` has no derivative) does the repeated `hypot` take over.
pub(crate) fn norm<T: Real, const N: usize>(a: [T; N]) -> T {
    let s = a.iter().fold(T::zero(), |acc, &x| x * x + acc);
    if s > T::from_f64(1e-280) && s < T::from_f64(1e280) {
        s.sqrt()
    } else {
        a.iter().fold(T::zero(), |acc, &x| acc.hypot(x))
    }
}

/// `true` if every component is finite.
pub(crate) fn finite<T: Real, const N: usize>(a: &[T; N]) -> bool {
    a.iter().all(|x| x.is_finite())
}

/// `a / |a|`, or `Degenerate { what }` for a zero vector.
pub(crate) fn unit<T: Real, const N: usize>(a: [T; N], what: &'static str) -> Result<[T; N], Error<T>> {
    let n = norm(a);
    if n == T::zero() {
        return Err(Error::Degenerate { what });
    }
    Ok(core::array::from_fn(|i| a[i] / n))
}

/// Spatial cross product `a × b`.
pub(crate) fn cross3<T: Real>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [
        a[1].mul_add(b[2], -(a[2] * b[1])),
        a[2].mul_add(b[0], -(a[0] * b[2])),
        a[0].mul_add(b[1], -(a[1] * b[0])),
    ]
}

/// Splits `v` into `(k·v, v − (k·v) k)` for a unit vector `k`.
pub(crate) fn split_axis<T: Real>(k: [T; 3], v: [T; 3]) -> (T, [T; 3]) {
    let along = dot(k, v);
    (along, axpy(v, -along, k))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn helpers() {
        assert_eq!(sub([1.0, 2.0, 3.0], [1.0, 1.0, 1.0]), [0.0, 1.0, 2.0]);
        assert_eq!(axpy([1.0, 1.0], 2.0, [1.0, -1.0]), [3.0, -1.0]);
        assert_eq!(dot([1.0, 2.0, 3.0], [4.0, 5.0, 6.0]), 32.0);
        assert_eq!(norm([2.0, 3.0, 6.0]), 7.0);
        // Outside the sum of squares' safe range the hypot chain answers.
        assert_eq!(norm([2e200, 3e200, 6e200]), 7e200);
        assert!((norm([2e-200, 3e-200, 6e-200]) / 7e-200 - 1.0).abs() < 1e-15);
        assert_eq!(norm([0.0, 0.0]), 0.0);
        assert_eq!(cross3([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]), [0.0, 0.0, 1.0]);
        assert_eq!(unit([0.0, 3.0, 4.0], "z"), Ok([0.0, 0.6, 0.8]));
        assert_eq!(unit([0.0, 0.0], "z"), Err(Error::Degenerate { what: "z" }));
        assert_eq!(split_axis([0.0, 0.0, 1.0], [1.0, 2.0, 3.0]), (3.0, [1.0, 2.0, 0.0]));
        assert!(!finite(&[1.0, f64::NAN]));
    }
}
