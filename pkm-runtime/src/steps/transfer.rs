//! A link across a joint whose value is given (an actuator in a forward
//! solution). No kernel: the joint's transform at the given value.

use super::{found, Found, Geometry, Given, JointValue, Solved};
use crate::scalar::Scalar;

/// The link `to` across `joint` from the known link `from`, at given value `input`.
pub fn execute<T: Scalar>(
    joint: usize,
    from: usize,
    to: usize,
    input: usize,
    geometry: &Geometry<T>,
    state: &Solved<T>,
    given: &Given<'_, T>,
) -> Found<T> {
    let value = JointValue::given(geometry.joints[joint].kind, given.values[input]);
    found(geometry, state, joint, from, to, value)
}
