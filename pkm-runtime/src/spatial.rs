//! Spatial solution plans and their interpreter.
//!
//! A spatial plan solves the links of a κ = 0 mechanism one joint at a time.
//! Every step finds one joint value between a link whose pose is known and
//! a new link, in closed form, from what the rest of the mechanism says
//! about one point (or direction) of the new link:
//!
//! * the point is known already ([`Step::Aim`]): a rotation (Paden–Kahan 1)
//!   or a slide;
//! * the point lies on a sphere, a plane or a cylinder ([`Step::Locus`]):
//!   the joint moves it on a circle or a line, and the intersection is
//!   `a·cosθ + b·sinθ = c`, a line–sphere quadratic, or linear;
//! * a direction of the new link is known ([`Step::Align`]);
//! * a parallelogram's plane must contain a known point ([`Step::PaPlane`]).
//!
//! The constraints come from the rest of the mechanism through "anchors":
//! chains of joints at value 0 that provably do not move the anchored point
//! (the point is on their axes) or its coordinate along one direction
//! (rotations about parallel axes, translations normal to it). Generated
//! code and this interpreter call the same kernels.

use crate::model::{framed_transform, place_frames, Joint, JointType, Model, Place};
use crate::plan::{PointRef, SolveError};
use crate::primitives::Sign;
use nalgebra::{Isometry3, Point3, Rotation3, Vector3};
use std::borrow::Cow;

/// A link's pose in the world.
pub type Pose3 = Isometry3<f64>;

/// A joint's type and places: all the kernels need (no name, no links).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Joint3 {
    /// R, P or Pa.
    pub kind: JointType,
    /// The two links it joins.
    pub links: [usize; 2],
    /// Its places on `links[0]` and `links[1]`.
    pub places: [Place; 2],
    /// The places' canonical frames, computed once ([`place_frames`]).
    pub frames: [Pose3; 2],
    /// The joint's transform at value 0 and its inverse, computed once (every
    /// step's motion starts from them).
    pub zero: [Pose3; 2],
    /// The inverse of the second place's frame.
    pub frame_v_inverse: Pose3,
}

impl Joint3 {
    /// A joint from its type, links and places.
    pub fn new(kind: JointType, links: [usize; 2], places: [Place; 2]) -> Joint3 {
        let frames = place_frames(&places);
        let zero = framed_transform(kind, &places, &frames, &[0.0; 3]);
        Joint3 {
            kind,
            links,
            places,
            frames,
            zero: [zero, zero.inverse()],
            frame_v_inverse: frames[1].inverse(),
        }
    }

    /// The geometry of a model joint.
    pub fn of(j: &Joint) -> Joint3 {
        Joint3::new(j.kind, j.links, j.places)
    }
}

fn v3(a: [f64; 3]) -> Vector3<f64> {
    Vector3::new(a[0], a[1], a[2])
}

/// The pose of the link across joint `j` from the known pose `from`, at
/// joint value `value`; `forward` when `from` is the joint's first link.
pub fn transfer(from: &Pose3, j: &Joint3, forward: bool, value: f64) -> Pose3 {
    let t = match j.kind {
        // F_u · Rz(θ) · F_v⁻¹ with the frames' parts computed once.
        JointType::R => {
            let (sin, cos) = (0.5 * value).sin_cos();
            let rz = nalgebra::UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(cos, 0.0, 0.0, sin));
            j.frames[0] * Isometry3::from_parts(nalgebra::Translation3::identity(), rz) * j.frame_v_inverse
        }
        _ => framed_transform(j.kind, &j.places, &j.frames, &[value]),
    };
    if forward {
        from * t
    } else {
        from * t.inverse()
    }
}

/// A world point: `local` on a link at `pose`.
#[inline]
pub fn at(pose: &Pose3, local: [f64; 3]) -> [f64; 3] {
    let p = pose.transform_point(&Point3::from(v3(local)));
    [p.x, p.y, p.z]
}

/// A world direction: `local` on a link at `pose`.
#[inline]
pub fn dir(pose: &Pose3, local: [f64; 3]) -> [f64; 3] {
    let d = pose.rotation * v3(local);
    [d.x, d.y, d.z]
}

/// How a point of the new link moves with the joint value: on a circle
/// `centre + R(axis, θ)·radius` (R and Pa joints) or a line `start + s·along`
/// (P joints, `along` unit).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Motion {
    /// `centre + R(axis, θ)·radius`, `axis` unit.
    Circle {
        /// Centre (for a parallelogram, the point the arm swings about).
        centre: [f64; 3],
        /// Unit axis.
        axis: [f64; 3],
        /// The point at θ = 0 minus the centre.
        radius: [f64; 3],
        /// The circle's radius from the links' own geometry, exact where
        /// `|radius|` carries the rounding of the world transform (what keeps
        /// nearly concentric circles accurate: see [`circle_to_distance`]).
        length: f64,
    },
    /// `start + s·along`, `along` unit.
    Line {
        /// The point at s = 0.
        start: [f64; 3],
        /// Unit direction.
        along: [f64; 3],
    },
}

fn arr(v: Vector3<f64>) -> [f64; 3] {
    [v.x, v.y, v.z]
}

/// The motion of the new link's point `local` as joint `j` turns or slides
/// from the known pose `from`.
pub fn motion(from: &Pose3, j: &Joint3, forward: bool, local: [f64; 3]) -> Motion {
    let zero = from * j.zero[usize::from(!forward)];
    let x0 = zero.transform_point(&Point3::from(v3(local))).coords;
    let (side_from, side_new) = if forward { (0, 1) } else { (1, 0) };
    match j.kind {
        JointType::P => {
            let (guide_side, sign) = if matches!(j.places[side_from], Place::Line { .. }) {
                (side_from, 1.0)
            } else {
                (side_new, -1.0)
            };
            let guide_pose = if guide_side == side_from { from } else { &zero };
            let d = guide_pose.rotation * v3(j.places[guide_side].axis()).normalize() * sign;
            Motion::Line {
                start: arr(x0),
                along: arr(d),
            }
        }
        JointType::Pa => {
            let frame = from * j.frames[side_from];
            let k = frame.rotation * Vector3::z();
            let (arm_side, sign) = if matches!(j.places[side_from], Place::Arm { .. }) {
                (side_from, 1.0)
            } else {
                (side_new, -1.0)
            };
            let Place::Arm { arm, .. } = j.places[arm_side] else {
                return Motion::Line {
                    start: arr(x0),
                    along: [0.0; 3],
                };
            };
            let arm_pose = if arm_side == side_from { from } else { &zero };
            let a = arm_pose.rotation * v3(arm) * sign;
            Motion::Circle {
                centre: arr(x0 - a),
                axis: arr(k),
                radius: arr(a),
                length: off_axis(v3(arm), v3(j.places[arm_side].axis())),
            }
        }
        _ => {
            let frame = from * j.frames[side_from];
            let sign = if forward { 1.0 } else { -1.0 };
            let k = frame.rotation * Vector3::z() * sign;
            let c = frame.translation.vector;
            let place = j.places[side_new];
            Motion::Circle {
                centre: arr(c),
                axis: arr(k),
                radius: arr(x0 - c),
                length: off_axis(v3(local) - v3(place.at()), v3(place.axis())),
            }
        }
    }
}

/// The distance of the offset `x` from an axis along `axis`, in one link's frame.
fn off_axis(x: Vector3<f64>, axis: Vector3<f64>) -> f64 {
    let k = axis.normalize();
    (x - k * k.dot(&x)).norm()
}

/// The axis a joint turns the new link about, if it turns it (R joints).
pub fn turning_axis(from: &Pose3, j: &Joint3, forward: bool) -> Option<[f64; 3]> {
    match j.kind {
        JointType::R => match motion(from, j, forward, [0.0; 3]) {
            Motion::Circle { axis, .. } => Some(axis),
            Motion::Line { .. } => None,
        },
        _ => None,
    }
}

/// The angle a pose is turned about unit `k` from the base's orientation.
pub fn angle_about(pose: &Pose3, k: [f64; 3]) -> f64 {
    let k = v3(k).normalize();
    let e = if k.x.abs() < 0.9 { Vector3::x() } else { Vector3::y() };
    let e = (e - k * k.dot(&e)).normalize();
    let r = pose.rotation * e;
    k.dot(&e.cross(&r)).atan2(e.dot(&r))
}

/// The value of a 1-DOF joint from the poses of its two links.
pub fn joint_value(j: &Joint3, u: &Pose3, v: &Pose3) -> f64 {
    let rel = u.inverse() * v;
    match j.kind {
        JointType::R => {
            let m = j.frames[0].inverse() * rel * j.frames[1];
            let r: Rotation3<f64> = m.rotation.to_rotation_matrix();
            r[(1, 0)].atan2(r[(0, 0)])
        }
        JointType::P => {
            let (guide, slider, rel) = if matches!(j.places[0], Place::Line { .. }) {
                (j.places[0], j.places[1], rel)
            } else {
                (j.places[1], j.places[0], rel.inverse())
            };
            let p = rel.transform_point(&Point3::from(v3(slider.at()))).coords;
            (p - v3(guide.at())).dot(&v3(guide.axis()).normalize())
        }
        JointType::Pa => {
            let (arm_side, rel) = if matches!(j.places[0], Place::Arm { .. }) {
                (0, rel)
            } else {
                (1, rel.inverse())
            };
            let (fa, fo) = (j.frames[arm_side], j.frames[1 - arm_side]);
            let t = (fa.inverse() * rel * fo).translation.vector;
            let Place::Arm { arm, .. } = j.places[arm_side] else {
                return f64::NAN;
            };
            let a = fa.rotation.inverse() * v3(arm);
            (a.x * t.y - a.y * t.x).atan2(a.x * t.x + a.y * t.y)
        }
        JointType::S => f64::NAN,
    }
}

/// A chain of hops: borrowed in generated code, owned in plans built at run time.
pub type Hops = Cow<'static, [Hop]>;

/// One joint crossed at value 0 on the way from a known link (see [`Anchor`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Hop {
    /// The joint.
    pub joint: usize,
    /// Whether it is crossed from its first link to its second.
    pub forward: bool,
}

/// A point known through a chain of joints that do not move it (or do not
/// move its coordinate along a direction): from known link `link`, across
/// `hops` at value 0, the point `point` of the last link.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Anchor {
    /// The known link.
    pub link: usize,
    /// Joints crossed at value 0.
    pub hops: Hops,
    /// The point on the last link.
    pub point: PointRef,
}

/// A direction known the same way: the axis of `joint`'s place on the last link.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Direction {
    /// The known link.
    pub link: usize,
    /// Joints crossed at value 0.
    pub hops: Hops,
    /// The joint whose axis is the direction.
    pub joint: usize,
}

/// What the rest of the mechanism says about a point of the new link.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Constraint {
    /// At the length of parallelogram `pa`'s arm from the anchored point.
    Sphere {
        /// The centre.
        centre: Anchor,
        /// The parallelogram.
        pa: usize,
    },
    /// Its coordinate along `normal` is that of the anchored point.
    Plane {
        /// The plane's normal.
        normal: Direction,
        /// A point with the same coordinate.
        anchor: Anchor,
    },
    /// At a fixed distance from the axis of joint `joint` (an R joint on known
    /// link `link`, parallel to the motion's axis), the distance its place on
    /// the point's side has from it; the point reaches that side through `hops`.
    Cylinder {
        /// From the new link to the link across `joint`.
        hops: Hops,
        /// The revolute.
        joint: usize,
        /// The known link it turns on.
        link: usize,
    },
    /// On the plane a slider (P joint `joint`, guide on known link `link`)
    /// sweeps with the motion's axis.
    Slider {
        /// From the new link to the slider's link.
        hops: Hops,
        /// The prismatic joint.
        joint: usize,
        /// The known link.
        link: usize,
    },
}

/// One step of a spatial plan.
#[derive(Debug, Clone, PartialEq)]
pub enum Step {
    /// A link placed by a pose output: its point at inputs `input..input+3`,
    /// turned by `inputs[input + 3]` about `about` if given.
    Place {
        /// The link.
        link: usize,
        /// The point whose position is given.
        point: PointRef,
        /// Index of x in the inputs.
        input: usize,
        /// The world axis of the given angle.
        about: Option<[f64; 3]>,
    },
    /// Through a joint whose value is input `input`.
    Transfer {
        /// The joint.
        joint: usize,
        /// Known link.
        from: usize,
        /// New link.
        to: usize,
        /// Index into the inputs.
        input: usize,
    },
    /// The value that brings `point` of `to` to the anchored position.
    Aim {
        /// The joint.
        joint: usize,
        /// Known link.
        from: usize,
        /// New link.
        to: usize,
        /// The point of `to`.
        point: PointRef,
        /// Where it must be.
        target: Anchor,
    },
    /// The value that puts `point` of `to` on a sphere, plane or cylinder.
    Locus {
        /// The joint.
        joint: usize,
        /// Known link.
        from: usize,
        /// New link.
        to: usize,
        /// The point of `to`.
        point: PointRef,
        /// Where it must be.
        constraint: Constraint,
        /// This step's index in the sign vector (`None`: one root).
        branch: Option<usize>,
    },
    /// A revolute's angle that makes `group`'s axis (on `to`) parallel to `target`.
    Align {
        /// The revolute.
        joint: usize,
        /// Known link.
        from: usize,
        /// New link.
        to: usize,
        /// A direction of `to` (from `to` across `hops`).
        group: Direction,
        /// The world direction it must take.
        target: Direction,
    },
    /// A revolute's angle that puts parallelogram `pa`'s plane (its hinge on
    /// `to`) through the anchored point (the other hinge).
    PaPlane {
        /// The revolute.
        joint: usize,
        /// Known link.
        from: usize,
        /// New link.
        to: usize,
        /// The parallelogram.
        pa: usize,
        /// The other hinge's position.
        target: Anchor,
    },
}

/// A spatial plan.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Plan {
    /// Steps in order.
    pub steps: Vec<Step>,
    /// How many ± choices (2^branches solutions).
    pub branches: usize,
    /// How many input values.
    pub n_inputs: usize,
    /// Forward plans: the input joints in input order.
    pub inputs: Vec<usize>,
}

impl Step {
    /// The joint this step solves (and so closes), if any.
    pub fn joint(&self) -> Option<usize> {
        match self {
            Step::Place { .. } => None,
            Step::Transfer { joint, .. }
            | Step::Aim { joint, .. }
            | Step::Locus { joint, .. }
            | Step::Align { joint, .. }
            | Step::PaPlane { joint, .. } => Some(*joint),
        }
    }
}

impl Plan {
    /// The joints no step solves, in order: the loops the plan never
    /// needed, whose closure [`run`] checks after the last step.
    pub fn open_joints(&self, n_joints: usize) -> Vec<usize> {
        let mut solved = vec![false; n_joints];
        for j in self.steps.iter().filter_map(Step::joint) {
            if let Some(s) = solved.get_mut(j) {
                *s = true;
            }
        }
        (0..n_joints).filter(|&j| !solved[j]).collect()
    }

    /// Which given values are angles: a pose's angle, a revolute's value.
    pub fn angular_inputs(&self, joints: &[Joint3]) -> Vec<bool> {
        let mut angular = vec![false; self.n_inputs];
        for s in &self.steps {
            match s {
                Step::Place {
                    input, about: Some(_), ..
                } => angular[input + 3] = true,
                Step::Transfer { joint, input, .. } => {
                    angular[*input] = matches!(joints[*joint].kind, JointType::R | JointType::Pa)
                }
                _ => {}
            }
        }
        angular
    }
}

/// A solution: every link's pose and every joint's value.
#[derive(Debug, Clone, PartialEq)]
pub struct Solution {
    /// Link poses.
    pub poses: Vec<Pose3>,
    /// Joint values.
    pub values: Vec<f64>,
}

fn bad(what: String) -> SolveError {
    SolveError::BadInput { what: Cow::Owned(what) }
}

/// A point of a link, in that link's frame: a joint's place on it or a named point.
#[inline]
pub fn local(joints: &[Joint3], named: &[[f64; 3]], point: PointRef, link: usize) -> [f64; 3] {
    match point {
        PointRef::Joint(j) => {
            let joint = &joints[j];
            joint.places[usize::from(joint.links[0] != link)].at()
        }
        PointRef::Named(n) => named[n],
    }
}

/// A point of a link of the model, in that link's frame.
pub fn local_point(model: &Model, point: PointRef, link: usize) -> Result<[f64; 3], SolveError> {
    match point {
        PointRef::Joint(j) => {
            let joint = model.joints.get(j).ok_or_else(|| bad(format!("no joint {j}")))?;
            let side = joint
                .links
                .iter()
                .position(|&l| l == link)
                .ok_or_else(|| bad(format!("joint {} does not touch link {link}", joint.name)))?;
            Ok(joint.places[side].at())
        }
        PointRef::Named(n) => model
            .points
            .get(n)
            .map(|p| p.at)
            .ok_or_else(|| bad(format!("no named point {n}"))),
    }
}

/// The pose of the last link of a hop chain (joints crossed at value 0)
/// from `link` at `pose`, and that link.
pub fn across(joints: &[Joint3], mut pose: Pose3, mut link: usize, hops: &[Hop]) -> (Pose3, usize) {
    for h in hops {
        let j = &joints[h.joint];
        // At value 0 the joint's transform (and its inverse) is precomputed.
        pose *= j.zero[usize::from(!h.forward)];
        link = if h.forward { j.links[1] } else { j.links[0] };
    }
    (pose, link)
}

pub(crate) fn anchor(joints: &[Joint3], named: &[[f64; 3]], poses: &[Pose3], a: &Anchor) -> [f64; 3] {
    let (pose, l) = across(joints, poses[a.link], a.link, &a.hops);
    at(&pose, local(joints, named, a.point, l))
}

pub(crate) fn direction(joints: &[Joint3], pose: Pose3, link: usize, d: &Direction) -> [f64; 3] {
    let (pose, l) = across(joints, pose, link, &d.hops);
    let j = &joints[d.joint];
    dir(&pose, j.places[usize::from(j.links[0] != l)].axis())
}

/// Runs the plan for one branch and verifies the solution: every open
/// joint must close ([`crate::consistency`]); where one does not, the error
/// names the given value the others contradict (`#k`: the plan knows no
/// names for the given values, see [`crate::consistency::name_given`]).
pub fn run(model: &Model, plan: &Plan, inputs: &[f64], signs: &[Sign]) -> Result<Solution, SolveError> {
    let geometry = crate::steps::Geometry::of(model);
    let open = plan.open_joints(geometry.joints.len());
    let name = |j: usize| model.joints[j].name.clone();
    let state = run_frames(model, &geometry, plan, inputs, signs)?;
    let extent = crate::consistency::extent(&state.poses.iter().map(|p| p.t).collect::<Vec<_>>());
    let residual = crate::steps::open_residual(&geometry, &state.poses, &open, extent);
    let rows = crate::steps::RESIDUAL_ROWS;
    if let Some((row, gap)) = crate::consistency::worst(&residual, extent) {
        let owner = Cow::Owned(format!("joint {}", name(open[row / rows])));
        let angular = plan.angular_inputs(&model.joints.iter().map(Joint3::of).collect::<Vec<_>>());
        let e = crate::consistency::inconsistent(owner, gap, inputs, &angular, extent, |g| {
            let s = run_frames(model, &geometry, plan, g, signs).ok()?;
            Some(crate::steps::open_residual(&geometry, &s.poses, &open, extent))
        });
        return Err(crate::consistency::name_given(e, &[]));
    }
    let values = (0..geometry.joints.len())
        .map(|j| crate::steps::value(&geometry, &state, j))
        .collect();
    Ok(Solution {
        poses: state.poses.iter().map(pose_of).collect(),
        values,
    })
}

/// A frame as an isometry.
pub fn pose_of(f: &crate::frame::Frame<f64>) -> Pose3 {
    let m = nalgebra::Matrix3::from_fn(|i, j| f.r[i][j]);
    let r = Rotation3::from_matrix_unchecked(m);
    Isometry3::from_parts(v3(f.t).into(), nalgebra::UnitQuaternion::from_rotation_matrix(&r))
}

/// The steps of one branch, unverified.
fn run_frames(
    model: &Model,
    geometry: &crate::steps::Geometry<f64>,
    plan: &Plan,
    inputs: &[f64],
    signs: &[Sign],
) -> Result<crate::steps::Solved<f64>, SolveError> {
    if inputs.len() != plan.n_inputs || signs.len() != plan.branches {
        return Err(bad(format!(
            "expected {} inputs and {} signs",
            plan.n_inputs, plan.branches
        )));
    }
    if let Some(i) = inputs.iter().position(|v| !v.is_finite()) {
        return Err(bad(format!("given value {} is {}", i + 1, inputs[i])));
    }
    let name = |j: usize| -> Cow<'static, str> { Cow::Owned(model.joints[j].name.clone()) };
    let given = crate::steps::Given {
        values: inputs,
        signs,
        name: &name,
    };
    crate::steps::run(plan, geometry, model.links.len(), &given)
}

/// Every branch of the plan.
/// Every branch of the plan; a branch that repeats an earlier one's solution
/// (a double root) says so ([`SolveError::DoubleRoot`]).
pub fn run_all(model: &Model, plan: &Plan, inputs: &[f64]) -> Vec<(Vec<Sign>, Result<Solution, SolveError>)> {
    let mut all = crate::plan::every_branch(plan.branches, |signs| run(model, plan, inputs, signs));
    let revolute: Vec<bool> = model
        .joints
        .iter()
        .map(|j| matches!(j.kind, JointType::R | JointType::Pa))
        .collect();
    crate::consistency::mark_double_roots_in(&mut all, &revolute, |s: &Solution| &s.values);
    all
}
