//! A point of the new link held on a sphere: at a parallelogram's arm length
//! from a known point. The joint moves the point on a circle (R, Pa) or a
//! line (P): a circle meeting a sphere (`a·cosθ + b·sinθ = c`, the constant
//! term formed stably near concentric circles) or a line meeting a sphere
//! (the stable quadratic).

use super::{as_value, call, found, Found, Geometry, Given, Kernel, Motion, Solved};
use crate::model::Place;
use crate::plan::{PointRef, SolveError};
use crate::primitives::{circle_to_distance_turn, line_sphere, Error as GeomError, Sign};
use crate::scalar::{add, norm, Scalar};
use crate::spatial::Anchor;

/// Step `k`: the value of `joint` that puts `point` of `to` at parallelogram
/// `pa`'s arm length from the anchored `centre`; `branch` picks the root.
#[allow(clippy::too_many_arguments)]
pub fn execute<T: Scalar>(
    k: usize,
    joint: usize,
    from: usize,
    to: usize,
    point: PointRef,
    centre: &Anchor,
    pa: usize,
    branch: Option<usize>,
    geometry: &Geometry<T>,
    state: &Solved<T>,
    given: &Given<'_, T>,
) -> Result<Found<T>, SolveError> {
    let j = &geometry.joints[joint];
    let m = j.motion(&state.poses[from], j.links[0] == from, geometry.local(point, to));
    let q = geometry.anchor(&state.poses, centre);
    let radius = arm_length(&geometry.joints[pa].places);
    let choice = T::choice(given.signs, branch);
    let r = to_distance(m, q, radius, choice, k, joint, given)?;
    Ok(found(geometry, state, joint, from, to, as_value(j.kind, r)))
}

/// The value that puts the moving point at distance `d` from `q`.
pub(crate) fn to_distance<T: Scalar>(
    m: Motion<T>,
    q: [T; 3],
    d: T,
    choice: T::Choice,
    k: usize,
    joint: usize,
    given: &Given<'_, T>,
) -> Result<[T; 2], SolveError> {
    match m {
        Motion::Circle {
            centre,
            axis,
            radius,
            length,
        } => {
            let args = super::args(&[centre, axis, radius], &[length, q[0], q[1], q[2], d]);
            call(Kernel::CircleDistance, &args, choice, k, joint, given)
        }
        Motion::Line { start, along } => {
            let args = super::args(&[start, along, q], &[d]);
            call(Kernel::LineDistance, &args, choice, k, joint, given)
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

/// The turn `[cos θ, sin θ]` that puts the circle's point
/// `centre + R(axis, θ)·radius` at distance `d` from `q`
/// ([`circle_to_distance_turn`], with the circle's exact radius `length`).
/// `args = [centre, axis, radius, length, q, d]`; `Plus` and `Minus` as there.
///
/// ```
/// use pkm_runtime::primitives::Sign;
/// use pkm_runtime::steps::on_sphere::circle_distance;
///
/// // The unit circle about z meets the unit circle about (1, 0, 0) at ±60°.
/// let a = [0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0];
/// let [c, s] = circle_distance(&a, Sign::Plus).unwrap();
/// assert!((c - 0.5).abs() < 1e-15 && (s.abs() - 0.75f64.sqrt()).abs() < 1e-15);
/// ```
#[inline]
pub fn circle_distance(args: &[f64; 14], sign: Sign) -> Result<[f64; 2], GeomError<f64>> {
    let centre = [args[0], args[1], args[2]];
    let axis = [args[3], args[4], args[5]];
    let p = add(centre, [args[6], args[7], args[8]]);
    let q = [args[10], args[11], args[12]];
    Ok(circle_to_distance_turn(centre, axis, p, Some(args[9]), q, args[13])?.branch(sign))
}

/// The slide `[t, 0]` that puts the line's point `start + t·along` (`along`
/// unit) at distance `d` from `q` ([`line_sphere`]).
/// `args = [start, along, q, d]`; `Plus` and `Minus` as there.
///
/// ```
/// use pkm_runtime::primitives::Sign;
/// use pkm_runtime::steps::on_sphere::line_distance;
///
/// // The x axis meets the sphere of radius 5 about (0, 3, 0) at x = ±4.
/// let a = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 3.0, 0.0, 5.0];
/// assert_eq!(line_distance(&a, Sign::Plus).unwrap()[0].abs(), 4.0);
/// ```
#[inline]
pub fn line_distance(args: &[f64; 10], sign: Sign) -> Result<[f64; 2], GeomError<f64>> {
    let start = [args[0], args[1], args[2]];
    let along = [args[3], args[4], args[5]];
    let q = [args[6], args[7], args[8]];
    Ok([line_sphere(start, along, q, args[9])?.branch(sign).t, 0.0])
}
