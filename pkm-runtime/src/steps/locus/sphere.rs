//! A point of the new link held on a sphere: at a parallelogram's arm length
//! from a known point, or at an S–S link's length from its other centre
//! ([`Radius`]; that sphere's match is [`crate::steps::rod::find_sphere`]). The joint moves the point on a circle (R, Pa) or a
//! line (P): a circle meeting a sphere (`a·cosθ + b·sinθ = c`, the constant
//! term formed stably near concentric circles) or a line meeting a sphere
//! (the foot of the perpendicular ± the half-chord).

use crate::model::Place;
use crate::plan::v3;
use crate::plan::{Anchor, Constraint, Radius};
use crate::scalar::{norm, Scalar};
use crate::singular::{Condition, Configuration, LinkPoint};
use crate::solution::{PointRef, SolveError};
use crate::steps::search::{reversed, Reach, Search};
use crate::steps::{Found, Motion, Move};
use crate::subproblems::{circle_distance::circle_distance, line_sphere::line_distance};
use nalgebra::Vector3;

/// The value of the joint that puts `point` of the new link at the
/// distance `radius` fixes (a parallelogram's arm, an S–S link's length)
/// from the anchored `centre`; `branch` picks the root.
pub fn execute<T: Scalar>(
    mv: &Move<'_, T>,
    point: PointRef,
    centre: &Anchor,
    radius: Radius,
    branch: Option<usize>,
) -> Result<Found<T>, SolveError> {
    let (_, m) = mv.motion(point);
    let q = mv.geometry.anchor(&mv.state.poses, centre);
    let radius = self::radius(mv.geometry, radius);
    Ok(mv.found(to_distance(mv, m, q, radius, mv.choice(branch))?))
}

/// The length `radius` says: a parallelogram's arm, or a rod's between
/// its centres.
pub fn radius<T: Scalar>(geometry: &crate::steps::Geometry<T>, radius: Radius) -> T {
    match radius {
        Radius::Arm(pa) => arm_length(&geometry.joints[pa].places),
        Radius::Rod { link, point, joint } => crate::steps::rod::length(geometry, link, point, joint),
    }
}

/// The value that puts the moving point at distance `d` from `q`.
pub(crate) fn to_distance<T: Scalar>(
    mv: &Move<'_, T>,
    m: Motion<T>,
    q: [T; 3],
    d: T,
    choice: T::Choice,
) -> Result<[T; 2], SolveError> {
    match m {
        Motion::Circle {
            centre,
            axis,
            radius,
            length,
        } => circle_distance(centre, axis, radius, length, q, d, choice, mv.site()).map_err(|e| mv.fail(e)),
        Motion::Line { start, along } => {
            let [plus, minus] = line_distance(start, along, q, d, mv.site()).map_err(|e| mv.fail(e))?;
            Ok([T::pick(choice, plus, minus), T::c(0.0)])
        }
    }
}

/// The length of a parallelogram's arm.
pub fn arm_length<T: Scalar>(places: &[Place<T>; 2]) -> T {
    places
        .iter()
        .find_map(|p| match p {
            Place::Arm { arm, .. } => Some(norm(*arm)),
            _ => None,
        })
        .unwrap_or(T::c(f64::NAN))
}

/// The planner's match for a sphere: parallelogram `q`, met on the link the
/// reach `r` ends at, hinged at the point, with its other hinge staying put
/// along a reach to a known link (the centre); the point keeps the arm's
/// length from it. `j` is the joint that moves the point.
pub(crate) fn find(s: &Search<'_>, j: usize, r: &Reach, q: usize) -> Option<Constraint> {
    if (r.x - v3(s.place(q, r.link).at())).norm() > s.tol {
        return None;
    }
    let next = s.other(q, r.link);
    let b = v3(s.place(q, next).at());
    let mut excl = vec![j, q];
    excl.extend(r.hops.iter().map(|h| h.joint));
    let c = s.fixed_reach(next, b, &excl).into_iter().find(|c| s.known[c.link])?;
    Some(Constraint::Sphere {
        centre: Anchor {
            link: c.link,
            hops: reversed(&c.hops),
            point: PointRef::Joint(q),
        },
        radius: Radius::Arm(q),
    })
}

/// The sphere's normal at the moving point `p` (from the anchored
/// `centre`), for the locus's factor ([`crate::steps::locus_factor`]).
pub(crate) fn normal(at: &Configuration, p: Vector3<f64>, centre: &Anchor) -> (Vector3<f64>, Condition, LinkPoint) {
    let (c, point) = at.anchored(centre);
    (p - c, Condition::TouchesSphere, point)
}
