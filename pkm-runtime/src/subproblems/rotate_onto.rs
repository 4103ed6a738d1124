//! The turn about an axis that carries one direction onto another
//! (Paden–Kahan subproblem 1).

use crate::primitives::Error as GeomError;
use crate::scalar::{cross, dot, Scalar};

/// The turn `[cos θ, sin θ]` about unit `k` that carries the direction of
/// `v` onto that of `u` (their components normal to `k`):
/// `θ = atan2(k·(v⊥ × u⊥), v⊥·u⊥)`, Paden–Kahan subproblem 1.
///
/// # Errors
/// [`GeomError::Degenerate`] when `v` or `u` lies on the axis (within
/// `1e-12` of the larger of their lengths): every turn would do.
///
/// ```
/// use pkm_runtime::subproblems::rotate_onto::turn_onto;
///
/// // x onto y about z: a quarter turn.
/// let t = turn_onto([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0, 0]).unwrap();
/// assert_eq!(t, [0.0, 1.0]);
/// ```
#[inline]
pub fn turn_onto<T: Scalar>(k: [T; 3], v: [T; 3], u: [T; 3], site: [usize; 2]) -> Result<[T; 2], GeomError<f64>> {
    turn(k, v, u, site).map(|(_, cs)| cs)
}

/// [`turn_onto`]'s terms before they are normalised (the cosine and sine
/// times `h = |v⊥||u⊥|`), then the turn.
#[inline]
pub(crate) fn turn<T: Scalar>(
    k: [T; 3],
    v: [T; 3],
    u: [T; 3],
    site: [usize; 2],
) -> Result<([T; 2], [T; 2]), GeomError<f64>> {
    use crate::scalar::{max, reject, Failure};
    let (vp, up) = (reject(v, k), reject(u, k));
    // Squared lengths: no square root on the way to the degeneracy test.
    let floor = T::c(1e-24) * max(dot(v, v), dot(u, u));
    let on_axis = || Failure::Degenerate("the point or direction lies on the turning axis");
    T::require(floor, dot(vp, vp), on_axis(), site)?;
    T::require(floor, dot(up, up), on_axis(), site)?;
    let [c, s] = crate::subproblems::rotate_onto::turn_terms(k, vp, up);
    let h = (c * c + s * s).sqrt();
    Ok(([c, s], [c / h, s / h]))
}

/// `k · (v × u)` and `v · u`: the sine and cosine (times the lengths) of
/// the turn about unit `k` from `v` to `u`, both normal to `k`.
pub(crate) fn turn_terms<T: Scalar>(k: [T; 3], v: [T; 3], u: [T; 3]) -> [T; 2] {
    [dot(v, u), dot(k, cross(v, u))]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::primitives::Error as GeomError;

    fn check(a: [f64; 9], expect: Result<f64, &str>) {
        let (k, v, u) = ([a[0], a[1], a[2]], [a[3], a[4], a[5]], [a[6], a[7], a[8]]);
        match (turn_onto(k, v, u, [0, 0]), expect) {
            (Ok([c, s]), Ok(angle)) => {
                assert!(
                    (c - angle.cos()).abs() < 1e-15 && (s - angle.sin()).abs() < 1e-15,
                    "{c} {s} vs {angle}"
                );
                assert!((c.hypot(s) - 1.0).abs() < 1e-15);
            }
            (Err(GeomError::Degenerate { what }), Err(w)) => assert!(what.contains(w), "{what}"),
            (got, want) => panic!("{got:?} vs {want:?}"),
        }
    }

    #[test]
    fn turns_onto_and_refuses_points_on_the_axis() {
        let q = std::f64::consts::FRAC_PI_2;
        check([0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], Ok(q));
        // Components along the axis do not matter.
        check(
            [0.0, 0.0, 1.0, 1.0, 0.0, 5.0, -1.0, 0.0, -3.0],
            Ok(std::f64::consts::PI),
        );
        // About −z the same turn is negative.
        check([0.0, 0.0, -1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], Ok(-q));
        // A tiny but honest perpendicular part still turns exactly.
        check([0.0, 0.0, 1.0, 1e-9, 0.0, 1.0, 0.0, 1e-9, 1.0], Ok(q));
        check(
            [0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0],
            Err("on the turning axis"),
        );
        check(
            [0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1e-13, 0.0, 1.0],
            Err("on the turning axis"),
        );
    }

    #[test]
    fn turns_about_a_slanted_axis_and_by_the_sign_of_the_turn() {
        use std::f64::consts::{FRAC_PI_2, PI};
        let d = 1.0 / 3f64.sqrt();
        // A third of a turn about the diagonal carries x to y (and y to z, z to x).
        check([d, d, d, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], Ok(2.0 * PI / 3.0));
        check([d, d, d, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0], Ok(2.0 * PI / 3.0));
        // Onto itself: no turn; onto −y from x about z: a quarter turn back.
        check([0.0, 0.0, 1.0, 3.0, 4.0, 0.0, 3.0, 4.0, 0.0], Ok(0.0));
        check([0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, -1.0, 0.0], Ok(-FRAC_PI_2));
    }

    /// `v` turned by `theta` about the unit `k` (Rodrigues:
    /// `v cosθ + (k × v) sinθ + k (k·v)(1 − cosθ)`), written out here.
    fn rodrigues(k: [f64; 3], theta: f64, v: [f64; 3]) -> [f64; 3] {
        let kxv = [
            k[1] * v[2] - k[2] * v[1],
            k[2] * v[0] - k[0] * v[2],
            k[0] * v[1] - k[1] * v[0],
        ];
        let kv = k[0] * v[0] + k[1] * v[1] + k[2] * v[2];
        let (s, c) = theta.sin_cos();
        std::array::from_fn(|i| v[i] * c + kxv[i] * s + k[i] * kv * (1.0 - c))
    }

    #[test]
    fn recovers_the_turn_that_made_the_target() {
        let n = (0.3f64 * 0.3 + 0.9 * 0.9 + 0.1 * 0.1).sqrt();
        let k = [0.3 / n, -0.9 / n, 0.1 / n];
        let v = [1.0, 2.0, 0.5];
        for theta in [-3.0, -1.2, -0.01, 0.4, 1.5, 2.9] {
            let u = rodrigues(k, theta, v);
            check([k[0], k[1], k[2], v[0], v[1], v[2], u[0], u[1], u[2]], Ok(theta));
        }
    }
}
