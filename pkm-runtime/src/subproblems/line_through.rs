//! A line turned about an axis until it passes a point:
//! `a·cosθ + b·sinθ = e` with `a = n₀·w`, `b = (k × n₀)·w` and `e` the
//! line's offset from the axis ([`super::trig::trig_turn`]).

use crate::primitives::Error as GeomError;
use crate::scalar::{cross, dot, sub, Failure, Scalar};

/// The turn `[cos θ, sin θ]` about the unit `axis` through `centre` that
/// puts the line `start + t·along` (at θ = 0, `along` normal to the axis)
/// through `b`: `a·cosθ + b·sinθ = e` of the module's derivation, solved by
/// [`crate::subproblems::trig::trig_turn`] (`along` need not be unit: every term
/// scales with it). `Plus` is `atan2(b, a) + acos(e/|w⊥|)`.
///
/// # Errors
/// [`GeomError::Unreachable`] by `|e| − |w⊥|` (both times `|along|`) when
/// `b` is nearer the axis than the line ever comes; [`GeomError::Degenerate`]
/// when `b` is on the axis.
///
/// ```
/// use pkm_runtime::primitives::Sign;
/// use pkm_runtime::subproblems::line_through::through;
///
/// // The x axis turned about z through the origin passes (0, 2): a quarter turn, or three.
/// let (o, z, x) = ([0.0; 3], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
/// let [c, s] = through(o, z, o, x, [0.0, 2.0, 0.0], Sign::Plus, [0, 0]).unwrap();
/// assert!(c.abs() < 1e-15 && (s - 1.0).abs() < 1e-15);
/// assert!(through(o, z, [0.0, 3.0, 0.0], x, [0.0, 2.0, 0.0], Sign::Plus, [0, 0]).is_err());
/// ```
#[inline]
pub fn through<T: Scalar>(
    centre: [T; 3],
    axis: [T; 3],
    start: [T; 3],
    along: [T; 3],
    b: [T; 3],
    choice: T::Choice,
    site: [usize; 2],
) -> Result<[T; 2], GeomError<f64>> {
    let n0 = cross(axis, along);
    let w = sub(b, centre);
    let a = dot(n0, w);
    let bb = dot(cross(axis, n0), w);
    let e = dot(n0, sub(start, centre));
    let h = (a * a + bb * bb).sqrt();
    let far = Failure::Unreachable("distance(axis, point) >= offset of the guide", e.abs() - h);
    crate::subproblems::trig::trig_turn(a, bb, e, choice, site, Some(far))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::primitives::Sign;

    /// By hand: the pivot C at the origin, the guide at offset e from it
    /// (the line y = e at θ = 0, along x), B at distance ρ and angle β. The
    /// turned line `−sinθ·x + cosθ·y = e` passes B where `ρ·sin(β − θ) = e`,
    /// i.e. `ρ·cos(θ − (β − π/2)) = e`, so `θ = β − π/2 ± acos(e/ρ)`, Plus `+`.
    #[test]
    fn both_roots_by_hand() {
        let z = [0.0, 0.0, 1.0];
        for &(e, rho, beta) in &[(0.0, 2.0, 0.3), (1.0, 2.0, 0.3), (-1.5, 2.0, 2.9), (0.7, 120.0, -1.0)] {
            let b = [rho * f64::cos(beta), rho * f64::sin(beta), 0.0];
            for (sign, pm) in [(Sign::Plus, 1.0), (Sign::Minus, -1.0)] {
                let want = beta - std::f64::consts::FRAC_PI_2 + pm * (e / rho).acos();
                // The line through (5, e) along 2x: the start and the length do not matter.
                let [c, s] = through([0.0; 3], z, [5.0, e, 0.0], [2.0, 0.0, 0.0], b, sign, [0, 0]).unwrap();
                assert!(
                    (c - want.cos()).abs() < 1e-14 && (s - want.sin()).abs() < 1e-14,
                    "{e} {rho} {beta}"
                );
                // The turned line passes B: its normal's component of B is e.
                assert!(((-s) * b[0] + c * b[1] - e).abs() < 1e-13 * rho);
            }
        }
    }

    #[test]
    fn tangency_and_refusals() {
        let z = [0.0, 0.0, 1.0];
        let x = [1.0, 0.0, 0.0];
        // B at distance |e|: the double root, the guide normal to CB.
        let [c, s] = through([0.0; 3], z, [0.0, 1.0, 0.0], x, [0.0, 1.0, 0.0], Sign::Plus, [0, 0]).unwrap();
        assert!((c - 1.0).abs() < 1e-15 && s.abs() < 1e-15);
        // Nearer: out of reach by |e| − ρ.
        match through([0.0; 3], z, [0.0, 1.0, 0.0], x, [0.0, 0.5, 0.0], Sign::Plus, [0, 0]) {
            Err(GeomError::Unreachable { by, .. }) => assert!((by - 0.5).abs() < 1e-15),
            other => panic!("{other:?}"),
        }
        // B on the axis with the line through it: any angle.
        assert!(matches!(
            through([0.0; 3], z, [0.0; 3], x, [0.0, 0.0, 3.0], Sign::Plus, [0, 0]),
            Err(GeomError::Degenerate { .. })
        ));
    }
}
