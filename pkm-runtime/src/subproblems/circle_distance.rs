//! A circle meeting a sphere: the turn about an axis that puts a point at
//! a given distance from another (Paden–Kahan subproblem 3), its constant
//! term formed stably near concentric circles and its root's sine by
//! Kahan's triangle area ([`super::triangle::kahan_sine`]).

use super::triangle::kahan_sine;
use crate::primitives::Error as GeomError;
use crate::scalar::{norm, Scalar};

/// The turn `[cos θ, sin θ]` that puts the circle's point
/// `centre + R(axis, θ)·radius` (`axis` unit, the turn right-handed) at
/// distance `d` from `q`, for every [`Scalar`]: with `p⊥`, `q⊥` the two
/// points' parts normal to the axis and `δ` their axial separation,
/// `|R(θ)p − q|² = δ² + rp² + rq² − 2((p⊥·q⊥) cosθ + (k·(p⊥ × q⊥)) sinθ)`,
/// so `θ` solves `(p⊥·q⊥) cosθ + (k·(p⊥ × q⊥)) sinθ =
/// (rp² + rq² + (δ − d)(δ + d))/2` by [`crate::subproblems::trig::trig_turns`]'s
/// formula, the circle's radius `rp` the exact `length` (a rotation keeps
/// `|p⊥|`, so `√(a² + b²) = rp·rq` needs no square root), the largest of
/// `rp`, `rq`, `|δ|`
/// paired with `d` so that nearly concentric circles cancel exactly, and the
/// root's sine by [`kahan_sine`]. `Plus` is the root counter-clockwise
/// (about the axis) of `q⊥`'s direction. A `d` beyond
/// `dmax = √(δ² + (rp + rq)²)` or short of `dmin = √(δ² + (rp − rq)²)` by
/// more than the tangency tolerance is out of reach by the difference; `p`
/// or `q` on the axis is degenerate.
///
/// ```
/// use pkm_runtime::primitives::Sign;
/// use pkm_runtime::subproblems::circle_distance::circle_distance;
///
/// // The unit circle about z meets the unit circle about (1, 0, 0) at ±60°.
/// let (o, z, x) = ([0.0; 3], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
/// let [c, s] = circle_distance(o, z, x, 1.0, x, 1.0, Sign::Plus, [0, 0]).unwrap();
/// assert!((c - 0.5).abs() < 1e-15 && (s.abs() - 0.75f64.sqrt()).abs() < 1e-15);
/// ```
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn circle_distance<T: Scalar>(
    centre: [T; 3],
    axis: [T; 3],
    radius: [T; 3],
    length: T,
    q: [T; 3],
    d: T,
    choice: T::Choice,
    site: [usize; 2],
) -> Result<[T; 2], GeomError<f64>> {
    use crate::scalar::{cross, dot, max, reject, sub, Failure};
    let k = axis;
    let pp = reject(radius, k);
    let qv = sub(q, centre);
    let qp = reject(qv, k);
    let delta = dot(k, sub(radius, qv));
    let rq = norm(qp);
    let zero = T::c(0.0);
    T::require(zero, length, Failure::Degenerate("p on the rotation axis"), site)?;
    T::require(zero, rq, Failure::Degenerate("q on the rotation axis"), site)?;
    // |p⊥| is the exact `length` (a rotation keeps it); measured, it would
    // differ by rounding only, at the cost of a square root and a division.
    let (cos_coef, sin_coef) = (dot(pp, qp), dot(k, cross(pp, qp)));
    // The largest of length, rq, |δ| is paired with d: (x − d)(x + d) + y² + z².
    let ad = delta.abs();
    let (x1, y1) = (max(length, rq), T::if_less_continuous(length, rq, length, rq));
    let (x, y, z) = (max(x1, ad), T::if_less_continuous(x1, ad, x1, ad), y1);
    let c = ((x - d) * (x + d) + (y * y + z * z)) / T::c(2.0);
    let sum = length + rq;
    let diff = length - rq;
    let far = Failure::Distance {
        d,
        dmax: (delta * delta + sum * sum).sqrt(),
        dmin: (delta * delta + diff * diff).sqrt(),
    };
    // The sine of the angle between p⊥ and q⊥'s turn, from the triangle
    // (rp, rq, d⊥) by Kahan's area: accurate where the roots meet (a
    // dyad near its fold), where √((1 − c)(1 + c)) loses half the digits.
    let d_perp = ((d - ad) * (d + ad)).sqrt();
    let known = crate::subproblems::trig::Known {
        norm: length * rq,
        sine: kahan_sine(length, rq, d_perp),
    };
    crate::subproblems::trig::trig_turn_with_sine(cos_coef, sin_coef, c, Some(known), choice, site, Some(far))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::primitives::Sign;

    /// What a circle's turn to a distance should give.
    #[derive(Debug)]
    enum Want {
        /// The Plus and Minus angles.
        Roots([f64; 2]),
        /// Out of reach by this much, the constraint naming this word.
        Far(f64, &'static str),
        /// No isolated root; the reason names this.
        Degenerate(&'static str),
    }

    /// The circle about the unit `k` through `centre` that `radius` sweeps
    /// (`length` its exact radius) against the sphere of radius `d` about `q`.
    fn check_circle(centre: [f64; 3], k: [f64; 3], radius: [f64; 3], length: f64, q: [f64; 3], d: f64, want: Want) {
        let got = [Sign::Plus, Sign::Minus].map(|s| circle_distance(centre, k, radius, length, q, d, s, [0, 0]));
        match (got, &want) {
            ([Ok(p), Ok(m)], Want::Roots(angles)) => {
                for ([cos, sin], angle) in [p, m].iter().zip(angles) {
                    assert!(
                        (cos - angle.cos()).abs() < 1e-15 && (sin - angle.sin()).abs() < 1e-15,
                        "d = {d}: {cos} {sin} vs {angle}"
                    );
                }
            }
            ([Err(GeomError::Unreachable { by, constraint }), _], Want::Far(far, word)) => {
                assert!((by - far).abs() <= 1e-9 * far, "d = {d}: by {by} vs {far}");
                assert!(constraint.contains(word), "{constraint}");
            }
            ([Err(GeomError::Degenerate { what }), _], Want::Degenerate(word)) => {
                assert!(what.contains(word), "{what}")
            }
            (got, _) => panic!("d = {d}: {got:?} vs {want:?}"),
        }
    }

    /// By hand: (1, 0, 0) turned by θ about z is `d` from (0, 2, 0) where
    /// `d² = cos²θ + (sinθ − 2)² = 5 − 4 sinθ`; with the point lifted to
    /// (1, 0, 1), `d² = 6 − 4 sinθ`. Plus is the root counter-clockwise of
    /// the direction to `q` (φ = π/2 here).
    #[test]
    fn circle_meets_sphere_tangency_and_refusals() {
        use std::f64::consts::{FRAC_PI_2, PI};
        use Want::*;
        let (o, z, p, q) = ([0.0; 3], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 2.0, 0.0]);
        check_circle(o, z, p, 1.0, q, 5f64.sqrt(), Roots([PI, 0.0]));
        check_circle(o, z, p, 1.0, q, 3f64.sqrt(), Roots([5.0 * PI / 6.0, PI / 6.0]));
        check_circle(o, z, p, 1.0, q, 7f64.sqrt(), Roots([-5.0 * PI / 6.0, -PI / 6.0]));
        // About −z the turns change sign.
        let down = [0.0, 0.0, -1.0];
        check_circle(o, down, p, 1.0, q, 3f64.sqrt(), Roots([-PI / 6.0, -5.0 * PI / 6.0]));
        // Moved to the centre (1, 1, 1): the same turns.
        check_circle([1.0; 3], z, p, 1.0, [1.0, 3.0, 1.0], 5f64.sqrt(), Roots([PI, 0.0]));
        // The nearest (1) and farthest (3) distances: one turn each.
        check_circle(o, z, p, 1.0, q, 1.0, Roots([FRAC_PI_2; 2]));
        check_circle(o, z, p, 1.0, q, 3.0, Roots([-FRAC_PI_2; 2]));
        // A hair beyond them (within TANGENCY_TOL): the same double roots.
        check_circle(o, z, p, 1.0, q, 1.0 - 1e-12, Roots([FRAC_PI_2; 2]));
        check_circle(o, z, p, 1.0, q, 3.0 + 1e-12, Roots([-FRAC_PI_2; 2]));
        // Beyond by more: out by the distance past 3, or short of 1.
        check_circle(o, z, p, 1.0, q, 3.5, Far(0.5, "largest"));
        check_circle(o, z, p, 1.0, q, 0.5, Far(0.5, "smallest"));
        // Lifted a unit along the axis: distances √2 … √10.
        let lifted = [1.0, 0.0, 1.0];
        check_circle(o, z, lifted, 1.0, q, 2.0, Roots([5.0 * PI / 6.0, PI / 6.0]));
        check_circle(o, z, lifted, 1.0, q, 10f64.sqrt(), Roots([-FRAC_PI_2; 2]));
        check_circle(o, z, lifted, 1.0, q, 4.0, Far(4.0 - 10f64.sqrt(), "largest"));
        check_circle(o, z, lifted, 1.0, q, 1.0, Far(2f64.sqrt() - 1.0, "smallest"));
        // On the axis, the distance does not depend on the turn.
        check_circle(o, z, [0.0, 0.0, 1.0], 0.0, q, 2.0, Degenerate("p on the rotation axis"));
        check_circle(o, z, p, 1.0, [0.0, 0.0, 3.0], 2.0, Degenerate("q on the rotation axis"));
    }

    /// Two circles of radius `r` in one plane, the second's centre `ulps`
    /// steps of 1.0 along y from the first's: they meet on the bisector,
    /// `half` (exact: half the centres' exact distance) from either centre
    /// along y, so the first circle's point there has `r·sinθ = half`
    /// and `|r·cosθ| = √(r² − half²)`, to an ulp or so of `r`.
    #[test]
    fn nearly_concentric_circles_keep_their_digits() {
        for (r, x0) in [(1.0, 0.0), (7.3, -3.7), (0.25, 4.2), (9.9, 1e-3)] {
            let o = [x0, 1.0, 0.0];
            let mut q = o;
            for ulps in 1..=10 {
                q[1] = f64::next_up(q[1]);
                let half = (q[1] - o[1]) / 2.0;
                for s in [Sign::Plus, Sign::Minus] {
                    let [c, sin] = circle_distance(o, [0.0, 0.0, 1.0], [r, 0.0, 0.0], r, q, r, s, [0, 0]).unwrap();
                    assert!(
                        (r * sin - half).abs() <= 4.0 * f64::EPSILON * r,
                        "r {r}, {ulps} ulps: {} vs {half}",
                        r * sin
                    );
                    let chord = (r * r - half * half).sqrt();
                    assert!(((r * c).abs() - chord).abs() <= 4.0 * f64::EPSILON * r, "{c}");
                }
            }
        }
    }
}
