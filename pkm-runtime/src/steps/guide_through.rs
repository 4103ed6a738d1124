//! A revolute's angle that puts a line of the new link through a known
//! point: the line a slide's far side travels on, seen from the new link
//! (the guide of a P joint on it, or the line its slider point runs along
//! on the other link). The RPR dyad of a planar mechanism, whose turning
//! links an inverted slider-crank or a quick-return's rocker are: the
//! rocker turns about its pivot C until its guide passes the crank pin B.
//!
//! With `w = B − C` (C on the turning axis `k`), the line's normal at
//! value 0 `n₀ = k × u₀` (`u₀` its direction) and its signed offset from
//! the axis `e = n₀·(P₀ − C)` (`P₀` a point of it; a turn about `k` keeps
//! it), the turned normal is `n(θ) = cosθ·n₀ + sinθ·(k × n₀)` and the line
//! passes B where `n(θ)·w = e`:
//!
//! `a·cosθ + b·sinθ = e`, `a = n₀·w`, `b = (k × n₀)·w`,
//!
//! [`super::on_plane::trig_turns`] (the circle-meets-plane kernel seen from
//! the new link's frame): `θ = atan2(b, a) ± acos(e/|w⊥|)`, two roots, one
//! double where B is at distance |e| from the axis (the guide normal to CB:
//! tangency, reported as such), none nearer; B on the axis is degenerate.
//! With `e = 0` the two roots are the line's two senses, half a turn apart.

use super::search::{reversed, Search};
use super::{Found, Motion, Move};
use crate::model::JointType;
use crate::plan::{v3, Anchor, Step};
use crate::primitives::Error as GeomError;
use crate::scalar::{cross, dot, sub, Failure, Scalar};
use crate::singular::{crossing, joint_point, Condition, Configuration, Factor};
use crate::solution::{PointRef, SolveError};

/// The angle of the revolute that puts the line `point` (on the link across
/// prismatic `slide` from the new link) travels on through the anchored
/// position `target`, `branch` choosing the root.
pub fn execute<T: Scalar>(
    mv: &Move<'_, T>,
    slide: usize,
    point: PointRef,
    target: &Anchor,
    branch: usize,
) -> Result<Found<T>, SolveError> {
    let (axis, zero) = mv.turning("a guide through a point needs a revolute")?;
    let j = mv.joint();
    let centre = zero.apply(j.places[usize::from(j.links[0] != mv.to)].at());
    let q = &mv.geometry.joints[slide];
    let beyond = if q.links[0] == mv.to { q.links[1] } else { q.links[0] };
    let x = mv.geometry.local(point, beyond);
    let Motion::Line { start, along } = q.motion(&zero, q.links[0] == mv.to, x) else {
        return Err(mv.fail(super::degenerate("a guide through a point needs a slide")));
    };
    let b = mv.geometry.anchor(&mv.state.poses, target);
    let r = through(centre, axis, start, along, b, mv.choice(Some(branch)), mv.site()).map_err(|e| mv.fail(e))?;
    Ok(mv.found(r))
}

/// The turn `[cos θ, sin θ]` about the unit `axis` through `centre` that
/// puts the line `start + t·along` (at θ = 0, `along` normal to the axis)
/// through `b`: `a·cosθ + b·sinθ = e` of the module's derivation, solved by
/// [`super::on_plane::trig_turn`] (`along` need not be unit: every term
/// scales with it). `Plus` is `atan2(b, a) + acos(e/|w⊥|)`.
///
/// # Errors
/// [`GeomError::Unreachable`] by `|e| − |w⊥|` (both times `|along|`) when
/// `b` is nearer the axis than the line ever comes; [`GeomError::Degenerate`]
/// when `b` is on the axis.
///
/// ```
/// use pkm_runtime::primitives::Sign;
/// use pkm_runtime::steps::guide_through::through;
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
    super::on_plane::trig_turn(a, bb, e, choice, site, Some(far))
}

/// The planner's match: a revolute `j` turning the new link `to` about `k`,
/// a prismatic `q` of `to` whose slide is normal to `k`, and beyond it a
/// link whose joint's place reaches a known link through revolutes on
/// their axes (parallel to `k`: the point stays in the plane the line
/// sweeps): that place, known, must lie on the line. Two roots.
pub(crate) fn find(s: &mut Search<'_>) -> bool {
    for (j, from, to) in s.candidates() {
        if s.kind(j) != JointType::R {
            continue;
        }
        let k = s.axis(j, to);
        for (q, joint) in s.model.joints.iter().enumerate() {
            // A given slide is no unknown of this dyad: the point would be
            // known along the line, and the step would leave it out. With
            // the slide given its two links are one body: `beyond_given`.
            if q == j || joint.kind != JointType::P || !joint.links.contains(&to) || s.used[q] || s.given[q].is_some() {
                continue;
            }
            if !Search::normal(s.axis(q, to), k) {
                continue;
            }
            let beyond = s.other(q, to);
            if s.known[beyond] {
                continue;
            }
            let (k_beyond, places) = s.across(q, to, j, k);
            for (point, x) in places {
                let reach = s
                    .fixed_reach(beyond, x, &[j, q])
                    .into_iter()
                    .find(|r| !r.hops.is_empty() && s.known[r.link] && s.hops_about(beyond, &r.hops, k_beyond));
                let Some(r) = reach else { continue };
                s.branches += 1;
                let step = Step::Guide {
                    joint: j,
                    from,
                    to,
                    slide: q,
                    point,
                    target: Anchor {
                        link: r.link,
                        hops: reversed(&r.hops),
                        point,
                    },
                    branch: s.branches - 1,
                };
                s.push(step, to, j);
                return true;
            }
        }
    }
    false
}

/// The step's factor: the derivative of `n(θ)·w − e`, `(k × n)·w`, over
/// `|w|`: the cosine between the guide and the turning centre's offset to
/// the point, zero where they are normal (tangency, the two roots meet).
pub(crate) fn factor(
    at: &Configuration,
    k: usize,
    joint: usize,
    from: usize,
    to: usize,
    slide: usize,
    target: &Anchor,
) -> Factor {
    let j = &at.g.joints[joint];
    let centre = v3(at.frames[from].apply(j.places[usize::from(j.links[0] != from)].at()));
    let q = &at.g.joints[slide];
    let side = usize::from(q.links[0] != to);
    let guide = v3(at.frames[to].rotate(super::place_axis(&q.places[side])));
    // A slider point on `to` takes its guide from the other side.
    let guide = match q.places[side] {
        crate::model::Place::Point { .. } => {
            let other = q.links[1 - side];
            v3(at.frames[other].rotate(super::place_axis(&q.places[1 - side])))
        }
        _ => guide,
    };
    let (b, point) = at.anchored(target);
    Factor {
        step: k,
        joint,
        condition: Condition::NormalToGuide,
        points: [joint_point(joint, from), point, joint_point(slide, to)],
        value: crossing(guide, b - centre, at.scale),
    }
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
