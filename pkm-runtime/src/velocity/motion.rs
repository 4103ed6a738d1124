//! Accelerations and the motion of bodies and points: every joint's second
//! derivative and every link's twist rate ([`accelerations`]), a body's pose,
//! twist and twist rate (a parallelogram's bar too, [`body_motion`]), and the
//! velocity and acceleration of every joint's point and named point.

use super::twist::{joint_twist_rates, Twist};
use super::{loops, twist_of_rate, Loops, Velocities, VelocityError};
use crate::kinematics::spanning_tree;
use crate::model::Model;
use nalgebra::{DVector, Isometry3, Vector3};

/// A configuration's accelerations: every joint's second derivative and
/// every link's twist rate (`(ω̇, the rate of v)`).
#[derive(Debug, Clone)]
pub struct Accelerations {
    /// Velocities first.
    pub velocities: Velocities,
    /// Every joint's second derivative.
    pub rates: Vec<f64>,
    /// Every link's twist derivative.
    pub twists: Vec<Twist>,
}

/// Every joint's unit-twist rates (see [`joint_twist_rates`]), by rate index.
fn all_twist_rates(model: &Model, l: &Loops, values: &[f64], qd: &[f64], twists: &[Twist]) -> Vec<Twist> {
    let mut out = Vec::with_capacity(qd.len());
    for (j, joint) in model.joints.iter().enumerate() {
        let r = l.offsets[j]..l.offsets[j] + joint.kind.dof();
        let u = joint.links[0];
        out.extend(joint_twist_rates(
            model,
            j,
            &values[r.clone()],
            &qd[r],
            &l.poses[u],
            &twists[u],
        ));
    }
    out
}

/// The time derivative of link `link`'s twist: `Σ ±(q̈ ξ + q̇ ξ̇)` along its path.
fn twist_rate(l: &Loops, link: usize, qd: &[f64], qdd: &[f64], xi_dot: &[Twist]) -> Twist {
    l.paths[link].iter().fold(Twist::zero(), |acc, &(col, s)| {
        let xi = twist_of_rate(&l.twists, &l.offsets, col);
        acc.add(&xi.scale(s * qdd[col])).add(&xi_dot[col].scale(s * qd[col]))
    })
}

/// Every joint's second derivative and every link's twist derivative from
/// the inputs' rates and second derivatives.
pub fn accelerations(
    model: &Model,
    values: &[f64],
    input_rates: &[f64],
    input_accels: &[f64],
) -> Result<Accelerations, VelocityError> {
    accelerations_on(&loops(model, values)?, model, values, input_rates, input_accels)
}

/// [`accelerations`] on velocity equations already formed at `values`
/// (for a caller that reads them too).
pub fn accelerations_on(
    l: &Loops,
    model: &Model,
    values: &[f64],
    input_rates: &[f64],
    input_accels: &[f64],
) -> Result<Accelerations, VelocityError> {
    let scale = crate::kinematics::model_scale(model);
    let (svd, conditioning) = l.passive_svd(scale);
    let solve = |rates: &[f64], bias: &DVector<f64>| l.solve_with(svd.as_ref(), conditioning, rates, bias, scale);
    let qd = solve(input_rates, &DVector::zeros(l.a.nrows()))?;
    let twists: Vec<Twist> = (0..model.links.len()).map(|k| l.link_twist(k, &qd)).collect();
    let xi_dot = all_twist_rates(model, l, values, &qd, &twists);
    // Bias: the differentiated loop rows with q̈ = 0.
    let zero = vec![0.0; qd.len()];
    let tree = spanning_tree(model)?;
    let mut bias = DVector::zeros(l.a.nrows());
    for (row, &c) in tree.cut.iter().enumerate() {
        let [u, v] = model.joints[c].links;
        let mut t = twist_rate(l, v, &qd, &zero, &xi_dot).add(&twist_rate(l, u, &qd, &zero, &xi_dot).scale(-1.0));
        for k in 0..model.joints[c].kind.dof() {
            let col = l.offsets[c] + k;
            t = t.add(&xi_dot[col].scale(-qd[col]));
        }
        for (i, x) in t.rows().iter().enumerate() {
            bias[6 * row + i] = *x;
        }
    }
    // An S–S link's spin acceleration `â·ω̇ = 0` (its spin is zero, so the
    // line's own turn adds nothing): the velocity-product part of `â·ω̇`.
    for (k, (link, axis)) in l.spins.iter().enumerate() {
        bias[l.loop_rows + k] = twist_rate(l, *link, &qd, &zero, &xi_dot).w.dot(axis);
    }
    let qdd = solve(input_accels, &bias)?;
    let twist_rates = (0..model.links.len())
        .map(|k| twist_rate(l, k, &qd, &qdd, &xi_dot))
        .collect();
    Ok(Accelerations {
        velocities: Velocities {
            rates: qd,
            twists,
            conditioning,
        },
        rates: qdd,
        twists: twist_rates,
    })
}

/// Where a body is and how it moves: its pose, twist and twist rate, and,
/// for a parallelogram's bar, how it turns on its arm-carrying link.
#[derive(Debug, Clone, Copy)]
pub struct BodyMotion {
    /// Its pose in the world (its frame: the link's, or the bar's).
    pub pose: Isometry3<f64>,
    /// Its twist.
    pub twist: Twist,
    /// Its twist rate.
    pub rate: Twist,
    /// A bar's turn: see [`BarTurn`].
    pub bar: Option<BarTurn>,
}

/// A parallelogram bar's motion on its arm-carrying link `carrier`: its
/// twist is the carrier's plus `θ̇ ξ`, with `θ` the joint's value (rate
/// index `rate`) and `ξ` the unit rotation about the hinge axis through
/// the hinge, world.
#[derive(Debug, Clone, Copy)]
pub struct BarTurn {
    /// The arm-carrying link.
    pub carrier: usize,
    /// The index of the parallelogram's rate among all rates.
    pub rate: usize,
    /// The unit twist of the bar relative to the carrier.
    pub xi: Twist,
}

/// The motion of a body carried by `carrier` at joint values `values`,
/// with the motion `a` from [`accelerations_on`] on `loops`. A bar's twist
/// is its arm-carrying link's plus `θ̇ ξ`; its rate adds `θ̈ ξ + θ̇ [V_c, ξ]`
/// (ξ is fixed in the carrier).
pub fn body_motion(
    model: &Model,
    loops: &Loops,
    a: &Accelerations,
    values: &[f64],
    carrier: &crate::mass_properties::Carrier,
) -> Result<BodyMotion, VelocityError> {
    use crate::mass_properties::{arm_side, bar_pose, Carrier};
    match *carrier {
        Carrier::Link(l) => Ok(BodyMotion {
            pose: loops.poses[l],
            twist: a.velocities.twists[l],
            rate: a.twists[l],
            bar: None,
        }),
        Carrier::Bar { joint, hinge } => {
            let Some((c, axis)) = arm_side(model, joint) else {
                return Err(VelocityError::NotABar { joint });
            };
            let col = loops.offsets[joint];
            let pose = bar_pose(&loops.poses[c], &axis, &hinge, values[col]);
            let w = loops.poses[c].rotation * axis;
            let xi = Twist {
                w,
                v: -w.cross(&pose.translation.vector),
            };
            let vc = a.velocities.twists[c];
            let (qd, qdd) = (a.velocities.rates[col], a.rates[col]);
            Ok(BodyMotion {
                pose,
                twist: vc.add(&xi.scale(qd)),
                rate: a.twists[c].add(&xi.scale(qdd)).add(&vc.bracket(&xi).scale(qd)),
                bar: Some(BarTurn {
                    carrier: c,
                    rate: col,
                    xi,
                }),
            })
        }
    }
}

/// The acceleration of the body point at world position `p` of a link with
/// twist `t` and twist rate `dt`.
pub fn point_acceleration(t: &Twist, dt: &Twist, p: &Vector3<f64>) -> Vector3<f64> {
    dt.v + dt.w.cross(p) + t.w.cross(&t.at(p))
}

/// Every joint's point (a slide's: its slider point), then every named
/// point, in the world at `poses`, with the link it moves with: the order of
/// a generated solution's `points`.
fn model_points(model: &Model, poses: &[Isometry3<f64>]) -> Vec<(usize, Vector3<f64>)> {
    let joints = model.joints.iter().enumerate().map(|(j, joint)| {
        let p = crate::kinematics::joint_point(model, poses, j);
        (joint.links[joint.point_side()], Vector3::from(p))
    });
    let named = model
        .points
        .iter()
        .map(|p| (p.link, poses[p.link].transform_point(&p.at.into()).coords));
    joints.chain(named).collect()
}

/// The velocity of every joint's point, then every named point (a generated
/// solution's `points` order), from the link twists at `poses`.
pub fn point_velocities(model: &Model, poses: &[Isometry3<f64>], twists: &[Twist]) -> Vec<[f64; 3]> {
    model_points(model, poses)
        .into_iter()
        .map(|(link, p)| twists[link].at(&p).into())
        .collect()
}

/// The acceleration of the same points, from the link twists and their rates.
pub fn point_accelerations(model: &Model, poses: &[Isometry3<f64>], a: &Accelerations) -> Vec<[f64; 3]> {
    model_points(model, poses)
        .into_iter()
        .map(|(link, p)| point_acceleration(&a.velocities.twists[link], &a.twists[link], &p).into())
        .collect()
}
