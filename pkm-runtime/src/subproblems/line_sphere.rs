//! A line meeting a sphere (the foot of the perpendicular ± the
//! half-chord) and, on it, a slide meeting a circle in the circle's plane.

use crate::primitives::{Error as GeomError, TANGENCY_TOL};
use crate::scalar::{norm, Failure, Scalar};

/// The slides `[t₊, t₋]` that put the line's point `start + t·u` (`u`
/// unit) at distance `d` from `q`, a line meeting a sphere, for every
/// [`Scalar`]: with `w = q − start`, the foot of the perpendicular
/// `t₀ = u·w` and the line's distance from `q` `e = |u × w|`,
/// `t = t₀ ± √((d − e)(d + e))`, no squared lengths subtracted. Within
/// `TANGENCY_TOL·e` beyond tangency both are the double root `t₀`; beyond
/// that, out of reach by `e − d`.
///
/// ```
/// use pkm_runtime::subproblems::line_sphere::line_distance;
///
/// // The x axis meets the sphere of radius 5 about (0, 3, 0) at x = ±4.
/// let (o, x, q) = ([0.0; 3], [1.0, 0.0, 0.0], [0.0, 3.0, 0.0]);
/// assert_eq!(line_distance(o, x, q, 5.0, [0, 0]).unwrap(), [4.0, -4.0]);
/// assert!(line_distance(o, x, q, 2.0, [0, 0]).is_err());
/// ```
#[inline]
pub fn line_distance<T: Scalar>(
    start: [T; 3],
    u: [T; 3],
    q: [T; 3],
    d: T,
    site: [usize; 2],
) -> Result<[T; 2], GeomError<f64>> {
    use crate::scalar::{cross, dot, sub, Failure};
    let w = sub(q, start);
    let t0 = dot(u, w);
    let e = norm(cross(u, w));
    let excess = e - d;
    let far = Failure::Unreachable("distance(centre, line) <= radius", excess);
    T::require(excess, T::c(TANGENCY_TOL) * e * T::c(1.0 + f64::EPSILON), far, site)?;
    // Within the tolerance beyond tangency: the double root.
    let zero = T::c(0.0);
    let short = d - e;
    let s = (T::if_less_continuous(short, zero, zero, short) * (d + e)).sqrt();
    Ok([t0 + s, t0 - s])
}

/// The slide `[t, 0]` along `along` (not unit: the slide's direction with
/// its component along the cylinder's axis removed) from `start` that puts
/// the point at distance `d` from `q`, all in the plane normal to the
/// cylinder's axis: [`crate::subproblems::line_sphere::line_distance`] along the unit
/// direction, divided by `|along|`; `choice` picks the root.
///
/// # Errors
/// [`GeomError::Degenerate`] when the slide is parallel to the cylinder's
/// axis (`|along| ≤ 1e-12`).
///
/// ```
/// use pkm_runtime::primitives::Sign;
/// use pkm_runtime::subproblems::line_sphere::line_circle;
///
/// // Along x at half speed (|along| = 0.5): the circle of radius 5 about (0, 3) at x = ±4.
/// let (o, x, q) = ([0.0; 3], [0.5, 0.0, 0.0], [0.0, 3.0, 0.0]);
/// assert_eq!(line_circle(o, x, q, 5.0, Sign::Plus, [0, 0]).unwrap(), [8.0, 0.0]);
/// assert!(line_circle(o, [0.0; 3], q, 5.0, Sign::Plus, [0, 0]).is_err());
/// ```
#[inline]
pub fn line_circle<T: Scalar>(
    start: [T; 3],
    along: [T; 3],
    q: [T; 3],
    d: T,
    choice: T::Choice,
    site: [usize; 2],
) -> Result<[T; 2], GeomError<f64>> {
    let n = norm(along);
    let parallel = Failure::Degenerate("the slide is parallel to the cylinder's axis");
    T::require(T::c(1e-12), n, parallel, site)?;
    let u = [along[0] / n, along[1] / n, along[2] / n];
    let [plus, minus] = crate::subproblems::line_sphere::line_distance(start, u, q, d, site)?;
    Ok([T::pick(choice, plus, minus) / n, T::c(0.0)])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The x axis against the sphere of radius `d` about `(x0, e, 0)`: the
    /// slides by hand are `x0 ± √(d² − e²)`.
    fn check(x0: f64, e: f64, d: f64, expect: Result<[f64; 2], &str>) {
        let got = line_distance([0.0; 3], [1.0, 0.0, 0.0], [x0, e, 0.0], d, [0, 0]);
        match (got, expect) {
            (Ok(t), Ok(want)) => {
                for (t, w) in t.iter().zip(want) {
                    assert!(
                        (t - w).abs() <= 4.0 * f64::EPSILON * w.abs().max(x0.abs()),
                        "{t} vs {w}"
                    );
                }
            }
            (Err(GeomError::Unreachable { constraint, .. }), Err(w)) => assert!(constraint.contains(w)),
            (got, want) => panic!("{got:?} vs {want:?}"),
        }
    }

    #[test]
    fn meets_refuses_and_keeps_digits_near_tangency() {
        check(0.0, 3.0, 5.0, Ok([4.0, -4.0]));
        check(10.0, 0.0, 2.0, Ok([12.0, 8.0]));
        // Near tangency d² − e² cancels; (d − e)(d + e) does not:
        // d − e = 2⁻⁴⁰ exactly, so the half-chord is √(2⁻⁴⁰·(2 + 2⁻⁴⁰)).
        let tiny = 2f64.powi(-40);
        let half = (tiny * (2.0 + tiny)).sqrt();
        check(0.0, 1.0, 1.0 + tiny, Ok([half, -half]));
        // A hair beyond tangency (within TANGENCY_TOL·e): the double root.
        check(7.0, 1.0, 1.0 - 1e-12, Ok([7.0, 7.0]));
        check(0.0, 3.0, 2.0, Err("distance(centre, line)"));
    }

    /// The line `start + t·u` against the sphere of radius `d` about `q`:
    /// the slides `[t₊, t₋]` by hand, or the excess out of reach.
    fn check_line(start: [f64; 3], u: [f64; 3], q: [f64; 3], d: f64, expect: Result<[f64; 2], f64>) {
        match (line_distance(start, u, q, d, [0, 0]), expect) {
            (Ok(t), Ok(want)) => {
                let scale = want[0].abs().max(want[1].abs()).max(d);
                for (t, w) in t.iter().zip(want) {
                    assert!((t - w).abs() <= 4.0 * f64::EPSILON * scale, "{t} vs {w}");
                }
            }
            (Err(GeomError::Unreachable { by, .. }), Err(far)) => {
                assert!((by - far).abs() <= 1e-9 * far, "by {by} vs {far}")
            }
            (got, want) => panic!("{got:?} vs {want:?}"),
        }
    }

    #[test]
    fn lines_in_any_direction_meet_the_sphere() {
        let (o, x) = ([0.0; 3], [1.0, 0.0, 0.0]);
        // From (−10, 0, 0) along x to the sphere of radius 5 about (0, 0, −3): x = ±4.
        check_line([-10.0, 0.0, 0.0], x, [0.0, 0.0, -3.0], 5.0, Ok([14.0, 6.0]));
        // Along the diagonal through the centre: ±the radius.
        let d = 1.0 / 3f64.sqrt();
        check_line(o, [d, d, d], o, 3.0, Ok([3.0, -3.0]));
        // From (1, 2, 2), on the sphere of radius 3, towards and through the centre.
        let u = [-1.0 / 3.0, -2.0 / 3.0, -2.0 / 3.0];
        check_line([1.0, 2.0, 2.0], u, o, 3.0, Ok([6.0, 0.0]));
        // Tangent exactly, and a hair beyond (within TANGENCY_TOL): the foot twice.
        check_line([-10.0, 5.0, 0.0], x, o, 5.0, Ok([10.0, 10.0]));
        check_line([-10.0, 0.0, 5.0 * (1.0 + 1e-12)], x, o, 5.0, Ok([10.0, 10.0]));
        // Out of reach by the line's distance less the radius.
        check_line([-10.0, 0.0, 5.001], x, o, 5.0, Err(0.001));
        check_line([-10.0, 3.0, 4.0], x, o, 4.0, Err(1.0));
    }

    /// A slide along `along` (not unit: the value is in its units) from
    /// `start` against the circle of radius 5 about (0, 3, 0) in its plane:
    /// by hand the unit slides are ±4 (Plus the farther along the slide), so
    /// the values are ±4/|along|, and
    /// the point reached is 5 from the centre.
    #[test]
    fn a_slide_meets_a_circle_in_the_slides_units() {
        use crate::primitives::Sign;
        let (o, q) = ([0.0; 3], [0.0, 3.0, 0.0]);
        for (along, want) in [([2.0, 0.0, 0.0], 2.0), ([0.5, 0.0, 0.0], 8.0), ([-1.0, 0.0, 0.0], 4.0)] {
            for (sign, w) in [(Sign::Plus, want), (Sign::Minus, -want)] {
                let [v, zero] = line_circle(o, along, q, 5.0, sign, [0, 0]).unwrap();
                assert_eq!((v, zero), (w, 0.0), "{along:?} {sign:?}");
                let at = [v * along[0] - q[0], v * along[1] - q[1], v * along[2] - q[2]];
                assert!((norm(at) - 5.0).abs() < 1e-15);
            }
        }
        // No slide: degenerate; out of reach: by the excess.
        assert!(matches!(
            line_circle(o, [0.0; 3], q, 5.0, Sign::Plus, [0, 0]),
            Err(GeomError::Degenerate { .. })
        ));
        match line_circle(o, [1.0, 0.0, 0.0], q, 2.0, Sign::Plus, [0, 0]) {
            Err(GeomError::Unreachable { by, .. }) => assert!((by - 1.0).abs() < 1e-15),
            got => panic!("{got:?}"),
        }
    }
}
