//! A point of the new link held on the plane a known slider sweeps with the
//! motion's axis (its guide and the turning axis span it): a circle meeting
//! a plane ([`super::on_plane`]).

use super::{as_value, found, Found, Geometry, Given, Motion, Solved};
use crate::plan::{step_error, PointRef, SolveError};
use crate::scalar::{cross, dot, Scalar};
use crate::spatial::Hop;

/// Step `k`: the value of `joint` that puts `point` of `to` (carried across
/// `hops` to the slider's link) on the plane prismatic `h` (guide on the
/// known `link`) sweeps with the motion's axis.
#[allow(clippy::too_many_arguments)]
pub fn execute<T: Scalar>(
    k: usize,
    joint: usize,
    from: usize,
    to: usize,
    point: PointRef,
    hops: &[Hop],
    h: usize,
    link: usize,
    branch: Option<usize>,
    geometry: &Geometry<T>,
    state: &Solved<T>,
    given: &Given<'_, T>,
) -> Result<Found<T>, SolveError> {
    let j = &geometry.joints[joint];
    let x = geometry.local(point, to);
    let m = j.motion(&state.poses[from], j.links[0] == from, x);
    let jh = &geometry.joints[h];
    let y = geometry.carry(x, hops);
    let (Motion::Circle { axis, .. }, Motion::Line { start, along }) =
        (m, jh.motion(&state.poses[link], jh.links[0] == link, y))
    else {
        return Err(step_error(
            k,
            (given.name)(joint),
            super::degenerate("a slider constraint needs a turning joint and a slide"),
        ));
    };
    let n = cross(axis, along);
    let choice = T::choice(given.signs, branch);
    let r = super::on_plane::to_plane(m, n, dot(n, start), choice, k, joint, given)?;
    Ok(found(geometry, state, joint, from, to, as_value(j.kind, r)))
}
