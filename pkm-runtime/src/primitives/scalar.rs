//! Scalar equations: the trigonometric equation `a·cosθ + b·sinθ = c` and the
//! quadratic `a x² + b x + c = 0`, both solved without cancellation.

use super::{ensure_finite, ensure_finite_roots, non_finite_result, Error, Roots2, TANGENCY_TOL};
use crate::real::Real;

/// Solves `a·cosθ + b·sinθ = c` for `θ ∈ [-π, π]`.
///
/// With `h = hypot(a, b)` and `φ = atan2(b, a)` the equation reads
/// `h·cos(θ − φ) = c`, so `θ = φ ± δ` with `δ = atan2(sqrt(h² − c²), c) ∈ [0, π]`.
/// Both branches are evaluated as a single `atan2` each (no `acos`, no angle
/// sum to wrap). After scaling `(a, b, c)` by `1/h` (so tiny or huge
/// coefficients neither under- nor overflow), with `s = sqrt((1 − |c|)(1 + |c|))`,
///
/// * `Plus`  (`θ = φ + δ`): `atan2(b·c + a·s, a·c − b·s)`,
/// * `Minus` (`θ = φ − δ`): `atan2(b·c − a·s, a·c + b·s)`.
///
/// # Errors and tangency
///
/// * `|c| = h`, or `|c|` exceeds `h` by at most [`TANGENCY_TOL`]`·h`:
///   [`Roots2::Tangent`] with `θ = φ` (if `c > 0`) or `φ + π` (if `c < 0`).
/// * `|c| > h` beyond that: [`Error::Unreachable`] with `by = |c| − h` (units of `c`).
/// * `a = b = 0`: [`Error::Degenerate`] (every or no `θ` solves it).
///
/// # Example
///
/// ```
/// use pkm_runtime::primitives::{trig_equation, Sign};
///
/// // 3 cosθ + 4 sinθ = 5 touches its maximum once, at θ = atan2(4, 3).
/// let r = trig_equation(3.0, 4.0, 5.0).unwrap();
/// assert!(r.is_tangent());
/// assert!((r.branch(Sign::Plus) - 4.0_f64.atan2(3.0)).abs() < 1e-15);
///
/// // cosθ = 0: θ = +π/2 (Plus) and −π/2 (Minus).
/// let r = trig_equation(1.0, 0.0, 0.0).unwrap();
/// let [p, m] = r.branches();
/// assert!((p - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
/// assert!((m + std::f64::consts::FRAC_PI_2).abs() < 1e-15);
/// ```
pub fn trig_equation<T: Real>(a: T, b: T, c: T) -> Result<Roots2<T>, Error<T>> {
    ensure_finite(&[a, b, c])?;
    let h = a.hypot(b);
    if h == T::zero() {
        return Err(Error::Degenerate { what: "a = b = 0" });
    }
    let abs_c = c.abs();
    if super::classify_excess(abs_c - h, h, "|c| <= hypot(a, b)")? {
        // c ≠ 0 here because |c| ≥ h·(1 − tol) > 0.
        let value = if c > T::zero() { b.atan2(a) } else { (-b).atan2(-a) };
        return Ok(Roots2::Tangent { value });
    }
    // Work with (a, b, c) / h: scale-free, so nothing under- or overflows.
    let (a, b, c) = (a / h, b / h, c / h);
    let abs_c = c.abs();
    let one = T::one();
    let s = ((one - abs_c) * (one + abs_c)).sqrt();
    let plus = b.mul_add(c, a * s).atan2(a.mul_add(c, -(b * s)));
    let minus = b.mul_add(c, -(a * s)).atan2(a.mul_add(c, b * s));
    Ok(Roots2::Two {
        branches: [plus, minus],
    })
}

/// Outcome of [`stable_quadratic`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum QuadraticRoots<T> {
    /// `a ≠ 0`: `Plus` is `(−b + sqrt(D)) / 2a` and `Minus` is `(−b − sqrt(D)) / 2a`
    /// with `D = b² − 4ac` (so `Plus < Minus` when `a < 0`); a double root
    /// `−b / 2a` is `Tangent`.
    Quadratic(Roots2<T>),
    /// `a = 0` exactly, `b ≠ 0`: the single root `−c / b` of the linear equation.
    Linear {
        /// `−c / b`.
        root: T,
    },
}

/// Real roots of `a x² + b x + c = 0` by the stable quadratic formula.
///
/// With `q = −(b + sign(b)·sqrt(D)) / 2` (`sign(0) = +1`) the roots are `q / a`
/// and `c / q`: the two terms of `b + sign(b)·sqrt(D)` never cancel, so both
/// roots keep full relative accuracy even when `|4ac| ≪ b²`. The
/// discriminant `D = b² − 4ac` is formed with fused multiply-adds and the
/// rounding error of `a·c` added back (Kahan), so it is accurate near a
/// double root. Only an exactly zero `a` is treated as linear; a tiny `a`
/// simply yields one huge root, correctly.
///
/// # Errors and tangency
///
/// * `D = 0`, or `D < 0` with `−D ≤ 2·`[`TANGENCY_TOL`]`·b²` (i.e. `2·sqrt(ac)`
///   exceeds `|b|` by at most about `TANGENCY_TOL·|b|`): `Tangent { value: −b / 2a }`.
/// * `D < 0` beyond that: [`Error::Unreachable`] with `by = sqrt(−D) / 2|a|`,
///   the imaginary part of the complex pair.
/// * `a = b = 0`: [`Error::Degenerate`].
///
/// # Example
///
/// ```
/// use pkm_runtime::primitives::{stable_quadratic, QuadraticRoots, Roots2};
///
/// // x² − 5x + 6 = (x − 3)(x − 2): Plus = 3, Minus = 2.
/// let r = stable_quadratic(1.0, -5.0, 6.0).unwrap();
/// assert_eq!(r, QuadraticRoots::Quadratic(Roots2::Two { branches: [3.0, 2.0] }));
///
/// // 2x − 4 = 0.
/// assert_eq!(stable_quadratic(0.0, 2.0, -4.0), Ok(QuadraticRoots::Linear { root: 2.0 }));
/// ```
pub fn stable_quadratic<T: Real>(a: T, b: T, c: T) -> Result<QuadraticRoots<T>, Error<T>> {
    ensure_finite(&[a, b, c])?;
    let zero = T::zero();
    let two = T::from_f64(2.0);
    let four = T::from_f64(4.0);
    if a == zero {
        if b == zero {
            return Err(Error::Degenerate { what: "a = b = 0" });
        }
        let root = -c / b;
        return if root.is_finite() {
            Ok(QuadraticRoots::Linear { root })
        } else {
            Err(non_finite_result())
        };
    }
    let ac = a * c;
    let ac_err = a.mul_add(c, -ac); // exact rounding error of a·c
    let disc = b.mul_add(b, -(four * ac)) - four * ac_err;
    let roots = if disc < zero {
        if -disc <= two * T::from_f64(TANGENCY_TOL) * b * b {
            Roots2::Tangent { value: -b / (two * a) }
        } else {
            return Err(Error::Unreachable {
                constraint: "b^2 >= 4ac (real roots)",
                by: (-disc).sqrt() / (two * a.abs()),
            });
        }
    } else if disc == zero {
        Roots2::Tangent { value: -b / (two * a) }
    } else {
        let s = disc.sqrt();
        if b >= zero {
            let q = -(b + s) / two; // q/a = (−b − s)/2a is the Minus root
            Roots2::Two {
                branches: [c / q, q / a],
            }
        } else {
            let q = (s - b) / two; // q/a = (−b + s)/2a is the Plus root
            Roots2::Two {
                branches: [q / a, c / q],
            }
        }
    };
    ensure_finite_roots(roots, |x: &T| x.is_finite()).map(QuadraticRoots::Quadratic)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::primitives::testing::{angle_diff, check_by, Want};
    use crate::primitives::Sign;
    use core::f64::consts::{FRAC_PI_2, PI};

    /// Solves, checks the outcome shape, and checks every returned θ against
    /// the defining equation; `exact` (if given) are the `[Plus, Minus]` angles.
    fn check(a: f64, b: f64, c: f64, want: Want, exact: Option<[f64; 2]>) {
        let h = a.hypot(b);
        let got = trig_equation(a, b, c);
        match (got, want) {
            (Ok(r @ Roots2::Two { .. }), Want::Two) | (Ok(r @ Roots2::Tangent { .. }), Want::Tangent) => {
                let tol = if want == Want::Tangent {
                    2.0 * TANGENCY_TOL * h
                } else {
                    1e-13 * h.max(1.0)
                };
                for th in r.branches() {
                    let res = a * th.cos() + b * th.sin() - c;
                    assert!(res.abs() <= tol, "({a},{b},{c}): θ={th} residual {res}");
                    assert!((-PI..=PI).contains(&th));
                }
                if let Some(e) = exact {
                    for s in Sign::ALL {
                        let d = angle_diff(r.branch(s), e[s.index()]);
                        assert!(d < 1e-14, "({a},{b},{c}) {s:?}: {} vs {}", r.branch(s), e[s.index()]);
                    }
                }
            }
            (Err(Error::Unreachable { by, .. }), Want::Unreachable(b)) => check_by(by, b),
            (Err(Error::Degenerate { .. }), Want::Degenerate) => {}
            (other, _) => panic!("({a},{b},{c}): wanted {want:?}, got {other:?}"),
        }
    }

    #[test]
    fn trig_equation_cases() {
        use Want::*;
        let phi = 4.0_f64.atan2(3.0);
        check(1.0, 0.0, 0.0, Two, Some([FRAC_PI_2, -FRAC_PI_2]));
        check(0.0, 1.0, 0.0, Two, Some([PI, 0.0]));
        check(3.0, 4.0, 0.0, Two, Some([phi + FRAC_PI_2, phi - FRAC_PI_2]));
        check(1.0, 1.0, 1.0, Two, Some([FRAC_PI_2, 0.0]));
        check(-2.0, 0.0, 1.0, Two, Some([PI + PI / 3.0, PI - PI / 3.0]));
        check(3.0, 4.0, 2.5, Two, Some([phi + PI / 3.0, phi - PI / 3.0]));
        check(1e-200, 2e-200, 1e-200, Two, None);
        check(1e150, -3e150, 2e150, Two, None);
        // a² + b² = c² exactly and within the tolerance on either side.
        check(3.0, 4.0, 5.0, Tangent, Some([phi, phi]));
        check(3.0, 4.0, -5.0, Tangent, Some([phi - PI, phi - PI]));
        check(0.0, 2.0, 2.0, Tangent, Some([FRAC_PI_2; 2]));
        check(3.0, 4.0, 5.0 * (1.0 + 1e-12), Tangent, Some([phi, phi]));
        check(3.0, 4.0, 5.0 * (1.0 - 1e-12), Two, None);
        check(3.0, 4.0, -5.0 * (1.0 - 1e-12), Two, None);
        check(3.0, 4.0, 5.0 + 1e-6, Unreachable(1e-6), None);
        check(1.0, 0.0, -2.0, Unreachable(1.0), None);
        check(0.0, 0.0, 0.0, Degenerate, None);
        check(0.0, 0.0, 1.0, Degenerate, None);
        check(f64::NAN, 1.0, 0.0, Degenerate, None);
        check(1.0, f64::INFINITY, 0.0, Degenerate, None);
    }

    #[test]
    fn trig_equation_near_tangent_branches_are_distinct_and_ordered() {
        // c just below h: δ = acos(1 − 1e-12) ≈ sqrt(2e-12), Plus above φ, Minus below.
        let phi = 4.0_f64.atan2(3.0);
        let r = trig_equation(3.0, 4.0, 5.0 * (1.0 - 1e-12)).unwrap();
        let [p, m] = r.branches();
        let delta = (2e-12_f64).sqrt();
        assert!((p - phi - delta).abs() < 1e-3 * delta, "{p}");
        assert!((phi - m - delta).abs() < 1e-3 * delta, "{m}");
    }

    /// Checks the outcome of `stable_quadratic` against `want` and, for
    /// roots, the defining equation and the branch order.
    fn check_quadratic(a: f64, b: f64, c: f64, want: Want, exact: Option<[f64; 2]>) {
        match (stable_quadratic(a, b, c), want) {
            (Ok(QuadraticRoots::Quadratic(r)), Want::Two | Want::Tangent) => {
                assert_eq!(r.is_tangent(), want == Want::Tangent, "({a},{b},{c}): {r:?}");
                let [p, m] = r.branches();
                if let Roots2::Two { .. } = r {
                    // Plus is (−b + √D)/2a: larger root iff a > 0.
                    assert_eq!(p > m, a > 0.0, "({a},{b},{c}): order {p} {m}");
                }
                if let Some([ep, em]) = exact {
                    assert!((p - ep).abs() <= 1e-15 * ep.abs(), "({a},{b},{c}): {p} vs {ep}");
                    assert!((m - em).abs() <= 1e-15 * em.abs(), "({a},{b},{c}): {m} vs {em}");
                } else {
                    for x in [p, m] {
                        let res = a * x * x + b * x + c;
                        let scale = (a * x * x).abs() + (b * x).abs() + c.abs();
                        assert!(res.abs() <= 1e-9 * scale, "({a},{b},{c}): x={x} res={res}");
                    }
                }
            }
            (Ok(QuadraticRoots::Linear { root }), Want::Two) => {
                assert_eq!(Some([root, root]), exact, "({a},{b},{c})");
            }
            (Err(Error::Unreachable { by, .. }), Want::Unreachable(b)) => check_by(by, b),
            (Err(Error::Degenerate { .. }), Want::Degenerate) => {}
            (other, _) => panic!("({a},{b},{c}): wanted {want:?}, got {other:?}"),
        }
    }

    #[test]
    fn stable_quadratic_cases() {
        use Want::*;
        check_quadratic(1.0, -5.0, 6.0, Two, Some([3.0, 2.0]));
        check_quadratic(1.0, 5.0, 6.0, Two, Some([-2.0, -3.0]));
        check_quadratic(-1.0, 5.0, -6.0, Two, Some([2.0, 3.0]));
        check_quadratic(2.0, 0.0, -8.0, Two, Some([2.0, -2.0]));
        check_quadratic(1.0, -3.0, 0.0, Two, Some([3.0, 0.0]));
        // Cancellation-prone: the small root of x² − 1e8 x + 1 is 1e-8 (1 + 1e-16).
        check_quadratic(1.0, -1e8, 1.0, Two, Some([1e8, 1e-8]));
        check_quadratic(1.0, 1e8, 1.0, Two, Some([-1e-8, -1e8]));
        // Tiny leading coefficient: roots 1 and −1e20 (to 1e-20 relative).
        check_quadratic(1e-20, 1.0, -1.0, Two, Some([1.0, -1e20]));
        check_quadratic(3.0, 7.0, -11.0, Two, None);
        // Double roots, exactly and within tolerance.
        check_quadratic(1.0, -2.0, 1.0, Tangent, Some([1.0, 1.0]));
        check_quadratic(4.0, 4.0, 1.0, Tangent, Some([-0.5, -0.5]));
        check_quadratic(1.0, -2.0, 1.0 + 1e-12, Tangent, Some([1.0, 1.0]));
        check_quadratic(1.0, -2.0, 1.0 - 1e-12, Two, None);
        // x² + 1: roots ±i, imaginary part 1; x² − 2x + 5: 1 ± 2i.
        check_quadratic(1.0, 0.0, 1.0, Unreachable(1.0), None);
        check_quadratic(1.0, -2.0, 5.0, Unreachable(2.0), None);
        check_quadratic(0.0, 2.0, -4.0, Two, Some([2.0, 2.0]));
        check_quadratic(0.0, -4.0, 0.0, Two, Some([0.0, 0.0]));
        check_quadratic(0.0, 0.0, 1.0, Degenerate, None);
        check_quadratic(0.0, 0.0, 0.0, Degenerate, None);
        check_quadratic(f64::NAN, 1.0, 1.0, Degenerate, None);
        check_quadratic(1e300, 1e300, -1e300, Degenerate, None); // b² overflows
    }

    #[test]
    fn stable_quadratic_discriminant_is_accurate_near_double_root() {
        // (x − 1)(x − (1 + 2^-26)): D = 2^-52 is below the rounding of b² = 4 + 2^-24 + ...,
        // recovered by the fused discriminant; the roots differ in the 8th digit.
        let r2 = 1.0 + 2f64.powi(-26);
        let (b, c) = (-(1.0 + r2), r2);
        let r = stable_quadratic(1.0, b, c).unwrap();
        let QuadraticRoots::Quadratic(Roots2::Two { branches: [p, m] }) = r else {
            panic!("{r:?}")
        };
        assert!((p - r2).abs() <= 4.0 * f64::EPSILON, "{p}");
        assert!((m - 1.0).abs() <= 4.0 * f64::EPSILON, "{m}");
    }
}
