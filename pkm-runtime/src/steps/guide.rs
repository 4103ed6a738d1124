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
//! [`crate::subproblems::trig::trig_turns`] (the circle-meets-plane kernel seen from
//! the new link's frame): `θ = atan2(b, a) ± acos(e/|w⊥|)`, two roots, one
//! double where B is at distance |e| from the axis (the guide normal to CB:
//! tangency, reported as such), none nearer; B on the axis is degenerate.
//! With `e = 0` the two roots are the line's two senses, half a turn apart.
//!
//! The slide may be on a link across a joint of the new link whose value
//! is given (a revolute parallel to the turning axis, or a slide): the two
//! are one body, the line carried across at that value (an inverted
//! slider-crank driven at the crank–block joint: crank and block turn
//! about the crank's pivot until the block's line passes the rocker's
//! pivot).

use super::search::Search;
use super::{Found, JointValue, Motion, Move};
use crate::model::JointType;
use crate::plan::{v3, Anchor, Step};
use crate::scalar::Scalar;
use crate::singular::{crossing, joint_point, Condition, Configuration, Factor};
use crate::solution::{PointRef, SolveError};
use crate::subproblems::line_through::through;

/// The angle of the revolute that puts the line `point` (on the link across
/// prismatic `slide` from the new link) travels on through the anchored
/// position `target`, `branch` choosing the root.
pub fn execute<T: Scalar>(
    mv: &Move<'_, T>,
    carried: Option<(usize, usize)>,
    slide: usize,
    point: PointRef,
    target: &Anchor,
    branch: usize,
) -> Result<Found<T>, SolveError> {
    let (axis, zero) = mv.turning("a guide through a point needs a revolute")?;
    let j = mv.joint();
    let centre = zero.apply(j.places[usize::from(j.links[0] != mv.to)].at());
    // The link the slide is on, and its pose with the new link at value 0.
    let (near, near_pose) = match carried {
        None => (mv.to, zero),
        Some((given, input)) => {
            let g = &mv.geometry.joints[given];
            let value = JointValue::given(g.kind, mv.given.values[input]);
            (g.other(mv.to), g.transfer(&zero, g.links[0] == mv.to, value))
        }
    };
    let q = &mv.geometry.joints[slide];
    let beyond = q.other(near);
    let x = mv.geometry.local(point, beyond);
    let Motion::Line { start, along } = q.motion(&near_pose, q.links[0] == near, x) else {
        return Err(mv.fail(super::degenerate("a guide through a point needs a slide")));
    };
    let b = mv.geometry.anchor(&mv.state.poses, target);
    let r = through(centre, axis, start, along, b, mv.choice(Some(branch)), mv.site()).map_err(|e| mv.fail(e))?;
    Ok(mv.found(r))
}

/// The planner's match: a revolute `j` turning the new link `to` about `k`,
/// a prismatic `q` of `to` whose slide is normal to `k` (or of the link
/// across a given revolute of `to` parallel to `k`, or a given slide: the
/// two are one body), and beyond it a link whose joint's place reaches a
/// known link through revolutes on their axes (parallel to `k`: the point
/// stays in the plane the line sweeps): that place, known, must lie on the
/// line. Two roots.
pub(crate) fn find(s: &mut Search<'_>) -> bool {
    for (j, from, to) in s.candidates() {
        if s.kind(j) != JointType::R {
            continue;
        }
        let k = s.axis(j, to);
        // The links the slide may be on: `to`, and those across its given
        // joints that keep `k` (with `k` in their frames).
        let mut near = vec![(to, None, k)];
        for (g, jg) in s.model.joints.iter().enumerate() {
            let Some(input) = s.given[g] else { continue };
            // A given revolute about `k`, or a given slide (either keeps `k`).
            let keeps_k = match jg.kind {
                JointType::R => Search::parallel(s.axis(g, to), k),
                JointType::P => true,
                _ => false,
            };
            let carries = g != j && jg.links.contains(&to) && !s.used[g];
            if carries && keeps_k && !s.known[s.other(g, to)] {
                let k_mid = s.rotation(&[s.hop(g, to)]).inverse() * k;
                near.push((s.other(g, to), Some((g, input)), k_mid));
            }
        }
        for (q, joint) in s.model.joints.iter().enumerate() {
            // A given slide is no unknown of this dyad: the point would be
            // known along the line, and the step would leave it out. With
            // the slide given its two links are one body: `beyond`. Unless
            // the three spheres already hold the point at the slide's
            // length ([`super::trilaterate`]: a U-P-U leg): then the line
            // through it is all that is left, and the closure checks the rest.
            let imposed = s.steps.iter().any(|st| match st {
                Step::Trilaterate { spheres, .. } => spheres
                    .iter()
                    .any(|o| matches!(o.radius, crate::plan::Span::Slid { slide, .. } if slide == q)),
                _ => false,
            });
            if q == j || joint.kind != JointType::P || s.used[q] || (s.given[q].is_some() && !imposed) {
                continue;
            }
            let Some(&(on, carried, k_on)) = near.iter().find(|(l, ..)| joint.links.contains(l)) else {
                continue;
            };
            if !Search::normal(s.axis(q, on), k_on) {
                continue;
            }
            let beyond = s.other(q, on);
            if s.known[beyond] || beyond == to {
                continue;
            }
            let (k_beyond, places) = s.across(q, on, j, k_on);
            for (point, x) in places {
                let Some(target) = s.known_about(beyond, point, x, &[j, q], k_beyond) else {
                    continue;
                };
                s.branches += 1;
                let step = Step::Guide {
                    joint: j,
                    from,
                    to,
                    carried,
                    slide: q,
                    point,
                    target,
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
#[allow(clippy::too_many_arguments)]
pub(crate) fn factor(
    at: &Configuration,
    k: usize,
    joint: usize,
    from: usize,
    to: usize,
    carried: Option<(usize, usize)>,
    slide: usize,
    target: &Anchor,
) -> Factor {
    let j = &at.g.joints[joint];
    let centre = v3(at.frames[from].apply(j.places[usize::from(j.links[0] != from)].at()));
    // The slide's link on the new link's side: `to`, or the one carried with it.
    let to = carried.map_or(to, |(given, _)| at.g.joints[given].other(to));
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
