//! A point of the new link held on a plane: its coordinate along a known
//! direction is that of a known point. On a circle: `a·cosθ + b·sinθ = c`;
//! on a line: one division.

use super::{as_value, call, found, Found, Geometry, Given, Kernel, Motion, Solved};
use crate::plan::{PointRef, SolveError};
use crate::primitives::{trig_turn, Error as GeomError, Sign};
use crate::scalar::{cross, dot, norm, scale, sub, Scalar};
use crate::spatial::{Anchor, Direction};

/// Step `k`: the value of `joint` that puts `point` of `to` on the plane
/// with normal `normal` through the anchored `anchor`.
#[allow(clippy::too_many_arguments)]
pub fn execute<T: Scalar>(
    k: usize,
    joint: usize,
    from: usize,
    to: usize,
    point: PointRef,
    normal: &Direction,
    anchor: &Anchor,
    branch: Option<usize>,
    geometry: &Geometry<T>,
    state: &Solved<T>,
    given: &Given<'_, T>,
) -> Result<Found<T>, SolveError> {
    let j = &geometry.joints[joint];
    let m = j.motion(&state.poses[from], j.links[0] == from, geometry.local(point, to));
    let n = geometry.direction(state.poses[normal.link], normal.link, normal);
    let offset = dot(n, geometry.anchor(&state.poses, anchor));
    let r = to_plane(m, n, offset, T::choice(given.signs, branch), k, joint, given)?;
    Ok(found(geometry, state, joint, from, to, as_value(j.kind, r)))
}

/// The value that puts the moving point on the plane `n·X = offset`.
pub(crate) fn to_plane<T: Scalar>(
    m: Motion<T>,
    n: [T; 3],
    offset: T,
    choice: T::Choice,
    k: usize,
    joint: usize,
    given: &Given<'_, T>,
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
            call(Kernel::CirclePlane, &[a, b, c], choice, k, joint, given)
        }
        Motion::Line { start, along } => {
            let args = [offset - dot(n, start), dot(n, along), norm(n)];
            call(Kernel::LinePlane, &args, choice, k, joint, given)
        }
    }
}

/// The turn `[cos θ, sin θ]` solving `a·cosθ + b·sinθ = c`
/// ([`trig_turn`]). `args = [a, b, c]`.
///
/// ```
/// use pkm_runtime::primitives::Sign;
/// use pkm_runtime::steps::on_plane::circle_plane;
///
/// assert_eq!(circle_plane(&[1.0, 0.0, 0.0], Sign::Plus).unwrap(), [0.0, 1.0]);
/// ```
#[inline]
pub fn circle_plane(args: &[f64; 3], sign: Sign) -> Result<[f64; 2], GeomError<f64>> {
    Ok(trig_turn(args[0], args[1], args[2])?.branch(sign))
}

/// The slide `[num / den, 0]` onto a plane, `num` the plane's offset from
/// the line's start along the normal, `den` the normal's component along
/// the line, `scale` the normal's length. `args = [num, den, scale]`.
///
/// # Errors
/// [`GeomError::Degenerate`] when the slide is parallel to the plane
/// (`|den| ≤ 1e-12·scale`).
///
/// ```
/// use pkm_runtime::primitives::Sign;
/// use pkm_runtime::steps::on_plane::line_plane;
///
/// assert_eq!(line_plane(&[3.0, 2.0, 2.0], Sign::Plus).unwrap(), [1.5, 0.0]);
/// assert!(line_plane(&[3.0, 0.0, 2.0], Sign::Plus).is_err());
/// ```
#[inline]
pub fn line_plane(args: &[f64; 3], _sign: Sign) -> Result<[f64; 2], GeomError<f64>> {
    let [num, den, scale] = *args;
    if den.abs() <= 1e-12 * scale {
        return Err(GeomError::Degenerate {
            what: "the slide is parallel to the plane it must reach",
        });
    }
    Ok([num / den, 0.0])
}
