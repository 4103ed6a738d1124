//! A revolute's angle that puts the line of a slide along its own axis
//! through a known point: seen along the axis, an aim. The new link `to`
//! turns about `k` through C; across its prismatic `slide`, whose line is
//! parallel to `k`, the link beyond carries a point `x` (a joint's place
//! there) that the rest of the mechanism knows, B. The slide moves `x`
//! along `k` only, so `to` and the link beyond are one body seen along
//! `k`, and the turn must carry `x`'s component normal to `k` onto B's:
//!
//! `θ = atan2(k·(v⊥ × u⊥), v⊥·u⊥)`, `v = P₀ − C`, `u = B − C`
//!
//! (`P₀` the point at the slide's value 0 with `to` at the turn's zero;
//! Paden–Kahan subproblem 1, [`crate::subproblems::rotate_onto::turn`]).
//! One root. It exists only where `|v⊥| = |u⊥|`; the plan makes that so
//! by an earlier step (a two-limb Schönflies robot: the arm's last joint
//! put at the distance the platform and the far limb's last link, one
//! body seen along the axis, keep it from the far limb's known joint), and
//! the slide's own step afterwards checks it (its miss across the line).
//! A circle against a cylinder (a locus) would meet it in a double root
//! every time, two equal branches and half the digits. Degenerate where
//! `x` is on the turning axis (every turn would do).

use super::search::Search;
use super::{JointValue, Motion, Move};
use crate::model::JointType;
use crate::plan::{v3, Anchor, Step};
use crate::scalar::{sub, Scalar};
use crate::singular::{joint_point, Condition, Configuration, Factor, LinkPoint};
use crate::solution::{PointRef, SolveError};
use crate::subproblems::rotate_onto::turn;

/// The angle of the revolute that puts the line `point` (on the link across
/// prismatic `slide` from the new link, the slide along the turning axis)
/// travels on through the anchored position `target`.
pub fn execute<T: Scalar>(
    mv: &Move<'_, T>,
    slide: usize,
    point: PointRef,
    target: &Anchor,
) -> Result<super::Found<T>, SolveError> {
    let (axis, zero) = mv.turning("an aim along the axis needs a revolute")?;
    let j = mv.joint();
    let centre = zero.apply(j.places[usize::from(j.links[0] != mv.to)].at());
    let q = &mv.geometry.joints[slide];
    let x = mv.geometry.local(point, q.other(mv.to));
    let Motion::Line { start, .. } = q.motion(&zero, q.links[0] == mv.to, x) else {
        return Err(mv.fail(super::degenerate("an aim along the axis needs a slide")));
    };
    let b = mv.geometry.anchor(&mv.state.poses, target);
    let ([c, s], [cos, sin]) = turn(axis, sub(start, centre), sub(b, centre), mv.site()).map_err(|e| mv.fail(e))?;
    Ok(mv.at(JointValue::Turn(cos, sin, Some(s.atan2(c)))))
}

/// The planner's match: a revolute `j` turning the new link `to` about `k`,
/// a prismatic `q` of `to` (its value not given) sliding along `k`, and
/// beyond it a link with a joint's place off `j`'s axis that reaches a
/// known link through revolutes on their axes, parallel to `k` (the point
/// keeps its place seen along `k`). One root.
pub(crate) fn find(s: &mut Search<'_>) -> bool {
    for (j, from, to) in s.candidates() {
        if s.kind(j) != JointType::R {
            continue;
        }
        let k = s.axis(j, to);
        for (q, joint) in s.model.joints.iter().enumerate() {
            let along = joint.kind == JointType::P && joint.links.contains(&to) && Search::parallel(s.axis(q, to), k);
            if q == j || !along || s.used[q] || s.given[q].is_some() || s.known[s.other(q, to)] {
                continue;
            }
            let beyond = s.other(q, to);
            let (k_beyond, places) = s.across(q, to, j, k);
            for (point, x) in places {
                // Seen from `to` the point must be off the turning axis.
                let seen = s.zero(q, to).transform_point(&x.into()).coords;
                if s.on_axis(j, to, seen) {
                    continue;
                }
                let Some(target) = s.known_about(beyond, point, x, &[j, q], k_beyond) else {
                    continue;
                };
                let step = Step::AimAlong {
                    joint: j,
                    from,
                    to,
                    slide: q,
                    point,
                    target,
                };
                s.push(step, to, j);
                return true;
            }
        }
    }
    false
}

/// The step's factor: the carried point's distance from the turning axis,
/// in units of the model's size (0: on the axis, every turn aims it).
pub(crate) fn factor(at: &Configuration, k: usize, step: &Step) -> Option<Factor> {
    let Step::AimAlong {
        joint,
        from,
        to,
        slide,
        point,
        ..
    } = *step
    else {
        return None;
    };
    let beyond = at.g.joints[slide].other(to);
    let p = at.world(beyond, point);
    let j = &at.g.joints[joint];
    let Motion::Circle { centre, axis, .. } = j.motion(&at.frames[from], j.links[0] == from, [0.0; 3]) else {
        return None;
    };
    Some(Factor {
        step: k,
        joint,
        condition: Condition::OnAxis,
        points: [
            joint_point(joint, from),
            LinkPoint { link: beyond, point },
            joint_point(slide, to),
        ],
        value: (v3(axis).cross(&(p - v3(centre))).norm() / at.scale).min(1.0),
    })
}
