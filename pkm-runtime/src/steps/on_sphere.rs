//! A point of the new link held on a sphere: at a parallelogram's arm length
//! from a known point, or at an S–S link's length from its other centre
//! ([`Radius`]; that sphere's match is [`super::sphere_link::find_sphere`]). The joint moves the point on a circle (R, Pa) or a
//! line (P): a circle meeting a sphere (`a·cosθ + b·sinθ = c`, the constant
//! term formed stably near concentric circles) or a line meeting a sphere
//! (the foot of the perpendicular ± the half-chord).

use super::search::{reversed, Reach, Search};
use super::{Found, Motion, Move};
use crate::model::Place;
use crate::plan::v3;
use crate::plan::{Anchor, Constraint, Radius};
use crate::primitives::{Error as GeomError, TANGENCY_TOL};
use crate::scalar::{norm, Scalar};
use crate::singular::{Condition, Configuration, LinkPoint};
use crate::solution::{PointRef, SolveError};
use nalgebra::Vector3;

/// The value of the joint that puts `point` of the new link at the
/// distance `radius` fixes (a parallelogram's arm, an S–S link's length)
/// from the anchored `centre`; `branch` picks the root.
pub fn execute<T: Scalar>(
    mv: &Move<'_, T>,
    point: PointRef,
    centre: &Anchor,
    radius: Radius,
    branch: Option<usize>,
) -> Result<Found<T>, SolveError> {
    let (_, m) = mv.motion(point);
    let q = mv.geometry.anchor(&mv.state.poses, centre);
    let radius = match radius {
        Radius::Arm(pa) => arm_length(&mv.geometry.joints[pa].places),
        Radius::Rod { link, point, joint } => super::sphere_link::length(mv.geometry, link, point, joint),
    };
    Ok(mv.found(to_distance(mv, m, q, radius, mv.choice(branch))?))
}

/// The value that puts the moving point at distance `d` from `q`.
pub(crate) fn to_distance<T: Scalar>(
    mv: &Move<'_, T>,
    m: Motion<T>,
    q: [T; 3],
    d: T,
    choice: T::Choice,
) -> Result<[T; 2], SolveError> {
    match m {
        Motion::Circle {
            centre,
            axis,
            radius,
            length,
        } => circle_distance(centre, axis, radius, length, q, d, choice, mv.site()).map_err(|e| mv.fail(e)),
        Motion::Line { start, along } => {
            let [plus, minus] = line_distance(start, along, q, d, mv.site()).map_err(|e| mv.fail(e))?;
            Ok([T::pick(choice, plus, minus), T::c(0.0)])
        }
    }
}

/// The length of a parallelogram's arm.
pub fn arm_length<T: Scalar>(places: &[Place<T>; 2]) -> T {
    places
        .iter()
        .find_map(|p| match p {
            Place::Arm { arm, .. } => Some(norm(*arm)),
            _ => None,
        })
        .unwrap_or(T::c(f64::NAN))
}

/// The turn `[cos θ, sin θ]` that puts the circle's point
/// `centre + R(axis, θ)·radius` (`axis` unit, the turn right-handed) at
/// distance `d` from `q`, for every [`Scalar`]: with `p⊥`, `q⊥` the two
/// points' parts normal to the axis and `δ` their axial separation,
/// `|R(θ)p − q|² = δ² + rp² + rq² − 2((p⊥·q⊥) cosθ + (k·(p⊥ × q⊥)) sinθ)`,
/// so `θ` solves `(p⊥·q⊥) cosθ + (k·(p⊥ × q⊥)) sinθ =
/// (rp² + rq² + (δ − d)(δ + d))/2` by [`super::on_plane::trig_turns`]'s
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
/// use pkm_runtime::steps::on_sphere::circle_distance;
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
    let (x1, y1) = (max(length, rq), T::if_less(length, rq, length, rq));
    let (x, y, z) = (max(x1, ad), T::if_less(x1, ad, x1, ad), y1);
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
    let known = super::on_plane::Known {
        norm: length * rq,
        sine: kahan_sine(length, rq, d_perp),
    };
    super::on_plane::trig_turn_with_sine(cos_coef, sin_coef, c, Some(known), choice, site, Some(far))
}

/// The sine of the angle between sides `p` and `q` of the triangle with
/// sides `p`, `q`, `r`: `2·area/(p·q)`, the area by Kahan's formula
/// (`¼√((a + (b + c))(c − (a − b))(c + (a − b))(a + (b − c)))`, `a ≥ b ≥ c`),
/// exact to a few ulps however flat the triangle; 0 where the sides are a
/// hair past flat (the tangency the caller allows).
///
/// ```
/// use pkm_runtime::steps::on_sphere::kahan_sine;
///
/// // The 3-4-5 triangle: the right angle is between 3 and 4.
/// assert!((kahan_sine(3.0, 4.0, 5.0) - 1.0).abs() < 1e-15);
/// // A needle: sides 1, 1 and r = 2 − 2⁻⁴⁰ (exact), so by hand
/// // sin = (r/2)·√((4 − 2⁻⁴⁰)·2⁻⁴⁰), within 2⁻⁴¹ of 2⁻¹⁹ (the cosine
/// // route, √((1 − c)(1 + c)) with c = (2 − r²)/2, is 4.5e-13 off here).
/// let r = 2.0 - 2f64.powi(-40);
/// let s = kahan_sine(1.0, 1.0, r);
/// let exact = (r / 2.0) * ((4.0 - 2f64.powi(-40)) * 2f64.powi(-40)).sqrt();
/// assert!((s / exact - 1.0).abs() < 4.0 * f64::EPSILON, "{s}");
/// ```
#[inline]
pub fn kahan_sine<T: Scalar>(p: T, q: T, r: T) -> T {
    use crate::scalar::max;
    let min = |x: T, y: T| T::if_less(x, y, x, y);
    let a = max(max(p, q), r);
    let b = max(min(p, q), min(max(p, q), r));
    let c = min(min(p, q), r);
    let zero = T::c(0.0);
    let neck = c - (a - b);
    let neck = T::if_less(neck, zero, zero, neck);
    let area4 = ((a + (b + c)) * (a + (b - c))).sqrt() * (neck * (c + (a - b))).sqrt();
    area4 / (T::c(2.0) * p * q)
}

/// The slides `[t₊, t₋]` that put the line's point `start + t·u` (`u`
/// unit) at distance `d` from `q`, a line meeting a sphere, for every
/// [`Scalar`]: with `w = q − start`, the foot of the perpendicular
/// `t₀ = u·w` and the line's distance from `q` `e = |u × w|`,
/// `t = t₀ ± √((d − e)(d + e))`, no squared lengths subtracted. Within
/// `TANGENCY_TOL·e` beyond tangency both are the double root `t₀`; beyond
/// that, out of reach by `e − d`.
///
/// ```
/// use pkm_runtime::steps::on_sphere::line_distance;
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
    let s = (T::if_less(short, zero, zero, short) * (d + e)).sqrt();
    Ok([t0 + s, t0 - s])
}

/// The planner's match for a sphere: parallelogram `q`, met on the link the
/// reach `r` ends at, hinged at the point, with its other hinge staying put
/// along a reach to a known link (the centre); the point keeps the arm's
/// length from it. `j` is the joint that moves the point.
pub(crate) fn find(s: &Search<'_>, j: usize, r: &Reach, q: usize) -> Option<Constraint> {
    if (r.x - v3(s.place(q, r.link).at())).norm() > s.tol {
        return None;
    }
    let next = s.other(q, r.link);
    let b = v3(s.place(q, next).at());
    let mut excl = vec![j, q];
    excl.extend(r.hops.iter().map(|h| h.joint));
    let c = s.fixed_reach(next, b, &excl).into_iter().find(|c| s.known[c.link])?;
    Some(Constraint::Sphere {
        centre: Anchor {
            link: c.link,
            hops: reversed(&c.hops),
            point: PointRef::Joint(q),
        },
        radius: Radius::Arm(q),
    })
}

/// The sphere's normal at the moving point `p` (from the anchored
/// `centre`), for the locus's factor ([`super::locus_factor`]).
pub(crate) fn normal(at: &Configuration, p: Vector3<f64>, centre: &Anchor) -> (Vector3<f64>, Condition, LinkPoint) {
    let (c, point) = at.anchored(centre);
    (p - c, Condition::TouchesSphere, point)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::primitives::Sign;

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

    /// The sine of the angle between the first two sides.
    fn check_sine(p: f64, q: f64, r: f64, want: f64) {
        let got = kahan_sine(p, q, r);
        assert!(
            (got - want).abs() <= 4.0 * f64::EPSILON * want,
            "({p}, {q}, {r}): {got} vs {want}"
        );
    }

    #[test]
    fn kahan_sine_of_any_angle_and_of_needles() {
        // 3-4-5: the right angle between 3 and 4; sin = 4/5 between 3 and 5, 3/5 between 4 and 5.
        check_sine(3.0, 4.0, 5.0, 1.0);
        check_sine(3.0, 5.0, 4.0, 0.8);
        check_sine(5.0, 4.0, 3.0, 0.6);
        check_sine(1.0, 1.0, 1.0, 0.75f64.sqrt());
        // Flat, and a hair past flat (the tangency the caller allows): 0.
        check_sine(1.0, 2.0, 3.0, 0.0);
        check_sine(1.0, 1.0, 2.0 + 4.0 * f64::EPSILON, 0.0);
        // A needle: unit sides over the base b = 2 − 1e-12 (2 − b exact). The
        // apex's height is h = √(1 − b²/4) = √((2 − b)(2 + b))/2, the area b·h/2,
        // so the sine between the unit sides is b·h.
        let b: f64 = 2.0 - 1e-12;
        let h = ((2.0 - b) * (2.0 + b)).sqrt() / 2.0;
        check_sine(1.0, 1.0, b, b * h);
    }
}
