//! Planar dyads: the Assur groups of class II, each solved in closed form for
//! both assembly branches.
//!
//! A dyad is two binary links joined to each other by an *internal* joint and
//! to known links by two *external* joints; R = revolute, P = prismatic. With
//! the external joints known, each dyad reduces to intersecting two loci:
//!
//! | dyad | loci intersected                     | primitive |
//! |------|--------------------------------------|-----------|
//! | RRR  | circle ∩ circle                      | [`rrr`]   |
//! | RRP  | circle ∩ line                        | [`rrp`]   |
//! | RPR  | line through B at an offset from A   | [`rpr`]   |
//! | PRP  | line ∩ line (both offset)            | [`prp`]   |
//! | PPR  | line ∩ line at a fixed angle         | [`ppr`]   |
//!
//! Points are `[x, y]`; `n = (−u.y, u.x)` is the *left normal* of a unit
//! direction `u`, and a *signed offset* `e` from a point `A` along a line with
//! direction `u` means the line `{A + e·n + t·u}` (positive = to the left).

use super::vec::{axpy, cross2, dot, finite, norm, perp2, sub, unit};
use super::{
    ensure_finite, ensure_finite_roots, half_chord, non_finite_input, non_finite_result, triangle_apex, Error,
    LinePoint, Roots2, PARALLEL_TOL,
};
use crate::real::Real;

/// RRR dyad: the point(s) at distance `r1` from `p1` and `r2` from `p2`
/// (circle–circle intersection).
///
/// ```text
///              X        Plus: left of the directed line p1 → p2
///             /|\
///         r1 / | \ r2
///           /  |h \
///        p1 ───┼─── p2  foot at distance x from p1
///           \  |  /
///            \ | /
///              X'       Minus: the mirror image
/// ```
///
/// The foot `x = (d² + r1² − r2²) / 2d` is computed as
/// `(d + (r1 − r2)(r1 + r2)/d) / 2` and the height `h` from the triangle
/// `(d, r1, r2)` with Kahan's stable area formula (sides sorted, fully
/// parenthesised), so needle-like triangles near tangency keep full accuracy.
///
/// # Errors and tangency (scale: the longest of `d, r1, r2`)
///
/// * `d > r1 + r2` (too far apart) or `d < |r1 − r2|` (one circle inside the
///   other) by at most [`TANGENCY_TOL`](super::TANGENCY_TOL)`·scale`, or exactly
///   equal: `Tangent` (the touching point).
/// * Beyond that: `Unreachable` with `by` = the distance excess
///   (`d − r1 − r2` or `|r1 − r2| − d`).
/// * Coincident centres, a negative radius or non-finite data: `Degenerate`.
///
/// # Example
///
/// ```
/// use pkm_runtime::primitives::{rrr, Sign};
///
/// // 3-4-5 triangle on the base (0,0)–(5,0).
/// let r = rrr([0.0, 0.0], 4.0, [5.0, 0.0], 3.0).unwrap();
/// let up = r.branch(Sign::Plus);
/// assert!((up[0] - 3.2_f64).abs() < 1e-15 && (up[1] - 2.4_f64).abs() < 1e-15);
/// ```
pub fn rrr<T: Real>(p1: [T; 2], r1: T, p2: [T; 2], r2: T) -> Result<Roots2<[T; 2]>, Error<T>> {
    if !(finite(&p1) && finite(&p2)) {
        return Err(non_finite_input());
    }
    ensure_finite(&[r1, r2])?;
    if r1 < T::zero() || r2 < T::zero() {
        return Err(Error::Degenerate {
            what: "negative radius",
        });
    }
    let d_vec = sub(p2, p1);
    let d = norm(d_vec);
    let u = unit(d_vec, "coincident centres")?;
    let (x, heights) = triangle_apex(d, r1, r2, "centre distance <= r1 + r2", "centre distance >= |r1 - r2|")?;
    let foot = axpy(p1, x, u);
    let n = perp2(u);
    ensure_finite_roots(heights.map(|h| axpy(foot, h, n)), finite)
}

/// RRP dyad: the point(s) of the line through `line_point` along `line_dir`
/// at distance `radius` from `centre` (circle–line intersection).
///
/// ```text
///   line_point ──────X'─────+─────X──────▶ line_dir
///                      \    |e   /
///                radius \   |   / radius
///                        centre
/// ```
///
/// With `u = unit(line_dir)`, `t0 = u·(centre − line_point)` (the foot) and
/// `e` the distance from the centre to the line, the solutions are
/// `t = t0 ± sqrt((radius − e)(radius + e))`; `Plus` is the larger `t`
/// (further along `line_dir`). The [`LinePoint`] gives the slider's joint
/// variable `t` and the joint point.
///
/// # Errors and tangency (scale: `e`)
///
/// * `e` exceeds `radius` by at most `TANGENCY_TOL·e`, or equals it: `Tangent` at the foot.
/// * Beyond: `Unreachable { by: e − radius }`.
/// * Negative radius, zero `line_dir`, non-finite data: `Degenerate`.
///
/// # Example
///
/// ```
/// use pkm_runtime::primitives::{rrp, Sign};
///
/// // Circle of radius 5 about the origin, line y = 3 from (−10, 3) along +x.
/// let r = rrp([0.0, 0.0], 5.0, [-10.0, 3.0], [1.0, 0.0]).unwrap();
/// assert_eq!(r.branch(Sign::Plus).point, [4.0, 3.0]);
/// assert_eq!(r.branch(Sign::Minus).t, 6.0);
/// ```
pub fn rrp<T: Real>(
    centre: [T; 2],
    radius: T,
    line_point: [T; 2],
    line_dir: [T; 2],
) -> Result<Roots2<LinePoint<T, 2>>, Error<T>> {
    if !(finite(&centre) && finite(&line_point) && finite(&line_dir)) {
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
    let e = cross2(u, w).abs();
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

/// Pose of the slider line of an [`rpr`] dyad.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SliderLine<T> {
    /// Direction angle `φ` of the line: `u = (cos φ, sin φ)`.
    pub angle: T,
    /// Slider coordinate `s` of `B` along `u`, from the foot `A + offset·n`.
    pub length: T,
}

/// RPR dyad: the line that passes through `b` and runs at signed perpendicular
/// offset `offset` to the left of `a` — its direction angle and the slider
/// length along it.
///
/// ```text
///    A + e·n ●━━━━━━ s ━━━━━━● B ──▶ u     (the slider line)
///            ┊ e
///            ● A
/// ```
///
/// Unknowns `φ`, `s` with `B − A = s·u + e·n`, `u = (cos φ, sin φ)`,
/// `n = (−sin φ, cos φ)`. Then `s² + e² = |B − A|² = L²`, so
/// `s = ± sqrt((L − |e|)(L + |e|))` (`Plus` = `s ≥ 0`, `B` ahead of the foot),
/// and `φ = atan2(s·Δy − e·Δx, s·Δx + e·Δy)` with `Δ = B − A`. With zero offset
/// this is the distance and bearing of `B` from `A` (`Plus`), or their
/// opposites (`Minus`). An offset that is the difference of two offsets
/// (line at `e_A` from `A` and at `e_B` from `B`) is passed as `e_A − e_B`.
///
/// # Errors and tangency (scale: `|e|`)
///
/// * `|e|` exceeds `L` by at most `TANGENCY_TOL·|e|`, or equals it: `Tangent` (`s = 0`).
/// * Beyond: `Unreachable { by: |e| − L }`.
/// * `A = B` with `e = 0`, non-finite data: `Degenerate`.
///
/// # Example
///
/// ```
/// use pkm_runtime::primitives::{rpr, Sign};
///
/// let r = rpr([0.0, 0.0], [3.0, 4.0], 0.0).unwrap();
/// let plus = r.branch(Sign::Plus);
/// assert_eq!(plus.length, 5.0);
/// assert!((plus.angle - 4.0_f64.atan2(3.0)).abs() < 1e-15);
/// assert_eq!(r.branch(Sign::Minus).length, -5.0);
/// ```
pub fn rpr<T: Real>(a: [T; 2], b: [T; 2], offset: T) -> Result<Roots2<SliderLine<T>>, Error<T>> {
    if !(finite(&a) && finite(&b)) {
        return Err(non_finite_input());
    }
    ensure_finite(&[offset])?;
    let d = sub(b, a);
    let len = norm(d);
    if len == T::zero() && offset == T::zero() {
        return Err(Error::Degenerate {
            what: "coincident joints with zero offset",
        });
    }
    let e = offset;
    let lengths = half_chord(e.abs(), len, "|AB| >= |offset|")?;
    Ok(lengths.map(|s| SliderLine {
        angle: s.mul_add(d[1], -(e * d[0])).atan2(s.mul_add(d[0], e * d[1])),
        length: s,
    }))
}

/// Intersection of two lines, with the line parameters of the intersection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineLine<T> {
    /// The intersection point.
    pub point: [T; 2],
    /// Parameter on line 1: `point = a1 + e1·n1 + t1·u1`.
    pub t1: T,
    /// Parameter on line 2: `point = a2 + e2·n2 + t2·u2`.
    pub t2: T,
}

/// PRP dyad: the intersection of two lines, each offset from its reference
/// point (line–line intersection with offsets).
///
/// Line `i` is `{a_i + e_i·n_i + t·u_i}` with `u_i = unit(v_i)` and left
/// normal `n_i`: the prismatic guide of a known link through `a_i`, with the
/// revolute joint offset `e_i` from it. The intersection is the internal
/// revolute joint; `t1`, `t2` are the two slider variables.
///
/// ```text
///                 ▲ u2
///                 │
///    a1 ─ ─ ─ ─ ─ ┼ ─ ─ ─▶ u1      (line 1 drawn at offset e1 = 0)
///                 │
///                 a2 + e2·n2
/// ```
///
/// Solved by Cramer's rule with `w = (a2 + e2·n2) − (a1 + e1·n1)`:
/// `t1 = (w × u2) / (u1 × u2)`, `t2 = (w × u1) / (u1 × u2)`.
///
/// # Errors
///
/// * `|u1 × u2| ≤` [`PARALLEL_TOL`] (parallel or nearly so): `Degenerate`.
/// * Zero direction, non-finite data or result: `Degenerate`.
///
/// # Example
///
/// ```
/// use pkm_runtime::primitives::prp;
///
/// // y = 1 (x-axis offset 1 to the left) meets x = 1 (line x = 3 along +y, offset 2 to the left).
/// let s = prp([0.0, 0.0], [1.0, 0.0], 1.0, [3.0, 0.0], [0.0, 1.0], 2.0).unwrap();
/// assert_eq!((s.point, s.t1, s.t2), ([1.0, 1.0], 1.0, 1.0));
/// ```
pub fn prp<T: Real>(a1: [T; 2], v1: [T; 2], e1: T, a2: [T; 2], v2: [T; 2], e2: T) -> Result<LineLine<T>, Error<T>> {
    if !(finite(&a1) && finite(&v1) && finite(&a2) && finite(&v2)) {
        return Err(non_finite_input());
    }
    ensure_finite(&[e1, e2])?;
    let u1 = unit(v1, "zero-length line direction")?;
    let u2 = unit(v2, "zero-length line direction")?;
    let sin = cross2(u1, u2);
    if sin.abs() <= T::from_f64(PARALLEL_TOL) {
        return Err(Error::Degenerate { what: "parallel lines" });
    }
    let b1 = axpy(a1, e1, perp2(u1));
    let b2 = axpy(a2, e2, perp2(u2));
    let w = sub(b2, b1);
    let t1 = cross2(w, u2) / sin;
    let t2 = cross2(w, u1) / sin;
    let point = axpy(b1, t1, u1);
    if t1.is_finite() && t2.is_finite() && finite(&point) {
        Ok(LineLine { point, t1, t2 })
    } else {
        Err(non_finite_result())
    }
}

/// PPR dyad: line 1 (through `a1` along `v1`, offset `e1`) meets line 2, which
/// makes the fixed angle `beta` with line 1 and is offset `e2` from the known
/// revolute joint `b`.
///
/// The first link slides along line 1 (external P); the second slides on the
/// first (internal P) along `u2 = rot(beta)·u1`, and is pinned at `b`
/// (external R). Line 2 is `{b + e2·n2 + t·u2}`; its intersection with line 1
/// locates the dyad. This is exactly [`prp`] with `a2 = b`, `v2 = u2`, and the
/// result is the same [`LineLine`]: `t1` is the external slider variable and
/// `t2` locates the intersection on line 2 relative to `b` (the internal
/// slider variable is `−t2`, the position of `b` seen from the intersection).
///
/// # Errors
///
/// As [`prp`]: `beta ≡ 0 (mod π)` within [`PARALLEL_TOL`] is `Degenerate`.
///
/// # Example
///
/// ```
/// use pkm_runtime::primitives::ppr;
///
/// // Line 1 is the x-axis; line 2 is perpendicular to it through (3, 5).
/// let s = ppr([0.0, 0.0], [1.0, 0.0], 0.0, [3.0, 5.0], std::f64::consts::FRAC_PI_2, 0.0).unwrap();
/// assert!((s.point[0] - 3.0_f64).abs() < 1e-15 && s.point[1].abs() < 1e-15);
/// assert!((s.t1 - 3.0_f64).abs() < 1e-15 && (s.t2 + 5.0_f64).abs() < 1e-15);
/// ```
pub fn ppr<T: Real>(a1: [T; 2], v1: [T; 2], e1: T, b: [T; 2], beta: T, e2: T) -> Result<LineLine<T>, Error<T>> {
    if !(finite(&v1) && beta.is_finite()) {
        return Err(non_finite_input());
    }
    let u1 = unit(v1, "zero-length line direction")?;
    let (s, c) = (beta.sin(), beta.cos());
    let u2 = [c.mul_add(u1[0], -(s * u1[1])), s.mul_add(u1[0], c * u1[1])];
    prp(a1, v1, e1, b, u2, e2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::primitives::testing::{angle_diff, check_by, check_line_hits, dist, Want};
    use crate::primitives::{Sign, TANGENCY_TOL};
    use core::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

    /// Checks an outcome shape; for solutions, the defining distances, the
    /// branch side, and (optionally) exact `[Plus, Minus]` points.
    fn check_rrr(p1: [f64; 2], r1: f64, p2: [f64; 2], r2: f64, want: Want, exact: Option<[[f64; 2]; 2]>) {
        let scale = dist(p1, p2).max(r1).max(r2);
        match (rrr(p1, r1, p2, r2), want) {
            (Ok(r), Want::Two | Want::Tangent) => {
                assert_eq!(r.is_tangent(), want == Want::Tangent, "{r:?}");
                let tol = if r.is_tangent() { 2.0 * TANGENCY_TOL } else { 1e-14 } * scale;
                for x in r.branches() {
                    assert!((dist(x, p1) - r1).abs() <= tol, "{x:?}: |x - p1| = {}", dist(x, p1));
                    assert!((dist(x, p2) - r2).abs() <= tol, "{x:?}: |x - p2| = {}", dist(x, p2));
                }
                if let Roots2::Two { branches: [p, m] } = r {
                    let d = sub(p2, p1);
                    assert!(cross2(d, sub(p, p1)) > 0.0 && cross2(d, sub(m, p1)) < 0.0, "{r:?}");
                }
                if let Some(e) = exact {
                    for s in Sign::ALL {
                        assert!(dist(r.branch(s), e[s.index()]) <= 1e-15 * scale, "{s:?}: {r:?}");
                    }
                }
            }
            (Err(Error::Unreachable { by, .. }), Want::Unreachable(b)) => check_by(by, b),
            (Err(Error::Degenerate { .. }), Want::Degenerate) => {}
            (other, _) => panic!("rrr({p1:?}, {r1}, {p2:?}, {r2}): wanted {want:?}, got {other:?}"),
        }
    }

    #[test]
    fn rrr_cases() {
        use Want::*;
        let o = [0.0, 0.0];
        check_rrr(o, 4.0, [5.0, 0.0], 3.0, Two, Some([[3.2, 2.4], [3.2, -2.4]]));
        check_rrr(o, 3.0, [5.0, 0.0], 4.0, Two, Some([[1.8, 2.4], [1.8, -2.4]]));
        check_rrr([1.0, 1.0], 4.0, [1.0, 6.0], 3.0, Two, Some([[-1.4, 4.2], [3.4, 4.2]]));
        check_rrr(
            [-2.0, 7.0],
            13.0,
            [-2.0, -3.0],
            13.0,
            Two,
            Some([[10.0, 2.0], [-14.0, 2.0]]),
        );
        check_rrr(
            [1e6, 1e6],
            4e6,
            [6e6, 1e6],
            3e6,
            Two,
            Some([[4.2e6, 3.4e6], [4.2e6, -1.4e6]]),
        );
        check_rrr([1e-9, 0.0], 4e-9, [6e-9, 0.0], 3e-9, Two, None);
        check_rrr([0.3, -0.7], 1.3, [1.9, 0.4], 0.9, Two, None);
        // External tangency: exactly, just inside (two nearby points), just and well beyond.
        check_rrr(o, 1.0, [2.0, 0.0], 1.0, Tangent, Some([[1.0, 0.0]; 2]));
        check_rrr(o, 1.0, [2.0 - 1e-12, 0.0], 1.0, Two, None);
        check_rrr(o, 1.0, [2.0 + 1e-12, 0.0], 1.0, Tangent, None);
        check_rrr(o, 1.0, [2.0 + 1e-6, 0.0], 1.0, Unreachable(1e-6), None);
        check_rrr(o, 1.0, [3.0, 0.0], 1.0, Unreachable(1.0), None);
        // Internal tangency (one circle inside the other), both ways round.
        check_rrr(o, 1.0, [0.5, 0.0], 0.5, Tangent, Some([[1.0, 0.0]; 2]));
        check_rrr(o, 0.5, [0.5, 0.0], 1.0, Tangent, Some([[-0.5, 0.0]; 2]));
        check_rrr(o, 1.0, [0.5 - 1e-12, 0.0], 0.5, Tangent, None);
        check_rrr(o, 1.0, [0.5 + 1e-12, 0.0], 0.5, Two, None);
        check_rrr(o, 1.0, [0.1, 0.0], 0.5, Unreachable(0.4), None);
        check_rrr(o, 0.5, [0.1, 0.0], 1.0, Unreachable(0.4), None);
        // Zero radius: the point must be p1 itself.
        check_rrr(o, 0.0, [3.0, 0.0], 3.0, Tangent, Some([o; 2]));
        check_rrr(o, 0.0, [3.0, 0.0], 2.0, Unreachable(1.0), None);
        check_rrr(o, 1.0, o, 1.0, Degenerate, None);
        check_rrr(o, -1.0, [1.0, 0.0], 1.0, Degenerate, None);
        check_rrr([f64::NAN, 0.0], 1.0, [1.0, 0.0], 1.0, Degenerate, None);
        check_rrr(o, f64::INFINITY, [1.0, 0.0], 1.0, Degenerate, None);
    }

    #[test]
    fn rrr_needle_height_is_accurate() {
        // d = 2 − 1e-12 between unit circles: h = sqrt((2 − d)(2 + d)) / 2 ≈ 1e-6,
        // where 2 − d is exact. A naive r1² − x² would lose ~4 of its digits.
        let d = 2.0 - 1e-12;
        let h = ((2.0 - d) * (2.0 + d)).sqrt() / 2.0;
        let r = rrr([0.0, 0.0], 1.0, [d, 0.0], 1.0).unwrap();
        assert_eq!(r.count(), 2);
        let [p, m] = r.branches();
        assert!(
            (p[1] - h).abs() <= 1e-14 * h && (m[1] + h).abs() <= 1e-14 * h,
            "{p:?} {m:?} vs {h}"
        );
    }

    fn check_rrp(c: [f64; 2], r: f64, a: [f64; 2], v: [f64; 2], want: Want, exact_t: Option<[f64; 2]>) {
        check_line_hits(rrp(c, r, a, v), want, (c, r), a, v, exact_t, dist(c, a).max(r));
    }

    #[test]
    fn rrp_cases() {
        use Want::*;
        let o = [0.0, 0.0];
        check_rrp(o, 5.0, [-10.0, 3.0], [1.0, 0.0], Two, Some([14.0, 6.0]));
        check_rrp(o, 5.0, [-10.0, 3.0], [2.0, 0.0], Two, Some([14.0, 6.0]));
        check_rrp(o, 5.0, [-10.0, 3.0], [-1.0, 0.0], Two, Some([-6.0, -14.0]));
        check_rrp(o, 5.0, [3.0, -10.0], [0.0, 7.0], Two, Some([14.0, 6.0]));
        check_rrp([1.0, 2.0], 5.0, [1.0, 2.0], [3.0, 4.0], Two, Some([5.0, -5.0]));
        check_rrp([0.2, -1.3], 3.5, [-4.0, 0.1], [1.0, 0.35], Two, None);
        check_rrp(o, 5.0, [-10.0, 5.0], [1.0, 0.0], Tangent, Some([10.0, 10.0]));
        check_rrp(o, 5.0, [-10.0, 5.0 * (1.0 + 1e-12)], [1.0, 0.0], Tangent, None);
        check_rrp(o, 5.0, [-10.0, 5.0 * (1.0 - 1e-12)], [1.0, 0.0], Two, None);
        check_rrp(o, 5.0, [-10.0, 5.001], [1.0, 0.0], Unreachable(0.001), None);
        check_rrp(o, 0.0, [-1.0, 0.0], [1.0, 0.0], Tangent, Some([1.0, 1.0]));
        check_rrp(o, 5.0, [1.0, 1.0], [0.0, 0.0], Degenerate, None);
        check_rrp(o, -5.0, [1.0, 1.0], [1.0, 0.0], Degenerate, None);
        check_rrp(o, 5.0, [1.0, f64::NAN], [1.0, 0.0], Degenerate, None);
    }

    fn check_rpr(a: [f64; 2], b: [f64; 2], e: f64, want: Want, exact: Option<[(f64, f64); 2]>) {
        let scale = dist(a, b).max(e.abs());
        match (rpr(a, b, e), want) {
            (Ok(r), Want::Two | Want::Tangent) => {
                assert_eq!(r.is_tangent(), want == Want::Tangent, "{r:?}");
                let tol = if r.is_tangent() { 2.0 * TANGENCY_TOL } else { 1e-14 } * scale;
                for sl in r.branches() {
                    let (sn, cs) = sl.angle.sin_cos();
                    // B − A = s·u + e·n
                    let rebuilt = [a[0] + sl.length * cs - e * sn, a[1] + sl.length * sn + e * cs];
                    assert!(dist(rebuilt, b) <= tol, "{sl:?}: {rebuilt:?}");
                }
                assert!(r.branch(Sign::Plus).length >= 0.0 && r.branch(Sign::Minus).length <= 0.0);
                if let Some(ex) = exact {
                    for s in Sign::ALL {
                        let (ang, len) = ex[s.index()];
                        let got = r.branch(s);
                        assert!(
                            angle_diff(got.angle, ang) < 1e-14 && (got.length - len).abs() < 1e-14,
                            "{s:?}: {got:?}"
                        );
                    }
                }
            }
            (Err(Error::Unreachable { by, .. }), Want::Unreachable(x)) => check_by(by, x),
            (Err(Error::Degenerate { .. }), Want::Degenerate) => {}
            (other, _) => panic!("rpr({a:?}, {b:?}, {e}): wanted {want:?}, got {other:?}"),
        }
    }

    #[test]
    fn rpr_cases() {
        use Want::*;
        let o = [0.0, 0.0];
        let phi = 4.0_f64.atan2(3.0);
        check_rpr(o, [3.0, 4.0], 0.0, Two, Some([(phi, 5.0), (phi - PI, -5.0)]));
        check_rpr(
            [1.0, 1.0],
            [1.0, 3.0],
            0.0,
            Two,
            Some([(FRAC_PI_2, 2.0), (-FRAC_PI_2, -2.0)]),
        );
        // 3-4-5 with offset 3: u = (0.8, −0.6) for s = 4, (−0.8, −0.6) for s = −4.
        let (p, m) = ((-0.6_f64).atan2(0.8), (-0.6_f64).atan2(-0.8));
        check_rpr(o, [5.0, 0.0], 3.0, Two, Some([(p, 4.0), (m, -4.0)]));
        check_rpr(o, [5.0, 0.0], -3.0, Two, Some([(-p, 4.0), (-m, -4.0)]));
        check_rpr([0.5, -2.0], [-1.5, 0.25], 1.2, Two, None);
        // |offset| = |AB|: the line is perpendicular to AB at B.
        check_rpr(o, [5.0, 0.0], 5.0, Tangent, Some([(-FRAC_PI_2, 0.0); 2]));
        check_rpr(o, [5.0, 0.0], -5.0, Tangent, Some([(FRAC_PI_2, 0.0); 2]));
        check_rpr(o, [5.0, 0.0], 5.0 * (1.0 + 1e-12), Tangent, None);
        check_rpr(o, [5.0, 0.0], 5.0 * (1.0 - 1e-12), Two, None);
        check_rpr(o, [5.0, 0.0], 6.0, Unreachable(1.0), None);
        check_rpr(o, o, 1.0, Unreachable(1.0), None);
        check_rpr(o, o, 0.0, Degenerate, None);
        check_rpr(o, [1.0, 0.0], f64::NAN, Degenerate, None);
    }

    type Line = ([f64; 2], [f64; 2], f64);

    /// Checks a line–line outcome: the point lies on both offset lines at the
    /// reported parameters; `exact` = (point, t1, t2).
    fn check_line_line(
        got: Result<LineLine<f64>, Error<f64>>,
        l1: Line,
        l2: Line,
        want: Want,
        exact: Option<([f64; 2], f64, f64)>,
    ) {
        match (got, want) {
            (Ok(s), Want::Two) => {
                let scale = 1.0 + s.t1.abs().max(s.t2.abs());
                for ((a, v, e), t) in [(l1, s.t1), (l2, s.t2)] {
                    let n = v[0].hypot(v[1]);
                    let (ux, uy) = (v[0] / n, v[1] / n);
                    let on = [a[0] - e * uy + t * ux, a[1] + e * ux + t * uy];
                    assert!(dist(on, s.point) <= 1e-14 * scale, "{s:?}: {on:?}");
                }
                if let Some((p, t1, t2)) = exact {
                    assert!(dist(s.point, p) <= 1e-14 * scale, "{s:?}");
                    assert!(
                        (s.t1 - t1).abs() <= 1e-14 * scale && (s.t2 - t2).abs() <= 1e-14 * scale,
                        "{s:?}"
                    );
                }
            }
            (Err(Error::Degenerate { .. }), Want::Degenerate) => {}
            (other, _) => panic!("{l1:?} ∩ {l2:?}: wanted {want:?}, got {other:?}"),
        }
    }

    fn check_prp(l1: Line, l2: Line, want: Want, exact: Option<([f64; 2], f64, f64)>) {
        check_line_line(prp(l1.0, l1.1, l1.2, l2.0, l2.1, l2.2), l1, l2, want, exact);
    }

    #[test]
    fn prp_cases() {
        use Want::*;
        let o = [0.0, 0.0];
        let x = [1.0, 0.0];
        check_prp(
            (o, x, 1.0),
            ([3.0, 0.0], [0.0, 1.0], 2.0),
            Two,
            Some(([1.0, 1.0], 1.0, 1.0)),
        );
        // Zero offsets: plain line intersection.
        check_prp(
            (o, x, 0.0),
            ([3.0, 0.0], [0.0, 1.0], 0.0),
            Two,
            Some(([3.0, 0.0], 3.0, 0.0)),
        );
        check_prp(
            (o, [1.0, 1.0], 0.0),
            ([2.0, 0.0], [0.0, 5.0], 0.0),
            Two,
            Some(([2.0, 2.0], 8f64.sqrt(), 2.0)),
        );
        check_prp(
            (o, [-2.0, 0.0], 0.5),
            ([3.0, 0.0], [0.0, -1.0], 0.0),
            Two,
            Some(([3.0, -0.5], -3.0, 0.5)),
        );
        check_prp(
            ([0.3, 0.1], [0.6, -0.8], -0.25),
            ([-1.0, 2.0], [0.2, 0.9], 0.7),
            Two,
            None,
        );
        // Nearly parallel: valid, far away, still on both lines.
        check_prp(
            (o, x, 0.0),
            ([0.0, 1.0], [1.0, 1e-9], 0.0),
            Two,
            Some(([-1e9, 0.0], -1e9, -1e9 * (1.0f64 + 1e-18).sqrt())),
        );
        check_prp((o, x, 0.0), ([0.0, 1.0], [1.0, 1e-13], 0.0), Degenerate, None);
        check_prp((o, x, 0.0), ([0.0, 1.0], [-2.0, 0.0], 0.0), Degenerate, None);
        check_prp((o, x, 0.0), (o, x, 0.0), Degenerate, None);
        check_prp((o, o, 0.0), (o, x, 0.0), Degenerate, None);
        check_prp((o, x, f64::NAN), (o, [0.0, 1.0], 0.0), Degenerate, None);
    }

    fn check_ppr(l1: Line, b: [f64; 2], beta: f64, e2: f64, want: Want, exact: Option<([f64; 2], f64, f64)>) {
        let n = l1.1[0].hypot(l1.1[1]);
        let (c, s) = (beta.cos(), beta.sin());
        let u2 = [(c * l1.1[0] - s * l1.1[1]) / n, (s * l1.1[0] + c * l1.1[1]) / n];
        check_line_line(ppr(l1.0, l1.1, l1.2, b, beta, e2), l1, (b, u2, e2), want, exact);
    }

    #[test]
    fn ppr_cases() {
        use Want::*;
        let o = [0.0, 0.0];
        let x = [1.0, 0.0];
        check_ppr(
            (o, x, 0.0),
            [3.0, 5.0],
            FRAC_PI_2,
            0.0,
            Two,
            Some(([3.0, 0.0], 3.0, -5.0)),
        );
        check_ppr(
            (o, x, 0.0),
            [3.0, 5.0],
            FRAC_PI_2,
            1.0,
            Two,
            Some(([2.0, 0.0], 2.0, -5.0)),
        );
        check_ppr(
            (o, x, 0.0),
            [0.0, 2.0],
            FRAC_PI_4,
            0.0,
            Two,
            Some(([-2.0, 0.0], -2.0, -8f64.sqrt())),
        );
        check_ppr(
            (o, [0.0, 3.0], 1.0),
            [4.0, 4.0],
            -FRAC_PI_2,
            0.0,
            Two,
            Some(([-1.0, 4.0], 4.0, -5.0)),
        );
        check_ppr(([1.0, -1.0], [0.3, 0.4], 0.2), [2.0, 0.5], 2.0, -0.3, Two, None);
        check_ppr((o, x, 0.0), [3.0, 5.0], 0.0, 0.0, Degenerate, None);
        check_ppr((o, x, 0.0), [3.0, 5.0], PI, 0.0, Degenerate, None);
        check_ppr((o, x, 0.0), [3.0, 5.0], f64::INFINITY, 0.0, Degenerate, None);
    }
}
