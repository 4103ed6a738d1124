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
use crate::plan::{step_error, PointRef, SolveError};
use crate::primitives::{circle_to_distance, line_sphere, trig_equation, Error as GeomError, Sign};
use nalgebra::{Isometry3, Point3, Rotation3, Unit, Vector3};
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

fn degenerate(what: &'static str) -> GeomError<f64> {
    GeomError::Degenerate { what }
}

/// The value that puts the moving point on the sphere about `centre` of
/// radius `radius` (`sign` picks the root).
pub fn on_sphere(m: &Motion, centre: [f64; 3], radius: f64, sign: Sign) -> Result<f64, GeomError<f64>> {
    match *m {
        Motion::Circle {
            centre: c,
            axis,
            radius: r,
            length,
        } => {
            let p = v3(c) + v3(r);
            Ok(circle_to_distance(c, axis, arr(p), Some(length), centre, radius)?.branch(sign))
        }
        Motion::Line { start, along } => Ok(line_sphere(start, along, centre, radius)?.branch(sign).t),
    }
}

/// The value that puts the moving point on the plane `normal·X = offset`.
/// A line meets it once (`sign` is ignored).
pub fn on_plane(m: &Motion, normal: [f64; 3], offset: f64, sign: Sign) -> Result<f64, GeomError<f64>> {
    let n = v3(normal);
    match *m {
        Motion::Circle {
            centre, axis, radius, ..
        } => {
            let (k, r) = (v3(axis), v3(radius));
            let r_par = k * k.dot(&r);
            let r_perp = r - r_par;
            let a = n.dot(&r_perp);
            let b = n.dot(&k.cross(&r_perp));
            let c = offset - n.dot(&v3(centre)) - n.dot(&r_par);
            Ok(trig_equation(a, b, c)?.branch(sign))
        }
        Motion::Line { start, along } => {
            let den = n.dot(&v3(along));
            let scale = n.norm();
            if den.abs() <= 1e-12 * scale {
                return Err(degenerate("the slide is parallel to the plane it must reach"));
            }
            Ok((offset - n.dot(&v3(start))) / den)
        }
    }
}

/// The value that puts the moving point at distance `radius` from the line
/// through `point` along `axis`, which must be parallel to the circle's axis
/// (a planar circle–circle intersection) or, for a line, normal to it.
pub fn on_cylinder(
    m: &Motion,
    point: [f64; 3],
    axis: [f64; 3],
    radius: f64,
    sign: Sign,
) -> Result<f64, GeomError<f64>> {
    let w = v3(axis).normalize();
    match *m {
        Motion::Circle {
            centre,
            axis: k,
            radius: r,
            length,
        } => {
            let x0 = v3(centre) + v3(r);
            // The line's point in the circle's plane: the distance is planar.
            let q = v3(point) + w * w.dot(&(x0 - v3(point)));
            Ok(circle_to_distance(centre, k, arr(x0), Some(length), arr(q), radius)?.branch(sign))
        }
        Motion::Line { start, along } => {
            // Remove the component along the cylinder's axis: a planar line–circle.
            let d = v3(along) - w * w.dot(&v3(along));
            let s0 = v3(start) - w * w.dot(&(v3(start) - v3(point)));
            if d.norm() <= 1e-12 {
                return Err(degenerate("the slide is parallel to the cylinder's axis"));
            }
            let hit = line_sphere(arr(s0), arr(d), point, radius)?.branch(sign);
            Ok(hit.t / d.norm())
        }
    }
}

/// The angle about unit `k` that turns `v` onto the direction of `u` (their
/// components normal to `k`): Paden–Kahan subproblem 1.
pub fn angle_onto(k: [f64; 3], v: [f64; 3], u: [f64; 3]) -> Result<f64, GeomError<f64>> {
    let k = v3(k);
    let (v, u) = (v3(v), v3(u));
    let vp = v - k * k.dot(&v);
    let up = u - k * k.dot(&u);
    let scale = v.norm().max(u.norm());
    if vp.norm() <= 1e-12 * scale || up.norm() <= 1e-12 * scale {
        return Err(degenerate("the point or direction lies on the turning axis"));
    }
    Ok(k.dot(&vp.cross(&up)).atan2(vp.dot(&up)))
}

/// The value that carries the moving point to `target` (a rotation about
/// the circle's axis, or the slide's projection).
pub fn aim(m: &Motion, target: [f64; 3]) -> Result<f64, GeomError<f64>> {
    match *m {
        Motion::Circle {
            centre, axis, radius, ..
        } => angle_onto(axis, radius, arr(v3(target) - v3(centre))),
        Motion::Line { start, along } => Ok((v3(target) - v3(start)).dot(&v3(along))),
    }
}

/// The angle of a revolute (about unit `axis`) that turns the new link's
/// direction `direction` (at value 0) parallel to `target`, the same sense.
pub fn align(axis: [f64; 3], direction: [f64; 3], target: [f64; 3]) -> Result<f64, GeomError<f64>> {
    angle_onto(axis, direction, target)
}

/// The angle of a revolute (about unit `axis`) that puts a parallelogram's
/// plane (normal `normal` at value 0, through `hinge`) through `target`: of
/// the two, the one nearer 0, since the half-turned parallelogram moves its
/// coupler the same way.
pub fn pa_plane(axis: [f64; 3], normal: [f64; 3], hinge: [f64; 3], target: [f64; 3]) -> Result<f64, GeomError<f64>> {
    let k = v3(axis);
    let n = v3(normal);
    let u = v3(target) - v3(hinge);
    let n_par = k * k.dot(&n);
    let n_perp = n - n_par;
    let a = n_perp.dot(&u);
    let b = k.cross(&n_perp).dot(&u);
    let c = -n_par.dot(&u);
    let [p, m] = trig_equation(a, b, c)?.branches();
    Ok(
        if crate::plan::wrap_angle(p).abs() <= crate::plan::wrap_angle(m).abs() {
            crate::plan::wrap_angle(p)
        } else {
            crate::plan::wrap_angle(m)
        },
    )
}

/// The pose of a link whose point `local` is at `position`, turned by
/// `angle` about `about` (unit, world) from the base's orientation, or not
/// turned.
pub fn place3(local: [f64; 3], position: [f64; 3], about: Option<([f64; 3], f64)>) -> Pose3 {
    let rotation = match about {
        Some((k, angle)) => nalgebra::UnitQuaternion::from_axis_angle(&Unit::new_normalize(v3(k)), angle),
        None => nalgebra::UnitQuaternion::identity(),
    };
    let t = v3(position) - rotation * v3(local);
    Isometry3::from_parts(t.into(), rotation)
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

/// Joint `j`'s closure residual between the poses `u` and `v` of its two
/// links: where its place on `v` is minus where `u` and the joint's own
/// value put it (3 lengths), then the rotation between those two poses as
/// a rotation vector times `extent` (3). Zero, to rounding, for a closed
/// joint. S joints: the two places' world points' difference only.
pub fn closure_residual(j: &Joint3, u: &Pose3, v: &Pose3, extent: f64) -> [f64; 6] {
    let pv = at(v, j.places[1].at());
    if j.kind == JointType::S {
        let pu = at(u, j.places[0].at());
        return [pu[0] - pv[0], pu[1] - pv[1], pu[2] - pv[2], 0.0, 0.0, 0.0];
    }
    let predicted = transfer(u, j, true, joint_value(j, u, v));
    let pp = at(&predicted, j.places[1].at());
    let turn = (predicted.rotation.inverse() * v.rotation).scaled_axis() * extent;
    [pp[0] - pv[0], pp[1] - pv[1], pp[2] - pv[2], turn.x, turn.y, turn.z]
}

/// The extent residuals are measured against: the largest coordinate
/// magnitude of the links' origins (where the geometry places them, at or
/// near their joints), at least 1; no allocation, no transform.
pub fn extent(poses: &[Pose3]) -> f64 {
    poses
        .iter()
        .flat_map(|p| p.translation.vector.iter().copied())
        .map(f64::abs)
        .filter(|c| c.is_finite())
        .fold(1.0, f64::max)
}

/// The residual of every open joint, 6 rows each (see [`closure_residual`]).
pub fn open_residual(joints: &[Joint3], poses: &[Pose3], open: &[usize], extent: f64) -> Vec<f64> {
    open.iter()
        .flat_map(|&k| {
            let j = &joints[k];
            closure_residual(j, &poses[j.links[0]], &poses[j.links[1]], extent)
        })
        .collect()
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

/// Executes step number `k` of a plan: sets the pose of the link it solves.
/// The interpreter and generated code both call this.
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn execute(
    k: usize,
    step: &Step,
    joints: &[Joint3],
    named: &[[f64; 3]],
    poses: &mut [Pose3],
    inputs: &[f64],
    signs: &[Sign],
    name: impl Fn(usize) -> Cow<'static, str>,
) -> Result<(), SolveError> {
    let err = |j: usize| {
        let n = name(j);
        move |e| step_error(k, n, e)
    };
    let (to, pose) = match step {
        Step::Place {
            link,
            point,
            input,
            about,
        } => {
            let p = [inputs[*input], inputs[input + 1], inputs[input + 2]];
            let l = local(joints, named, *point, *link);
            (*link, place3(l, p, about.map(|a| (a, inputs[input + 3]))))
        }
        Step::Transfer { joint, from, to, input } => {
            let forward = joints[*joint].links[0] == *from;
            (*to, transfer(&poses[*from], &joints[*joint], forward, inputs[*input]))
        }
        Step::Aim {
            joint,
            from,
            to,
            point,
            target,
        } => {
            let (j, f) = (&joints[*joint], poses[*from]);
            let forward = j.links[0] == *from;
            let m = motion(&f, j, forward, local(joints, named, *point, *to));
            let value = aim(&m, anchor(joints, named, poses, target)).map_err(err(*joint))?;
            (*to, transfer(&f, j, forward, value))
        }
        Step::Locus {
            joint,
            from,
            to,
            point,
            constraint,
            branch,
        } => {
            let (j, f) = (&joints[*joint], poses[*from]);
            let forward = j.links[0] == *from;
            let x = local(joints, named, *point, *to);
            let m = motion(&f, j, forward, x);
            let sign = branch.map_or(Sign::Plus, |b| signs[b]);
            let value = match constraint {
                Constraint::Sphere { centre, pa } => on_sphere(
                    &m,
                    anchor(joints, named, poses, centre),
                    arm_length(&joints[*pa].places),
                    sign,
                ),
                Constraint::Plane { normal, anchor: a } => {
                    let n = direction(joints, poses[normal.link], normal.link, normal);
                    let p = anchor(joints, named, poses, a);
                    on_plane(&m, n, v3(n).dot(&v3(p)), sign)
                }
                Constraint::Cylinder { hops, joint: h, link } => {
                    let jh = &joints[*h];
                    let known_side = usize::from(jh.links[0] != *link);
                    let line_point = at(&poses[*link], jh.places[known_side].at());
                    let line_axis = dir(&poses[*link], jh.places[known_side].axis());
                    // The point across the hops, and its distance from h's axis there.
                    let y = carry(joints, x, hops);
                    let place = jh.places[1 - known_side];
                    let a = v3(place.axis()).normalize();
                    let d = y - v3(place.at());
                    on_cylinder(&m, line_point, line_axis, (d - a * a.dot(&d)).norm(), sign)
                }
                Constraint::Slider { hops, joint: h, link } => {
                    let jh = &joints[*h];
                    let y = carry(joints, x, hops);
                    match (m, motion(&poses[*link], jh, jh.links[0] == *link, arr(y))) {
                        (Motion::Circle { axis, .. }, Motion::Line { start, along }) => {
                            let n = v3(axis).cross(&v3(along));
                            on_plane(&m, arr(n), n.dot(&v3(start)), sign)
                        }
                        _ => Err(degenerate("a slider constraint needs a turning joint and a slide")),
                    }
                }
            }
            .map_err(err(*joint))?;
            (*to, transfer(&f, j, forward, value))
        }
        Step::Align {
            joint,
            from,
            to,
            group,
            target,
        } => {
            let (j, f) = (&joints[*joint], poses[*from]);
            let forward = j.links[0] == *from;
            let k = turning_axis(&f, j, forward).ok_or_else(|| bad("align through a non-revolute".into()))?;
            // The group's direction with this joint at 0.
            let zero = f * j.zero[usize::from(!forward)];
            let d = direction(joints, zero, *to, group);
            let w = direction(joints, poses[target.link], target.link, target);
            let value = align(k, d, w).map_err(err(*joint))?;
            (*to, transfer(&f, j, forward, value))
        }
        Step::PaPlane {
            joint,
            from,
            to,
            pa,
            target,
        } => {
            let (j, f) = (&joints[*joint], poses[*from]);
            let forward = j.links[0] == *from;
            let k =
                turning_axis(&f, j, forward).ok_or_else(|| bad("a parallelogram turned by a non-revolute".into()))?;
            let zero = f * j.zero[usize::from(!forward)];
            let p = &joints[*pa];
            let side = usize::from(p.links[0] != *to);
            let (n, hinge) = (dir(&zero, p.places[side].axis()), at(&zero, p.places[side].at()));
            let value = pa_plane(k, n, hinge, anchor(joints, named, poses, target)).map_err(err(*joint))?;
            (*to, transfer(&f, j, forward, value))
        }
    };
    poses[to] = pose;
    Ok(())
}

/// Every joint value from the link poses.
pub fn values<const J: usize>(joints: &[Joint3; J], poses: &[Pose3]) -> [f64; J] {
    core::array::from_fn(|k| {
        let j = &joints[k];
        joint_value(j, &poses[j.links[0]], &poses[j.links[1]])
    })
}

/// Verifies a solution's link poses: every open joint must close
/// ([`crate::consistency`]). Where one does not, the error names the given
/// value the others contradict, found by re-solving (`solve`, the same
/// branch at other given values) nearby. `joint_names` and `given_names`
/// name joints and given values (`#k` where a name is missing). The
/// interpreter and generated code both call this.
#[allow(clippy::too_many_arguments)]
pub fn verify(
    joints: &[Joint3],
    poses: &[Pose3],
    open: &[usize],
    joint_names: &dyn Fn(usize) -> Cow<'static, str>,
    given: &[f64],
    angular: &[bool],
    given_names: &[&str],
    mut solve: impl FnMut(&[f64]) -> Option<Vec<Pose3>>,
) -> Result<(), SolveError> {
    let extent = extent(poses);
    // The worst open joint, without allocating (the path every solution takes).
    let worst = open
        .iter()
        .filter_map(|&k| {
            let j = &joints[k];
            let r = closure_residual(j, &poses[j.links[0]], &poses[j.links[1]], extent);
            crate::consistency::worst(&r, extent).map(|(_, gap)| (k, gap))
        })
        .max_by(|a, b| a.1.total_cmp(&b.1));
    let Some((joint, gap)) = worst else {
        return Ok(());
    };
    let owner = Cow::Owned(format!("joint {}", joint_names(joint)));
    let e = crate::consistency::inconsistent(owner, gap, given, angular, extent, |g| {
        let poses = solve(g)?;
        Some(open_residual(joints, &poses, open, extent))
    });
    Err(crate::consistency::name_given(e, given_names))
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

/// The length of a parallelogram's arm.
pub fn arm_length(places: &[Place; 2]) -> f64 {
    places
        .iter()
        .find_map(|p| match p {
            Place::Arm { arm, .. } => Some(v3(*arm).norm()),
            _ => None,
        })
        .unwrap_or(f64::NAN)
}

/// A point of a link in the frame of the last link of `hops` (at value 0).
fn carry(joints: &[Joint3], x: [f64; 3], hops: &[Hop]) -> Vector3<f64> {
    let (pose, _) = across(joints, Pose3::identity(), usize::MAX, hops);
    pose.inverse_transform_point(&Point3::from(v3(x))).coords
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
