//! A link across a joint whose value is given (an actuator in a forward
//! solution). No kernel: the joint's transform at the given value.

use super::{Found, JointValue, Move};
use crate::scalar::Scalar;

/// The new link across the joint, at given value `input`.
pub fn execute<T: Scalar>(mv: &Move<'_, T>, input: usize) -> Found<T> {
    mv.at(JointValue::given(mv.joint().kind, mv.given.values[input]))
}
