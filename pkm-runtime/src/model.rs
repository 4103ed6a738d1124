//! A numeric model of a mechanism at given dimensions: links, joints placed
//! in the frames of their two links, named points. The plan interpreter, the
//! reference Newton solver and the command line work on it.
//!
//! # Joint conventions
//! A joint's frame on a link has its origin at the joint's point and its z
//! axis along the joint's axis; its x axis is the canonical perpendicular
//! ([`canonical_frame`]). With `F_u`, `F_v` the joint's frames on links u =
//! `links[0]` and v = `links[1]` and `T_u`, `T_v` the links' poses in the
//! world:
//! - R (value θ): `T_v = T_u · F_u · Rz(θ) · F_v⁻¹`. In a planar model the axes
//!   are z and the frames are pure translations, so θ is the angle of v's x
//!   axis from u's x axis.
//! - P (value s): the guide line `through q along d` sits on one link, the
//!   slider's point `p` on the other; the slider keeps the guide link's
//!   orientation and its point is at `q + s·d̂`. With the guide on u:
//!   `T_v = T_u · Trans(q + s·d̂) · Trans(−p)`; with the guide on v the same
//!   relation read the other way.
//! - S (values rx, ry, rz, a rotation vector): `T_v = T_u · Trans(c_u) · Rot(r) · Trans(−c_v)`.

use nalgebra::Isometry3;

use crate::kinematics;

/// Joint types the numeric model knows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointType {
    /// Revolute.
    R,
    /// Prismatic.
    P,
    /// Spherical.
    S,
    /// Parallelogram of four revolutes, one value: the angle its arm has
    /// turned about the hinge axis. The two links translate relative to each
    /// other (their frames stay parallel).
    Pa,
}

impl JointType {
    /// The joint's number of variables.
    pub const fn dof(self) -> usize {
        match self {
            JointType::R | JointType::P | JointType::Pa => 1,
            JointType::S => 3,
        }
    }
}

/// Where a joint sits on one of its links, in the link's frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Place<T = f64> {
    /// A point with the joint's axis through it (R joints).
    Axis {
        /// The point.
        at: [T; 3],
        /// The axis direction (need not be unit).
        axis: [T; 3],
    },
    /// A point: an S joint's centre, or a P joint's slider point.
    Point {
        /// The point.
        at: [T; 3],
    },
    /// A P joint's guide line.
    Line {
        /// A point of the line.
        through: [T; 3],
        /// Its direction (need not be unit).
        along: [T; 3],
    },
    /// A parallelogram's hinge on the link that carries its arm: the hinge
    /// point, the hinge axis, and the arm (from this hinge to the other
    /// link's hinge point when the joint value is 0; perpendicular to the axis).
    Arm {
        /// The hinge point.
        at: [T; 3],
        /// The hinge axis (need not be unit).
        axis: [T; 3],
        /// The arm vector.
        arm: [T; 3],
    },
}

impl<T: Copy> Place<T> {
    /// The place's point (a guide line's `through` point).
    pub fn at(&self) -> [T; 3] {
        match *self {
            Place::Axis { at, .. } | Place::Point { at } | Place::Line { through: at, .. } | Place::Arm { at, .. } => {
                at
            }
        }
    }

    /// The place's direction: an axis, a guide's direction, or z for a bare point.
    pub fn axis(&self) -> [T; 3]
    where
        T: From<f64>,
    {
        match *self {
            Place::Axis { axis, .. } | Place::Arm { axis, .. } | Place::Line { along: axis, .. } => axis,
            Place::Point { .. } => [0.0.into(), 0.0.into(), 1.0.into()],
        }
    }

    /// The place with every coordinate mapped by `f`.
    pub fn map<U>(&self, f: impl Fn(T) -> U) -> Place<U> {
        let m = |v: [T; 3]| v.map(&f);
        match *self {
            Place::Axis { at, axis } => Place::Axis {
                at: m(at),
                axis: m(axis),
            },
            Place::Point { at } => Place::Point { at: m(at) },
            Place::Line { through, along } => Place::Line {
                through: m(through),
                along: m(along),
            },
            Place::Arm { at, axis, arm } => Place::Arm {
                at: m(at),
                axis: m(axis),
                arm: m(arm),
            },
        }
    }
}

/// A joint of the model.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// Its name.
    pub name: String,
    /// Its type.
    pub kind: JointType,
    /// The links it connects (u, v).
    pub links: [usize; 2],
    /// Its place on u and on v.
    pub places: [Place; 2],
    /// Whether it is an input.
    pub actuated: bool,
}

/// A named point fixed on a link.
#[derive(Debug, Clone, PartialEq)]
pub struct NamedPoint {
    /// Its name.
    pub name: String,
    /// Its link.
    pub link: usize,
    /// Its coordinates in the link's frame.
    pub at: [f64; 3],
}

/// A mechanism at given dimensions. Link 0 is the base, at the identity.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    /// The mechanism's name.
    pub name: String,
    /// Whether every joint moves in the xy plane.
    pub planar: bool,
    /// Link names; 0 is the base.
    pub links: Vec<String>,
    /// Joints in declaration order. Joint values are stored in this order,
    /// [`JointType::dof`] values each.
    pub joints: Vec<Joint>,
    /// Named points.
    pub points: Vec<NamedPoint>,
}

impl Joint {
    /// The link at the other end from `link`.
    pub fn other(&self, link: usize) -> usize {
        if self.links[0] == link {
            self.links[1]
        } else {
            self.links[0]
        }
    }

    /// Which side's place is the joint's point: the slider's for a P joint
    /// (the side without the guide line), otherwise its first link's.
    pub fn point_side(&self) -> usize {
        usize::from(matches!(self.places[0], Place::Line { .. }))
    }
}

impl Model {
    /// The index of each joint's first value in a joint-value vector, and the vector's length.
    pub fn value_offsets(&self) -> (Vec<usize>, usize) {
        let mut offsets = Vec::with_capacity(self.joints.len());
        let mut n = 0;
        for j in &self.joints {
            offsets.push(n);
            n += j.kind.dof();
        }
        (offsets, n)
    }

    /// Which entries of a joint-value vector are lengths: the values of the
    /// P joints (the rest are angles).
    pub fn length_values(&self) -> Vec<bool> {
        let (offsets, n) = self.value_offsets();
        let mut lengths = vec![false; n];
        for (j, joint) in self.joints.iter().enumerate() {
            lengths[offsets[j]] = joint.kind == JointType::P;
        }
        lengths
    }

    /// The actuated joints, in declaration order.
    pub fn inputs(&self) -> Vec<usize> {
        (0..self.joints.len()).filter(|&j| self.joints[j].actuated).collect()
    }
}

/// The joint frame with origin `at` and z along `axis`; x is the unit
/// vector of the world x axis made perpendicular to z (the world y axis when
/// z is within about 25° of x).
pub fn canonical_frame(at: [f64; 3], axis: [f64; 3]) -> Isometry3<f64> {
    kinematics::frame::<f64>(at, axis).into()
}

/// The pose of `links[1]` relative to `links[0]` for the joint's values
/// (`T_u⁻¹ · T_v`), by the conventions above.
pub fn joint_transform(joint: &Joint, values: &[f64]) -> Isometry3<f64> {
    place_transform(joint.kind, &joint.places, values)
}

/// As [`joint_transform`], from the joint's type and places alone.
pub fn place_transform(kind: JointType, places: &[Place; 2], values: &[f64]) -> Isometry3<f64> {
    kinematics::joint_pose(kind, places, &kinematics::frames(places), values).into()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::v3;
    use nalgebra::Vector3;

    fn close(a: Vector3<f64>, b: [f64; 3]) -> bool {
        (a - v3(b)).norm() < 1e-12
    }

    #[test]
    fn planar_revolute_angle_is_measured_from_x() {
        // A crank of length 2 about the base origin at 90°: its far end is at (0, 2).
        let j = Joint {
            name: "R1".into(),
            kind: JointType::R,
            links: [0, 1],
            places: [
                Place::Axis {
                    at: [0.0; 3],
                    axis: [0.0, 0.0, 1.0],
                },
                Place::Axis {
                    at: [0.0; 3],
                    axis: [0.0, 0.0, 1.0],
                },
            ],
            actuated: true,
        };
        let t = joint_transform(&j, &[std::f64::consts::FRAC_PI_2]);
        assert!(close(
            t.transform_point(&[2.0, 0.0, 0.0].into()).coords,
            [0.0, 2.0, 0.0]
        ));
    }

    #[test]
    fn prismatic_slider_point_runs_along_the_guide() {
        // Guide through (1, -3, 0) along x on the base; slider point (0.5, 0, 0): at s = 4 it is at (5, -3, 0).
        let guide = Place::Line {
            through: [1.0, -3.0, 0.0],
            along: [2.0, 0.0, 0.0],
        };
        let slider = Place::Point { at: [0.5, 0.0, 0.0] };
        for (places, forward) in [([guide, slider], true), ([slider, guide], false)] {
            let j = Joint {
                name: "P1".into(),
                kind: JointType::P,
                links: [0, 1],
                places,
                actuated: false,
            };
            let t = joint_transform(&j, &[4.0]);
            // Pose of the slider in the base frame.
            let slider_pose = if forward { t } else { t.inverse() };
            assert!(close(
                slider_pose.transform_point(&[0.5, 0.0, 0.0].into()).coords,
                [5.0, -3.0, 0.0]
            ));
        }
    }

    #[test]
    fn canonical_frame_is_orthonormal_and_right_handed() {
        for axis in [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.3, -0.4, 0.8]] {
            let f = canonical_frame([1.0, 2.0, 3.0], axis);
            let r = f.rotation.to_rotation_matrix();
            assert!((r.matrix().determinant() - 1.0).abs() < 1e-12);
            assert!((r * Vector3::z() - v3(axis).normalize()).norm() < 1e-12);
        }
    }
}
