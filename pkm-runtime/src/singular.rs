//! Which factor of a Jacobian's determinant vanishes, and at which joint points.
//!
//! A closed-form plan fixes the unknown joints one step at a time: each step
//! is one scalar equation in one joint value, the links before it already
//! placed. In the plan's order the velocity equations are block-triangular,
//! so the determinant of the passive Jacobian is, up to nonzero factors, the
//! product of the steps' own derivatives. Normalised, a step's derivative is
//! the sine of the angle at which the moving point's path crosses the surface
//! it must reach (or, for a direction, the sine between the turning axis and
//! the direction). That sine is this module's *factor*: 0 exactly when the
//! step's two roots meet or its equation degenerates.
//!
//! The forward plan's factors are those of `det J_o` (output singularities,
//! seed 000 §2.3's f-terms); the inverse plan's, evaluated at the same
//! configuration, are those of `det J_i` (input singularities).

use crate::frame::Frame;
use crate::model::{JointType, Model};
use crate::plan::{self, Pose3};
use crate::solution::PointRef;
use crate::steps::{Geometry, Motion};
use nalgebra::{Point3, Vector3};

/// A point of a link: a joint's place on it, or a named point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LinkPoint {
    /// The link.
    pub link: usize,
    /// The point.
    pub point: PointRef,
}

/// What a vanishing factor means geometrically.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Condition {
    /// The path of `points[1]`, moved by the step's joint about (or along)
    /// `points[0]`, touches the sphere about `points[2]`.
    TouchesSphere,
    /// … touches the plane through `points[2]` (normal known).
    TouchesPlane,
    /// … touches the cylinder about the axis of joint `points[2]`.
    TouchesCylinder,
    /// … touches the plane in which joint `points[2]` slides.
    TouchesSliderPlane,
    /// … touches the circle about the pin `points[2]` of a link a point
    /// output pins there.
    TouchesCircle,
    /// `points[1]` lies on the axis of the step's joint `points[0]`.
    OnAxis,
    /// The axis of `points[1]` (or of the target `points[2]`) is parallel to
    /// the turning axis of `points[0]`.
    AxisParallel,
    /// The plane of parallelogram `points[1]` (or the plane a slide
    /// `points[1]` sweeps beyond a revolute) touches `points[2]` as
    /// `points[0]` turns.
    PlaneTouches,
    /// `points[0]`, `points[1]`, `points[2]` are collinear (an RRR dyad).
    Collinear,
    /// `points[0]points[1]` is normal to the guide of `points[2]` (an RRP dyad).
    NormalToGuide,
    /// The step's prismatic `points[0]` slides along the line it must bring
    /// `points[1]` onto (the guide of the slide at `points[2]`'s side): the
    /// two lines of a PRP or RPP dyad are parallel.
    SlideAlongLine,
    /// The axes of `points[0]`, `points[1]`, `points[2]`, through one
    /// centre, lie in one plane (a spherical RRR dyad folded).
    Coplanar,
    /// The line from the point where the axes of `points[0]` and
    /// `points[1]` meet to `points[2]` lies in the plane of the two axes
    /// (two turns about meeting axes: the two roots meet).
    InAxesPlane,
}

/// One step's factor at a configuration.
#[derive(Debug, Clone, PartialEq)]
pub struct Factor {
    /// The step's index in its plan.
    pub step: usize,
    /// The joint the step solves.
    pub joint: usize,
    /// What vanishes.
    pub condition: Condition,
    /// The joint points involved (see [`Condition`]).
    pub points: [LinkPoint; 3],
    /// The factor, in [0, 1]: 0 on the singularity.
    pub value: f64,
}

impl Factor {
    /// The factor in words, with the model's names and, in brackets, any
    /// named point at the same place in `poses` (for example
    /// `R11 (B1), R12 (C1), R13 (B2) are collinear`).
    pub fn describe(&self, model: &Model, poses: &[Pose3]) -> String {
        let [a, b, c] = self.points.map(|p| point_name(model, poses, p));
        let j = &model.joints[self.joint].name;
        let moved = |surface: String| format!("the path of {b} moved by {a} touches {surface}");
        match self.condition {
            Condition::TouchesSphere => moved(format!("the sphere about {c}")),
            Condition::TouchesPlane => moved(format!("the plane through {c}")),
            Condition::TouchesCylinder => moved(format!("the cylinder about {c}'s axis")),
            Condition::TouchesSliderPlane => moved(format!("the plane {c} slides in")),
            Condition::TouchesCircle => moved(format!("the circle about the pin {c}")),
            Condition::OnAxis => format!("{b} lies on the axis of {j}"),
            Condition::AxisParallel => format!("the axis of {b} or {c} is parallel to {j}'s"),
            Condition::PlaneTouches => format!("the plane of {b} turned by {j} only touches {c}"),
            Condition::Collinear => format!("{a}, {b}, {c} are collinear"),
            Condition::NormalToGuide => format!("{a}{b} is normal to the guide of {c}"),
            Condition::SlideAlongLine => format!("{j} slides along the line {b} must meet ({c})"),
            Condition::Coplanar => format!("the axes of {a}, {b}, {c} lie in one plane"),
            Condition::InAxesPlane => format!("{c} lies in the plane of the axes of {a} and {b}"),
        }
    }
}

/// A point's name: a joint's or a named point's, with any other named point
/// at the same place in `poses` in brackets (`R12 (C1)`).
pub fn point_name(model: &Model, poses: &[Pose3], p: LinkPoint) -> String {
    let (name, at) = match p.point {
        PointRef::Named(n) => (model.points[n].name.clone(), model.points[n].at),
        PointRef::Joint(j) => {
            let joint = &model.joints[j];
            // A slide's point is its slider point, whichever link names it.
            let side = if joint.kind == JointType::P {
                joint.point_side()
            } else {
                joint.links.iter().position(|&l| l == p.link).unwrap_or(0)
            };
            return named_as(
                model,
                poses,
                joint.name.clone(),
                joint.links[side],
                joint.places[side].at(),
            );
        }
    };
    named_as(model, poses, name, p.link, at)
}

fn named_as(model: &Model, poses: &[Pose3], name: String, link: usize, at: [f64; 3]) -> String {
    let world = |link: usize, at: [f64; 3]| poses[link].transform_point(&Point3::from(v3(at))).coords;
    let here = world(link, at);
    let tolerance = 1e-9 * crate::kinematics::model_scale(model);
    let aliases: Vec<&str> = model
        .points
        .iter()
        .filter(|q| q.name != name && (world(q.link, q.at) - here).norm() <= tolerance)
        .map(|q| q.name.as_str())
        .collect();
    if aliases.is_empty() {
        name
    } else {
        format!("{name} ({})", aliases.join(", "))
    }
}

use crate::plan::v3;

/// |cos| of the angle between `t` and `n`: 0 when either is (relatively) zero.
pub(crate) fn crossing(t: Vector3<f64>, n: Vector3<f64>, scale: f64) -> f64 {
    let (a, b) = (t.norm(), n.norm());
    if a <= 1e-12 * scale || b <= 1e-12 * scale {
        return 0.0;
    }
    (t.dot(&n) / (a * b)).abs().min(1.0)
}

/// |sin| of the angle between `a` and `b`: 0 when either is zero.
pub(crate) fn sine(a: Vector3<f64>, b: Vector3<f64>) -> f64 {
    let (x, y) = (a.norm(), b.norm());
    if x == 0.0 || y == 0.0 {
        return 0.0;
    }
    (a.cross(&b).norm() / (x * y)).min(1.0)
}

pub(crate) fn joint_point(joint: usize, link: usize) -> LinkPoint {
    LinkPoint {
        link,
        point: PointRef::Joint(joint),
    }
}

/// One configuration of a model as the factors measure it: the steps' own
/// geometry and pose algebra (the factors differentiate what they solve),
/// the link poses as frames, and the model's size.
pub(crate) struct Configuration {
    pub(crate) g: Geometry<f64>,
    pub(crate) frames: Vec<Frame<f64>>,
    pub(crate) scale: f64,
}

impl Configuration {
    fn of(model: &Model, poses: &[Pose3]) -> Self {
        Configuration {
            g: Geometry::of(model),
            frames: poses.iter().map(plan::frame_of).collect(),
            scale: crate::kinematics::model_scale(model),
        }
    }

    /// A point of a link in the world.
    pub(crate) fn world(&self, link: usize, point: PointRef) -> Vector3<f64> {
        v3(self.frames[link].apply(self.g.local(point, link)))
    }

    /// An anchored point in the world, and the link point it names.
    pub(crate) fn anchored(&self, a: &plan::Anchor) -> (Vector3<f64>, LinkPoint) {
        let (_, last) = self.g.across(self.frames[a.link], a.link, &a.hops);
        (
            v3(self.g.anchor(&self.frames, a)),
            LinkPoint {
                link: last,
                point: a.point,
            },
        )
    }

    /// The moving point in the world and its velocity per unit joint rate.
    pub(crate) fn path(&self, joint: usize, from: usize, to: usize, point: PointRef) -> (Vector3<f64>, Vector3<f64>) {
        let j = &self.g.joints[joint];
        let forward = j.links[0] == from;
        let p = self.world(to, point);
        let t = match j.motion(&self.frames[from], forward, self.g.local(point, to)) {
            Motion::Circle { centre, axis, .. } => v3(axis).cross(&(p - v3(centre))),
            Motion::Line { along, .. } => v3(along) * self.scale,
        };
        (p, t)
    }
}

/// The factor of every solving step of a spatial plan at the link poses
/// `poses` (from any solution: a branch of the plan, or of another plan of
/// the same model). Steps that only place a link from given values (inputs
/// or a pose) have none; each other step kind's factor is its `factor`, in
/// its file in [`crate::steps`].
pub fn spatial_factors(model: &Model, plan: &plan::Plan, poses: &[Pose3]) -> Vec<Factor> {
    let at = Configuration::of(model, poses);
    plan.steps
        .iter()
        .enumerate()
        .filter_map(|(k, step)| crate::steps::factor(&at, k, step))
        .collect()
}
