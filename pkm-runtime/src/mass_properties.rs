//! A mechanism's bodies, gravity and external loads in the units the
//! dynamics computes in: kilograms, the file's length unit `L` and
//! seconds. A force of the file (N) is `1/L` of those units' force
//! (kg·L/s²) when `L` is in metres, a moment (N·L) likewise, gravity
//! (m/s²) is `g/L` in L/s²; [`Loading::to_newtons`] takes a result back.

use nalgebra::{Matrix3, Vector3};

/// One link's mass properties.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    /// The link.
    pub link: usize,
    /// Mass (kg).
    pub mass: f64,
    /// The centroid in the link's frame (L).
    pub centroid: Vector3<f64>,
    /// The inertia tensor about the centroid, link axes (kg·L²).
    pub inertia: Matrix3<f64>,
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
