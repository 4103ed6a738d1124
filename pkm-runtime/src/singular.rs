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

use crate::model::{JointType, Model};
use crate::solution::PointRef;
use crate::spatial::{self, Constraint, Pose3, Step};
use crate::steps::{place_axis, Geometry, Motion};
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
    /// `points[1]` lies on the axis of the step's joint `points[0]`.
    OnAxis,
    /// The axis of `points[1]` (or of the target `points[2]`) is parallel to
    /// the turning axis of `points[0]`.
    AxisParallel,
    /// The plane of parallelogram `points[1]` touches `points[2]` as
    /// `points[0]` turns.
    PlaneTouches,
    /// `points[0]`, `points[1]`, `points[2]` are collinear (an RRR dyad).
    Collinear,
    /// `points[0]points[1]` is normal to the guide of `points[2]` (an RRP dyad).
    NormalToGuide,
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
            Condition::OnAxis => format!("{b} lies on the axis of {j}"),
            Condition::AxisParallel => format!("the axis of {b} or {c} is parallel to {j}'s"),
            Condition::PlaneTouches => format!("the plane of {b} turned by {j} only touches {c}"),
            Condition::Collinear => format!("{a}, {b}, {c} are collinear"),
            Condition::NormalToGuide => format!("{a}{b} is normal to the guide of {c}"),
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

fn v3(a: [f64; 3]) -> Vector3<f64> {
    Vector3::new(a[0], a[1], a[2])
}

/// |cos| of the angle between `t` and `n`: 0 when either is (relatively) zero.
fn crossing(t: Vector3<f64>, n: Vector3<f64>, scale: f64) -> f64 {
    let (a, b) = (t.norm(), n.norm());
    if a <= 1e-12 * scale || b <= 1e-12 * scale {
        return 0.0;
    }
    (t.dot(&n) / (a * b)).abs().min(1.0)
}

/// |sin| of the angle between `a` and `b`: 0 when either is zero.
fn sine(a: Vector3<f64>, b: Vector3<f64>) -> f64 {
    let (x, y) = (a.norm(), b.norm());
    if x == 0.0 || y == 0.0 {
        return 0.0;
    }
    (a.cross(&b).norm() / (x * y)).min(1.0)
}

fn joint_point(joint: usize, link: usize) -> LinkPoint {
    LinkPoint {
        link,
        point: PointRef::Joint(joint),
    }
}

/// The factor of every solving step of a spatial plan at the link poses
/// `poses` (from any solution: a branch of the plan, or of another plan of
/// the same model). Steps that only place a link from given values (inputs
/// or a pose) have none.
pub fn spatial_factors(model: &Model, plan: &spatial::Plan, poses: &[Pose3]) -> Vec<Factor> {
    // The steps' own geometry and pose algebra: the factors differentiate what they solve.
    let g = Geometry::of(model);
    let frames: Vec<_> = poses.iter().map(spatial::frame_of).collect();
    let scale = crate::kinematics::model_scale(model);
    let mut out = Vec::new();
    for (k, step) in plan.steps.iter().enumerate() {
        let world = |link: usize, point: PointRef| v3(frames[link].apply(g.local(point, link)));
        let anchored = |a: &spatial::Anchor| {
            let (_, last) = g.across(frames[a.link], a.link, &a.hops);
            (
                v3(g.anchor(&frames, a)),
                LinkPoint {
                    link: last,
                    point: a.point,
                },
            )
        };
        // The moving point's velocity per unit joint rate.
        let path = |joint: usize, from: usize, to: usize, point: PointRef| {
            let j = &g.joints[joint];
            let forward = j.links[0] == from;
            let p = world(to, point);
            let t = match j.motion(&frames[from], forward, g.local(point, to)) {
                Motion::Circle { centre, axis, .. } => v3(axis).cross(&(p - v3(centre))),
                Motion::Line { along, .. } => v3(along) * scale,
            };
            (p, t)
        };
        let factor = match step {
            Step::Place { .. } | Step::Transfer { .. } => continue,
            Step::Locus {
                joint,
                from,
                to,
                point,
                constraint,
                ..
            } => {
                let (p, t) = path(*joint, *from, *to, *point);
                let (n, condition, other) = match constraint {
                    Constraint::Sphere { centre, .. } => {
                        let (c, at) = anchored(centre);
                        (p - c, Condition::TouchesSphere, at)
                    }
                    Constraint::Plane { normal, anchor } => {
                        let n = g.direction(frames[normal.link], normal.link, normal);
                        (v3(n), Condition::TouchesPlane, anchored(anchor).1)
                    }
                    Constraint::Cylinder { joint: h, link, .. } => {
                        let jh = &g.joints[*h];
                        let side = usize::from(jh.links[0] != *link);
                        let c = v3(frames[*link].apply(jh.places[side].at()));
                        let w = v3(frames[*link].rotate(place_axis(&jh.places[side]))).normalize();
                        let d = p - c;
                        (d - w * w.dot(&d), Condition::TouchesCylinder, joint_point(*h, *link))
                    }
                    Constraint::Slider { joint: h, link, .. } => {
                        let jh = &g.joints[*h];
                        let side = usize::from(jh.links[0] != *link);
                        let along = v3(frames[*link].rotate(place_axis(&jh.places[side])));
                        let j = &g.joints[*joint];
                        let axis = match j.motion(&frames[*from], j.links[0] == *from, [0.0; 3]) {
                            Motion::Circle { axis, .. } => v3(axis),
                            Motion::Line { along, .. } => v3(along),
                        };
                        (
                            axis.cross(&along),
                            Condition::TouchesSliderPlane,
                            joint_point(*h, *link),
                        )
                    }
                };
                Factor {
                    step: k,
                    joint: *joint,
                    condition,
                    points: [
                        joint_point(*joint, *from),
                        LinkPoint {
                            link: *to,
                            point: *point,
                        },
                        other,
                    ],
                    value: crossing(t, n, scale),
                }
            }
            Step::Aim {
                joint,
                from,
                to,
                point,
                target,
            } => {
                let (_, t) = path(*joint, *from, *to, *point);
                Factor {
                    step: k,
                    joint: *joint,
                    condition: Condition::OnAxis,
                    points: [
                        joint_point(*joint, *from),
                        LinkPoint {
                            link: *to,
                            point: *point,
                        },
                        anchored(target).1,
                    ],
                    // The point's distance from the axis, in units of the size.
                    value: (t.norm() / scale).min(1.0),
                }
            }
            Step::Align {
                joint,
                from,
                to,
                group,
                target,
            } => {
                let j = &g.joints[*joint];
                let k_axis = j.turning_axis(&frames[*from], j.links[0] == *from).unwrap_or([0.0; 3]);
                let d = g.direction(frames[*to], *to, group);
                let w = g.direction(frames[target.link], target.link, target);
                let (_, group_link) = g.across(frames[*to], *to, &group.hops);
                let (_, target_link) = g.across(frames[target.link], target.link, &target.hops);
                Factor {
                    step: k,
                    joint: *joint,
                    condition: Condition::AxisParallel,
                    points: [
                        joint_point(*joint, *from),
                        joint_point(group.joint, group_link),
                        joint_point(target.joint, target_link),
                    ],
                    value: sine(v3(k_axis), v3(d)).min(sine(v3(k_axis), v3(w))),
                }
            }
            Step::PaPlane {
                joint,
                from,
                to,
                pa,
                target,
            } => {
                let j = &g.joints[*joint];
                let k_axis = v3(j.turning_axis(&frames[*from], j.links[0] == *from).unwrap_or([0.0; 3]));
                let p = &g.joints[*pa];
                let side = usize::from(p.links[0] != *to);
                let n = v3(frames[*to].rotate(place_axis(&p.places[side])));
                let hinge = v3(frames[*to].apply(p.places[side].at()));
                let (c, at) = anchored(target);
                // d/dθ (n·u) = (k × n)·u: the plane's normal turning against the target's direction.
                Factor {
                    step: k,
                    joint: *joint,
                    condition: Condition::PlaneTouches,
                    points: [joint_point(*joint, *from), joint_point(*pa, *to), at],
                    value: crossing(k_axis.cross(&n), c - hinge, scale),
                }
            }
        };
        out.push(factor);
    }
    out
}
