//! A link placed by a pose output: its point at the given position, turned
//! by the given angle about a world axis (or not turned). No kernel: the
//! pose is the given values themselves.

use super::{Geometry, Given};
use crate::frame::Frame;
use crate::plan::PointRef;
use crate::scalar::{constant, sub, unit, Scalar};

/// The pose of `link` whose `point` is at the given values `input..input+3`,
/// turned by the value `input + 3` about the world axis `about` if given.
pub fn execute<T: Scalar>(
    link: usize,
    point: PointRef,
    input: usize,
    about: Option<[f64; 3]>,
    geometry: &Geometry<T>,
    given: &Given<'_, T>,
) -> Frame<T> {
    let v = given.values;
    let position = [v[input], v[input + 1], v[input + 2]];
    let local = geometry.local(point, link);
    let mut pose = match about {
        Some(k) => {
            let angle = v[input + 3];
            Frame::about(unit(constant(k)), angle.cos(), angle.sin())
        }
        None => Frame::identity(),
    };
    pose.t = sub(position, pose.rotate(local));
    pose
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
