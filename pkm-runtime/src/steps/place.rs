//! A link placed by a pose output: its point at the given position, turned
//! by the given angle about a world axis, by three given angles
//! ([`PoseParts`]: `R = R_z(rz)·R_y(ry)·R_x(rx)`), or not turned. No
//! kernel: the pose is the given values themselves.

use super::{Geometry, Given};
use crate::frame::Frame;
use crate::plan::Turn;
use crate::scalar::{constant, sub, unit, Scalar};
use crate::solution::PointRef;

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
        Turn::Angles => {
            let v = given.values;
            rotation_of_angles([v[next], v[next + 1], v[next + 2]])
        }
        Turn::Fixed | Turn::Free => Frame::identity(),
    };
    pose.t = sub(position, pose.rotate(local));
    pose
}

/// Which of a spatial pose's six values an output gives, in the order
/// x, y, z (the point's position), rx, ry, rz (the link's orientation as
/// `R = R_z(rz)·R_y(ry)·R_x(rx)`: turned about the world x axis first, then
/// y, then z; roll, pitch and yaw). The values not given are the
/// mechanism's to decide (a platform's parasitic motion).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct PoseParts(pub [bool; 6]);

impl PoseParts {
    /// The parts' names, in order.
    pub const NAMES: [&'static str; 6] = ["x", "y", "z", "rx", "ry", "rz"];

    /// All six given.
    pub fn all(&self) -> bool {
        self.0.iter().all(|g| *g)
    }

    /// How many are given.
    pub fn count(&self) -> usize {
        self.0.iter().filter(|g| **g).count()
    }

    /// The indices (0..6) of the given parts, in order.
    pub fn given(&self) -> impl Iterator<Item = usize> + '_ {
        (0..6).filter(|&i| self.0[i])
    }

    /// The indices of the parts not given, in order.
    pub fn free(&self) -> impl Iterator<Item = usize> + '_ {
        (0..6).filter(|&i| !self.0[i])
    }
}

/// `R_z(rz)·R_y(ry)·R_x(rx)` for `[rx, ry, rz]`, written out.
pub fn rotation_of_angles<T: Scalar>(angles: [T; 3]) -> Frame<T> {
    let [x, y, z] = [0, 1, 2].map(|i| (angles[i].cos(), angles[i].sin()));
    elementary(2, z).then(&elementary(1, y)).then(&elementary(0, x))
}

/// The rotation about world axis `i` by the turn `(cos, sin)`.
pub fn elementary<T: Scalar>(i: usize, (c, s): (T, T)) -> Frame<T> {
    let mut k = constant([0.0; 3]);
    k[i] = T::c(1.0);
    Frame::about(k, c, s)
}

/// The six values of `pose` at its local point `local`: the point's world
/// position and the angles `[rx, ry, rz]` of `R = R_z·R_y·R_x`
/// (`rz = atan2(r₁₀, r₀₀)`, `ry = atan2(−r₂₀, √(r₀₀² + r₁₀²))`,
/// `rx = atan2(r₂₁, r₂₂)`; at `ry = ±π/2` rx and rz are one freedom and
/// rz takes the angle `atan2(r₁₀, r₀₀)` of rounding). What a parts output
/// reads, in the interpreter and generated code alike.
pub fn pose_values<T: Scalar>(pose: &Frame<T>, local: [T; 3]) -> [T; 6] {
    let p = pose.apply(local);
    let r = &pose.r;
    let rz = r[1][0].atan2(r[0][0]);
    let ry = (-r[2][0]).atan2((r[0][0] * r[0][0] + r[1][0] * r[1][0]).sqrt());
    let rx = r[2][1].atan2(r[2][2]);
    [p[0], p[1], p[2], rx, ry, rz]
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
