//! A revolute's angle that turns the plane the rest of a leg sweeps
//! through a known point: the first half of a U joint in a U-P-S or U-P-U
//! leg whose two ends are known (a Stewart–Gough platform's leg, once the
//! platform is placed). The new link (the U's cross) turns about the known
//! axis `u` of revolute J through `c`; beyond it a revolute Q of the new
//! link, axis `k`, turns the next link, whose slide is normal to `k`: a
//! point beyond the slide moves, whatever Q and the slide do, in the plane
//! normal to `k` through the slide's line. That point is known (`t`,
//! through joints that keep it put: a spherical joint's centre), so the
//! plane must contain it.
//!
//! With `k₀` the axis of Q at θ = 0 (unit), `P₀` a point of the line the
//! point travels on at θ = 0 (Q and the slide at 0) and `e = k₀·(P₀ − c)`
//! (the plane's offset from `c`, which a turn about `u` through `c` keeps),
//! the turned normal `n(θ) = (u·k₀)u + cosθ·k₀⊥ + sinθ·(u × k₀)` (Rodrigues,
//! `k₀⊥ = k₀ − (u·k₀)u`) and `w = t − c`, the plane contains `t` where
//! `n(θ)·w = e`:
//!
//! `a·cosθ + b·sinθ = e − (u·k₀)(u·w)`, `a = k₀⊥·w`, `b = (u × k₀)·w`,
//!
//! [`crate::subproblems::trig::trig_turn`]: `θ = atan2(b, a) ± acos(…/√(a² + b²))`,
//! two roots, one double where the plane only touches `t`'s circle about
//! `u` (tangency, reported as such), none beyond. Where the plane passes
//! through `c` (`e = 0`, decided by the planner on the geometry: a U-P leg
//! whose slide passes through the U's centre), the two roots are half a
//! turn apart and turn the plane onto itself (`n(θ + π) = −n(θ)`): the
//! second is the first with the cross flipped, and the joints beyond reach
//! the same leg poses from either, so the step takes `Plus` and does not
//! branch (the leg's two senses are the next step's choice). `t` on the
//! axis `u` (with `u ⊥ k₀`) is degenerate: the leg along the U's first
//! axis, every θ.

use super::search::{reversed, Search};
use super::{place_axis, Found, Motion, Move};
use crate::model::JointType;
use crate::plan::{v3, Anchor, Step};
use crate::primitives::Error as GeomError;
use crate::scalar::{cross, dot, scale, sub, unit, Failure, Scalar};
use crate::singular::{crossing, joint_point, Condition, Configuration, Factor};
use crate::solution::{PointRef, SolveError};

/// The angle of the revolute that turns the plane of revolute `across` (on
/// the new link) and prismatic `slide` (beyond it) through the anchored
/// position `target` of `point` (on the link beyond the slide); `branch`
/// chooses the root (`None`: the plane passes through the turning centre,
/// both roots are one plane, `Plus`).
pub fn execute<T: Scalar>(
    mv: &Move<'_, T>,
    across: usize,
    slide: usize,
    point: PointRef,
    target: &Anchor,
    branch: Option<usize>,
) -> Result<Found<T>, SolveError> {
    let (u, zero) = mv.turning("a plane through a point needs a revolute")?;
    let g = mv.geometry;
    let j = mv.joint();
    let centre = zero.apply(j.places[usize::from(j.links[0] != mv.to)].at());
    let r = &g.joints[across];
    let r_side = usize::from(r.links[0] != mv.to);
    let k0 = zero.rotate(unit(place_axis(&r.places[r_side])));
    // The link beyond Q at Q = 0, and the line the point travels on there.
    let mid = r.links[1 - r_side];
    let mid_zero = zero.then(&r.zero[r_side]);
    let q = &g.joints[slide];
    let beyond = q.other(mid);
    let x = g.local(point, beyond);
    let Motion::Line { start, .. } = q.motion(&mid_zero, q.links[0] == mid, x) else {
        return Err(mv.fail(super::degenerate("a plane through a point needs a slide")));
    };
    let e = dot(k0, sub(start, centre));
    let t = g.anchor(&mv.state.poses, target);
    let turn = plane(centre, u, k0, e, t, mv.choice(branch), mv.site()).map_err(|e| mv.fail(e))?;
    Ok(mv.found(turn))
}

/// The turn `[cos θ, sin θ]` about the unit `axis` through `centre` that
/// carries the plane `k0·(X − centre) = e` (`k0` unit) through `t`: the
/// module's `a·cosθ + b·sinθ = e − (u·k₀)(u·w)`, solved by
/// [`crate::subproblems::trig::trig_turn`]. `Plus` is `atan2(b, a) + acos(…)`.
///
/// # Errors
/// [`GeomError::Unreachable`] by `|e − (u·k₀)(u·w)| − √(a² + b²)` when no
/// turn brings the plane to `t`; [`GeomError::Degenerate`] when `a = b = 0`
/// (`t` on the axis with `k0 ⊥ axis`, or `k0` along the axis).
///
/// ```
/// use pkm_runtime::primitives::Sign;
/// use pkm_runtime::steps::plane_through::plane;
///
/// // The plane x = 0 turned about z through the origin contains (1, 1, 5): at 135° (Plus) or −45°.
/// let (o, z, x) = ([0.0; 3], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
/// let [c, s] = plane(o, z, x, 0.0, [1.0, 1.0, 5.0], Sign::Plus, [0, 0]).unwrap();
/// assert!((c + s).abs() < 1e-15 && (c * c + s * s - 1.0).abs() < 1e-15);
/// ```
#[inline]
pub fn plane<T: Scalar>(
    centre: [T; 3],
    axis: [T; 3],
    k0: [T; 3],
    e: T,
    t: [T; 3],
    choice: T::Choice,
    site: [usize; 2],
) -> Result<[T; 2], GeomError<f64>> {
    let w = sub(t, centre);
    let along = dot(axis, k0);
    let k_perp = sub(k0, scale(along, axis));
    let a = dot(k_perp, w);
    let b = dot(cross(axis, k0), w);
    let c = e - along * dot(axis, w);
    let h = (a * a + b * b).sqrt();
    let far = Failure::Unreachable("|plane offset| <= distance(axis, point)", c.abs() - h);
    crate::subproblems::trig::trig_turn(a, b, c, choice, site, Some(far))
}

/// The planner's match: a revolute `j` turning the new link `to`, a
/// revolute `r` of `to` (not parallel to `j`) to an unknown link `mid`, a
/// prismatic `q` of `mid` whose slide is normal to `r`'s axis, to an
/// unknown link `beyond`, and a joint's place on `beyond` that stays put
/// through joints to a known link (on their axes, or a spherical joint's
/// centre): that point, known, must lie in the plane `r` and `q` sweep.
/// Two roots, one plane where it passes through `j`'s axis point (`e = 0`
/// at the nominal geometry, to the planner's tolerance): no branch then.
pub(crate) fn find(s: &mut Search<'_>) -> bool {
    let open = |s: &Search<'_>, q: usize, kind: JointType| s.kind(q) == kind && !s.used[q] && s.given[q].is_none();
    for (j, from, to) in s.candidates() {
        if s.kind(j) != JointType::R {
            continue;
        }
        for r in 0..s.model.joints.len() {
            if r == j || !open(s, r, JointType::R) || !s.model.joints[r].links.contains(&to) {
                continue;
            }
            let mid = s.other(r, to);
            if s.known[mid] || Search::parallel(s.axis(r, to), s.axis(j, to)) {
                continue;
            }
            let k_mid = s.axis(r, mid);
            for q in 0..s.model.joints.len() {
                // The slide may be given (a driven U-P-U leg of a platform
                // the three spheres placed): the plane does not read it.
                let slide = s.kind(q) == JointType::P && !s.used[q];
                if q == r || !slide || !s.model.joints[q].links.contains(&mid) {
                    continue;
                }
                if !Search::normal(s.axis(q, mid), k_mid) {
                    continue;
                }
                let beyond = s.other(q, mid);
                if s.known[beyond] || beyond == to {
                    continue;
                }
                let (_, places) = s.across(q, mid, r, k_mid);
                for (point, x) in places {
                    let reach = s
                        .fixed_reach(beyond, x, &[j, r, q])
                        .into_iter()
                        .find(|h| !h.hops.is_empty() && s.known[h.link]);
                    let Some(h) = reach else { continue };
                    // The plane's offset from j's place at r = q = 0, in to's frame.
                    let p = s.zero(r, to) * (s.zero(q, mid) * nalgebra::Point3::from(x));
                    let c = v3(s.place(j, to).at());
                    let e = s.axis(r, to).normalize().dot(&(p.coords - c));
                    let branch = (e.abs() > s.tol).then(|| {
                        s.branches += 1;
                        s.branches - 1
                    });
                    let step = Step::PlaneThrough {
                        joint: j,
                        from,
                        to,
                        across: r,
                        slide: q,
                        point,
                        target: Anchor {
                            link: h.link,
                            hops: reversed(&h.hops),
                            point,
                        },
                        branch,
                    };
                    s.push(step, to, j);
                    return true;
                }
            }
        }
    }
    false
}

/// The step's factor: the derivative of `n(θ)·w − e`, `(u × n)·w`, over
/// `|u × n|·|w|`: the cosine between the turning plane's motion at `t` and
/// `t`'s offset from the centre, zero where the two roots meet (for a U-P
/// leg: the leg along the U's first axis).
#[allow(clippy::too_many_arguments)]
pub(crate) fn factor(
    at: &Configuration,
    k: usize,
    joint: usize,
    from: usize,
    to: usize,
    across: usize,
    slide: usize,
    target: &Anchor,
) -> Factor {
    let j = &at.g.joints[joint];
    let j_side = usize::from(j.links[0] != from);
    let centre = v3(at.frames[from].apply(j.places[j_side].at()));
    let u = v3(at.frames[from].rotate(unit(place_axis(&j.places[j_side]))));
    let r = &at.g.joints[across];
    let n = v3(at.frames[to].rotate(unit(place_axis(&r.places[usize::from(r.links[0] != to)]))));
    let mid = r.other(to);
    let (t, point) = at.anchored(target);
    Factor {
        step: k,
        joint,
        condition: Condition::PlaneTouches,
        points: [joint_point(joint, from), joint_point(slide, mid), point],
        value: crossing(u.cross(&n), t - centre, at.scale),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::primitives::Sign;

    /// By hand: the axis z through the origin, the plane's normal at θ = 0
    /// `k₀ = (cos γ, 0, sin γ)` (γ its tilt out of the turning plane), the
    /// point `t = (ρ cos β, ρ sin β, h)`. Turned, `n = (cos γ cos θ,
    /// cos γ sin θ, sin γ)` and `n·t = ρ cos γ cos(θ − β) + h sin γ = e`, so
    /// `θ = β ± acos((e − h sin γ)/(ρ cos γ))`, Plus `+`.
    #[test]
    fn both_roots_by_hand() {
        let z = [0.0, 0.0, 1.0];
        for &(gamma, e, rho, beta, hz) in &[
            (0.0, 0.0, 2.0, 0.3, 5.0),
            (0.0, 1.0, 2.0, 0.3, -1.0),
            (0.4, -0.5, 3.0, 2.9, 1.5),
            (-0.2, 0.7, 120.0, -1.0, 40.0),
        ] {
            let k0 = [f64::cos(gamma), 0.0, f64::sin(gamma)];
            let t = [rho * f64::cos(beta), rho * f64::sin(beta), hz];
            let delta = ((e - hz * f64::sin(gamma)) / (rho * f64::cos(gamma))).acos();
            for (sign, pm) in [(Sign::Plus, 1.0), (Sign::Minus, -1.0)] {
                let want = beta + pm * delta;
                let [c, s] = plane([0.0; 3], z, k0, e, t, sign, [0, 0]).unwrap();
                assert!(
                    (c - want.cos()).abs() < 1e-14 && (s - want.sin()).abs() < 1e-14,
                    "{gamma} {e} {rho} {beta}: {c} {s} vs {want}"
                );
                // The turned plane contains t.
                let n = [f64::cos(gamma) * c, f64::cos(gamma) * s, f64::sin(gamma)];
                assert!((dot(n, t) - e).abs() < 1e-13 * rho);
            }
        }
        // Off the origin: the same, shifted by the centre.
        let (o, d) = ([10.0, -4.0, 2.0], [0.3, 0.4, 0.0]);
        let [c, s] = plane(
            o,
            z,
            [1.0, 0.0, 0.0],
            0.0,
            [o[0] + d[0], o[1] + d[1], 7.0],
            Sign::Plus,
            [0, 0],
        )
        .unwrap();
        let want = f64::atan2(0.4, 0.3) + std::f64::consts::FRAC_PI_2;
        assert!((c - want.cos()).abs() < 1e-15 && (s - want.sin()).abs() < 1e-15);
    }

    #[test]
    fn tangency_and_refusals() {
        let z = [0.0, 0.0, 1.0];
        let x = [1.0, 0.0, 0.0];
        // t at distance |e| from the axis: the double root, the plane touching t's circle.
        let [c, s] = plane([0.0; 3], z, x, 1.0, [1.0, 0.0, 3.0], Sign::Plus, [0, 0]).unwrap();
        assert!((c - 1.0).abs() < 1e-15 && s.abs() < 1e-15);
        // Nearer: out of reach by |e| − ρ.
        match plane([0.0; 3], z, x, 1.0, [0.5, 0.0, 0.0], Sign::Plus, [0, 0]) {
            Err(GeomError::Unreachable { by, .. }) => assert!((by - 0.5).abs() < 1e-15),
            other => panic!("{other:?}"),
        }
        // t on the axis: every plane through the axis contains it.
        assert!(matches!(
            plane([0.0; 3], z, x, 0.0, [0.0, 0.0, 3.0], Sign::Plus, [0, 0]),
            Err(GeomError::Degenerate { .. })
        ));
        // The normal along the axis: no turn moves the plane.
        assert!(matches!(
            plane([0.0; 3], z, z, 0.0, [1.0, 0.0, 3.0], Sign::Plus, [0, 0]),
            Err(GeomError::Degenerate { .. })
        ));
    }
}
