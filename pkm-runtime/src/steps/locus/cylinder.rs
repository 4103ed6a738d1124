//! A point of the new link held on a cylinder: at a fixed distance from the
//! axis of a known revolute parallel to the motion's axis (a planar
//! circle–circle intersection), or, for a slide normal to that axis, a
//! planar line–circle intersection. The point may reach the revolute
//! across slides along the motion's axis, which keep its distance from
//! that axis (links one body seen along it: `Search::axial_reach`).

use crate::plan::v3;
use crate::plan::{Constraint, Hop};
use crate::scalar::{add, dot, norm, reject, scale, sub, unit, Scalar};
use crate::singular::{joint_point, Condition, Configuration, LinkPoint};
use crate::solution::{PointRef, SolveError};
use crate::steps::search::{Reach, Search};
use crate::steps::{Found, Motion, Move};
use crate::subproblems::line_sphere::line_circle;
use nalgebra::{UnitQuaternion, Vector3};

/// The value of the joint that puts `point` of the new link at the
/// distance its carrier across `hops` keeps from the axis of revolute `h`
/// on the known link `link`.
pub fn execute<T: Scalar>(
    mv: &Move<'_, T>,
    point: PointRef,
    hops: &[Hop],
    h: usize,
    link: usize,
    branch: Option<usize>,
) -> Result<Found<T>, SolveError> {
    let (x, m) = mv.motion(point);
    Ok(mv.found(meet(mv, m, x, hops, h, link, branch)?))
}

/// The value that puts the point moving as `m` at the distance its
/// carrier (`x`, carried across `hops` to the link across revolute `h`
/// from the known `link`) keeps from `h`'s axis: circle–circle or, for a
/// slide, planar line–circle; `branch` picks the root.
pub fn meet<T: Scalar>(
    mv: &Move<'_, T>,
    m: Motion<T>,
    x: [T; 3],
    hops: &[Hop],
    h: usize,
    link: usize,
    branch: Option<usize>,
) -> Result<[T; 2], SolveError> {
    let (g, poses) = (mv.geometry, &mv.state.poses);
    let jh = &g.joints[h];
    let known_side = usize::from(jh.links[0] != link);
    let line_point = poses[link].apply(jh.places[known_side].at());
    let line_axis = unit(poses[link].rotate(crate::steps::place_axis(&jh.places[known_side])));
    // The point across the hops, and its distance from h's axis there.
    let y = g.carry(x, hops);
    let place = jh.places[1 - known_side];
    let radius = norm(reject(sub(y, place.at()), unit(crate::steps::place_axis(&place))));
    about(mv, m, line_point, line_axis, radius, branch)
}

/// The value that puts the point moving as `m` at `radius` from the line
/// through `line_point` along the unit `line_axis` (world), parallel to a
/// circle's axis or normal to a slide: circle–circle or planar
/// line–circle; `branch` picks the root. The cylinder about a revolute,
/// or about a pinned link's pin ([`super::pin`]).
pub(crate) fn about<T: Scalar>(
    mv: &Move<'_, T>,
    m: Motion<T>,
    line_point: [T; 3],
    line_axis: [T; 3],
    radius: T,
    branch: Option<usize>,
) -> Result<[T; 2], SolveError> {
    let choice = mv.choice(branch);
    match m {
        Motion::Circle {
            centre,
            axis,
            radius: r,
            length,
        } => {
            // The line's point in the circle's plane: the distance is planar.
            let x0 = add(centre, r);
            let q = add(line_point, scale(dot(line_axis, sub(x0, line_point)), line_axis));
            crate::subproblems::circle_distance::circle_distance(centre, axis, r, length, q, radius, choice, mv.site())
                .map_err(|e| mv.fail(e))
        }
        Motion::Line { start, along } => {
            // Without the components along the cylinder's axis: a planar line–circle.
            let d = reject(along, line_axis);
            let s0 = sub(start, scale(dot(line_axis, sub(start, line_point)), line_axis));
            line_circle(s0, d, line_point, radius, choice, mv.site()).map_err(|e| mv.fail(e))
        }
    }
}

/// The planner's match for a cylinder: revolute `q`, met on the link the
/// reach `r` ends at, parallel to the motion's axis `k` (in the new link's
/// frame; `rot` turns the reach's link's frame into it), its other link
/// known (or, in a planar mechanism, pinned at `q`: it turns about `q` as
/// if known). `turning`: the point moves on a circle and the hops that
/// carry it turn about `k` too.
pub(crate) fn find(
    s: &Search<'_>,
    r: &Reach,
    q: usize,
    k: Vector3<f64>,
    rot: UnitQuaternion<f64>,
    turning: bool,
) -> Option<Constraint> {
    let next = s.other(q, r.link);
    let held = s.known[next] || (s.model.planar && s.pinned_at(next, v3(s.place(q, next).at())));
    if !(turning && held) {
        return None;
    }
    let dir = rot * s.axis(q, r.link);
    Search::parallel(dir, k).then(|| Constraint::Cylinder {
        hops: r.hops.clone().into(),
        joint: q,
        link: next,
    })
}

/// The planner's match for a slide against a cylinder: revolute `q`, met on
/// the link the reach `r` ends at, its other link known, its axis normal to
/// the slide `k` (in the new link's frame, `to`'s; `rot` turns the reach's
/// link's frame into it), and the hops that carry the point turning about
/// that axis, so the point stays in the plane the circle about `q` lies in:
/// a planar slider dyad, its slide found along the line directly.
pub(crate) fn find_slide(
    s: &Search<'_>,
    to: usize,
    r: &Reach,
    q: usize,
    k: Vector3<f64>,
    rot: UnitQuaternion<f64>,
) -> Option<Constraint> {
    let next = s.other(q, r.link);
    let dir = rot * s.axis(q, r.link);
    (s.known[next] && s.hops_about(to, &r.hops, dir) && Search::normal(dir, k)).then(|| Constraint::Cylinder {
        hops: r.hops.clone().into(),
        joint: q,
        link: next,
    })
}

/// The cylinder's normal at the moving point `p`: `p`'s offset from the
/// axis of revolute `h` on `link`, for the locus's factor
/// ([`crate::steps::locus_factor`]).
pub(crate) fn normal(
    at: &Configuration,
    p: Vector3<f64>,
    h: usize,
    link: usize,
) -> (Vector3<f64>, Condition, LinkPoint) {
    let jh = &at.g.joints[h];
    let side = usize::from(jh.links[0] != link);
    let c = v3(at.frames[link].apply(jh.places[side].at()));
    let w = v3(at.frames[link].rotate(crate::steps::place_axis(&jh.places[side]))).normalize();
    let d = p - c;
    (d - w * w.dot(&d), Condition::TouchesCylinder, joint_point(h, link))
}
