//! Spatial primitives: intersections of lines, planes and spheres, and the
//! rotation of a point about an axis to a prescribed distance.
//!
//! Points and vectors are `[x, y, z]`; directions, normals and axes need not
//! be unit length.

use super::paden_kahan::axis_pair;
use super::scalar::trig_equation;
use super::vec::{axpy, cross3, dot, finite, norm, sub, unit};
use super::{
    ensure_finite, ensure_finite_roots, half_chord, non_finite_input, non_finite_result, triangle_apex, Error,
    LinePoint, Roots2, PARALLEL_TOL,
};
use crate::real::Real;

/// Intersection of the line `{line_point + t·unit(line_dir)}` with the plane
/// through `plane_point` with normal `plane_normal`.
///
/// `t = n·(plane_point − line_point) / (n·u)` with unit `n`, `u`.
///
/// # Errors
///
/// * `|n·u| ≤` [`PARALLEL_TOL`] (line parallel to the plane, inside it or not): `Degenerate`.
/// * Zero direction or normal, non-finite data or result: `Degenerate`.
///
/// # Example
///
/// ```
/// use pkm_runtime::primitives::line_plane;
///
/// // The diagonal through the origin meets the plane z = 3 at (3, 3, 3).
/// let hit = line_plane([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [0.0, 0.0, 3.0], [0.0, 0.0, 1.0]).unwrap();
/// assert!((hit.t - 27.0_f64.sqrt()).abs() < 1e-14);
/// assert!(hit.point.iter().all(|c| (c - 3.0_f64).abs() < 1e-14));
/// ```
pub fn line_plane<T: Real>(
    line_point: [T; 3],
    line_dir: [T; 3],
    plane_point: [T; 3],
    plane_normal: [T; 3],
) -> Result<LinePoint<T, 3>, Error<T>> {
    if !(finite(&line_point) && finite(&line_dir) && finite(&plane_point) && finite(&plane_normal)) {
        return Err(non_finite_input());
    }
    let u = unit(line_dir, "zero-length line direction")?;
    let n = unit(plane_normal, "zero-length plane normal")?;
    let cos = dot(n, u);
    if cos.abs() <= T::from_f64(PARALLEL_TOL) {
        return Err(Error::Degenerate {
            what: "line parallel to plane",
        });
    }
    let t = dot(n, sub(plane_point, line_point)) / cos;
    let point = axpy(line_point, t, u);
    if t.is_finite() && finite(&point) {
        Ok(LinePoint { t, point })
    } else {
        Err(non_finite_result())
    }
}

/// Intersection of the line `{line_point + t·unit(line_dir)}` with the
/// sphere of `radius` about `centre`.
///
/// With `t0` the foot of the centre
/// on the line and `e = |u × (centre − line_point)|` its distance,
/// `t = t0 ± sqrt((radius − e)(radius + e))`; `Plus` is the larger `t`.
///
/// # Errors and tangency (scale: `e`)
///
/// * `e` exceeds `radius` by at most [`TANGENCY_TOL`](super::TANGENCY_TOL)`·e`,
///   or equals it: `Tangent` at the foot.
/// * Beyond: `Unreachable { by: e − radius }`.
/// * Negative radius, zero direction, non-finite data: `Degenerate`.
///
/// # Example
///
/// ```
/// use pkm_runtime::primitives::{line_sphere, Sign};
///
/// let r = line_sphere([-10.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 3.0, 0.0], 5.0).unwrap();
/// assert_eq!(r.branch(Sign::Plus).point, [4.0, 0.0, 0.0]);
/// assert_eq!(r.branch(Sign::Minus).t, 6.0);
/// ```
pub fn line_sphere<T: Real>(
    line_point: [T; 3],
    line_dir: [T; 3],
    centre: [T; 3],
    radius: T,
) -> Result<Roots2<LinePoint<T, 3>>, Error<T>> {
    if !(finite(&line_point) && finite(&line_dir) && finite(&centre)) {
        return Err(non_finite_input());
    }
    ensure_finite(&[radius])?;
    if radius < T::zero() {
        return Err(Error::Degenerate {
            what: "negative radius",
        });
    }
    let u = unit(line_dir, "zero-length line direction")?;
    let w = sub(centre, line_point);
    let t0 = dot(u, w);
    let e = norm(cross3(u, w));
    let chords = half_chord(e, radius, "distance(centre, line) <= radius")?;
    let roots = chords.map(|s| {
        let t = t0 + s;
        LinePoint {
            t,
            point: axpy(line_point, t, u),
        }
    });
    ensure_finite_roots(roots, |p| p.t.is_finite() && finite(&p.point))
}

/// Trilateration: the point(s) at distances `r1`, `r2`, `r3` from the centres
/// `c1`, `c2`, `c3` (sphere–sphere–sphere intersection).
///
/// In the frame `ex = unit(c2 − c1)`, `ey` = unit of the part of `c3 − c1`
/// normal to `ex` (so `c3 = c1 + i·ex + j·ey`, `j > 0`), `ez = ex × ey`, the
/// problem is solved as three stable planar steps, no squared lengths
/// subtracted:
///
/// 1. spheres 1 and 2 meet in a circle in the plane `x = x0`, of radius `ρ`
///    (the foot and Kahan height of the triangle `(d, r1, r2)`);
/// 2. sphere 3 cuts that plane in a circle of radius
///    `ρ3 = sqrt((r3 − |x0 − i|)(r3 + |x0 − i|))` about `c1 + x0·ex + j·ey`;
/// 3. the two circles meet, within the plane, at `y`, `±z` (Kahan again).
///
/// `Plus` is the solution with `z > 0`, on the side of `(c2 − c1) × (c3 − c1)`.
///
/// # Errors and tangency
///
/// Each step can be `Unreachable` (with `by` the distance excess of that
/// step and a `constraint` naming it) or tangent within
/// [`TANGENCY_TOL`](super::TANGENCY_TOL) of its longest length; any tangency
/// makes the result `Tangent` (the point in the plane of the centres).
/// `c1 = c2`, collinear centres (`j ≤` [`PARALLEL_TOL`]`·|c3 − c1|`), negative
/// radii and non-finite data are `Degenerate`.
///
/// # Example
///
/// ```
/// use pkm_runtime::primitives::{trilaterate, Sign};
///
/// // (2, 3, ±6) is at distance 7 from (0,0,0), (4,0,0) and (0,6,0).
/// let r = trilaterate([0.0, 0.0, 0.0], 7.0, [4.0, 0.0, 0.0], 7.0, [0.0, 6.0, 0.0], 7.0).unwrap();
/// let p = r.branch(Sign::Plus);
/// assert!((p[0] - 2.0_f64).abs() < 1e-14 && (p[1] - 3.0_f64).abs() < 1e-14 && (p[2] - 6.0_f64).abs() < 1e-14);
/// ```
pub fn trilaterate<T: Real>(
    c1: [T; 3],
    r1: T,
    c2: [T; 3],
    r2: T,
    c3: [T; 3],
    r3: T,
) -> Result<Roots2<[T; 3]>, Error<T>> {
    if !(finite(&c1) && finite(&c2) && finite(&c3)) {
        return Err(non_finite_input());
    }
    ensure_finite(&[r1, r2, r3])?;
    if r1 < T::zero() || r2 < T::zero() || r3 < T::zero() {
        return Err(Error::Degenerate {
            what: "negative radius",
        });
    }
    let e12 = sub(c2, c1);
    let d = norm(e12);
    let ex = unit(e12, "coincident centres c1 = c2")?;
    let w3 = sub(c3, c1);
    let i = dot(ex, w3);
    let across = axpy(w3, -i, ex);
    let j = norm(across);
    if j <= T::from_f64(PARALLEL_TOL) * norm(w3) {
        return Err(Error::Degenerate {
            what: "collinear centres",
        });
    }
    let ey = unit(across, "collinear centres")?;
    let ez = cross3(ex, ey);
    // 1. Circle of spheres 1 and 2: centre c1 + x0·ex, radius rho.
    let (x0, rho) = triangle_apex(
        d,
        r1,
        r2,
        "spheres 1 and 2 meet: |c1 c2| <= r1 + r2",
        "spheres 1 and 2 meet: |c1 c2| >= |r1 - r2|",
    )?;
    let rho = rho.branch(super::Sign::Plus);
    // 2. Circle of sphere 3 in the plane x = x0.
    let rho3 = half_chord((x0 - i).abs(), r3, "sphere 3 reaches the plane of circle 1-2")?;
    let rho3 = rho3.branch(super::Sign::Plus);
    // 3. The two circles within that plane; their centres are j apart along ey.
    let (y, zs) = triangle_apex(
        j,
        rho,
        rho3,
        "circle 1-2 meets sphere 3 (too far)",
        "circle 1-2 meets sphere 3 (nested)",
    )?;
    // A tangency in step 1 or 2 (ρ = 0 or ρ3 = 0) makes step 3 tangent or unreachable by itself.
    let base = axpy(axpy(c1, x0, ex), y, ey);
    ensure_finite_roots(zs.map(|z| axpy(base, z, ez)), finite)
}

/// Rotation angles `θ` of the point `p` about the axis through `axis_point`
/// along `axis_dir` (right-handed) that bring it to distance `d` from `q`:
/// `|R(θ)·(p − o) + o − q| = d`. The circle–sphere subproblem (IK-Geo
/// subproblem 3; [`pk3`](super::pk3) is this function).
///
/// ```text
///            axis k
///              ▲        R(θ)p
///              │   ╭──────●────╮        circle swept by p
///              o ──┼───────────┼──
///                  ╰───────────╯
///                         ╲ d
///                          ● q
/// ```
///
/// Split `p − o` and `q − o` into axial parts (difference `δ = k·(p − q)`)
/// and radial parts `p⊥`, `q⊥` of lengths `rp`, `rq`. Then
/// `|R(θ)p − q|² = δ² + rp² + rq² − 2·(a·cosθ + b·sinθ)` with
/// `a = p⊥·q⊥`, `b = k·(p⊥ × q⊥)`, so `θ` solves
/// [`trig_equation`]`(a, b, c)` with `c = (rp² + rq² + (δ − d)(δ + d)) / 2`,
/// and inherits its branch order (`Plus` = `φ + δ'`, `φ = atan2(b, a)`).
///
/// # Errors and tangency
///
/// * Tangency as in [`trig_equation`] (scale `rp·rq`): `d` at the extreme
///   distances `dmin = hypot(δ, rp − rq)` or `dmax = hypot(δ, rp + rq)`.
/// * `d` outside `[dmin, dmax]`: `Unreachable` with `by = d − dmax` or
///   `dmin − d` (a length).
/// * `p` or `q` on the axis (the distance does not depend on `θ`), zero axis,
///   negative `d`, non-finite data: `Degenerate`.
///
/// # Example
///
/// ```
/// use pkm_runtime::primitives::{rotate_to_distance, Sign};
///
/// use std::f64::consts::PI;
///
/// // Rotating (1,0,0) about z: |R(θ)p − (0,2,0)|² = 5 − 4 sinθ, which is 3 for
/// // sinθ = 1/2, i.e. θ = 5π/6 (Plus) and θ = π/6 (Minus).
/// let r = rotate_to_distance([0.0; 3], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 2.0, 0.0], 3.0_f64.sqrt())
///     .unwrap();
/// assert!((r.branch(Sign::Plus) - 5.0 * PI / 6.0).abs() < 1e-12);
/// assert!((r.branch(Sign::Minus) - PI / 6.0).abs() < 1e-12);
/// ```
pub fn rotate_to_distance<T: Real>(
    axis_point: [T; 3],
    axis_dir: [T; 3],
    p: [T; 3],
    q: [T; 3],
    d: T,
) -> Result<Roots2<T>, Error<T>> {
    circle_to_distance(axis_point, axis_dir, p, None, q, d)
}

/// [`rotate_to_distance`] for a circle whose radius `rp` is known exactly
/// (from a link's own geometry) rather than measured from `p`, which then
/// gives only the direction of θ = 0. `None` measures it from `p`.
///
/// Why: when `q` is near the axis (`rq → 0`, two circle centres nearly
/// coincident) the constant term `c = (rp² + rq² + δ² − d²)/2` is tiny, and
/// `rp` measured from world coordinates carries a rounding error of
/// `ε·rp`, which becomes an angle error `ε·rp/rq`. With `rp` exact and the
/// largest of `rp`, `rq`, `|δ|` paired with `d` as `(x − d)(x + d)`, equal
/// radii give `c = (rq² + δ²)/2` to full relative accuracy.
///
/// # Example
///
/// ```
/// use pkm_runtime::primitives::{circle_to_distance, Sign};
///
/// // Two unit circles whose centres are 1e-14 apart (the second about (1e-14, 0, 0)):
/// // they meet where x = 5e-15, y = ±sqrt(1 − x²).
/// let r = circle_to_distance([0.0; 3], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], Some(1.0), [1e-14, 0.0, 0.0], 1.0)
///     .unwrap();
/// let theta = r.branch(Sign::Plus);
/// // θ = π/2 − 5e-15: its cosine is 5e-15 to within an ulp of π/2.
/// assert!((theta.cos() - 5e-15).abs() < 3e-16 && (theta.sin() - 1.0).abs() < 1e-15);
/// ```
pub fn circle_to_distance<T: Real>(
    axis_point: [T; 3],
    axis_dir: [T; 3],
    p: [T; 3],
    rp: Option<T>,
    q: [T; 3],
    d: T,
) -> Result<Roots2<T>, Error<T>> {
    if !(finite(&axis_point) && finite(&axis_dir) && finite(&p) && finite(&q)) {
        return Err(non_finite_input());
    }
    ensure_finite(&[d])?;
    if let Some(r) = rp {
        ensure_finite(&[r])?;
    }
    if d < T::zero() || rp.is_some_and(|r| r < T::zero()) {
        return Err(Error::Degenerate {
            what: "negative distance",
        });
    }
    let k = unit(axis_dir, "zero-length axis")?;
    let ax = axis_pair(axis_point, k, p, q);
    if ax.rp == T::zero() || rp == Some(T::zero()) {
        return Err(Error::Degenerate {
            what: "p on the rotation axis",
        });
    }
    if ax.rq == T::zero() {
        return Err(Error::Degenerate {
            what: "q on the rotation axis",
        });
    }
    // The coefficients scale with the exact radius; p's direction is all that is measured.
    let (rp, scale) = match rp {
        Some(r) => (r, r / ax.rp),
        None => (ax.rp, T::one()),
    };
    let (rq, delta) = (ax.rq, ax.delta);
    let c = sum_of_squares_minus(rp, rq, delta.abs(), d) / T::from_f64(2.0);
    trig_equation(ax.cos_coef * scale, ax.sin_coef * scale, c).map_err(|e| match e {
        Error::Unreachable { .. } => {
            let dmax = delta.hypot(rp + rq);
            let dmin = delta.hypot(rp - rq);
            if d > dmax {
                Error::Unreachable {
                    constraint: "d <= largest distance from q to the circle",
                    by: d - dmax,
                }
            } else {
                let by = dmin - d;
                Error::Unreachable {
                    constraint: "d >= smallest distance from q to the circle",
                    by: if by > T::zero() { by } else { T::zero() },
                }
            }
        }
        other => other,
    })
}

/// `a² + b² + c² − d²` (all non-negative) with the largest of `a, b, c`
/// paired with `d` as `(x − d)(x + d)`: exact cancellation when `x = d`.
fn sum_of_squares_minus<T: Real>(a: T, b: T, c: T, d: T) -> T {
    let (x, y, z) = if a >= b && a >= c {
        (a, b, c)
    } else if b >= c {
        (b, a, c)
    } else {
        (c, a, b)
    };
    (x - d) * (x + d) + y.mul_add(y, z * z)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::primitives::testing::{angle_diff, check_by, check_line_hits, dist, rotate, Lcg, Want};
    use crate::primitives::{Sign, TANGENCY_TOL};
    use core::f64::consts::{FRAC_PI_2, PI};

    fn unit_f(v: [f64; 3]) -> [f64; 3] {
        let n = dist(v, [0.0; 3]);
        [v[0] / n, v[1] / n, v[2] / n]
    }

    fn dot_f(a: [f64; 3], b: [f64; 3]) -> f64 {
        a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    }

    fn check_line_plane(
        lp: [f64; 3],
        ld: [f64; 3],
        pp: [f64; 3],
        pn: [f64; 3],
        want: Want,
        exact: Option<([f64; 3], f64)>,
    ) {
        match (line_plane(lp, ld, pp, pn), want) {
            (Ok(hit), Want::Two) => {
                let scale = 1.0 + hit.t.abs() + dist(lp, pp);
                let (u, n) = (unit_f(ld), unit_f(pn));
                let on_line = [lp[0] + hit.t * u[0], lp[1] + hit.t * u[1], lp[2] + hit.t * u[2]];
                assert!(dist(on_line, hit.point) <= 1e-14 * scale, "{hit:?}");
                let off = dot_f(n, [hit.point[0] - pp[0], hit.point[1] - pp[1], hit.point[2] - pp[2]]);
                assert!(off.abs() <= 1e-14 * scale, "{hit:?}: off the plane by {off}");
                if let Some((p, t)) = exact {
                    assert!(
                        dist(hit.point, p) <= 1e-14 * scale && (hit.t - t).abs() <= 1e-14 * scale,
                        "{hit:?}"
                    );
                }
            }
            (Err(Error::Degenerate { .. }), Want::Degenerate) => {}
            (other, _) => panic!("line_plane({lp:?}, {ld:?}, {pp:?}, {pn:?}): wanted {want:?}, got {other:?}"),
        }
    }

    #[test]
    fn line_plane_cases() {
        use Want::*;
        let o = [0.0; 3];
        let z = [0.0, 0.0, 1.0];
        check_line_plane(
            o,
            [1.0, 1.0, 1.0],
            [0.0, 0.0, 3.0],
            z,
            Two,
            Some(([3.0; 3], 27f64.sqrt())),
        );
        check_line_plane(
            [1.0, 2.0, 3.0],
            [0.0, 0.0, -2.0],
            o,
            [0.0, 0.0, 5.0],
            Two,
            Some(([1.0, 2.0, 0.0], 3.0)),
        );
        check_line_plane(
            o,
            [1.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            Two,
            Some(([1.0, 0.0, 0.0], 1.0)),
        );
        check_line_plane(
            [5.0, 5.0, 5.0],
            [1.0, 0.0, 0.0],
            o,
            [-1.0, 0.0, 0.0],
            Two,
            Some(([0.0, 5.0, 5.0], -5.0)),
        );
        check_line_plane(
            [0.3, -0.2, 0.9],
            [0.1, 0.7, -0.4],
            [1.0, 1.0, -1.0],
            [0.2, -0.3, 0.9],
            Two,
            None,
        );
        // Nearly parallel: valid but far; parallel within PARALLEL_TOL: degenerate.
        check_line_plane(o, [1.0, 0.0, 1e-9], [0.0, 0.0, 1.0], z, Two, None);
        check_line_plane(o, [1.0, 0.0, 1e-13], [0.0, 0.0, 1.0], z, Degenerate, None);
        check_line_plane(o, [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], z, Degenerate, None);
        check_line_plane(o, [1.0, 0.0, 0.0], o, z, Degenerate, None); // line inside the plane
        check_line_plane(o, [0.0; 3], o, z, Degenerate, None);
        check_line_plane(o, z, o, [0.0; 3], Degenerate, None);
        check_line_plane(o, z, [f64::NAN, 0.0, 0.0], z, Degenerate, None);
    }

    fn check_line_sphere(lp: [f64; 3], ld: [f64; 3], c: [f64; 3], r: f64, want: Want, exact_t: Option<[f64; 2]>) {
        check_line_hits(
            line_sphere(lp, ld, c, r),
            want,
            (c, r),
            lp,
            ld,
            exact_t,
            dist(lp, c).max(r),
        );
    }

    #[test]
    fn line_sphere_cases() {
        use Want::*;
        let o = [0.0; 3];
        let x = [1.0, 0.0, 0.0];
        check_line_sphere([-10.0, 0.0, 0.0], x, [0.0, 3.0, 0.0], 5.0, Two, Some([14.0, 6.0]));
        check_line_sphere([-10.0, 0.0, 0.0], x, [0.0, 0.0, -3.0], 5.0, Two, Some([14.0, 6.0]));
        check_line_sphere(o, [1.0, 1.0, 1.0], o, 3.0, Two, Some([3.0, -3.0]));
        check_line_sphere([1.0, 2.0, 2.0], [-2.0, -4.0, -4.0], o, 3.0, Two, Some([6.0, 0.0]));
        check_line_sphere([0.4, -0.3, 2.0], [0.2, 0.1, -1.0], [0.1, 0.2, 0.3], 0.9, Two, None);
        check_line_sphere([-10.0, 5.0, 0.0], x, o, 5.0, Tangent, Some([10.0, 10.0]));
        check_line_sphere([-10.0, 0.0, 5.0 * (1.0 + 1e-12)], x, o, 5.0, Tangent, None);
        check_line_sphere([-10.0, 0.0, 5.0 * (1.0 - 1e-12)], x, o, 5.0, Two, None);
        check_line_sphere([-10.0, 0.0, 5.001], x, o, 5.0, Unreachable(0.001), None);
        check_line_sphere([-10.0, 3.0, 4.0], x, o, 4.0, Unreachable(1.0), None);
        check_line_sphere(o, x, o, -1.0, Degenerate, None);
        check_line_sphere(o, [0.0; 3], o, 1.0, Degenerate, None);
        check_line_sphere(o, x, [0.0, f64::INFINITY, 0.0], 1.0, Degenerate, None);
    }

    type Spheres = [([f64; 3], f64); 3];

    fn check_tri(s: Spheres, want: Want, exact: Option<[[f64; 3]; 2]>) {
        let [(c1, r1), (c2, r2), (c3, r3)] = s;
        let scale = [dist(c1, c2), dist(c1, c3), r1, r2, r3].into_iter().fold(0.0, f64::max);
        match (trilaterate(c1, r1, c2, r2, c3, r3), want) {
            (Ok(roots), Want::Two | Want::Tangent) => {
                assert_eq!(roots.is_tangent(), want == Want::Tangent, "{roots:?}");
                let tol = if roots.is_tangent() { 4.0 * TANGENCY_TOL } else { 1e-14 } * scale;
                for p in roots.branches() {
                    for (c, r) in s {
                        assert!(
                            (dist(p, c) - r).abs() <= tol,
                            "{p:?}: |p - {c:?}| = {} != {r}",
                            dist(p, c)
                        );
                    }
                }
                if let Roots2::Two { branches: [p, m] } = roots {
                    let n = cross3(sub(c2, c1), sub(c3, c1));
                    assert!(dot_f(n, sub(p, c1)) > 0.0 && dot_f(n, sub(m, c1)) < 0.0, "{roots:?}");
                }
                if let Some(e) = exact {
                    for sg in Sign::ALL {
                        assert!(
                            dist(roots.branch(sg), e[sg.index()]) <= 1e-14 * scale,
                            "{sg:?}: {roots:?}"
                        );
                    }
                }
            }
            (Err(Error::Unreachable { by, .. }), Want::Unreachable(b)) => check_by(by, b),
            (Err(Error::Degenerate { .. }), Want::Degenerate) => {}
            (other, _) => panic!("trilaterate({s:?}): wanted {want:?}, got {other:?}"),
        }
    }

    #[test]
    fn trilaterate_cases() {
        use Want::*;
        let o = [0.0; 3];
        let (a, b, c) = ([4.0, 0.0, 0.0], [0.0, 6.0, 0.0], [6.0, 0.0, 0.0]);
        let up_down = Some([[2.0, 3.0, 6.0], [2.0, 3.0, -6.0]]);
        check_tri([(o, 7.0), (a, 7.0), (b, 7.0)], Two, up_down);
        check_tri([(b, 7.0), (o, 7.0), (a, 7.0)], Two, up_down);
        check_tri(
            [(o, 7.0), (b, 7.0), (a, 7.0)],
            Two,
            Some([[2.0, 3.0, -6.0], [2.0, 3.0, 6.0]]),
        );
        let shift = |p: [f64; 3]| [p[0] + 10.0, p[1] - 20.0, p[2] + 30.0];
        check_tri(
            [(shift(o), 7.0), (shift(a), 7.0), (shift(b), 7.0)],
            Two,
            Some([shift([2.0, 3.0, 6.0]), shift([2.0, 3.0, -6.0])]),
        );
        // (3, 4, 0) is at distance 5 from (0,0,0), (6,0,0) and (0,8,0): a tangency.
        let b8 = [0.0, 8.0, 0.0];
        check_tri([(o, 5.0), (c, 5.0), (b8, 5.0)], Tangent, Some([[3.0, 4.0, 0.0]; 2]));
        check_tri([(o, 5.0), (c, 5.0), (b8, 5.0 - 1e-12)], Tangent, None);
        check_tri([(o, 5.0), (c, 5.0), (b8, 5.0 + 1e-12)], Two, None);
        check_tri(
            [(o, 5.0), (c, 5.0), (b8, 4.5)],
            Unreachable(4.0 - 11.25f64.sqrt()),
            None,
        );
        check_tri([(o, 2.0), (c, 2.0), (b8, 5.0)], Unreachable(2.0), None);
        check_tri([(o, 5.0), (c, 5.0), ([20.0, 8.0, 0.0], 3.0)], Unreachable(14.0), None);
        // Spheres 1 and 2 tangent: the only candidate is (3, 0, 0).
        check_tri(
            [(o, 3.0), (c, 3.0), ([3.0, 4.0, 0.0], 4.0)],
            Tangent,
            Some([[3.0, 0.0, 0.0]; 2]),
        );
        check_tri(
            [(o, 1.0), ([2.0, 0.0, 0.0], 1.0), ([4.0, 0.0, 0.0], 1.0)],
            Degenerate,
            None,
        );
        check_tri([(o, 1.0), (o, 1.0), (b, 1.0)], Degenerate, None);
        check_tri([(o, 1.0), (a, 1.0), (o, 1.0)], Degenerate, None);
        check_tri([(o, -1.0), (a, 1.0), (b, 1.0)], Degenerate, None);
        check_tri([(o, f64::NAN), (a, 1.0), (b, 1.0)], Degenerate, None);
    }

    #[test]
    fn trilaterate_recovers_random_points() {
        let mut g = Lcg(7);
        for _ in 0..50 {
            let x = g.point(2.0);
            let cs = [g.point(3.0), g.point(3.0), g.point(3.0)];
            let s = cs.map(|c| (c, dist(c, x)));
            check_tri(s, Want::Two, None);
            let r = trilaterate(s[0].0, s[0].1, s[1].0, s[1].1, s[2].0, s[2].1).unwrap();
            let best = r
                .branches()
                .map(|p| dist(p, x))
                .into_iter()
                .fold(f64::INFINITY, f64::min);
            assert!(best <= 1e-9, "{x:?}: {r:?}");
        }
    }

    fn check_rtd(o: [f64; 3], k: [f64; 3], p: [f64; 3], q: [f64; 3], d: f64, want: Want, exact: Option<[f64; 2]>) {
        let scale = dist(p, o).max(dist(q, o)).max(d);
        match (rotate_to_distance(o, k, p, q, d), want) {
            (Ok(r), Want::Two | Want::Tangent) => {
                assert_eq!(r.is_tangent(), want == Want::Tangent, "{r:?}");
                let tol = if r.is_tangent() { 2.0 * TANGENCY_TOL } else { 1e-13 } * scale;
                for th in r.branches() {
                    let got = dist(rotate(o, k, th, p), q);
                    assert!((got - d).abs() <= tol, "θ = {th}: distance {got} != {d}");
                }
                if let Some(e) = exact {
                    for s in Sign::ALL {
                        assert!(angle_diff(r.branch(s), e[s.index()]) <= 1e-7, "{s:?}: {r:?}");
                    }
                }
            }
            (Err(Error::Unreachable { by, .. }), Want::Unreachable(b)) => check_by(by, b),
            (Err(Error::Degenerate { .. }), Want::Degenerate) => {}
            (other, _) => panic!("rotate_to_distance({o:?}, {k:?}, {p:?}, {q:?}, {d}): wanted {want:?}, got {other:?}"),
        }
    }

    #[test]
    fn circle_to_distance_nearly_concentric() {
        // Two circles of radius r in the plane z = 0, the second's centre k ulps
        // of x = 1 to the right of the first's: they meet at x = c/2 exactly,
        // y = ±sqrt(r² − (c/2)²); the angle of the first circle's point must
        // keep that to an ulp.
        let mut rng = Lcg(5);
        for _ in 0..200 {
            let r = 10.0 * rng.uniform(0.1, 1.0);
            let o = [rng.uniform(-5.0, 5.0), 1.0, 0.0];
            let mut q = o;
            for ulps in 1..=10 {
                q[1] = f64::next_up(q[1]);
                let half = (q[1] - o[1]) / 2.0;
                let roots = circle_to_distance(o, [0.0, 0.0, 1.0], [o[0] + r, o[1], 0.0], Some(r), q, r).unwrap();
                for theta in roots.branches() {
                    let (s, c) = theta.sin_cos();
                    // The meeting points' offset along the centres' line is `half`.
                    assert!(
                        (r * s - half).abs() <= 4.0 * f64::EPSILON * r,
                        "{ulps} ulps: {} vs {half}",
                        r * s
                    );
                    assert!((r * c).abs() - (r * r - half * half).sqrt() <= 4.0 * f64::EPSILON * r);
                }
            }
        }
    }

    #[test]
    fn rotate_to_distance_cases() {
        use Want::*;
        let o = [0.0; 3];
        let z = [0.0, 0.0, 1.0];
        let (p, q) = ([1.0, 0.0, 0.0], [0.0, 2.0, 0.0]);
        // |R(θ)p − q|² = 5 − 4 sinθ.
        check_rtd(o, z, p, q, 5f64.sqrt(), Two, Some([PI, 0.0]));
        check_rtd(o, z, p, q, 3f64.sqrt(), Two, Some([5.0 * PI / 6.0, PI / 6.0]));
        check_rtd(o, z, p, q, 7f64.sqrt(), Two, Some([-5.0 * PI / 6.0, -PI / 6.0]));
        check_rtd(
            o,
            [0.0, 0.0, -2.0],
            p,
            q,
            3f64.sqrt(),
            Two,
            Some([-PI / 6.0, -5.0 * PI / 6.0]),
        );
        check_rtd(
            [1.0, 1.0, 1.0],
            [0.0, 0.0, 3.0],
            [2.0, 1.0, 1.0],
            [1.0, 3.0, 1.0],
            5f64.sqrt(),
            Two,
            Some([PI, 0.0]),
        );
        check_rtd(o, z, p, q, 1.0, Tangent, Some([FRAC_PI_2; 2]));
        check_rtd(o, z, p, q, 3.0, Tangent, Some([-FRAC_PI_2; 2]));
        check_rtd(o, z, p, q, 1.0 - 1e-12, Tangent, None);
        check_rtd(o, z, p, q, 1.0 + 1e-12, Two, None);
        check_rtd(o, z, p, q, 3.0 + 1e-12, Tangent, None);
        check_rtd(o, z, p, q, 3.5, Unreachable(0.5), None);
        check_rtd(o, z, p, q, 0.5, Unreachable(0.5), None);
        // Axial offset 1: reachable distances [√2, √10].
        let p1 = [1.0, 0.0, 1.0];
        check_rtd(o, z, p1, q, 2.0, Two, None);
        check_rtd(o, z, p1, q, 10f64.sqrt(), Tangent, Some([-FRAC_PI_2; 2]));
        check_rtd(o, z, p1, q, 4.0, Unreachable(4.0 - 10f64.sqrt()), None);
        check_rtd(o, z, p1, q, 1.0, Unreachable(2f64.sqrt() - 1.0), None);
        check_rtd(o, z, [0.0, 0.0, 1.0], q, 2.0, Degenerate, None);
        check_rtd(o, z, p, [0.0, 0.0, 3.0], 2.0, Degenerate, None);
        check_rtd(o, [0.0; 3], p, q, 2.0, Degenerate, None);
        check_rtd(o, z, p, q, -1.0, Degenerate, None);
        check_rtd(o, z, p, q, f64::NAN, Degenerate, None);
    }

    #[test]
    fn rotate_to_distance_recovers_random_angles() {
        let mut g = Lcg(11);
        for _ in 0..50 {
            let (o, k, p, q) = (g.point(1.0), g.point(1.0), g.point(2.0), g.point(2.0));
            let theta = g.uniform(-PI, PI);
            let d = dist(rotate(o, k, theta, p), q);
            check_rtd(o, k, p, q, d, Want::Two, None);
            let r = rotate_to_distance(o, k, p, q, d).unwrap();
            let best = r
                .branches()
                .map(|t| angle_diff(t, theta))
                .into_iter()
                .fold(f64::INFINITY, f64::min);
            assert!(best <= 1e-7, "θ = {theta}: {r:?}");
        }
    }
}
