//! A link placed by a pose output: its point at the given position, turned
//! by the given angle about a world axis (or not turned). No kernel: the
//! pose is the given values themselves.

use super::{Geometry, Given};
use crate::frame::Frame;
use crate::scalar::{constant, sub, unit, Scalar};
use crate::solution::PointRef;
use crate::spatial::Turn;

/// The pose of `link` whose `point` is at the given values from `input`
/// (x, y, and z unless `planar`), turned as `turn` says: by the next value
/// about a world axis, or not at all (a pinned link keeps the base's
/// orientation until a later step turns it).
pub fn execute<T: Scalar>(
    link: usize,
    point: PointRef,
    input: usize,
    planar: bool,
    turn: Turn,
    geometry: &Geometry<T>,
    given: &Given<'_, T>,
) -> Frame<T> {
    let local = geometry.local(point, link);
    let (position, next) = given_point(given.values, input, planar, local[2]);
    let mut pose = match turn {
        Turn::About(k) => {
            let angle = given.values[next];
            Frame::about(unit(constant(k)), angle.cos(), angle.sin())
        }
        Turn::Fixed | Turn::Free => Frame::identity(),
    };
    pose.t = sub(position, pose.rotate(local));
    pose
}

/// The given position from `input` and the index after it: x, y and z, or
/// in a planar mechanism x, y and the point's own `z`.
pub fn given_point<T: Scalar>(values: &[T], input: usize, planar: bool, z: T) -> ([T; 3], usize) {
    if planar {
        ([values[input], values[input + 1], z], input + 2)
    } else {
        ([values[input], values[input + 1], values[input + 2]], input + 3)
    }
}

/// The angle `pose` is turned about unit `k` from the base's orientation:
/// of the direction normal to `k` that a frame about `k` takes for its x
/// axis ([`super::canonical_frame`]), the angle it has turned through about `k`.
/// What a pose output's angle is, in the interpreter and generated code alike.
pub fn angle_about<T: Scalar>(pose: &Frame<T>, k: [T; 3]) -> T {
    let frame = super::canonical_frame(constant([0.0; 3]), k);
    let (k, e) = (frame.column(2), frame.column(0));
    let r = pose.rotate(e);
    crate::scalar::dot(k, crate::scalar::cross(e, r)).atan2(crate::scalar::dot(e, r))
}
