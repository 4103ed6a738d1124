//! A point of the new link held on the plane a known slider sweeps with the
//! motion's axis (its guide and the turning axis span it): a circle meeting
//! a plane ([`crate::steps::locus::plane`]). `Plus` is the point farther along the
//! guide (a slider-crank's open assembly).

use crate::plan::v3;
use crate::plan::{Constraint, Hop};
use crate::scalar::{cross, dot, Scalar};
use crate::singular::{joint_point, Condition, Configuration, LinkPoint};
use crate::solution::{PointRef, SolveError};
use crate::steps::search::{Reach, Search};
use crate::steps::{Found, Motion, Move};
use nalgebra::{UnitQuaternion, Vector3};

/// The value of the joint that puts `point` of the new link (carried
/// across `hops` to the slider's link) on the plane prismatic `h` (guide on
/// the known `link`) sweeps with the motion's axis.
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

/// The value that puts the point moving as `m` (a circle) on the plane the
/// slider `h` sweeps with the circle's axis, its carrier `x` carried across
/// `hops` to the slider's link; `branch` picks the root.
pub fn meet<T: Scalar>(
    mv: &Move<'_, T>,
    m: Motion<T>,
    x: [T; 3],
    hops: &[Hop],
    h: usize,
    link: usize,
    branch: Option<usize>,
) -> Result<[T; 2], SolveError> {
    let jh = &mv.geometry.joints[h];
    let y = mv.geometry.carry(x, hops);
    let (Motion::Circle { axis, .. }, Motion::Line { start, along }) =
        (m, jh.motion(&mv.state.poses[link], jh.links[0] == link, y))
    else {
        return Err(mv.fail(crate::steps::degenerate(
            "a slider constraint needs a turning joint and a slide",
        )));
    };
    // Normal `along × axis`: then `Plus` is the root farther along the
    // guide (see `locus::plane::to_plane`: its + root lies along axis × n).
    let n = cross(along, axis);
    super::plane::to_plane(mv, m, n, dot(n, start), mv.choice(branch))
}

/// The planner's match for a slider plane: prismatic `q`, met on the link
/// the reach `r` ends at, its guide normal to the motion's axis `k` (in the
/// new link's frame; `rot` turns the reach's link's frame into it), its
/// other link known. `turning`: the point moves on a circle and the hops
/// that carry it turn about `k` too.
pub(crate) fn find(
    s: &Search<'_>,
    r: &Reach,
    q: usize,
    k: Vector3<f64>,
    rot: UnitQuaternion<f64>,
    turning: bool,
) -> Option<Constraint> {
    let next = s.other(q, r.link);
    if !(turning && s.known[next]) {
        return None;
    }
    let dir = rot * s.axis(q, r.link);
    Search::normal(dir, k).then(|| Constraint::Slider {
        hops: r.hops.clone().into(),
        joint: q,
        link: next,
    })
}

/// The normal of the plane prismatic `h` (guide on `link`) sweeps with the
/// axis of `joint` (turning from `from`): `axis × guide`, for the locus's
/// factor ([`crate::steps::locus_factor`]).
pub(crate) fn normal(
    at: &Configuration,
    joint: usize,
    from: usize,
    h: usize,
    link: usize,
) -> (Vector3<f64>, Condition, LinkPoint) {
    let jh = &at.g.joints[h];
    let side = usize::from(jh.links[0] != link);
    let along = v3(at.frames[link].rotate(crate::steps::place_axis(&jh.places[side])));
    let j = &at.g.joints[joint];
    let axis = match j.motion(&at.frames[from], j.links[0] == from, [0.0; 3]) {
        Motion::Circle { axis, .. } => v3(axis),
        Motion::Line { along, .. } => v3(along),
    };
    (axis.cross(&along), Condition::TouchesSliderPlane, joint_point(h, link))
}
