//! A point of the new link held on a plane: its coordinate along a known
//! direction is that of a known point. On a circle: `a·cosθ + b·sinθ = c`;
//! on a line: one division.

use crate::model::JointType;
use crate::plan::v3;
use crate::plan::{Anchor, Direction};
use crate::plan::{Constraint, Hop};
use crate::scalar::{cross, dot, norm, scale, sub, Scalar};
use crate::singular::{Condition, Configuration, LinkPoint};
use crate::solution::{PointRef, SolveError};
use crate::steps::search::{reversed, Reach, Search};
use crate::steps::{Found, Motion, Move};
use crate::subproblems::{line_plane::line_plane, trig::trig_turn};
use nalgebra::Vector3;

/// The value of the joint that puts `point` of the new link on the plane
/// with normal `normal` through the anchored `anchor`.
pub fn execute<T: Scalar>(
    mv: &Move<'_, T>,
    point: PointRef,
    normal: &Direction,
    anchor: &Anchor,
    branch: Option<usize>,
) -> Result<Found<T>, SolveError> {
    let (_, m) = mv.motion(point);
    let n = mv.geometry.direction(mv.state.poses[normal.link], normal.link, normal);
    let offset = dot(n, mv.geometry.anchor(&mv.state.poses, anchor));
    Ok(mv.found(to_plane(mv, m, n, offset, mv.choice(branch))?))
}

/// The value that puts the moving point on the plane `n·X = offset`.
pub(crate) fn to_plane<T: Scalar>(
    mv: &Move<'_, T>,
    m: Motion<T>,
    n: [T; 3],
    offset: T,
    choice: T::Choice,
) -> Result<[T; 2], SolveError> {
    match m {
        Motion::Circle {
            centre, axis, radius, ..
        } => {
            let r_par = scale(dot(axis, radius), axis);
            let r_perp = sub(radius, r_par);
            let a = dot(n, r_perp);
            let b = dot(n, cross(axis, r_perp));
            let c = offset - dot(n, centre) - dot(n, r_par);
            trig_turn(a, b, c, choice, mv.site(), None).map_err(|e| mv.fail(e))
        }
        Motion::Line { start, along } => {
            line_plane(offset - dot(n, start), dot(n, along), norm(n), mv.site()).map_err(|e| mv.fail(e))
        }
    }
}

/// The planner's match for a plane: from the link the reach `r` ends at, a
/// path of revolutes (and parallelograms) parallel to one direction, and
/// translations normal to it, to a known link; the plane's normal is that
/// direction and it must cut the motion (`k` in the new link's frame, a
/// circle's axis or a line's direction). The bool: whether the step
/// branches (a circle meets a plane twice, a line once).
pub(crate) fn find(
    s: &Search<'_>,
    j: usize,
    point: PointRef,
    r: &Reach,
    k: Vector3<f64>,
    circle: bool,
) -> Option<(Constraint, bool)> {
    type Node = (Vec<Hop>, usize, Option<(usize, Vector3<f64>)>);
    let rot0 = s.rotation(&r.hops);
    let mut queue: Vec<Node> = vec![(vec![], r.link, None)];
    let mut seen = vec![r.link];
    let mut i = 0;
    while i < queue.len() {
        let (hops, link, w) = queue[i].clone();
        i += 1;
        if s.known[link] && !hops.is_empty() {
            let Some((g, wdir)) = w else { continue };
            // The plane must cut the motion: not parallel to a circle's plane or a line.
            let wk = wdir.normalize().dot(&k.normalize()).abs();
            if (circle && wk >= 1.0 - 1e-9) || (!circle && wk <= 1e-9) {
                continue;
            }
            let Some(g_pos) = hops.iter().position(|h| h.joint == g) else {
                continue;
            };
            let mut all = r.hops.clone();
            all.extend(hops.iter().copied());
            // The normal: g's axis on the link before it, seen from the known link.
            let normal = Direction {
                link,
                hops: reversed(&hops[g_pos..]),
                joint: g,
            };
            return Some((
                Constraint::Plane {
                    normal,
                    anchor: Anchor {
                        link,
                        hops: reversed(&all),
                        point,
                    },
                },
                circle,
            ));
        }
        if s.known[link] {
            continue;
        }
        let rot = rot0 * s.rotation(&hops);
        for (q, joint) in s.model.joints.iter().enumerate() {
            if q == j
                || !joint.links.contains(&link)
                || hops.iter().any(|h| h.joint == q)
                || r.hops.iter().any(|h| h.joint == q)
            {
                continue;
            }
            let next = s.other(q, link);
            if seen.contains(&next) {
                continue;
            }
            let dir = rot * s.axis(q, link);
            let w_next = match (joint.kind, w) {
                (JointType::R | JointType::Pa, None) => Some((q, dir)),
                (JointType::R | JointType::Pa, Some((_, wd))) if Search::parallel(dir, wd) => w,
                (JointType::P, Some((_, wd))) if Search::normal(dir, wd) => w,
                _ => continue,
            };
            seen.push(next);
            let mut h = hops.clone();
            h.push(s.hop(q, link));
            queue.push((h, next, w_next));
        }
    }
    None
}

/// The plane's normal (`normal` seen from its link), for the locus's
/// factor ([`crate::steps::locus_factor`]).
pub(crate) fn normal(at: &Configuration, normal: &Direction, anchor: &Anchor) -> (Vector3<f64>, Condition, LinkPoint) {
    let n = at.g.direction(at.frames[normal.link], normal.link, normal);
    (v3(n), Condition::TouchesPlane, at.anchored(anchor).1)
}
