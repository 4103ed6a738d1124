//! A plan as text: one line per step, in the theory's words.
//!
//! ```text
//! forward plan: given R1; 1 ± choice, 2 branches
//!   0 Transfer     R1 places crank from base: given 0
//!   1 Locus        R2 places coupler from crank: R3 on the cylinder about R4 of base, carried to rocker, ± choice 0
//!   2 Aim          R4 places rocker from base: R3 onto R3 of coupler
//!   check R3, by the miss of step 2, its turns skipped where only the results are solved
//! ```
//!
//! A step solves the joint it names (none for a place step) and places the
//! link after "places"; what follows the colon is the condition it solves
//! for, and a step that picks one of two roots says which ± choice (its
//! index in the sign vector) picks it. The header says what the plan is
//! given, in input order (`given 0` is the first given value), and how many
//! branches it lists; the last lines are the checks run once the steps are
//! done ([`Plan::checks`]).

use super::{Anchor, Check, Constraint, Direction, Plan, Radius, Step, Turn};
use crate::model::{JointType, Model};
use crate::solution::PointRef;
use crate::steps::place::PoseParts;
use crate::steps::slide_to_line::Meet;
use std::collections::BTreeMap;
use std::fmt;

/// A plan written out with the names of a model's joints, links and points
/// ([`Plan::display`]).
pub struct Listing<'a> {
    plan: &'a Plan,
    model: &'a Model,
}

impl Plan {
    /// The plan as text, with `model`'s names (the model it was planned
    /// for): see [`Listing`].
    pub fn display<'a>(&'a self, model: &'a Model) -> Listing<'a> {
        Listing { plan: self, model }
    }

    /// Whether the plan solves forward (from the actuators' values) rather
    /// than inverse (from the outputs).
    pub fn is_forward(&self) -> bool {
        !self.inputs.is_empty()
    }
}

impl Listing<'_> {
    fn joint(&self, j: usize) -> &str {
        self.model.joints.get(j).map_or("?", |j| &j.name)
    }

    fn link(&self, l: usize) -> &str {
        self.model.links.get(l).map_or("?", String::as_str)
    }

    /// The link across joint `given` from `to` (`usize::MAX` where there is no such joint).
    fn across(&self, given: usize, to: usize) -> usize {
        self.model.joints.get(given).map_or(usize::MAX, |j| j.other(to))
    }

    fn point(&self, p: PointRef) -> &str {
        match p {
            PointRef::Joint(j) => self.joint(j),
            PointRef::Named(k) => self.model.points.get(k).map_or("?", |p| &p.name),
        }
    }

    /// ` through R3, R4` for joints crossed at value 0, nothing for none.
    fn through(&self, hops: &[super::Hop]) -> String {
        if hops.is_empty() {
            return String::new();
        }
        let names: Vec<&str> = hops.iter().map(|h| self.joint(h.joint)).collect();
        format!(" through {}", names.join(", "))
    }

    /// The link reached from `link` across `hops`.
    fn end(&self, link: usize, hops: &[super::Hop]) -> usize {
        hops.iter().fold(link, |_, h| {
            self.model
                .joints
                .get(h.joint)
                .map_or(usize::MAX, |j| j.links[usize::from(h.forward)])
        })
    }

    /// `R3 of coupler`, or `S1 known from platform through R6`: a point
    /// known on a known link, or carried to it across joints that do not
    /// move it.
    fn anchor(&self, a: &Anchor) -> String {
        // A joint's own place, across that joint alone: the same point on
        // both of its links.
        let own = matches!((a.point, &a.hops[..]), (PointRef::Joint(p), [h]) if h.joint == p);
        if a.hops.is_empty() || own {
            format!("{} of {}", self.point(a.point), self.link(a.link))
        } else {
            format!(
                "{} known from {}{}",
                self.point(a.point),
                self.link(a.link),
                self.through(&a.hops)
            )
        }
    }

    /// `S1 of platform` where a step's point is its target's own point,
    /// else `R3 at S1 of platform`.
    fn point_at(&self, point: PointRef, target: &Anchor) -> String {
        if target.point == point {
            self.anchor(target)
        } else {
            format!("{} at {}", self.point(point), self.anchor(target))
        }
    }

    /// `the axis of R2 of crank`, or `the axis of R13 known from base through P2`.
    fn direction(&self, d: &Direction) -> String {
        if d.hops.is_empty() {
            format!("the axis of {} of {}", self.joint(d.joint), self.link(d.link))
        } else {
            format!(
                "the axis of {} known from {}{}",
                self.joint(d.joint),
                self.link(d.link),
                self.through(&d.hops)
            )
        }
    }

    /// `, radius on rod` for a cylinder's or a slider plane's point carried
    /// from the new link `to` across `hops`: the link whose place of the
    /// joint sets the radius (or the offset).
    fn carried(&self, to: usize, hops: &[super::Hop]) -> String {
        if hops.is_empty() {
            String::new()
        } else {
            format!(", carried to {}", self.link(self.end(to, hops)))
        }
    }

    fn constraint(&self, to: usize, c: &Constraint) -> String {
        match c {
            Constraint::Sphere { centre, radius } => {
                let radius = match *radius {
                    Radius::Arm(pa) => format!("{}'s arm", self.joint(pa)),
                    Radius::Rod { link, point, joint } => {
                        format!("{}–{} on {}", self.joint(joint), self.point(point), self.link(link))
                    }
                };
                format!("the sphere about {} of radius {radius}", self.anchor(centre))
            }
            Constraint::Plane { normal, anchor } => {
                format!(
                    "the plane through {} normal to {}",
                    self.anchor(anchor),
                    self.direction(normal)
                )
            }
            Constraint::Cylinder { hops, joint, link } => format!(
                "the cylinder about {} of {}{}",
                self.joint(*joint),
                self.link(*link),
                self.carried(to, hops)
            ),
            Constraint::Slider { hops, joint, link } => format!(
                "the plane slider {} sweeps on {}{}",
                self.joint(*joint),
                self.link(*link),
                self.carried(to, hops)
            ),
            Constraint::Pin {
                hops,
                link,
                pin,
                sphere,
            } => format!(
                "the {} about {}'s pin {}{}",
                if *sphere { "sphere" } else { "circle" },
                self.link(*link),
                self.point(*pin),
                self.carried(to, hops)
            ),
        }
    }

    /// What step `s` reads of the given values, by input index: a place's
    /// coordinates and angles, a parasitic step's parts, a given joint.
    fn given(&self, s: &Step, out: &mut BTreeMap<usize, String>) {
        match *s {
            Step::Place {
                link,
                point,
                input,
                planar,
                turn,
            } => {
                let xyz = if planar { "x, y" } else { "x, y, z" };
                let turn = match turn {
                    Turn::About(k) => format!(" and its angle about {}", axis(k)),
                    Turn::Angles => " and its rx, ry, rz".into(),
                    Turn::Fixed | Turn::Free => String::new(),
                };
                out.insert(
                    input,
                    format!("{xyz} of {} at {}{turn}", self.link(link), self.point(point)),
                );
            }
            Step::Parasitic {
                link,
                point,
                input,
                parts,
                ..
            } => {
                let names: Vec<&str> = parts.given().map(|p| PoseParts::NAMES[p]).collect();
                out.insert(
                    input,
                    format!("{} of {} at {}", names.join(", "), self.link(link), self.point(point)),
                );
            }
            Step::Transfer { joint, input, .. } => {
                out.insert(input, self.joint(joint).to_string());
            }
            Step::Beyond { given, input, .. } => {
                out.insert(input, self.joint(given).to_string());
            }
            _ => {}
        }
    }

    /// What the step solves for, after the colon (empty for none).
    fn condition(&self, s: &Step) -> String {
        match s {
            Step::Place { point, input, turn, .. } => {
                let turn = match turn {
                    Turn::Fixed => "not turned".to_string(),
                    Turn::About(k) => format!("turned about {}", axis(*k)),
                    Turn::Angles => "turned by rx, ry, rz".to_string(),
                    Turn::Free => "pinned, turned by a later step".to_string(),
                };
                format!("{} at given {input}, {turn}", self.point(*point))
            }
            Step::Parasitic { parts, limbs, .. } => {
                let free: Vec<&str> = parts.free().map(|p| PoseParts::NAMES[p]).collect();
                let held: Vec<&str> = limbs.iter().map(|l| self.point(l.point)).collect();
                format!("{} free; {} held on planes", free.join(", "), held.join(", "))
            }
            Step::Trilaterate { spheres, link, .. } => {
                let held: Vec<String> = spheres
                    .iter()
                    .map(|s| match s.radius {
                        crate::plan::Span::Rigid(radius) => {
                            let c = crate::plan::Constraint::Sphere {
                                centre: s.centre.clone(),
                                radius,
                            };
                            format!("{} on {}", self.point(s.point), self.constraint(*link, &c))
                        }
                        crate::plan::Span::Slid { slide, input, .. } => format!(
                            "{} on the sphere about {} of radius across {} (given {input})",
                            self.point(s.point),
                            self.anchor(&s.centre),
                            self.joint(slide)
                        ),
                    })
                    .collect();
                format!("not turned; {}", held.join("; "))
            }
            Step::Transfer { input, .. } => format!("given {input}"),
            Step::Aim { point, target, .. } => format!("{} onto {}", self.point(*point), self.anchor(target)),
            Step::Locus {
                point, constraint, to, ..
            } => format!("{} on {}", self.point(*point), self.constraint(*to, constraint)),
            Step::Align { group, target, .. } => {
                format!("{} along {}", self.direction(group), self.direction(target))
            }
            Step::PaPlane { pa, target, .. } => {
                format!("the plane of {} through {}", self.joint(*pa), self.anchor(target))
            }
            Step::Guide {
                carried: Some((given, input)),
                slide,
                point,
                target,
                ..
            } => format!(
                "the line of {} carried across {} at given {input} through {}",
                self.joint(*slide),
                self.joint(*given),
                self.point_at(*point, target)
            ),
            Step::Guide {
                slide, point, target, ..
            }
            | Step::AimAlong {
                slide, point, target, ..
            }
            | Step::SlideToLine {
                slide,
                point,
                meet: Meet::Through(target),
                ..
            } => format!(
                "the line of {} through {}",
                self.joint(*slide),
                self.point_at(*point, target)
            ),
            Step::SlideToLine {
                slide,
                point,
                to,
                meet: Meet::Onto { hops, link },
                ..
            } => format!(
                "{}{} onto the line of {} on {}",
                self.point(*point),
                self.carried(*to, hops),
                self.joint(*slide),
                self.link(*link)
            ),
            Step::Cone { across, target, .. } => format!(
                "the axis of {} at its angle from {}",
                self.joint(*across),
                self.direction(target)
            ),
            Step::Beyond {
                joint,
                given,
                input,
                point,
                constraint: Constraint::Slider { hops, joint: h, link },
                to,
                ..
            } if self.model.joints.get(*joint).is_some_and(|j| j.kind == JointType::P) => {
                // A slide meets the slider's line, not the plane it sweeps.
                let beyond = self.across(*given, *to);
                format!(
                    "{} carried across {} at given {input}, on the line slider {} runs on {}{}",
                    self.point(*point),
                    self.joint(*given),
                    self.joint(*h),
                    self.link(*link),
                    self.carried(beyond, hops)
                )
            }
            Step::Beyond {
                given,
                input,
                point,
                constraint,
                to,
                ..
            } => {
                // The constraint's hops start from the link across `given`.
                let beyond = self.across(*given, *to);
                format!(
                    "{} carried across {} at given {input}, on {}",
                    self.point(*point),
                    self.joint(*given),
                    self.constraint(beyond, constraint)
                )
            }
            Step::Rod { other, target, .. } => format!(
                "{} at {}, its spin by convention",
                self.joint(*other),
                self.anchor(target)
            ),
            Step::PlaneThrough {
                across,
                slide,
                point,
                target,
                ..
            } => format!(
                "the plane normal to {} along {} through {}",
                self.joint(*across),
                self.joint(*slide),
                self.point_at(*point, target)
            ),
            Step::TwoTurns {
                across, point, target, ..
            } => format!(
                "with {}, {} onto {}",
                self.joint(*across),
                self.point(*point),
                self.anchor(target)
            ),
        }
    }
}

/// The step's variant name.
fn kind(s: &Step) -> &'static str {
    match s {
        Step::Place { .. } => "Place",
        Step::Parasitic { .. } => "Parasitic",
        Step::Trilaterate { .. } => "Trilaterate",
        Step::Transfer { .. } => "Transfer",
        Step::Aim { .. } => "Aim",
        Step::Locus { .. } => "Locus",
        Step::Align { .. } => "Align",
        Step::PaPlane { .. } => "PaPlane",
        Step::Guide { .. } => "Guide",
        Step::AimAlong { .. } => "AimAlong",
        Step::Cone { .. } => "Cone",
        Step::Beyond { .. } => "Beyond",
        Step::SlideToLine { .. } => "SlideToLine",
        Step::Rod { .. } => "Rod",
        Step::PlaneThrough { .. } => "PlaneThrough",
        Step::TwoTurns { .. } => "TwoTurns",
    }
}

/// A world axis: `z` for a coordinate axis, else its components.
fn axis(k: [f64; 3]) -> String {
    match k {
        [1.0, 0.0, 0.0] => "x".into(),
        [0.0, 1.0, 0.0] => "y".into(),
        [0.0, 0.0, 1.0] => "z".into(),
        [x, y, z] => format!("({x}, {y}, {z})"),
    }
}

impl fmt::Display for Listing<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let plan = self.plan;
        let mut given = BTreeMap::new();
        if plan.is_forward() {
            for (i, &j) in plan.inputs.iter().enumerate() {
                given.insert(i, self.joint(j).to_string());
            }
        } else {
            plan.steps.iter().for_each(|s| self.given(s, &mut given));
        }
        let given: Vec<String> = given.into_values().collect();
        let n = plan.branches;
        writeln!(
            f,
            "{} plan: given {}; {n} ± choice{}, {} branch{}",
            if plan.is_forward() { "forward" } else { "inverse" },
            given.join(", "),
            if n == 1 { "" } else { "s" },
            1usize << n,
            if n == 0 { "" } else { "es" },
        )?;
        for (k, s) in plan.steps.iter().enumerate() {
            write!(f, "{k:>3} {:<12} ", kind(s))?;
            if let Some(j) = s.joint() {
                write!(f, "{} ", self.joint(j))?;
            }
            write!(f, "places {}", self.link(s.solves().1))?;
            if let (Some((_, from)), _) = s.solves() {
                write!(f, " from {}", self.link(from))?;
            }
            write!(f, ": {}", self.condition(s))?;
            match s {
                Step::PlaneThrough { branch: None, .. } => write!(f, ", its other root by convention")?,
                _ => {
                    if let Some(b) = s.branch() {
                        write!(f, ", ± choice {b}")?;
                    }
                }
            }
            writeln!(f)?;
        }
        for check in plan.checks(self.model.joints.len()) {
            match check {
                Check::Joint(j) => {
                    write!(f, "  check {}", self.joint(j))?;
                    if let Some(b) = plan.by_miss.iter().find(|b| b.joint == j) {
                        match b.plane {
                            Some(p) => write!(f, ", by the sphere's miss of steps {p} and {}", b.aim)?,
                            None => write!(f, ", by the miss of step {}", b.aim)?,
                        }
                        if b.skipped {
                            write!(f, ", its turns skipped where only the results are solved")?;
                        }
                    }
                    writeln!(f)?;
                }
                Check::Pin(k) => writeln!(f, "  check the point step {k} pinned")?,
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::super::{ByMiss, Hop};
    use super::*;
    use crate::kinematics::tests::{four_bar, joint, model, z_axis};
    use crate::model::{JointType, NamedPoint};
    use std::borrow::Cow;

    fn hop(joint: usize, forward: bool) -> Cow<'static, [Hop]> {
        Cow::Owned(vec![Hop { joint, forward }])
    }

    /// The four-bar's forward plan, as the planner makes it: the crank
    /// given; the coupler turned about R2 until its R3, carried across R3
    /// to the rocker, is on the circle about R4 the rocker's length fixes
    /// (two roots); the rocker aimed at R3, which closes R3 by the aim's
    /// miss, and nothing reads the rocker for the output.
    #[test]
    fn a_four_bar_forward() {
        let m = four_bar(100.0, 250.0, 200.0, 300.0);
        let plan = Plan {
            steps: vec![
                Step::Transfer {
                    joint: 0,
                    from: 0,
                    to: 1,
                    input: 0,
                },
                Step::Locus {
                    joint: 1,
                    from: 1,
                    to: 2,
                    point: PointRef::Joint(2),
                    constraint: Constraint::Cylinder {
                        hops: hop(2, true),
                        joint: 3,
                        link: 0,
                    },
                    branch: Some(0),
                },
                Step::Aim {
                    joint: 3,
                    from: 0,
                    to: 3,
                    point: PointRef::Joint(2),
                    target: Anchor {
                        link: 2,
                        hops: hop(2, true),
                        point: PointRef::Joint(2),
                    },
                },
            ],
            branches: 1,
            n_inputs: 1,
            inputs: vec![0],
            by_miss: vec![ByMiss {
                joint: 2,
                aim: 2,
                plane: None,
                skipped: true,
            }],
        };
        assert_eq!(
            plan.display(&m).to_string(),
            "\
forward plan: given R1; 1 ± choice, 2 branches
  0 Transfer     R1 places crank from base: given 0
  1 Locus        R2 places coupler from crank: R3 on the cylinder about R4 of base, carried to rocker, ± choice 0
  2 Aim          R4 places rocker from base: R3 onto R3 of coupler
  check R3, by the miss of step 2, its turns skipped where only the results are solved
"
        );
    }

    /// One U-P-S leg of a Stewart–Gough platform, inverse: the platform
    /// placed by its whole pose; the U's cross turned until the plane its
    /// second axis and the slide sweep holds the ball (one plane, the cross
    /// turned over left to the convention); the U's second half turning
    /// the cylinder until the slide's line passes the ball (two senses);
    /// the rod slid onto it, the ball closed by that aim's miss.
    #[test]
    fn a_ups_leg_inverse() {
        use JointType::{P, R, S};
        let joints = vec![
            joint("U1.a", R, [0, 1], [z_axis(0.0, 0.0); 2], false),
            joint("U1.b", R, [1, 2], [z_axis(0.0, 0.0); 2], false),
            joint("P1", P, [2, 3], [z_axis(0.0, 0.0); 2], true),
            joint("S1", S, [3, 4], [z_axis(0.0, 0.0); 2], false),
        ];
        let o = NamedPoint {
            name: "o".into(),
            link: 4,
            at: [0.0; 3],
        };
        let m = model(
            "leg",
            false,
            &["base", "U1.cross", "A1", "A2", "platform"],
            joints,
            vec![o],
        );
        let ball = Anchor {
            link: 4,
            hops: hop(3, false),
            point: PointRef::Joint(3),
        };
        let plan = Plan {
            steps: vec![
                Step::Place {
                    link: 4,
                    point: PointRef::Named(0),
                    input: 0,
                    planar: false,
                    turn: Turn::Angles,
                },
                Step::PlaneThrough {
                    joint: 0,
                    from: 0,
                    to: 1,
                    across: 1,
                    slide: 2,
                    point: PointRef::Joint(3),
                    target: ball.clone(),
                    branch: None,
                },
                Step::Guide {
                    joint: 1,
                    from: 1,
                    to: 2,
                    carried: None,
                    slide: 2,
                    point: PointRef::Joint(3),
                    target: ball.clone(),
                    branch: 0,
                },
                Step::Aim {
                    joint: 2,
                    from: 2,
                    to: 3,
                    point: PointRef::Joint(3),
                    target: ball,
                },
            ],
            branches: 1,
            n_inputs: 6,
            inputs: vec![],
            by_miss: vec![ByMiss {
                joint: 3,
                aim: 3,
                plane: None,
                skipped: false,
            }],
        };
        assert_eq!(
            plan.display(&m).to_string(),
            "\
inverse plan: given x, y, z of platform at o and its rx, ry, rz; 1 ± choice, 2 branches
  0 Place        places platform: o at given 0, turned by rx, ry, rz
  1 PlaneThrough U1.a places U1.cross from base: the plane normal to U1.b along P1 through S1 of platform, its other root by convention
  2 Guide        U1.b places A1 from U1.cross: the line of P1 through S1 of platform, ± choice 0
  3 Aim          P1 places A2 from A1: S1 onto S1 of platform
  check S1, by the miss of step 3
"
        );
    }
}
