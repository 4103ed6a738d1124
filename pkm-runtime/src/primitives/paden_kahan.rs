//! The Paden–Kahan subproblems of screw-theory inverse kinematics.
//!
//! Rotations are right-handed about unit axes through a given point; all
//! angles are returned in `[-π, π]`.
//!
//! * [`pk1`]: rotation about one axis taking `p` to `q`.
//! * [`pk2`]: successive rotations about two intersecting axes taking `p` to `q`.
//! * [`pk3`]: rotation about one axis bringing `p` to a distance from `q`
//!   (delegates to [`rotate_to_distance`]).

use super::spatial::rotate_to_distance;
use super::vec::{axpy, cross3, dot, finite, norm, split_axis, sub, unit};
use super::{half_chord, non_finite_input, Error, Roots2, PARALLEL_TOL, TANGENCY_TOL};
use crate::real::Real;

/// `p` and `q` decomposed about a unit axis `k` through `o` (crate-private).
pub(crate) struct AxisPair<T> {
    /// Axial separation `k·(p − q)`.
    pub(crate) delta: T,
    /// Distance of `p` from the axis.
    pub(crate) rp: T,
    /// Distance of `q` from the axis.
    pub(crate) rq: T,
    /// `|p − o|`.
    pub(crate) np: T,
    /// `|q − o|`.
    pub(crate) nq: T,
    /// `p⊥·q⊥`: `q⊥·R(θ)p⊥ = cos_coef·cosθ + sin_coef·sinθ`.
    pub(crate) cos_coef: T,
    /// `k·(p⊥ × q⊥)`.
    pub(crate) sin_coef: T,
}

/// Decomposes `p` and `q` about the unit axis `k` through `o`.
pub(crate) fn axis_pair<T: Real>(o: [T; 3], k: [T; 3], p: [T; 3], q: [T; 3]) -> AxisPair<T> {
    let (pv, qv) = (sub(p, o), sub(q, o));
    let (_, pp) = split_axis(k, pv);
    let (_, qp) = split_axis(k, qv);
    AxisPair {
        delta: dot(k, sub(p, q)),
        rp: norm(pp),
        rq: norm(qp),
        np: norm(pv),
        nq: norm(qv),
        cos_coef: dot(pp, qp),
        sin_coef: dot(k, cross3(pp, qp)),
    }
}

/// The angle of the rotation about the unit axis `k` through `o` that takes
/// the radial part of `p` to the direction of the radial part of `q`, without
/// checking that `p` and `q` lie on one circle (the least-squares angle).
fn rotation_angle<T: Real>(o: [T; 3], k: [T; 3], p: [T; 3], q: [T; 3], what: &'static str) -> Result<T, Error<T>> {
    let ax = axis_pair(o, k, p, q);
    if ax.rp == T::zero() || ax.rq == T::zero() {
        return Err(Error::Degenerate { what });
    }
    Ok(ax.sin_coef.atan2(ax.cos_coef))
}

/// Paden–Kahan subproblem 1: the angle `θ` of the rotation about the axis
/// through `axis_point` along `axis_dir` that takes `p` to `q`:
/// `R(θ)·(p − o) = q − o`.
///
/// `θ = atan2(k·(p⊥ × q⊥), p⊥·q⊥)` with `p⊥`, `q⊥` the parts of `p − o`,
/// `q − o` normal to the unit axis `k`.
///
/// # Errors (scale: `max(|p − o|, |q − o|)`)
///
/// * `|k·(p − q)| >` [`TANGENCY_TOL`]`·scale` (not in one plane normal to the
///   axis): `Unreachable { by: |k·(p − q)| }`.
/// * `||p⊥| − |q⊥|| > TANGENCY_TOL·scale` (not equidistant from the axis):
///   `Unreachable { by: ||p⊥| − |q⊥|| }`.
/// * `p` or `q` on the axis (any `θ` works), zero axis, non-finite data: `Degenerate`.
///
/// # Example
///
/// ```
/// use pkm_runtime::primitives::pk1;
///
/// // A quarter turn about z takes (1, 0, 5) to (0, 1, 5).
/// let th = pk1([0.0; 3], [0.0, 0.0, 1.0], [1.0, 0.0, 5.0], [0.0, 1.0, 5.0]).unwrap();
/// assert!((th - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
/// ```
pub fn pk1<T: Real>(axis_point: [T; 3], axis_dir: [T; 3], p: [T; 3], q: [T; 3]) -> Result<T, Error<T>> {
    if !(finite(&axis_point) && finite(&axis_dir) && finite(&p) && finite(&q)) {
        return Err(non_finite_input());
    }
    let k = unit(axis_dir, "zero-length axis")?;
    let ax = axis_pair(axis_point, k, p, q);
    let tol = T::from_f64(TANGENCY_TOL) * if ax.np > ax.nq { ax.np } else { ax.nq };
    if ax.delta.abs() > tol {
        return Err(Error::Unreachable {
            constraint: "k.p = k.q (one plane normal to the axis)",
            by: ax.delta.abs(),
        });
    }
    if (ax.rp - ax.rq).abs() > tol {
        return Err(Error::Unreachable {
            constraint: "p and q equidistant from the axis",
            by: (ax.rp - ax.rq).abs(),
        });
    }
    rotation_angle(axis_point, k, p, q, "p and q on the rotation axis")
}

/// Paden–Kahan subproblem 2: angles `(θ1, θ2)` of rotations about two axes
/// through the common point `axes_point` (unit directions `k1`, `k2`) with
/// `R(k1, θ1)·R(k2, θ2)·(p − r) = q − r` (rotate about `k2` first).
///
/// The intermediate point `c = R(k2, θ2)(p − r) = R(k1, −θ1)(q − r)` lies on
/// both circles: `k2·c = k2·(p − r)`, `k1·c = k1·(q − r)`, `|c| = |p − r|`.
/// Hence `c = α·k1 + β·k2 ± γ·ŵ` with `ŵ = unit(k1 × k2)`,
/// `α = (k1·q − s·k2·p) / |w|²`, `β = (k2·p − s·k1·q) / |w|²` (`s = k1·k2`),
/// and `γ = sqrt((|p| − |z0|)(|p| + |z0|))`, `z0 = α·k1 + β·k2`. Each `c`
/// gives `θ2` and `θ1` by subproblem 1. `Plus` is `+γ` (the intermediate point
/// on the side of `k1 × k2`).
///
/// # Errors and tangency
///
/// * `|z0|` exceeds `|p − r|` by at most [`TANGENCY_TOL`]`·|z0|`, or equals it:
///   `Tangent` (`c = z0`); beyond: `Unreachable { by: |z0| − |p − r| }`.
/// * `||p − r| − |q − r|| > TANGENCY_TOL·max(|p − r|, |q − r|)`: `Unreachable`.
/// * Parallel axes (`|k1 × k2| ≤` [`PARALLEL_TOL`]), `p` at the axes'
///   intersection, `p` on axis 2 or `q` on axis 1 (an angle is free), zero
///   axes, non-finite data: `Degenerate`.
///
/// # Example
///
/// ```
/// use pkm_runtime::primitives::{pk2, Sign};
/// use std::f64::consts::FRAC_PI_2;
///
/// // About z then x: (0,1,0) reaches (1,0,0) via c = +y (θ2 = 0, θ1 = −π/2)
/// // or c = −y (θ2 = π, θ1 = π/2).
/// let r = pk2([0.0; 3], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]).unwrap();
/// let (t1, t2) = r.branch(Sign::Plus);
/// assert!((t1 + FRAC_PI_2).abs() < 1e-15 && t2.abs() < 1e-15);
/// let (t1, t2) = r.branch(Sign::Minus);
/// assert!((t1 - FRAC_PI_2).abs() < 1e-15 && (t2.abs() - std::f64::consts::PI).abs() < 1e-15);
/// ```
pub fn pk2<T: Real>(
    axes_point: [T; 3],
    k1: [T; 3],
    k2: [T; 3],
    p: [T; 3],
    q: [T; 3],
) -> Result<Roots2<(T, T)>, Error<T>> {
    if !(finite(&axes_point) && finite(&k1) && finite(&k2) && finite(&p) && finite(&q)) {
        return Err(non_finite_input());
    }
    let k1 = unit(k1, "zero-length axis")?;
    let k2 = unit(k2, "zero-length axis")?;
    let w = cross3(k1, k2);
    let n = norm(w);
    if n <= T::from_f64(PARALLEL_TOL) {
        return Err(Error::Degenerate { what: "parallel axes" });
    }
    let w_hat = unit(w, "parallel axes")?;
    let (pv, qv) = (sub(p, axes_point), sub(q, axes_point));
    let (np, nq) = (norm(pv), norm(qv));
    let scale = if np > nq { np } else { nq };
    if (np - nq).abs() > T::from_f64(TANGENCY_TOL) * scale {
        return Err(Error::Unreachable {
            constraint: "|p - r| = |q - r|",
            by: (np - nq).abs(),
        });
    }
    if np == T::zero() {
        return Err(Error::Degenerate {
            what: "p at the intersection of the axes",
        });
    }
    let s = dot(k1, k2);
    let (kp, kq) = (dot(k2, pv), dot(k1, qv));
    let n2 = n * n;
    let alpha = (-s).mul_add(kp, kq) / n2;
    let beta = (-s).mul_add(kq, kp) / n2;
    let z0 = axpy(axpy([T::zero(); 3], alpha, k1), beta, k2);
    let gammas = half_chord(norm(z0), np, "circles about axis 1 and axis 2 intersect")?;
    let origin = [T::zero(); 3];
    gammas.try_map(|g| {
        let c = axpy(z0, g, w_hat);
        let theta2 = rotation_angle(origin, k2, pv, c, "p on axis 2")?;
        let theta1 = rotation_angle(origin, k1, c, qv, "q on axis 1")?;
        Ok((theta1, theta2))
    })
}

/// Paden–Kahan subproblem 3: angles `θ` of the rotation about the axis
/// through `axis_point` along `axis_dir` with `|R(θ)·(p − o) + o − q| = d`.
///
/// This is [`rotate_to_distance`] (same arguments, branches and errors).
///
/// # Example
///
/// ```
/// use pkm_runtime::primitives::pk3;
///
/// // (1,0,0) about z comes within distance 1 of (0,2,0) once, at θ = π/2.
/// let r = pk3([0.0; 3], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 2.0, 0.0], 1.0).unwrap();
/// assert!(r.is_tangent());
/// assert!((r.branches()[0] - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
/// ```
pub fn pk3<T: Real>(axis_point: [T; 3], axis_dir: [T; 3], p: [T; 3], q: [T; 3], d: T) -> Result<Roots2<T>, Error<T>> {
    rotate_to_distance(axis_point, axis_dir, p, q, d)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::primitives::testing::{angle_diff, check_by, dist, rotate, Lcg, Want};
    use crate::primitives::Sign;
    use core::f64::consts::{FRAC_PI_2, PI};

    fn check_pk1(o: [f64; 3], k: [f64; 3], p: [f64; 3], q: [f64; 3], want: Want, exact: Option<f64>) {
        match (pk1(o, k, p, q), want) {
            (Ok(th), Want::Two) => {
                let scale = dist(p, o).max(dist(q, o));
                let moved = rotate(o, k, th, p);
                assert!(
                    dist(moved, q) <= 1e-14 * scale.max(1.0) + 2.0 * TANGENCY_TOL * scale,
                    "θ = {th}: {moved:?}"
                );
                if let Some(e) = exact {
                    assert!(angle_diff(th, e) <= 1e-15, "θ = {th}, wanted {e}");
                }
            }
            (Err(Error::Unreachable { by, .. }), Want::Unreachable(b)) => check_by(by, b),
            (Err(Error::Degenerate { .. }), Want::Degenerate) => {}
            (other, _) => panic!("pk1({o:?}, {k:?}, {p:?}, {q:?}): wanted {want:?}, got {other:?}"),
        }
    }

    #[test]
    fn pk1_cases() {
        use Want::*;
        let o = [0.0; 3];
        let z = [0.0, 0.0, 1.0];
        check_pk1(o, z, [1.0, 0.0, 5.0], [0.0, 1.0, 5.0], Two, Some(FRAC_PI_2));
        check_pk1(o, z, [1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], Two, Some(PI));
        check_pk1(o, z, [1.0, 0.0, 0.0], [0.0, -1.0, 0.0], Two, Some(-FRAC_PI_2));
        check_pk1(
            o,
            [0.0, 0.0, -4.0],
            [1.0, 0.0, 0.0],
            [0.0, -1.0, 0.0],
            Two,
            Some(FRAC_PI_2),
        );
        check_pk1(o, z, [3.0, 4.0, 0.0], [3.0, 4.0, 0.0], Two, Some(0.0));
        check_pk1(
            [1.0, 1.0, 0.0],
            [0.0, 0.0, 2.0],
            [2.0, 1.0, 3.0],
            [1.0, 2.0, 3.0],
            Two,
            Some(FRAC_PI_2),
        );
        check_pk1(
            o,
            [1.0, 1.0, 1.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            Two,
            Some(2.0 * PI / 3.0),
        );
        check_pk1(o, z, [1.0, 0.0, 5.0], [0.0, 1.0 + 1e-12, 5.0], Two, None);
        check_pk1(o, z, [1.0, 0.0, 5.0], [0.0, 1.0, 6.0], Unreachable(1.0), None);
        check_pk1(o, z, [1.0, 0.0, 5.0], [0.0, 2.0, 5.0], Unreachable(1.0), None);
        check_pk1(o, z, [0.0, 0.0, 1.0], [0.0, 0.0, 1.0], Degenerate, None);
        check_pk1(o, [0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], Degenerate, None);
        check_pk1(o, z, [f64::NAN, 0.0, 0.0], [0.0, 1.0, 0.0], Degenerate, None);
    }

    #[test]
    fn pk1_recovers_random_angles() {
        let mut g = Lcg(3);
        for _ in 0..50 {
            let (o, k, p) = (g.point(1.0), g.point(1.0), g.point(2.0));
            let theta = g.uniform(-PI, PI);
            let q = rotate(o, k, theta, p);
            check_pk1(o, k, p, q, Want::Two, None);
            let th = pk1(o, k, p, q).unwrap();
            assert!(angle_diff(th, theta) <= 1e-12, "{th} vs {theta}");
        }
    }

    fn check_pk2(
        r: [f64; 3],
        k1: [f64; 3],
        k2: [f64; 3],
        p: [f64; 3],
        q: [f64; 3],
        want: Want,
        exact: Option<[(f64, f64); 2]>,
    ) {
        match (pk2(r, k1, k2, p, q), want) {
            (Ok(roots), Want::Two | Want::Tangent) => {
                assert_eq!(roots.is_tangent(), want == Want::Tangent, "{roots:?}");
                let scale = dist(p, r).max(dist(q, r));
                let tol = if roots.is_tangent() { 4.0 * TANGENCY_TOL } else { 1e-13 } * scale;
                for (t1, t2) in roots.branches() {
                    let moved = rotate(r, k1, t1, rotate(r, k2, t2, p));
                    assert!(dist(moved, q) <= tol, "({t1}, {t2}): {moved:?}");
                }
                if let Roots2::Two {
                    branches: [(_, p2), (_, m2)],
                } = roots
                {
                    let w = [
                        k1[1] * k2[2] - k1[2] * k2[1],
                        k1[2] * k2[0] - k1[0] * k2[2],
                        k1[0] * k2[1] - k1[1] * k2[0],
                    ];
                    let side = |t2: f64| {
                        let c = rotate(r, k2, t2, p);
                        (c[0] - r[0]) * w[0] + (c[1] - r[1]) * w[1] + (c[2] - r[2]) * w[2]
                    };
                    assert!(side(p2) > 0.0 && side(m2) < 0.0, "{roots:?}");
                }
                if let Some(e) = exact {
                    for s in Sign::ALL {
                        let (t1, t2) = roots.branch(s);
                        let (e1, e2) = e[s.index()];
                        assert!(
                            angle_diff(t1, e1) <= 1e-14 && angle_diff(t2, e2) <= 1e-14,
                            "{s:?}: {roots:?}"
                        );
                    }
                }
            }
            (Err(Error::Unreachable { by, .. }), Want::Unreachable(b)) => check_by(by, b),
            (Err(Error::Degenerate { .. }), Want::Degenerate) => {}
            (other, _) => panic!("pk2({r:?}, {k1:?}, {k2:?}, {p:?}, {q:?}): wanted {want:?}, got {other:?}"),
        }
    }

    #[test]
    fn pk2_cases() {
        use Want::*;
        let o = [0.0; 3];
        let (x, y, z) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
        check_pk2(o, z, x, y, x, Two, Some([(-FRAC_PI_2, 0.0), (FRAC_PI_2, PI)]));
        // The same, shifted to the axes' intersection (1, 2, 3) and with scaled axes.
        let sh = |v: [f64; 3]| [v[0] + 1.0, v[1] + 2.0, v[2] + 3.0];
        check_pk2(
            sh(o),
            [0.0, 0.0, 2.0],
            [3.0, 0.0, 0.0],
            sh(y),
            sh(x),
            Two,
            Some([(-FRAC_PI_2, 0.0), (FRAC_PI_2, PI)]),
        );
        // Tangent: (1,0,1) → (0,1,1) needs c = z0 = p exactly: θ2 = 0, θ1 = π/2.
        check_pk2(
            o,
            z,
            x,
            [1.0, 0.0, 1.0],
            [0.0, 1.0, 1.0],
            Tangent,
            Some([(FRAC_PI_2, 0.0); 2]),
        );
        // Within 1e-12 of that tangency, beyond (Tangent) and inside (two close solutions).
        let beyond = [0.0, (1.0 - 2e-12f64).sqrt(), 1.0 + 1e-12];
        check_pk2(o, z, x, [1.0, 0.0, 1.0], beyond, Tangent, None);
        let inside = [0.0, (1.0 + 2e-12f64).sqrt(), 1.0 - 1e-12];
        check_pk2(o, z, x, [1.0, 0.0, 1.0], inside, Two, None);
        check_pk2(
            o,
            z,
            x,
            [1.0, 0.0, 1.0],
            [0.0, 0.0, 2f64.sqrt()],
            Unreachable(3f64.sqrt() - 2f64.sqrt()),
            None,
        );
        check_pk2(o, z, x, x, [0.0, 0.0, 2.0], Unreachable(1.0), None);
        check_pk2(o, z, [0.0, 0.0, -1.0], x, y, Degenerate, None);
        check_pk2(o, z, [1e-13, 0.0, 1.0], x, y, Degenerate, None);
        check_pk2(o, z, x, x, y, Degenerate, None); // p on axis 2
        check_pk2(o, z, x, y, z, Degenerate, None); // q on axis 1
        check_pk2(o, z, x, o, o, Degenerate, None);
        check_pk2(o, [0.0; 3], x, y, x, Degenerate, None);
        check_pk2(o, z, x, [f64::NAN; 3], x, Degenerate, None);
    }

    #[test]
    fn pk2_recovers_random_angles() {
        let mut g = Lcg(5);
        for _ in 0..50 {
            let (r, k1, k2, p) = (g.point(1.0), g.point(1.0), g.point(1.0), g.point(2.0));
            let (t1, t2) = (g.uniform(-PI, PI), g.uniform(-PI, PI));
            let q = rotate(r, k1, t1, rotate(r, k2, t2, p));
            check_pk2(r, k1, k2, p, q, Want::Two, None);
            let roots = pk2(r, k1, k2, p, q).unwrap();
            let best = roots
                .branches()
                .map(|(a, b)| angle_diff(a, t1).max(angle_diff(b, t2)))
                .into_iter()
                .fold(f64::INFINITY, f64::min);
            assert!(best <= 1e-9, "({t1}, {t2}): {roots:?}");
        }
    }

    #[test]
    fn pk3_is_rotate_to_distance() {
        let args = ([0.5, -0.2, 0.1], [0.3, 0.9, -0.1], [1.0, 2.0, 0.5], [-1.0, 0.4, 0.2]);
        for d in [0.5, 1.5, 2.5, 4.0, 9.0] {
            assert_eq!(
                pk3(args.0, args.1, args.2, args.3, d),
                rotate_to_distance(args.0, args.1, args.2, args.3, d)
            );
        }
    }
}
