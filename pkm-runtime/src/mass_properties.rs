//! A mechanism's bodies, gravity and external loads in the units the
//! dynamics computes in: kilograms, the file's length unit `L` and
//! seconds. A force of the file (N) is `1/L` of those units' force
//! (kg·L/s²) when `L` is in metres, a moment (N·L) likewise, gravity
//! (m/s²) is `g/L` in L/s²; [`Loading::to_newtons`] takes a result back.

use crate::model::{JointType, Model, Place};
use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};

/// What a body moves with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Carrier {
    /// A link: the body's frame is the link's.
    Link(usize),
    /// A swinging bar of the parallelogram joint `joint` (a `Pa`), which is
    /// not a link of the model: hinged at `hinge`, a point of the link that
    /// holds the joint's arm (in that link's frame), it turns with the
    /// joint's value about the hinge axis. Its frame has its origin at the
    /// hinge and the arm-carrying link's axes turned by the value about the
    /// hinge axis ([`bar_pose`]): at value 0 they are that link's axes.
    Bar {
        /// The parallelogram joint.
        joint: usize,
        /// The hinge, in the arm-carrying link's frame (L).
        hinge: Vector3<f64>,
    },
}

/// One body's mass properties.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    /// What it moves with.
    pub carrier: Carrier,
    /// Mass (kg).
    pub mass: f64,
    /// The centroid in the body's frame (L).
    pub centroid: Vector3<f64>,
    /// The inertia tensor about the centroid, the body's axes (kg·L²).
    pub inertia: Matrix3<f64>,
}

/// A parallelogram joint's arm-carrying link (the side whose place is the
/// [`Place::Arm`]) and its hinge axis, unit, in that link's frame; `None`
/// for a joint without an arm.
pub fn arm_side(model: &Model, joint: usize) -> Option<(usize, Vector3<f64>)> {
    let j = model.joints.get(joint).filter(|j| j.kind == JointType::Pa)?;
    (0..2).find_map(|side| match j.places[side] {
        Place::Arm { axis, .. } => Some((j.links[side], Vector3::from(axis).normalize())),
        _ => None,
    })
}

/// A bar's pose in the world: `T_c · Trans(hinge) · Rot(â, θ)`, with `T_c`
/// the arm-carrying link's pose, `â` its hinge axis (link frame) and `θ`
/// the parallelogram's value.
pub fn bar_pose(
    carrier_pose: &Isometry3<f64>,
    axis: &Vector3<f64>,
    hinge: &Vector3<f64>,
    theta: f64,
) -> Isometry3<f64> {
    let turn = Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(*axis), theta);
    carrier_pose * Isometry3::from_parts(Translation3::from(*hinge), UnitQuaternion::from_rotation_matrix(&turn))
}

/// An external load on a link: a force through one of its points and a
/// moment, base axes, in kg·L/s² and kg·L²/s².
#[derive(Debug, Clone, PartialEq)]
pub struct PointLoad {
    /// The link.
    pub link: usize,
    /// Where the force acts, in the link's frame (L).
    pub at: Vector3<f64>,
    /// The force.
    pub force: Vector3<f64>,
    /// The moment.
    pub moment: Vector3<f64>,
}

/// What inverse dynamics reads besides the kinematics.
#[derive(Debug, Clone, PartialEq)]
pub struct Loading {
    /// The bodies with mass.
    pub bodies: Vec<Body>,
    /// Gravity, base axes (L/s²).
    pub gravity: Vector3<f64>,
    /// External loads.
    pub loads: Vec<PointLoad>,
    /// The length unit in metres.
    pub metres_per_unit: f64,
}

impl Loading {
    /// A force (kg·L/s²) in N, or a moment (kg·L²/s²) in N·L.
    pub fn to_newtons(&self, x: f64) -> f64 {
        x * self.metres_per_unit
    }
}
