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

    /// The loading with the idle spin of every S–S link taken out
    /// ([`idle_spin_line`]). Such a link turns freely about the line
    /// through its two ball centres: the position fixes it by a convention
    /// and the velocity analysis by another, and nothing in the mechanism
    /// resists it. The dynamics take it as not spinning (its angular
    /// velocity about the line zero at every instant), which a body
    /// symmetric about the line (its centroid on it, its inertia the same
    /// about every normal to it) keeps: its moment about the line then
    /// does no work, and with it dropped (`I − (âᵀIâ) ââᵀ`) its inertial
    /// wrench is the same whatever spin a path's convention gives it. A
    /// body that is not symmetric, or a load with a moment about the line,
    /// would make the forces depend on the spin, and a load off the line or
    /// with a moment would spin it: an error naming the link.
    pub fn idle_spins_dropped(&self, model: &Model) -> Result<std::borrow::Cow<'_, Loading>, (usize, String)> {
        let lines: Vec<Option<(Vector3<f64>, Vector3<f64>)>> =
            (0..model.links.len()).map(|l| idle_spin_line(model, l)).collect();
        if lines.iter().all(Option::is_none) {
            return Ok(std::borrow::Cow::Borrowed(self));
        }
        let size = crate::kinematics::model_scale(model);
        let mut out = self.clone();
        for b in &mut out.bodies {
            let Carrier::Link(l) = b.carrier else { continue };
            let Some((point, axis)) = lines[l] else { continue };
            if let Some(problem) = idle_spin_problem(&b.centroid, &b.inertia, &point, &axis, size) {
                return Err((l, problem));
            }
            b.inertia = without_axial(&b.inertia, &axis);
        }
        for load in &self.loads {
            let Some((point, axis)) = lines[load.link] else {
                continue;
            };
            if let Some(problem) = idle_spin_load_problem(&load.at, &load.moment, &point, &axis, size) {
                return Err((load.link, problem));
            }
        }
        Ok(std::borrow::Cow::Owned(out))
    }
}

/// The line about which `link` turns freely: for a link held by exactly
/// two spherical joints and by nothing else (an S–S coupler), the first
/// ball's centre and the unit direction to the second's, in the link's
/// frame; `None` for any other link (or two centres at one point).
pub fn idle_spin_line(model: &Model, link: usize) -> Option<(Vector3<f64>, Vector3<f64>)> {
    let joints = model.joints.iter().map(|j| (j.kind, j.links, j.places));
    let (a, d) = crate::skc_reactions::idle_spin_line(joints, link)?;
    let d = Vector3::from(d);
    d.iter().all(|x| x.is_finite()).then(|| (Vector3::from(a), d))
}

/// Why a body on a link that turns freely about the line through `point`
/// along the unit `axis` (the body's frame) would make the forces depend
/// on that turn, if it would: its centroid off the line (by more than
/// 1e-9 of `size`), or its inertia not the same about every normal to the
/// line (the line not a principal axis, or the two other principal moments
/// unequal, by more than 1e-9 of the trace).
pub fn idle_spin_problem(
    centroid: &Vector3<f64>,
    inertia: &Matrix3<f64>,
    point: &Vector3<f64>,
    axis: &Vector3<f64>,
    size: f64,
) -> Option<String> {
    let off = (centroid - point).cross(axis).norm();
    if off.is_nan() || off > 1e-9 * size {
        return Some(format!(
            "its centroid is {off:e} off the line through its two ball centres, about which it turns freely: give it a centroid on that line"
        ));
    }
    let along = axis.dot(&(inertia * axis));
    let transverse = 0.5 * (inertia.trace() - along);
    let symmetric = Matrix3::identity() * transverse + axis * axis.transpose() * (along - transverse);
    let asymmetry = (inertia - symmetric).abs().max();
    if asymmetry.is_nan() || asymmetry > 1e-9 * inertia.trace().abs() {
        return Some(format!(
            "its inertia is not the same about every normal to the line through its two ball centres, about which it turns freely (off by {asymmetry:e}): give it an inertia symmetric about that line"
        ));
    }
    None
}

/// Why a load at `at` (the link's frame) with the moment `moment` on a
/// link that turns freely about the line through `point` along `axis`
/// would turn it, if it would: a force off the line (by more than 1e-9 of
/// `size`), or a moment (whose component along the line depends on the
/// link's pose). A force through the line has no moment about it.
pub fn idle_spin_load_problem(
    at: &Vector3<f64>,
    moment: &Vector3<f64>,
    point: &Vector3<f64>,
    axis: &Vector3<f64>,
    size: f64,
) -> Option<String> {
    let off = (at - point).cross(axis).norm();
    (off.is_nan() || off > 1e-9 * size || moment.norm() > 0.0).then(|| {
        "a load on it has a moment about the line through its two ball centres, about which it turns freely (a moment, or a force off the line): nothing would hold it".to_string()
    })
}

/// An inertia without its moment about the unit `axis`: `I − (âᵀIâ) ââᵀ`
/// (for an inertia symmetric about the axis, the moment about every
/// normal to it, the axial one zero).
pub fn without_axial(inertia: &Matrix3<f64>, axis: &Vector3<f64>) -> Matrix3<f64> {
    let rows = core::array::from_fn(|i| core::array::from_fn(|j| inertia[(i, j)]));
    let dropped = crate::skc_reactions::without_axial(&rows, &[axis.x, axis.y, axis.z]);
    Matrix3::from_fn(|i, j| dropped[i][j])
}

/// The inertia tensor in the link's axes from its moments as declared:
/// one about z (planar: a link that turns about z only, whose other moments
/// do no work), three principal, or the six entries `(Ixx, Iyy, Izz, Ixy,
/// Ixz, Iyz)` of the tensor.
pub fn inertia_tensor(n: &[f64]) -> nalgebra::Matrix3<f64> {
    match *n {
        [izz] => Matrix3::from_diagonal(&Vector3::new(0.0, 0.0, izz)),
        [ixx, iyy, izz] => Matrix3::from_diagonal(&Vector3::new(ixx, iyy, izz)),
        [ixx, iyy, izz, ixy, ixz, iyz] => Matrix3::new(ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz),
        _ => Matrix3::from_element(f64::NAN),
    }
}

/// Why the moments `n` (one about z; three principal; or the six entries
/// of the tensor) are not a rigid body's inertia, if they are not: every
/// value finite, the tensor positive semi-definite, and its principal
/// moments satisfy the triangle inequality `I₁ + I₂ ≥ I₃` (to 1e-9 of the
/// trace, for rounded tables).
pub fn inertia_problem(n: &[f64]) -> Option<String> {
    if n.iter().any(|x| !x.is_finite()) {
        return Some("an inertia is not finite".into());
    }
    let principal: Vec<f64> = match n.len() {
        1 => return (n[0] < 0.0).then(|| format!("the moment of inertia is {}, negative", n[0])),
        3 => n.to_vec(),
        6 => inertia_tensor(n).symmetric_eigenvalues().iter().copied().collect(),
        k => return Some(format!("an inertia has 1, 3 or 6 values, not {k}")),
    };
    let trace: f64 = principal.iter().sum();
    let slack = 1e-9 * trace.abs();
    if let Some(m) = principal.iter().find(|&&m| m < -slack) {
        return Some(format!(
            "a principal moment of inertia is {m}, negative: the tensor is not positive semi-definite"
        ));
    }
    for k in 0..3 {
        let others = trace - principal[k];
        if principal[k] > others + slack {
            return Some(format!(
                "the principal moments {:?} break the triangle inequality: {} exceeds the sum of the other two ({others})",
                principal, principal[k]
            ));
        }
    }
    None
}

/// Why a body of mass `mass` with inertia moments `moments` (as
/// [`inertia_problem`] reads them) is not a rigid body, if it is not.
pub fn body_problem(mass: f64, moments: &[f64]) -> Option<String> {
    if !(mass >= 0.0 && mass.is_finite()) {
        return Some(format!("the mass is {mass}"));
    }
    inertia_problem(moments)
}
