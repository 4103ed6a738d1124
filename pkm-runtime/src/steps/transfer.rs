//! A link across a joint whose value is given (an actuator in a forward
//! solution). No kernel: the joint's transform at the given value.

use super::{Found, JointValue, Move};
use crate::scalar::Scalar;

/// The new link across the joint, at given value `input`.
pub fn execute<T: Scalar>(mv: &Move<'_, T>, input: usize) -> Found<T> {
    mv.at(JointValue::given(mv.joint().kind, mv.given.values[input]))
}

/// The planner's match: a joint whose value is given, between a known link
/// and a new one, carries the new link across.
pub(crate) fn find(s: &mut super::search::Search<'_>) -> bool {
    use crate::plan::Step;
    for (j, joint) in s.model.joints.iter().enumerate() {
        let (Some(input), false) = (s.given[j], s.used[j]) else {
            continue;
        };
        let [u, v] = joint.links;
        if s.known[u] != s.known[v] {
            let (from, to) = if s.known[u] { (u, v) } else { (v, u) };
            s.push(
                Step::Transfer {
                    joint: j,
                    from,
                    to,
                    input,
                },
                to,
                j,
            );
            return true;
        }
    }
    false
}
