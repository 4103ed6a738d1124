//! The forward position of a mechanism whose legs each end in one ball
//! joint (the 6-UPS, the 3-RPS, the 3-SPR, the 3-PRS): every assembly,
//! each real one certified, where the POC coupling degree leaves no
//! closed-form plan (κ ≥ 2).
//!
//! With its inputs given, each leg without its ball is a chain with one or
//! two passive revolutes: its ball centre, seen from the body the chain
//! starts on, moves on a circle (one revolute: an R-P-S's, a P-R-S's, an
//! S-P-R's seen from the platform) or a sphere (two revolutes whose axes
//! meet: a U-P-S's). The platform's pose is then the root of one equation
//! per sphere and two per circle ([`system`]), every complex root found by
//! parameter homotopy ([`homotopy`]), each real one certified by
//! Krawczyk's operator and solved for every joint by the inverse plan
//! ([`solve`]).
//!
//! Nothing here knows a mechanism: [`BallLegs::of`] reads the legs off any
//! model and says why where they do not have this form.

pub mod homotopy;
pub mod solve;
pub mod system;

use crate::model::{joint_transform, JointType, Model, Place};
use nalgebra::{Isometry3, Point3, Vector3};
use system::{Body, Locus};

/// One leg: the chain from the body its locus is fixed in to the ball.
#[derive(Debug, Clone, PartialEq)]
pub struct Leg {
    /// The ball joint.
    pub ball_joint: usize,
    /// The body the chain starts on.
    pub on: Body,
    /// The chain's joints from that body, each with whether it is crossed
    /// from its first link to its second.
    pub chain: Vec<(usize, bool)>,
    /// The ball centre on the chain's last link, in its frame.
    pub near: [f64; 3],
    /// The ball centre on the other body, in its frame.
    pub far: [f64; 3],
}

/// A mechanism's legs, each ending in a ball.
#[derive(Debug, Clone, PartialEq)]
pub struct BallLegs {
    /// The platform link.
    pub platform: usize,
    /// The legs, in the order of their first joints.
    pub legs: Vec<Leg>,
    /// Each leg's locus: a circle (true) or a sphere, and its body.
    pub shape: Vec<(Body, bool)>,
    /// The mechanism's size (lengths are solved over it).
    pub scale: f64,
}

/// Why the legs do not have the form this solution needs.
pub type Why = String;

impl BallLegs {
    /// The legs of `model` between the base (link 0) and `platform`:
    /// serial chains of links with two joints each, one ball joint at
    /// either end, the rest revolutes and slides with one or two passive
    /// revolutes (two whose axes meet), giving as many equations as the
    /// pose's six values.
    ///
    /// # Errors
    /// Why not, naming the joint or the leg.
    pub fn of(model: &Model, platform: usize) -> Result<BallLegs, Why> {
        let at_link = |l: usize| -> Vec<usize> {
            (0..model.joints.len())
                .filter(|&j| model.joints[j].links.contains(&l))
                .collect()
        };
        let mut legs = Vec::new();
        for first in at_link(0) {
            // Walk from the base to the platform through links of two joints.
            let mut path = vec![first];
            let mut link = model.joints[first].other(0);
            while link != platform {
                if link == 0 {
                    return Err(format!("joint {} joins the base to itself", model.joints[first].name));
                }
                let next: Vec<usize> = at_link(link).into_iter().filter(|&j| Some(&j) != path.last()).collect();
                let [j] = next[..] else {
                    return Err(format!(
                        "link {} has {} joints: the legs are not serial chains from the base to the platform",
                        model.links[link],
                        next.len() + 1
                    ));
                };
                path.push(j);
                link = model.joints[j].other(link);
                if path.len() > model.joints.len() {
                    return Err("a leg loops".to_string());
                }
            }
            legs.push(Self::leg(model, platform, &path)?);
        }
        let shape: Vec<(Body, bool)> = legs.iter().map(|l| (l.on, Self::passive(model, l) == 1)).collect();
        if !homotopy::square(&shape) {
            return Err(format!(
                "the legs give {} equations for the pose's 6 values (a sphere one, a circle two)",
                system::rows(&shape) - 1
            ));
        }
        Ok(BallLegs {
            platform,
            legs,
            shape,
            scale: crate::kinematics::model_scale(model),
        })
    }

    /// The legs of `model` to the link the declared `outputs` place (a
    /// pose, a point or a pose's parts, all of one link).
    ///
    /// # Errors
    /// Outputs of several links or a joint's value, or [`Self::of`]'s.
    pub fn for_outputs(model: &Model, outputs: &[crate::newton::Output]) -> Result<BallLegs, Why> {
        use crate::newton::Output;
        let links: Vec<Option<usize>> = outputs
            .iter()
            .map(|o| match *o {
                Output::Pose { link, .. } | Output::Point { link, .. } | Output::Parts { link, .. } => Some(link),
                Output::Joint(_) => None,
            })
            .collect();
        match links[..] {
            [Some(first), ..] if links.iter().all(|l| *l == Some(first)) && first != 0 => Self::of(model, first),
            _ => Err("the outputs are not one platform's pose or point".to_string()),
        }
    }

    fn passive(model: &Model, leg: &Leg) -> usize {
        leg.chain.iter().filter(|&&(j, _)| !model.joints[j].actuated).count()
    }

    /// One leg from its joints, base first.
    fn leg(model: &Model, platform: usize, path: &[usize]) -> Result<Leg, Why> {
        let names = || {
            path.iter()
                .map(|&j| model.joints[j].name.as_str())
                .collect::<Vec<_>>()
                .join("-")
        };
        let balls: Vec<usize> = (0..path.len())
            .filter(|&k| model.joints[path[k]].kind == JointType::S)
            .collect();
        let (ball, on, rest): (usize, Body, Vec<usize>) = match balls[..] {
            [k] if k + 1 == path.len() => (path[k], Body::Base, path[..k].to_vec()),
            [0] => (path[0], Body::Platform, path[1..].iter().rev().copied().collect()),
            _ => return Err(format!("leg {} does not end in one ball joint", names())),
        };
        // Cross the chain from its body.
        let mut link = if on == Body::Base { 0 } else { platform };
        let mut chain = Vec::new();
        for &j in &rest {
            let joint = &model.joints[j];
            if !joint.actuated && joint.kind != JointType::R {
                return Err(format!(
                    "leg {}: its passive joint {} is not a revolute (only passive revolutes are solved here)",
                    names(),
                    joint.name
                ));
            }
            chain.push((j, joint.links[0] == link));
            link = joint.other(link);
        }
        let joint = &model.joints[ball];
        let side = usize::from(joint.links[1] == link);
        let passive = chain.iter().filter(|&&(j, _)| !model.joints[j].actuated).count();
        if !(1..=2).contains(&passive) {
            return Err(format!(
                "leg {} has {passive} passive joints besides its ball (one or two)",
                names()
            ));
        }
        Ok(Leg {
            ball_joint: ball,
            on,
            chain,
            near: joint.places[side].at(),
            far: joint.places[1 - side].at(),
        })
    }

    /// Each leg's locus at the inputs `inputs` (the actuated joints in
    /// declaration order), lengths over the size.
    ///
    /// # Errors
    /// A leg whose two passive revolutes' axes do not meet.
    pub fn loci(&self, model: &Model, inputs: &[f64]) -> Result<Vec<Locus<f64>>, Why> {
        let actuated = model.inputs();
        let s = self.scale;
        // A slide's length is limited as the plans limit a given length
        // (`steps::REACH` sizes): beyond it rounding merges assemblies.
        for (&j, &v) in actuated.iter().zip(inputs) {
            if model.joints[j].kind == JointType::P && v.abs() > crate::steps::REACH * s {
                return Err(format!(
                    "{} = {v:e}: |given length| <= 1e10 sizes of the mechanism ({:.3e})",
                    model.joints[j].name,
                    crate::steps::REACH * s
                ));
            }
        }
        let mut out = Vec::with_capacity(self.legs.len());
        for leg in &self.legs {
            let mut pose = Isometry3::identity();
            let mut axes: Vec<(Point3<f64>, Vector3<f64>)> = Vec::new();
            for &(j, forward) in &leg.chain {
                let joint = &model.joints[j];
                let value = actuated.iter().position(|&a| a == j).map_or(0.0, |k| inputs[k]);
                if !joint.actuated {
                    let place = &joint.places[usize::from(!forward)];
                    let Place::Axis { at, axis } = *place else {
                        return Err(format!("joint {} has no axis", joint.name));
                    };
                    axes.push((pose * Point3::from(at), pose * Vector3::from(axis).normalize()));
                }
                let t = joint_transform(joint, &[value]);
                pose *= if forward { t } else { t.inverse() };
            }
            let x = pose * Point3::from(leg.near);
            let (centre, normal) = match axes[..] {
                [(a, u)] => (a + u * (x - a).dot(&u), Some(u)),
                [(a, u), (b, v)] => {
                    // Where the two axes meet.
                    let w = u.cross(&v);
                    let n2 = w.norm_squared();
                    let t = (b - a).cross(&v).dot(&w) / n2;
                    let c = a + u * t;
                    let gap = (b - a).dot(&w).abs() / n2.sqrt();
                    if !(n2 > 1e-12 && gap <= 1e-9 * s) {
                        return Err(format!(
                            "the two passive revolutes before ball {} do not meet (their axes are {gap:.3e} apart)",
                            model.joints[leg.ball_joint].name
                        ));
                    }
                    (c, None)
                }
                _ => return Err("a leg has no passive revolute".to_string()),
            };
            let d = x - centre;
            out.push(Locus {
                on: leg.on,
                ball: leg.far.map(|v| v / s),
                centre: [centre.x / s, centre.y / s, centre.z / s],
                normal: normal.map(|n| [n.x, n.y, n.z]),
                radius2: d.norm_squared() / (s * s),
            });
        }
        Ok(out)
    }
}
