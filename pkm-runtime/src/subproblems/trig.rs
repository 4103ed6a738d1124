//! `a·cosθ + b·sinθ = c`: the turns `[cos θ, sin θ]` that satisfy it, the
//! kernel of every circle meeting a plane (a point turning about an axis
//! held on a plane, a turning line through a point, a circle meeting a
//! sphere once the constant term is formed).

use crate::primitives::{Error as GeomError, TANGENCY_TOL};
use crate::scalar::{Failure, Scalar};

/// Both turns `[cos θ, sin θ]` (Plus, Minus) solving `a·cosθ + b·sinθ = c`,
/// for every [`Scalar`]. With `h = √(a² + b²)` and `φ = atan2(b, a)` the
/// equation is `h·cos(θ − φ) = c`, so `θ = φ ± δ`, `cos δ = c/h`: scaled by
/// `h`, `|c| ≤ h` up to the tangency tolerance (clamped there: a double
/// root), `s = √((1 − |c|)(1 + |c|))` (no cancellation near `|c| = 1`), the
/// turns `(a c ∓ b s, b c ± a s)`, Plus `θ = φ + δ`. `a = b = 0` is
/// degenerate. `far` replaces the error of an unreachable `c` (by default
/// `|c| − h` out of reach).
///
/// ```
/// use pkm_runtime::subproblems::trig::trig_turns;
///
/// assert_eq!(trig_turns(1.0, 0.0, 0.0, [0, 0], None).unwrap(), [[0.0, 1.0], [0.0, -1.0]]);
/// assert!(trig_turns(1.0, 0.0, 2.0, [0, 0], None).is_err());
/// ```
#[inline]
pub fn trig_turns<T: Scalar>(
    a: T,
    b: T,
    c: T,
    site: [usize; 2],
    far: Option<Failure<T>>,
) -> Result<[[T; 2]; 2], GeomError<f64>> {
    trig_turns_with_sine(a, b, c, None, site, far)
}

/// What a caller of [`trig_turns_with_sine`] knows better than the
/// generic formulas: `h = √(a² + b²)` as a product of lengths it already
/// has (positive, checked by the caller: one square root and the test of
/// `a = b = 0` fewer), and the root's sine `s`, formed more accurately than
/// `√((1 − |c|)(1 + |c|))` near a double root (Kahan's triangle area,
/// [`crate::subproblems::circle_distance::circle_distance`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Known<T> {
    pub(crate) norm: T,
    pub(crate) sine: T,
}

/// [`trig_turns`], with `h` and the root's sine given where the caller
/// knows them ([`Known`]).
#[inline]
pub(crate) fn trig_turns_with_sine<T: Scalar>(
    a: T,
    b: T,
    c: T,
    known: Option<Known<T>>,
    site: [usize; 2],
    far: Option<Failure<T>>,
) -> Result<[[T; 2]; 2], GeomError<f64>> {
    let h = match known {
        Some(k) => k.norm,
        None => {
            let h = (a * a + b * b).sqrt();
            T::require(T::c(0.0), h, Failure::Degenerate("a = b = 0"), site)?;
            h
        }
    };
    let excess = c.abs() - h;
    let far = far.unwrap_or(Failure::Unreachable("|c| <= hypot(a, b)", excess));
    T::require(excess, T::c(TANGENCY_TOL) * h * T::c(1.0 + f64::EPSILON), far, site)?;
    let (a, b, c) = (a / h, b / h, c / h);
    // Within the tolerance beyond tangency: the double root.
    let one = T::c(1.0);
    let c = T::if_less_continuous(one, c, one, T::if_less_continuous(c, -one, -one, c));
    let s = match known {
        Some(k) => k.sine,
        None => {
            let abs_c = c.abs();
            ((one - abs_c) * (one + abs_c)).sqrt()
        }
    };
    Ok([[a * c - b * s, b * c + a * s], [a * c + b * s, b * c - a * s]])
}

/// The turn of [`trig_turns`] that `choice` picks.
#[inline]
pub fn trig_turn<T: Scalar>(
    a: T,
    b: T,
    c: T,
    choice: T::Choice,
    site: [usize; 2],
    far: Option<Failure<T>>,
) -> Result<[T; 2], GeomError<f64>> {
    trig_turn_with_sine(a, b, c, None, choice, site, far)
}

/// The turn of [`trig_turns_with_sine`] that `choice` picks.
#[inline]
pub(crate) fn trig_turn_with_sine<T: Scalar>(
    a: T,
    b: T,
    c: T,
    known: Option<Known<T>>,
    choice: T::Choice,
    site: [usize; 2],
    far: Option<Failure<T>>,
) -> Result<[T; 2], GeomError<f64>> {
    let [p, m] = trig_turns_with_sine(a, b, c, known, site, far)?;
    Ok([T::pick(choice, p[0], m[0]), T::pick(choice, p[1], m[1])])
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, PI};

    /// What `a·cosθ + b·sinθ = c` should give.
    #[derive(Debug)]
    enum Want {
        /// The Plus and Minus angles.
        Roots([f64; 2]),
        /// Out of reach by this much (`|c| − √(a² + b²)`).
        Far(f64),
        /// No isolated root.
        Degenerate,
    }

    fn check(a: f64, b: f64, c: f64, want: Want) {
        match (trig_turns(a, b, c, [0, 0], None), &want) {
            (Ok(turns), Want::Roots(angles)) => {
                for ([cos, sin], angle) in turns.iter().zip(angles) {
                    assert!(
                        (cos - angle.cos()).abs() < 1e-15 && (sin - angle.sin()).abs() < 1e-15,
                        "({a}, {b}, {c}): {cos} {sin} vs {angle}"
                    );
                }
            }
            (Err(GeomError::Unreachable { by, .. }), Want::Far(far)) => {
                assert!((by - far).abs() <= 1e-9 * far, "({a}, {b}, {c}): by {by} vs {far}")
            }
            (Err(GeomError::Degenerate { .. }), Want::Degenerate) => {}
            (got, _) => panic!("({a}, {b}, {c}): {got:?} vs {want:?}"),
        }
    }

    /// By hand: with `φ = atan2(b, a)` the equation is `√(a² + b²)·cos(θ − φ) = c`,
    /// so `θ = φ ± acos(c/√(a² + b²))`, Plus the `+`.
    #[test]
    fn both_roots_tangency_and_refusals() {
        use Want::*;
        let phi = 4f64.atan2(3.0);
        check(1.0, 0.0, 0.0, Roots([FRAC_PI_2, -FRAC_PI_2]));
        check(0.0, 1.0, 0.0, Roots([PI, 0.0]));
        check(3.0, 4.0, 0.0, Roots([phi + FRAC_PI_2, phi - FRAC_PI_2]));
        // cosθ + sinθ = 1: θ = 0 or π/2.
        check(1.0, 1.0, 1.0, Roots([FRAC_PI_2, 0.0]));
        // −2 cosθ = 1: cosθ = −1/2, φ = π, and π ± π/3.
        check(-2.0, 0.0, 1.0, Roots([PI + PI / 3.0, PI - PI / 3.0]));
        // c/h = 1/2: φ ± π/3.
        check(3.0, 4.0, 2.5, Roots([phi + PI / 3.0, phi - PI / 3.0]));
        // Large coefficients scale out: cos(θ − φ) = 2/√10.
        let (phi3, delta) = ((-3f64).atan2(1.0), (2.0 / 10f64.sqrt()).acos());
        check(1e150, -3e150, 2e150, Roots([phi3 + delta, phi3 - delta]));
        // |c| = h: the double root φ, or φ + π for negative c.
        check(3.0, 4.0, 5.0, Roots([phi, phi]));
        check(3.0, 4.0, -5.0, Roots([phi - PI, phi - PI]));
        check(0.0, 2.0, 2.0, Roots([FRAC_PI_2, FRAC_PI_2]));
        // Beyond tangency by 1e-12 of h (within TANGENCY_TOL): the double root.
        check(3.0, 4.0, 5.0 * (1.0 + 1e-12), Roots([phi, phi]));
        check(3.0, 4.0, -5.0 * (1.0 + 1e-12), Roots([phi - PI, phi - PI]));
        // Beyond by more: out of reach by |c| − h.
        check(3.0, 4.0, 5.0 + 1e-6, Far(1e-6));
        check(1.0, 0.0, -2.0, Far(1.0));
        check(0.0, 0.0, 0.0, Degenerate);
        check(0.0, 0.0, 1.0, Degenerate);
    }

    #[test]
    fn keeps_the_digits_of_two_roots_near_tangency() {
        // cosθ = 1 − 2⁻⁴⁰ (exact): sinθ = ±√((1 − c)(1 + c)) = ±√(2⁻⁴⁰(2 − 2⁻⁴⁰)),
        // two distinct roots ~1.3e-6 either side of 0, Plus above.
        let tiny = 2f64.powi(-40);
        let sin = (tiny * (2.0 - tiny)).sqrt();
        let [[cp, sp], [cm, sm]] = trig_turns(1.0, 0.0, 1.0 - tiny, [0, 0], None).unwrap();
        assert_eq!([cp, cm], [1.0 - tiny; 2]);
        assert!((sp / sin - 1.0).abs() <= 2.0 * f64::EPSILON, "{sp} vs {sin}");
        assert!((sm / -sin - 1.0).abs() <= 2.0 * f64::EPSILON, "{sm} vs {}", -sin);
    }
}
