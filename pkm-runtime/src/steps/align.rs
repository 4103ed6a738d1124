//! A revolute's angle that turns a direction of the new link parallel to a
//! known direction (the same sense): Paden–Kahan subproblem 1 on
//! directions, [`crate::subproblems::rotate_onto::turn_onto`].

use super::search::{reversed, Search};
use super::{Found, JointValue, Move};
use crate::frame::Frame;
use crate::model::JointType;
use crate::plan::v3;
use crate::plan::{Direction, Hop, Step};
use crate::scalar::{dot, reject, scale, sub, unit, Failure, Scalar};
use crate::singular::{joint_point, sine, Condition, Configuration, Factor};
use crate::solution::SolveError;
use crate::subproblems::triad::triad;
use nalgebra::Vector3;

/// The angle of the revolute that makes `group` (a direction of the new
/// link) parallel to `target`, and the new link's frame from the two
/// directions it is now known by ([`triad`]): exact to rounding where the
/// turn composed onto the known link's frame would carry that frame's
/// rounding, and constant where both directions are (the known link's
/// turn then cancels, as in a planar chain aligned with a fixed axis).
pub fn execute<T: Scalar>(mv: &Move<'_, T>, group: &Direction, target: &Direction) -> Result<Found<T>, SolveError> {
    let (axis, zero) = mv.turning("an alignment needs a revolute")?;
    let j = mv.joint();
    // In the new link's own frame: the joint's axis (the sense `axis`
    // turns by) and the group's direction, constants of the geometry.
    let side = usize::from(j.links[0] != mv.to);
    let sense = T::c(if mv.forward() { 1.0 } else { -1.0 });
    let k_local = scale(sense, j.frames[side].column(2));
    let d_local = mv.geometry.direction(Frame::identity(), mv.to, group);
    let w = mv.geometry.direction(mv.state.poses[target.link], target.link, target);
    let (d_perp, w_perp) = (reject(d_local, k_local), reject(w, axis));
    // The lengths normal to the axis decide degeneracy: the group's from
    // the link's own geometry, the target's as it stands.
    let on_axis = || Failure::Degenerate("the point or direction lies on the turning axis");
    let site = mv.site();
    T::require(
        T::c(1e-24) * dot(d_local, d_local),
        dot(d_perp, d_perp),
        on_axis(),
        site,
    )
    .map_err(|e| mv.fail(e))?;
    T::require(T::c(1e-24) * dot(w, w), dot(w_perp, w_perp), on_axis(), site).map_err(|e| mv.fail(e))?;
    // The turn from the group's direction at 0 onto the target's.
    let [c, s] = crate::subproblems::rotate_onto::turn_terms(axis, reject(zero.rotate(d_local), axis), w_perp);
    let h = (c * c + s * s).sqrt();
    let value = JointValue::Turn(c / h, s / h, Some(s.atan2(c)));
    let r = triad([axis, unit(w_perp)], [k_local, unit(d_perp)]);
    // The joint's centre stays put: on the known link and on the new one.
    let place = |l: usize| j.places[usize::from(j.links[0] != l)].at();
    let centre = mv.state.poses[mv.from].apply(place(mv.from));
    let turned = Frame { r, ..Frame::identity() };
    let pose = Frame {
        r,
        t: sub(centre, turned.rotate(place(mv.to))),
    };
    Ok((mv.joint, mv.to, pose, value))
}

/// The planner's match: a revolute whose axis is not parallel to a group
/// of parallel revolutes (with translations between them) that leads from
/// the new link to a known one: the revolute turns the group's direction
/// onto the last revolute's axis on the link beyond it.
pub(crate) fn find(s: &mut Search<'_>) -> bool {
    for (j, from, to) in s.candidates() {
        if s.kind(j) != JointType::R {
            continue;
        }
        let k = s.axis(j, to);
        // Breadth-first through revolutes parallel to the first one met
        // (the group: that joint, the hops to it, its direction in `to`'s
        // frame) and translations; `last` is the last revolute crossed.
        #[derive(Clone)]
        struct Node {
            hops: Vec<Hop>,
            link: usize,
            group: Option<(usize, Vec<Hop>, Vector3<f64>)>,
            last: Option<usize>,
        }
        let mut queue = vec![Node {
            hops: vec![],
            link: to,
            group: None,
            last: None,
        }];
        let mut seen = vec![to];
        let mut i = 0;
        while i < queue.len() {
            let Node {
                hops,
                link,
                group,
                last,
            } = queue[i].clone();
            i += 1;
            if s.known[link] && !hops.is_empty() {
                let (Some((g, ghops, a)), Some(last)) = (group, last) else {
                    continue;
                };
                // The group's direction must not be the joint's own axis.
                if Search::parallel(a, k) {
                    continue;
                }
                // The target: the last revolute's axis on the link beyond it.
                let Some(pos) = hops.iter().position(|h| h.joint == last) else {
                    continue;
                };
                let step = Step::Align {
                    joint: j,
                    from,
                    to,
                    group: Direction {
                        link: to,
                        hops: ghops.into(),
                        joint: g,
                    },
                    target: Direction {
                        link,
                        hops: reversed(&hops[pos + 1..]),
                        joint: last,
                    },
                };
                s.push(step, to, j);
                return true;
            }
            if s.known[link] {
                continue;
            }
            for (q, joint) in s.model.joints.iter().enumerate() {
                if q == j || !joint.links.contains(&link) || hops.iter().any(|h| h.joint == q) {
                    continue;
                }
                let next = s.other(q, link);
                if seen.contains(&next) {
                    continue;
                }
                let (group, last) = match joint.kind {
                    JointType::P | JointType::Pa => (group.clone(), last),
                    JointType::R => {
                        let dir = s.rotation(&hops) * s.axis(q, link);
                        match &group {
                            None => (Some((q, hops.clone(), dir)), Some(q)),
                            Some((_, _, a)) if Search::parallel(*a, dir) => (group.clone(), Some(q)),
                            Some(_) => continue,
                        }
                    }
                    JointType::S => continue,
                };
                seen.push(next);
                let mut h = hops.clone();
                h.push(s.hop(q, link));
                queue.push(Node {
                    hops: h,
                    link: next,
                    group,
                    last,
                });
            }
        }
    }
    false
}

/// The alignment's factor: the sine between the turning axis and the
/// group's direction, or the target's if smaller (0: turning does not move
/// the group's direction, or the target lies along the axis).
pub(crate) fn factor(
    at: &Configuration,
    k: usize,
    joint: usize,
    from: usize,
    to: usize,
    group: &Direction,
    target: &Direction,
) -> Factor {
    let (g, frames) = (&at.g, &at.frames);
    let j = &g.joints[joint];
    let k_axis = j.turning_axis(&frames[from], j.links[0] == from).unwrap_or([0.0; 3]);
    let d = g.direction(frames[to], to, group);
    let w = g.direction(frames[target.link], target.link, target);
    let (_, group_link) = g.across(frames[to], to, &group.hops);
    let (_, target_link) = g.across(frames[target.link], target.link, &target.hops);
    Factor {
        step: k,
        joint,
        condition: Condition::AxisParallel,
        points: [
            joint_point(joint, from),
            joint_point(group.joint, group_link),
            joint_point(target.joint, target_link),
        ],
        value: sine(v3(k_axis), v3(d)).min(sine(v3(k_axis), v3(w))),
    }
}
