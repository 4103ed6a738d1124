//! A revolute's angle that turns a direction of the new link parallel to a
//! known direction (the same sense): Paden–Kahan subproblem 1 on
//! directions, [`super::aim::turn_onto`].

use super::search::{reversed, Search};
use super::{Found, Move};
use crate::model::JointType;
use crate::scalar::Scalar;
use crate::singular::{joint_point, sine, Condition, Configuration, Factor};
use crate::solution::SolveError;
use crate::spatial::v3;
use crate::spatial::{Direction, Hop, Step};
use nalgebra::Vector3;

/// The angle of the revolute that makes `group` (a direction of the new
/// link) parallel to `target`.
pub fn execute<T: Scalar>(mv: &Move<'_, T>, group: &Direction, target: &Direction) -> Result<Found<T>, SolveError> {
    let (axis, zero) = mv.turning("an alignment needs a revolute")?;
    // The group's direction with this joint at 0.
    let d = mv.geometry.direction(zero, mv.to, group);
    let w = mv.geometry.direction(mv.state.poses[target.link], target.link, target);
    Ok(mv.found(super::aim::turn_onto(axis, d, w, mv.site()).map_err(|e| mv.fail(e))?))
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
