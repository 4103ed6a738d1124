//! A revolute's angle that turns a direction of the new link parallel to a
//! known direction (the same sense): Paden–Kahan subproblem 1 on
//! directions, [`super::aim::turn_onto`].

use super::{Found, Move};
use crate::scalar::Scalar;
use crate::solution::SolveError;
use crate::spatial::Direction;

/// The angle of the revolute that makes `group` (a direction of the new
/// link) parallel to `target`.
pub fn execute<T: Scalar>(mv: &Move<'_, T>, group: &Direction, target: &Direction) -> Result<Found<T>, SolveError> {
    let (axis, zero) = mv.turning("an alignment needs a revolute")?;
    // The group's direction with this joint at 0.
    let d = mv.geometry.direction(zero, mv.to, group);
    let w = mv.geometry.direction(mv.state.poses[target.link], target.link, target);
    Ok(mv.found(super::aim::turn_onto(axis, d, w, mv.site()).map_err(|e| mv.fail(e))?))
}
