//! A revolute's angle that turns a direction of the new link parallel to a
//! known direction (the same sense): Paden–Kahan subproblem 1 on
//! directions, [`super::aim::turn_onto`].

use super::{as_value, found, Found, Geometry, Given, Solved};
use crate::plan::{step_error, SolveError};
use crate::scalar::Scalar;
use crate::spatial::Direction;

/// Step `k`: the angle of revolute `joint` that makes `group` (a direction
/// of `to`) parallel to `target`.
#[allow(clippy::too_many_arguments)]
pub fn execute<T: Scalar>(
    k: usize,
    joint: usize,
    from: usize,
    to: usize,
    group: &Direction,
    target: &Direction,
    geometry: &Geometry<T>,
    state: &Solved<T>,
    given: &Given<'_, T>,
) -> Result<Found<T>, SolveError> {
    let j = &geometry.joints[joint];
    let forward = j.links[0] == from;
    let f = &state.poses[from];
    let axis = j.turning_axis(f, forward).ok_or_else(|| {
        step_error(
            k,
            (given.name)(joint),
            super::degenerate("an alignment needs a revolute"),
        )
    })?;
    // The group's direction with this joint at 0.
    let zero = f.then(&j.zero[usize::from(!forward)]);
    let d = geometry.direction(zero, to, group);
    let w = geometry.direction(state.poses[target.link], target.link, target);
    let turn = super::aim::turn_onto(axis, d, w, [k, joint]).map_err(|e| super::fail(k, joint, given, e))?;
    Ok(found(geometry, state, joint, from, to, as_value(j.kind, turn)))
}
