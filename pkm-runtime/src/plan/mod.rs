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
//! * a parallelogram's plane must contain a known point ([`Step::PaPlane`]);
//! * a line of the new link must pass through a known point ([`Step::Guide`]);
//!   a line along the turning axis, seen along it, is an aim ([`Step::AimAlong`]);
//! * a point beyond a joint whose value is given, carried rigidly at that
//!   value, lies on a cylinder ([`Step::Beyond`]);
//! * a slide brings a point onto a line, neither turning ([`Step::SlideToLine`]).
//! * an axis of the new link must keep its angle from a known axis that
//!   meets it and the turning axis at one centre ([`Step::Cone`]).
//! * a link ending in spherical joints at both ends, whose two centres are
//!   known, is placed between them, its idle spin by a convention
//!   ([`Step::Rod`]).
//! * the plane a revolute of the new link and a slide beyond it sweep must
//!   contain a known point ([`Step::PlaneThrough`]: a U's first half in a
//!   leg whose two ends are known).
//! * two revolutes in series, their axes meeting at a point, must carry a
//!   point of the link beyond the second to a known position
//!   ([`Step::TwoTurns`]: IK-Geo's subproblem 2, a U's first half when the
//!   link beyond it reaches a known point).
//!
//! The constraints come from the rest of the mechanism through "anchors":
//! chains of joints at value 0 that provably do not move the anchored point
//! (the point is on their axes) or its coordinate along one direction
//! (rotations about parallel axes, translations normal to it). The steps
//! themselves are [`crate::steps`]: the interpreter (`run.rs`) runs them at `f64`, and
//! generated code is their trace.

use crate::model::{JointType, Model};
use crate::primitives::Sign;
use crate::solution::{PointRef, SolveError};
use nalgebra::{Isometry3, Point3, Vector3};
use std::borrow::Cow;

mod listing;
pub use listing::Listing;
mod run;
pub use run::{frame_of, local_point, output_values, pose_of, run, run_all, Prepared, Solution};

/// A link's pose in the world.
pub type Pose3 = Isometry3<f64>;

/// An array as a nalgebra vector.
pub(crate) fn v3(a: [f64; 3]) -> Vector3<f64> {
    Vector3::new(a[0], a[1], a[2])
}

/// A world point: `local` on a link at `pose`.
#[inline]
pub fn at(pose: &Pose3, local: [f64; 3]) -> [f64; 3] {
    let p = pose.transform_point(&Point3::from(v3(local)));
    [p.x, p.y, p.z]
}

/// The angle a pose is turned about unit `k` from the base's orientation.
pub fn angle_about(pose: &Pose3, k: [f64; 3]) -> f64 {
    crate::steps::place::angle_about(&frame_of(pose), k)
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

/// What fixes a sphere's radius ([`Constraint::Sphere`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Radius {
    /// The length of parallelogram `0`'s arm.
    Arm(usize),
    /// The distance of `point` of `link` from the centre of `link`'s
    /// spherical joint `joint`: a rigid link keeps it (an S–S link's
    /// length, an R–S or U–S link's point on the revolute's axis).
    Rod {
        /// The link.
        link: usize,
        /// The point whose distance is kept (another joint's place).
        point: PointRef,
        /// The spherical joint.
        joint: usize,
    },
}

/// What the rest of the mechanism says about a point of the new link.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Constraint {
    /// At the distance `radius` fixes from the anchored point.
    Sphere {
        /// The centre.
        centre: Anchor,
        /// The parallelogram's arm, or the S–S link, that fixes the radius.
        radius: Radius,
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
    /// At a fixed distance from the pin of `link`, a link a point output
    /// pins at its point `pin` (its turn unknown): the distance the point,
    /// carried across `hops` to `link`, keeps from the pin there, in the
    /// plane (a circle) or in space (a sphere, `sphere`)
    /// ([`crate::steps::locus::pin`]).
    Pin {
        /// From the new link to the pinned link.
        hops: Hops,
        /// The pinned link.
        link: usize,
        /// Its pin: the output's point.
        pin: PointRef,
        /// A spatial mechanism's sphere about the pin, not a planar circle.
        sphere: bool,
    },
}

/// A point of a link held on a sphere ([`Step::Trilaterate`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OnSphere {
    /// The point.
    pub point: crate::solution::PointRef,
    /// The sphere's centre.
    pub centre: Anchor,
    /// What fixes its radius.
    pub radius: Span,
}

/// The radius of a sphere a point is held on ([`OnSphere`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Span {
    /// A length no joint changes: a rod's, a parallelogram's arm.
    Rigid(Radius),
    /// Across a driven slide (a U-P-U leg): the distance of `point`, on
    /// the link across `slide` from `link`, carried across at the slide's
    /// given value (input `input`), from the centre of `joint` on `link`.
    Slid {
        /// The link with the centre.
        link: usize,
        /// The spherical (or U) joint whose place is the centre.
        joint: usize,
        /// The driven slide.
        slide: usize,
        /// Its input.
        input: usize,
        /// The point on the link across the slide.
        point: crate::solution::PointRef,
    },
}

/// How a placed link is turned.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Turn {
    /// Not at all: it keeps the base's orientation (a translating link).
    Fixed,
    /// By the given value after the position, an angle about this world axis.
    About([f64; 3]),
    /// By the three angles given after the position, `[rx, ry, rz]` of
    /// `R = R_z(rz)·R_y(ry)·R_x(rx)` ([`crate::steps::place::PoseParts`]).
    Angles,
    /// Unknown: only the point is given (a point output). The link is
    /// pinned there, not known: a later step turns it, and the solution is
    /// verified to keep the point where it was given.
    Free,
}

/// What a solution is verified by once the steps are done
/// ([`Plan::checks`]); each gives [`crate::steps::RESIDUAL_ROWS`] rows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Check {
    /// A joint no step solves: it must close.
    Joint(usize),
    /// The place step at this index pinned a link by a point: the point
    /// must still be where it was given.
    Pin(usize),
}

impl Check {
    /// What the check is about, for errors: `joint R3`, `the output point of link coupler`.
    pub fn owner(&self, plan: &Plan, joint: impl Fn(usize) -> String, link: impl Fn(usize) -> String) -> String {
        match *self {
            Check::Joint(j) => format!("joint {}", joint(j)),
            Check::Pin(k) => match plan.steps.get(k) {
                Some(Step::Place { link: l, .. }) => format!("the output point of link {}", link(*l)),
                _ => format!("step {k}"),
            },
        }
    }
}

/// One step of a spatial plan.
#[derive(Debug, Clone, PartialEq)]
pub enum Step {
    /// A link placed by an output: its point at the given position
    /// (`inputs[input..]`: x, y, and z unless `planar`), turned as `turn` says.
    Place {
        /// The link.
        link: usize,
        /// The point whose position is given.
        point: PointRef,
        /// Index of x in the inputs.
        input: usize,
        /// Only x and y are given (z is the point's own, as every link of a
        /// planar mechanism moves in its plane).
        planar: bool,
        /// How the link is turned.
        turn: Turn,
    },
    /// A link given in part by an output ([`crate::steps::place::PoseParts`]
    /// leaving some of its six values to the mechanism), the rest from the
    /// planes its limbs hold its points on ([`crate::steps::parasitic`]).
    Parasitic {
        /// The link.
        link: usize,
        /// The point whose position is given (in part).
        point: PointRef,
        /// Index of the first given value in the inputs.
        input: usize,
        /// Which of x, y, z, rx, ry, rz are given.
        parts: crate::steps::place::PoseParts,
        /// One limb per free part.
        limbs: Vec<crate::steps::parasitic::Limb>,
        /// This step's index in the sign vector (`None`: one root, no free angle).
        branch: Option<usize>,
    },
    /// A translating link (it keeps the base's orientation: its POC set
    /// has no rotation) placed by three of its points, each held on a
    /// sphere about a known point ([`crate::steps::trilaterate`]): three
    /// spheres meeting, two roots.
    Trilaterate {
        /// The link.
        link: usize,
        /// Its three points, each with its sphere.
        spheres: Vec<OnSphere>,
        /// This step's index in the sign vector.
        branch: usize,
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
    /// A revolute's angle that puts the line `point` travels on (`point` on
    /// the link across prismatic `slide` from `to`, the slide along the
    /// turning axis) through the anchored position: seen along the axis,
    /// an aim ([`crate::steps::aim_along`]). One root.
    AimAlong {
        /// The revolute.
        joint: usize,
        /// Known link.
        from: usize,
        /// New link.
        to: usize,
        /// The prismatic along the turning axis.
        slide: usize,
        /// The point on the link beyond the slide.
        point: PointRef,
        /// Where it is known.
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
    /// `to`) through the anchored point (the other hinge): two roots half a
    /// turn apart where the parallelogram's axis is normal to the
    /// revolute's, two postures of the leg ([`crate::steps::pa_plane`]).
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
        /// This step's index in the sign vector (it always branches),
        /// numbered after every other step's, so that the postures plans
        /// listed before it branched keep their numbers.
        branch: usize,
    },
    /// A revolute's angle that puts the line `point` travels on, seen from
    /// `to` (`point` is on the link across prismatic `slide` from `to`, or
    /// from the link `carried` makes one body with `to`), through the
    /// anchored position (the same point, known).
    Guide {
        /// The revolute.
        joint: usize,
        /// Known link.
        from: usize,
        /// New link.
        to: usize,
        /// A joint of `to` whose value is given, `(joint, input)` (a
        /// revolute about the turning axis, or a slide): the slide is on
        /// the link across it, carried at that value (`None`: the slide is
        /// `to`'s own).
        carried: Option<(usize, usize)>,
        /// The prismatic joint whose slide the line is.
        slide: usize,
        /// The point on the link beyond the slide.
        point: PointRef,
        /// Where it is known.
        target: Anchor,
        /// This step's index in the sign vector (it always branches).
        branch: usize,
    },
    /// A revolute's angle that turns the axis of revolute `across` (on
    /// `to`) to the angle the link beyond it keeps from the axis of
    /// `target.joint`, known: three axes through one centre (a spherical
    /// RRR dyad), a cone against a circle.
    Cone {
        /// The revolute.
        joint: usize,
        /// Known link.
        from: usize,
        /// New link.
        to: usize,
        /// The revolute of `to` whose axis is turned.
        across: usize,
        /// The known axis: a revolute of the link beyond `across`, on a known link.
        target: Direction,
        /// This step's index in the sign vector (it always branches).
        branch: usize,
    },
    /// A revolute's (or, in a planar mechanism, a slide's) value that puts
    /// `point`, on the link across the joint `given` (whose value is input
    /// `input`) from `to`, on `constraint` (a cylinder; for a turn a
    /// slider's plane, for a slide a slider's line): with the value given
    /// the two links move as one body.
    Beyond {
        /// The revolute or prismatic.
        joint: usize,
        /// Known link.
        from: usize,
        /// New link.
        to: usize,
        /// The joint of `to` whose value is given.
        given: usize,
        /// Index into the inputs.
        input: usize,
        /// The point on the link across `given`.
        point: PointRef,
        /// Where it must be (hops from the link across `given`).
        constraint: Constraint,
        /// This step's index in the sign vector (`None`: one root, a slide
        /// onto a slider's line).
        branch: Option<usize>,
    },
    /// A prismatic's slide that brings a point and the line of prismatic
    /// `slide` together (`meet`: which of the two the new link carries).
    SlideToLine {
        /// The prismatic.
        joint: usize,
        /// Known link.
        from: usize,
        /// New link.
        to: usize,
        /// The prismatic whose line it is.
        slide: usize,
        /// The point: on the link beyond `slide` from `to`, or on `to`.
        point: PointRef,
        /// Which of the point and the line `to` carries, and where the other is known.
        meet: crate::steps::slide_to_line::Meet,
    },
    /// A link whose only joints are two spherical ones, `joint` (on known
    /// link `from`) and `other` (whose centre `target` anchors), placed
    /// between the two known centres; its spin about the line between them
    /// is idle, and is fixed by the convention of
    /// [`crate::steps::rod::carry_line`] (the smallest turn from
    /// the world's axes that carries the link's drawn S–S line onto the
    /// centres' line).
    Rod {
        /// The spherical joint on the known link.
        joint: usize,
        /// Known link.
        from: usize,
        /// The S–S link.
        to: usize,
        /// Its other spherical joint.
        other: usize,
        /// That joint's centre, known.
        target: Anchor,
    },
    /// A revolute's angle that turns the plane normal to the axis of
    /// revolute `across` (on `to`) through the line of prismatic `slide`
    /// (of the link beyond `across`) until it contains the anchored
    /// position of `point` (on the link beyond `slide`).
    PlaneThrough {
        /// The revolute.
        joint: usize,
        /// Known link.
        from: usize,
        /// New link.
        to: usize,
        /// The revolute of `to` whose axis is the plane's normal.
        across: usize,
        /// The prismatic beyond it, normal to that axis.
        slide: usize,
        /// The point on the link beyond the slide.
        point: PointRef,
        /// Where it is known.
        target: Anchor,
        /// This step's index in the sign vector (`None`: the plane passes
        /// through the turning axis, its two roots are one plane).
        branch: Option<usize>,
    },
    /// A revolute's angle that turns the new link until the revolute
    /// `across` of it, whose axis meets the turning axis at `across`'s
    /// place, can turn the link beyond onto the anchored position of
    /// `point` (on that link): the first angle of IK-Geo's subproblem 2
    /// ([`crate::steps::two_turns`]); the second is the aim that follows.
    TwoTurns {
        /// The revolute.
        joint: usize,
        /// Known link.
        from: usize,
        /// New link.
        to: usize,
        /// The second revolute, of `to`.
        across: usize,
        /// The point on the link beyond `across`.
        point: PointRef,
        /// Where it is known.
        target: Anchor,
        /// This step's index in the sign vector (it always branches).
        branch: usize,
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
    /// Open joints whose closure is checked by the miss of the aim that
    /// left them open ([`crate::steps::aim::miss`]), not by the aimed
    /// link's pose ([`Plan::check_by_miss`]): where nothing else reads that
    /// pose, solving for the outputs alone skips the aim's turn.
    pub by_miss: Vec<ByMiss>,
}

/// An open joint checked by a miss ([`Plan::by_miss`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ByMiss {
    /// The open joint.
    pub joint: usize,
    /// The aim that left it open.
    pub aim: usize,
    /// The parallelogram plane that turned the aim's known link, where the
    /// two together carry the aim's point over a whole sphere and nothing
    /// else reads that link either: the sphere's miss checks the joint
    /// ([`crate::steps::pa_plane::sphere_miss`]) and both turns are skipped.
    pub plane: Option<usize>,
    /// Whether nothing else reads the aimed link (nor the plane's): solving
    /// for the results skips the turns. Otherwise the miss still checks
    /// the joint, and the turn is computed where what reads it needs it.
    pub skipped: bool,
}

impl Step {
    /// Whether the step reads `link`'s pose: as its known link or where an
    /// anchor, direction or constraint starts.
    pub fn reads(&self, link: usize) -> bool {
        match self {
            Step::Place { .. } => false,
            Step::Trilaterate { spheres, .. } => spheres.iter().any(|s| s.centre.link == link),
            Step::Parasitic { limbs, .. } => limbs
                .iter()
                .any(|l| l.normal.link == link || l.anchor.link == link || l.known == Some(link)),
            Step::Transfer { from, .. } => *from == link,
            Step::Aim { from, target, .. }
            | Step::PaPlane { from, target, .. }
            | Step::Guide { from, target, .. }
            | Step::AimAlong { from, target, .. }
            | Step::PlaneThrough { from, target, .. }
            | Step::TwoTurns { from, target, .. }
            | Step::Rod { from, target, .. } => *from == link || target.link == link,
            Step::Align {
                from, group, target, ..
            } => *from == link || group.link == link || target.link == link,
            Step::Cone { from, target, .. } => *from == link || target.link == link,
            Step::Locus { from, constraint, .. } | Step::Beyond { from, constraint, .. } => {
                *from == link
                    || match constraint {
                        Constraint::Sphere { centre, .. } => centre.link == link,
                        Constraint::Plane { normal, anchor } => normal.link == link || anchor.link == link,
                        Constraint::Cylinder { link: l, .. }
                        | Constraint::Slider { link: l, .. }
                        | Constraint::Pin { link: l, .. } => *l == link,
                    }
            }
            Step::SlideToLine { from, meet, .. } => {
                use crate::steps::slide_to_line::Meet;
                *from == link
                    || match meet {
                        Meet::Through(target) => target.link == link,
                        Meet::Onto { link: l, .. } => *l == link,
                    }
            }
        }
    }

    /// The joints of the loop the step closes, for errors: the joint it
    /// solves, then those its constraint reaches through, in order, each once.
    pub fn loop_joints(&self) -> Vec<usize> {
        let mut out: Vec<usize> = self.joint().into_iter().collect();
        let mut add = |j: usize| {
            if !out.contains(&j) {
                out.push(j);
            }
        };
        let hops = |h: &Hops| h.iter().map(|h| h.joint).collect::<Vec<_>>();
        match self {
            Step::Place { .. } | Step::Transfer { .. } => {}
            Step::Parasitic { limbs, .. } => {
                for l in limbs {
                    hops(&l.anchor.hops).into_iter().rev().for_each(&mut add);
                }
            }
            Step::Trilaterate { spheres, .. } => {
                for s in spheres {
                    hops(&s.centre.hops).into_iter().rev().for_each(&mut add);
                }
            }
            Step::Aim { target, .. } => hops(&target.hops).into_iter().rev().for_each(&mut add),
            Step::Align { group, target, .. } => {
                hops(&group.hops).into_iter().for_each(&mut add);
                add(group.joint);
                hops(&target.hops).into_iter().rev().for_each(&mut add);
                add(target.joint);
            }
            Step::PaPlane { pa, target, .. } => {
                add(*pa);
                hops(&target.hops).into_iter().rev().for_each(&mut add);
            }
            Step::Guide {
                slide, target, carried, ..
            } => {
                if let Some((given, _)) = carried {
                    add(*given);
                }
                add(*slide);
                hops(&target.hops).into_iter().rev().for_each(&mut add);
            }
            Step::AimAlong { slide, target, .. } => {
                add(*slide);
                hops(&target.hops).into_iter().rev().for_each(&mut add);
            }
            Step::Cone { across, target, .. } => {
                add(*across);
                hops(&target.hops).into_iter().rev().for_each(&mut add);
                add(target.joint);
            }
            Step::Rod { other, target, .. } => {
                add(*other);
                hops(&target.hops).into_iter().rev().for_each(&mut add);
            }
            Step::TwoTurns { across, target, .. } => {
                add(*across);
                hops(&target.hops).into_iter().rev().for_each(&mut add);
            }
            Step::PlaneThrough {
                across, slide, target, ..
            } => {
                add(*across);
                add(*slide);
                hops(&target.hops).into_iter().rev().for_each(&mut add);
            }
            Step::Beyond { given, constraint, .. } => {
                add(*given);
                if let Constraint::Cylinder { hops: h, joint, .. } | Constraint::Slider { hops: h, joint, .. } =
                    constraint
                {
                    hops(h).into_iter().for_each(&mut add);
                    add(*joint);
                }
            }
            Step::SlideToLine { slide, meet, .. } => {
                use crate::steps::slide_to_line::Meet;
                match meet {
                    Meet::Through(target) => {
                        add(*slide);
                        hops(&target.hops).into_iter().rev().for_each(&mut add);
                    }
                    Meet::Onto { hops: h, .. } => {
                        hops(h).into_iter().for_each(&mut add);
                        add(*slide);
                    }
                }
            }
            Step::Locus { constraint, .. } => match constraint {
                Constraint::Sphere { centre, radius } => {
                    match *radius {
                        Radius::Arm(pa) => add(pa),
                        Radius::Rod { point, joint, .. } => {
                            if let PointRef::Joint(p) = point {
                                add(p);
                            }
                            add(joint);
                        }
                    }
                    hops(&centre.hops).into_iter().rev().for_each(&mut add);
                }
                Constraint::Plane { normal, anchor } => {
                    hops(&anchor.hops).into_iter().rev().for_each(&mut add);
                    add(normal.joint);
                }
                Constraint::Cylinder { hops: h, joint, .. } | Constraint::Slider { hops: h, joint, .. } => {
                    hops(h).into_iter().for_each(&mut add);
                    add(*joint);
                }
                Constraint::Pin { hops: h, .. } => hops(h).into_iter().for_each(&mut add),
            },
        }
        out
    }

    /// The step's index in the sign vector, where it chooses a root.
    pub fn branch(&self) -> Option<usize> {
        match self {
            Step::Locus { branch, .. }
            | Step::Parasitic { branch, .. }
            | Step::PlaneThrough { branch, .. }
            | Step::Beyond { branch, .. } => *branch,
            Step::Guide { branch, .. }
            | Step::Trilaterate { branch, .. }
            | Step::Cone { branch, .. }
            | Step::TwoTurns { branch, .. }
            | Step::PaPlane { branch, .. } => Some(*branch),
            Step::Place { .. }
            | Step::Transfer { .. }
            | Step::Aim { .. }
            | Step::AimAlong { .. }
            | Step::Align { .. }
            | Step::SlideToLine { .. }
            | Step::Rod { .. } => None,
        }
    }

    /// The joint this step solves (and so closes), if any.
    pub fn joint(&self) -> Option<usize> {
        self.solves().0.map(|(joint, _)| joint)
    }

    /// What the step solves: the joint it turns or slides with the known
    /// link it starts from (`None` for a step that places a link from the
    /// given values alone, `Place` and `Parasitic`), and the link it places.
    pub fn solves(&self) -> (Option<(usize, usize)>, usize) {
        match *self {
            Step::Place { link, .. } | Step::Parasitic { link, .. } | Step::Trilaterate { link, .. } => (None, link),
            Step::Transfer { joint, from, to, .. }
            | Step::Aim { joint, from, to, .. }
            | Step::Locus { joint, from, to, .. }
            | Step::Align { joint, from, to, .. }
            | Step::PaPlane { joint, from, to, .. }
            | Step::Guide { joint, from, to, .. }
            | Step::AimAlong { joint, from, to, .. }
            | Step::Beyond { joint, from, to, .. }
            | Step::SlideToLine { joint, from, to, .. }
            | Step::Cone { joint, from, to, .. }
            | Step::Rod { joint, from, to, .. }
            | Step::PlaneThrough { joint, from, to, .. }
            | Step::TwoTurns { joint, from, to, .. } => (Some((joint, from)), to),
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

    /// The postures of the assemblies the plan lists that it fixes by a
    /// convention rather than listing each (architecture.md, "Every
    /// assembly"), in words, by the joints' and links' names: an S–S
    /// link's idle spin ([`Step::Rod`]), a U-P leg's cross turned over
    /// ([`Step::PlaneThrough`] through the turning centre). Empty where
    /// every assembly is listed.
    pub fn conventions(&self, joint: impl Fn(usize) -> String, link: impl Fn(usize) -> String) -> Vec<String> {
        self.steps
            .iter()
            .filter_map(|s| match *s {
                Step::Rod {
                    joint: j, to, other, ..
                } => Some(format!(
                    "{}'s spin about the line through the centres of {} and {} is idle: one turn is listed, \
                     the smallest from its drawn orientation",
                    link(to),
                    joint(j),
                    joint(other)
                )),
                Step::PlaneThrough {
                    joint: j,
                    to,
                    branch: None,
                    ..
                } => Some(format!(
                    "{}, turned over about {}, reaches the same leg line with the leg turned half a turn \
                     about it (the same joint points and slide): one of the two is listed",
                    link(to),
                    joint(j)
                )),
                _ => None,
            })
            .collect()
    }

    /// How many ± choices the plan makes: it has 2^choices branches.
    pub fn choices(&self) -> usize {
        self.branches
    }

    /// The joints a forward plan takes its given values for, in their order
    /// (an inverse plan's given values are the outputs: the model's inputs).
    pub fn input_joints(&self, model: &Model) -> Vec<usize> {
        if self.inputs.len() == self.n_inputs {
            self.inputs.clone()
        } else {
            model.inputs()
        }
    }

    /// Every joint value of one branch, verified ([`run`]), in the model's
    /// layout ([`Solution::model_values`]: what the model's kinematics and
    /// velocity equations take).
    pub fn solve(&self, model: &Model, given: &[f64], signs: &[Sign]) -> Result<Vec<f64>, SolveError> {
        run(model, self, given, signs).map(|s| s.model_values(model))
    }

    /// Its steps' determinant factors at the link poses `poses`
    /// ([`crate::singular::spatial_factors`]).
    pub fn factors(&self, model: &Model, poses: &[Pose3]) -> Vec<crate::singular::Factor> {
        crate::singular::spatial_factors(model, self, poses)
    }

    /// Marks the open joints an aim leaves, whose closure its miss can check
    /// ([`Plan::by_miss`]): where the joint's closure is its centres alone
    /// once the turn is undone (a spherical joint, or a revolute whose axis the turn keeps:
    /// parallel to the aim's axis, as every axis of a planar mechanism is,
    /// or an aim that slides or swings a parallelogram). [`ByMiss::skipped`] where no later step, no other
    /// check and none of `needed` (the links whose poses the results read)
    /// reads the aimed link. Where a parallelogram plane turned the aim's
    /// known link and the two reach a whole sphere, both links unread, the
    /// sphere's miss checks the joint and both turns go.
    pub fn check_by_miss(&mut self, model: &Model, needed: &[bool]) {
        use crate::steps::{pa_plane, Geometry};
        let geometry = Geometry::of(model);
        let tol = 1e-9 * crate::kinematics::model_scale(model).max(1.0);
        let open = self.open_joints(model.joints.len());
        // Nothing but the steps `skip` from `after` on, no other open
        // joint's check and no result reads `link`.
        let unread = |link: usize, after: usize, skip: &[usize], o: usize| {
            !needed[link]
                && !self.steps[after..]
                    .iter()
                    .enumerate()
                    .any(|(i, s)| !skip.contains(&(after + i)) && s.reads(link))
                && !open.iter().any(|&j| j != o && model.joints[j].links.contains(&link))
        };
        let mut by_miss = Vec::new();
        for (k, step) in self.steps.iter().enumerate() {
            let Step::Aim {
                joint,
                from,
                to,
                point,
                target,
            } = step
            else {
                continue;
            };
            let [hop] = &target.hops[..] else { continue };
            let o = hop.joint;
            if *point != PointRef::Joint(o) {
                continue;
            }
            let skipped = unread(*to, k + 1, &[], o);
            let centres_only = |keeps_axis: bool| match model.joints[o].kind {
                JointType::S => true,
                JointType::R => keeps_axis,
                _ => false,
            };
            let plane = self.steps[..k]
                .iter()
                .position(|s| matches!(s, Step::PaPlane { to: t, pa, .. } if t == from && pa == joint));
            let plane = plane.filter(|&kp| {
                skipped
                    && unread(*from, kp + 1, &[k], o)
                    && pa_plane::reaches_sphere(&geometry, &self.steps[kp], step, tol).is_some_and(centres_only)
            });
            if plane.is_some() || centres_only(crate::steps::aim::keeps_axis(&geometry, step, o)) {
                by_miss.push(ByMiss {
                    joint: o,
                    aim: k,
                    plane,
                    skipped,
                });
            }
        }
        self.by_miss = by_miss;
    }

    /// The links whose poses nothing needs once the open joints of
    /// [`Plan::by_miss`] are checked by their misses (the aims' links, and
    /// the planes' that turned their known links): solving for the results
    /// skips them, so the checks' scale does not measure them ([`Plan::measured`]).
    pub fn unread_links(&self) -> Vec<usize> {
        let to = |k: usize| match self.steps[k] {
            Step::Aim { to, .. } | Step::PaPlane { to, .. } => Some(to),
            _ => None,
        };
        self.by_miss
            .iter()
            .filter(|b| b.skipped)
            .flat_map(|b| [Some(b.aim), b.plane])
            .flatten()
            .filter_map(to)
            .collect()
    }

    /// The link origins the scale of a solution's checks measures
    /// ([`crate::consistency::extent`]): those of the links the results
    /// need, not [`Plan::unread_links`].
    pub fn measured<T: Copy>(&self, origins: &[[T; 3]]) -> Vec<[T; 3]> {
        let unread = self.unread_links();
        origins
            .iter()
            .enumerate()
            .filter(|(l, _)| !unread.contains(l))
            .map(|(_, t)| *t)
            .collect()
    }

    /// What a solution is verified by after the last step: the joints no
    /// step closes, then the pinned links' points.
    pub fn checks(&self, n_joints: usize) -> Vec<Check> {
        let pins = self.steps.iter().enumerate().filter_map(|(k, s)| match s {
            Step::Place { turn: Turn::Free, .. } => Some(Check::Pin(k)),
            _ => None,
        });
        self.open_joints(n_joints)
            .into_iter()
            .map(Check::Joint)
            .chain(pins)
            .collect()
    }

    /// Which given values are angles: a pose's angle, a revolute's value.
    pub fn angular_inputs(&self, model: &Model) -> Vec<bool> {
        let mut angular = vec![false; self.n_inputs];
        for s in &self.steps {
            match s {
                Step::Place {
                    input,
                    planar,
                    turn: Turn::About(_),
                    ..
                } => angular[input + if *planar { 2 } else { 3 }] = true,
                Step::Place {
                    input,
                    turn: Turn::Angles,
                    ..
                } => angular[input + 3..input + 6].fill(true),
                Step::Parasitic { input, parts, .. } => {
                    for (i, part) in parts.given().enumerate() {
                        angular[input + i] = part >= 3;
                    }
                }
                Step::Transfer { joint, input, .. } => {
                    angular[*input] = matches!(model.joints[*joint].kind, JointType::R | JointType::Pa)
                }
                _ => {}
            }
        }
        angular
    }
}
