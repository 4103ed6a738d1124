//! Inverse dynamics by Newton–Euler over the ordered SKCs (seed 003 §3.1),
//! with every joint's reaction.
//!
//! Each moving link balances the wrenches its joints exert on it against
//! its inertial wrench less gravity and the loads:
//! `Σ W_joints + W_loads = (m (a_c − g), I α + ω × I ω)`. A joint's reaction
//! `W_j` is the wrench its first link exerts on its second (force and moment
//! about the base origin while solving); it does no work along the joint's
//! own motion (`ξ·W_j = 0` for each of its unit twists ξ) unless the joint
//! is actuated, where `ξ·W_j` is the actuator's force or torque.
//!
//! The SKCs are solved in the reverse of the position solution's order:
//! SKC k's unknowns are the reactions of its own joints (those of its SOCs,
//! including the ones that hang it on earlier links), its equations are its
//! own links' balances, and the reactions of later SKCs' joints on its links
//! are known by then. κ = 0 makes each block square up to the overconstraint:
//! a loop with ξ_L < 6 leaves 6 − ξ_L reaction components that rigid-body
//! statics cannot determine ([`Reactions::undetermined`]); the block is then
//! solved in the least-squares sense with the minimum norm of the reactions
//! (forces in N, moments in N·L divided by the mechanism's size), and the
//! actuators' forces must not depend on that choice (checked). A planar
//! mechanism balances (Fx, Fy, Mz) per link.
//!
//! Near a configuration where an SKC's force equations lose rank beyond the
//! overconstraint (a change point, where reactions grow like 1/(φ − φ*)),
//! its kinematic conditioning c falls to 0: the σ_r/σ_1 of its passive
//! rows acting on its cut joints' reactions, the transpose of its passive
//! velocity equations ([`crate::force_system::tree`]; the whole block's
//! where it does not reduce). The position then carries ε/c, the rates
//! ε/c², the accelerations and forces ε/c³: below
//! [`crate::force_system::least_conditioning`] (6.06e-4 in motion, 1.5e-5
//! at rest) that leaves fewer than six digits and the answer is refused
//! ([`DynamicsError::NearChangePoint`], naming the SKC's joints); above it
//! the conditioning is returned with the reactions.

use crate::force_system::{min_norm, near_change_point, Decomposition};
use crate::mass_properties::{Carrier, Loading};
use crate::model::Model;
use crate::velocity::{self, BarTurn, Twist, VelocityError};
use nalgebra::{DMatrix, DVector, Point3, Vector3};
use std::fmt;

/// An SKC for the force analysis: its new links, its joints, and how many
/// reaction components the topology says it leaves undetermined
/// (Σ (6 − ξ_L) over its loops; Σ (3 − ξ_L) for a planar mechanism).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SkcParts {
    /// The links it adds, which its equations balance.
    pub links: Vec<usize>,
    /// Its joints, whose reactions it solves.
    pub joints: Vec<usize>,
    /// Reaction components statics cannot determine.
    pub undetermined: usize,
}

/// One joint's reaction: the force and the moment its first link exerts on
/// its second, about the joint's point, base axes (N and N·L).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointReaction {
    /// The force.
    pub force: [f64; 3],
    /// The moment about the joint's point.
    pub moment: [f64; 3],
}

/// What inverse dynamics by Newton–Euler finds.
#[derive(Debug, Clone, PartialEq)]
pub struct Reactions {
    /// The actuators' forces (N) or torques (N·L), in input order.
    pub actuators: Vec<f64>,
    /// Every joint's reaction.
    pub joints: Vec<JointReaction>,
    /// Per SKC, the reaction components statics leaves undetermined (the
    /// reactions given are the minimum-norm ones).
    pub undetermined: Vec<usize>,
    /// Per SKC, its kinematic conditioning: σ_r/σ_1 of its passive rows on
    /// its cut joints' reactions, r their rank (of its whole block where it
    /// does not reduce to its cut joints; for a determined SKC far from a
    /// change point, the lower bound
    /// [`crate::force_system::conditioning_bound`]).
    pub conditioning: Vec<f64>,
    /// The largest residual of a link's balance, relative to its largest term.
    pub balance: f64,
}

/// Below this conditioning an SKC's force equations count as singular.
pub const FORCE_SINGULAR: f64 = 1e-10;

/// Above this relative residual a link's balance is not an answer (the
/// solves leave about ε over the conditioning: 1e-12 or less away from
/// change points, and [`FORCE_SINGULAR`] bounds the conditioning).
pub const UNBALANCED: f64 = 1e-6;

/// Why inverse dynamics has no answer.
#[derive(Debug, Clone, PartialEq)]
pub enum DynamicsError {
    /// The motion itself has none (an output singularity, bad values).
    Velocity(VelocityError),
    /// The position has none: the generated inverse dynamics solves it
    /// first, on the branch asked for.
    Position(crate::solution::SolveError),
    /// A mass or an inertia given through the parameters is not a rigid
    /// body's.
    MassProperties {
        /// The link (or body) it belongs to.
        body: std::borrow::Cow<'static, str>,
        /// What is wrong with it.
        problem: String,
    },
    /// An SKC is so near a change point that the answer would keep fewer
    /// than six digits: its kinematic conditioning is below the least
    /// ([`crate::force_system::least_conditioning`]).
    NearChangePoint {
        /// The SKC, from 0 in the position solution's order.
        skc: usize,
        /// Its joints.
        joints: Vec<usize>,
        /// Its kinematic conditioning.
        conditioning: f64,
        /// The least that keeps six digits.
        least: f64,
        /// Whether an input moves (rates and accelerations lose digits
        /// faster than positions).
        moving: bool,
    },
    /// An SKC's force equations are singular: a change point.
    ForceSingular {
        /// The SKC, from 0 in the position solution's order.
        skc: usize,
        /// Its joints.
        joints: Vec<usize>,
        /// Its conditioning.
        conditioning: f64,
    },
    /// The actuators' forces depend on the undetermined reactions.
    Undetermined {
        /// The SKC.
        skc: usize,
    },
    /// The SKCs given do not hold every joint and moving link once.
    BadParts(String),
    /// A reaction is not a number (the values, rates or loading were not).
    NotFinite,
    /// The joint values given do not close the loops: no configuration.
    NotClosed {
        /// The largest loop-closure residual (lengths over the size, radians).
        residual: f64,
    },
    /// The reactions found do not balance a link (relative residual).
    Unbalanced {
        /// The largest relative residual.
        balance: f64,
    },
}

impl DynamicsError {
    /// The error in words, each joint by `name` (its index in the model).
    pub fn describe(&self, name: &dyn Fn(usize) -> String) -> String {
        let names = |joints: &[usize]| joints.iter().map(|&j| name(j)).collect::<Vec<_>>().join(", ");
        match self {
            DynamicsError::Velocity(e) => e.to_string(),
            DynamicsError::Position(e) => e.to_string(),
            DynamicsError::MassProperties { body, problem } => format!("the mass properties of `{body}`: {problem}"),
            DynamicsError::NearChangePoint {
                skc,
                joints,
                conditioning,
                least,
                moving,
            } => {
                let lost = if *moving {
                    "the rates and accelerations (errors ε/c² and ε/c³), and with them the forces,"
                } else {
                    "the position (error ε/c), and with it the forces (ε/c²),"
                };
                format!(
                    "SKC {} (joints {}) is next to a change point: its kinematic conditioning c = {conditioning:.1e} \
                     is below {least:.2e}, where {lost} keep fewer than 6 digits",
                    skc + 1,
                    names(joints)
                )
            }
            DynamicsError::ForceSingular {
                skc,
                joints,
                conditioning,
            } => format!(
                "the force equations of SKC {} (joints {}) are singular here (conditioning {conditioning:e}): a change point",
                skc + 1,
                names(joints)
            ),
            DynamicsError::Undetermined { skc } => {
                format!("the actuators' forces in SKC {} are not determined by statics", skc + 1)
            }
            DynamicsError::BadParts(why) => format!("the SKCs given are not a partition: {why}"),
            DynamicsError::NotFinite => "a reaction is not a finite number".to_string(),
            DynamicsError::NotClosed { residual } => format!(
                "the joint values do not close the mechanism's loops (residual {residual:e}): solve the position first"
            ),
            DynamicsError::Unbalanced { balance } => {
                format!("the reactions found leave a link unbalanced by {balance:e} of its largest force")
            }
        }
    }
}

impl fmt::Display for DynamicsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.describe(&|j| j.to_string()))
    }
}

impl std::error::Error for DynamicsError {}

impl From<VelocityError> for DynamicsError {
    fn from(e: VelocityError) -> Self {
        DynamicsError::Velocity(e)
    }
}

/// A wrench about the base origin as d numbers: (fx, fy, mz) planar,
/// (fx, fy, fz, mx, my, mz) spatial.
fn wrench(planar: bool, f: Vector3<f64>, m: Vector3<f64>) -> Vec<f64> {
    if planar {
        vec![f.x, f.y, m.z]
    } else {
        vec![f.x, f.y, f.z, m.x, m.y, m.z]
    }
}

/// Where a wrench of `d` numbers ([`wrench`]) turns from forces to
/// moments: (fx, fy | mz) planar, (f | m) spatial.
fn moments_from(d: usize) -> usize {
    if d == 3 {
        2
    } else {
        3
    }
}

/// A twist's power coefficients against such a wrench: (vx, vy, ωz) or (v, ω).
fn coefficients(planar: bool, t: &Twist) -> Vec<f64> {
    if planar {
        vec![t.v.x, t.v.y, t.w.z]
    } else {
        vec![t.v.x, t.v.y, t.v.z, t.w.x, t.w.y, t.w.z]
    }
}

/// Every joint's reaction and the actuators' forces at joint values
/// `values` with the inputs' rates and accelerations, SKC by SKC in
/// reverse order (`skcs` in the position solution's order).
pub fn inverse_dynamics(
    model: &Model,
    loading: &Loading,
    skcs: &[SkcParts],
    values: &[f64],
    input_rates: &[f64],
    input_accels: &[f64],
) -> Result<Reactions, DynamicsError> {
    let planar = model.planar;
    let d = if planar { 3 } else { 6 };
    check_parts(model, skcs)?;
    let size = crate::kinematics::model_scale(model);
    closes(model, values, size)?;
    // An S–S link's idle spin does no work (see `Loading::idle_spins_dropped`).
    let loading = &*loading
        .idle_spins_dropped(model)
        .map_err(|(link, problem)| DynamicsError::MassProperties {
            body: model.links[link].clone().into(),
            problem,
        })?;
    let loops = velocity::loops(model, values)?;
    let motion = velocity::accelerations_on(&loops, model, values, input_rates, input_accels)?;
    // Moments and moment rows in units of the mechanism's size.
    let unit = |i: usize| if i >= moments_from(d) { size } else { 1.0 };
    let poses = &loops.poses;
    // What each link's joints must supply: its inertial wrench less gravity
    // and the loads (Euler's equations in the link's own axes).
    let mut demand: Vec<Vec<f64>> = vec![vec![0.0; d]; model.links.len()];
    // Per parallelogram, its bars' demand along their motion with its first
    // link held: Σ D_i·ξ'_i (see `bar_demand`).
    let mut bar_work = vec![0.0; model.joints.len()];
    for b in &loading.bodies {
        let m = velocity::body_motion(model, &loops, &motion, values, &b.carrier)?;
        let (t, dt) = (&m.twist, &m.rate);
        let c = (m.pose * Point3::from(b.centroid)).coords;
        let a = dt.v + dt.w.cross(&c) + t.w.cross(&t.at(&c));
        let rot = m.pose.rotation;
        let (w_body, dw_body) = (rot.inverse() * t.w, rot.inverse() * dt.w);
        let m_c = rot * (b.inertia * dw_body + w_body.cross(&(b.inertia * w_body)));
        let f = b.mass * (a - loading.gravity);
        let w = wrench(planar, f, m_c + c.cross(&f));
        let link = match (b.carrier, m.bar) {
            (Carrier::Bar { joint, .. }, Some(bar)) => {
                let (first, power) = bar_demand(model, &loops, joint, &bar, &w);
                bar_work[joint] += power;
                first
            }
            (Carrier::Link(l), _) => l,
            (Carrier::Bar { joint, .. }, None) => return Err(VelocityError::NotABar { joint }.into()),
        };
        demand[link].iter_mut().zip(w).for_each(|(x, y)| *x += y);
    }
    for l in &loading.loads {
        let p = (poses[l.link] * Point3::from(l.at)).coords;
        let w = wrench(planar, l.force, l.moment + p.cross(&l.force));
        demand[l.link].iter_mut().zip(w).for_each(|(x, y)| *x -= y);
    }
    let mut reaction: Vec<Option<Vec<f64>>> = vec![None; model.joints.len()];
    let mut undetermined = vec![0; skcs.len()];
    let mut conditioning = vec![1.0; skcs.len()];
    let moving = input_rates.iter().chain(input_accels).any(|&v| v != 0.0);
    for (k, skc) in skcs.iter().enumerate().rev() {
        let n = skc.joints.len() * d;
        let passive = passive_rows(model, &loops, skc, size);
        // The kinematic conditioning, where the SKC reduces to its cut joints.
        let kinematic = kinematic_conditioning(model, skc, &passive, d);
        if let Some(c) = kinematic {
            near_change_point(c, moving, k, &skc.joints)?;
        }
        let rows = skc.links.len() * d + passive.len();
        let mut a = DMatrix::zeros(rows, n);
        let mut rhs = DVector::zeros(rows);
        for (r, &l) in skc.links.iter().enumerate() {
            for c in 0..d {
                rhs[r * d + c] = demand[l][c] / unit(c);
            }
            for (j, joint) in model.joints.iter().enumerate() {
                let Some(sign) = acting_on(joint, l) else { continue };
                match (skc.joints.iter().position(|&x| x == j), &reaction[j]) {
                    (Some(i), _) => {
                        for c in 0..d {
                            a[(r * d + c, i * d + c)] = sign;
                        }
                    }
                    (None, Some(w)) => {
                        for c in 0..d {
                            rhs[r * d + c] -= sign * w[c] / unit(c);
                        }
                    }
                    // No joint of an earlier SKC touches this SKC's links.
                    (None, None) => {}
                }
            }
        }
        for (p, row) in passive.iter().enumerate() {
            let at = skc.links.len() * d + p;
            for c in 0..d {
                a[(at, row.at * d + c)] = row.coefficients[c];
            }
            // ξ·W = 0, or a parallelogram's −Σ D_i·ξ'_i with massive bars.
            rhs[at] = -bar_work[row.joint] * row.scale;
        }
        // Zero rows (or columns) up to a square matrix, so that the
        // decomposition holds the whole null space (the thin one has only
        // min(rows, n) rows of Vᵀ).
        let size_n = rows.max(n);
        let a = a.resize(size_n, size_n, 0.0);
        let rhs = rhs.resize_vertically(size_n, 0.0);
        // Each actuator twist's power coefficients against the unknowns.
        let mut actuated = Vec::new();
        for (i, &j) in skc.joints.iter().enumerate().filter(|(_, &j)| model.joints[j].actuated) {
            for t in &loops.twists[j] {
                let xi = coefficients(planar, t);
                let mut row = vec![0.0; size_n];
                for c in 0..d {
                    row[i * d + c] = xi[c] * unit(c);
                }
                actuated.extend(row);
            }
        }
        let svd = a.clone().svd(true, true);
        let (Some(u), Some(v_t)) = (svd.u.as_ref(), svd.v_t.as_ref()) else {
            return Err(DynamicsError::NotFinite);
        };
        let decomposition = Decomposition {
            n: size_n,
            singular_values: svd.singular_values.as_slice(),
            u: u.as_slice(),
            v_t: v_t.as_slice(),
            matrix: a.as_slice(),
        };
        let mut x = vec![0.0; size_n];
        let solved = min_norm(
            &decomposition,
            rhs.as_slice(),
            k,
            &skc.joints,
            n,
            skc.undetermined,
            &actuated,
            size,
            &mut x,
        )?;
        conditioning[k] = match kinematic {
            Some(c) => c,
            None => {
                near_change_point(solved.conditioning, moving, k, &skc.joints)?;
                solved.conditioning
            }
        };
        undetermined[k] = solved.undetermined;
        for (i, &j) in skc.joints.iter().enumerate() {
            reaction[j] = Some((0..d).map(|c| x[i * d + c] * unit(c)).collect());
        }
    }
    let reaction: Vec<Vec<f64>> = reaction
        .into_iter()
        .map(|w| w.unwrap_or_else(|| vec![0.0; d]))
        .collect();
    if reaction.iter().flatten().any(|x| !x.is_finite()) {
        return Err(DynamicsError::NotFinite);
    }
    let balance = balance(model, &demand, &reaction, d, size);
    // Verified: every link balances under the reactions found.
    if balance.is_nan() || balance > UNBALANCED {
        return Err(DynamicsError::Unbalanced { balance });
    }
    let mut actuators = Vec::new();
    for j in model.inputs() {
        for t in &loops.twists[j] {
            let xi = coefficients(planar, t);
            // An actuated parallelogram also drives its bars.
            let own: f64 = (0..d).map(|c| xi[c] * reaction[j][c]).sum();
            actuators.push(loading.to_newtons(own + bar_work[j]));
        }
    }
    let joints = (0..model.joints.len())
        .map(|j| {
            let w = &reaction[j];
            let (f, m_o) = if planar {
                (Vector3::new(w[0], w[1], 0.0), Vector3::new(0.0, 0.0, w[2]))
            } else {
                (Vector3::new(w[0], w[1], w[2]), Vector3::new(w[3], w[4], w[5]))
            };
            let joint = &model.joints[j];
            let side = joint.point_side();
            let p = (poses[joint.links[side]] * Point3::from(joint.places[side].at())).coords;
            let m_p = m_o - p.cross(&f);
            let n = |v: Vector3<f64>| [0, 1, 2].map(|i| loading.to_newtons(v[i]));
            JointReaction {
                force: n(f),
                moment: n(m_p),
            }
        })
        .collect();
    Ok(Reactions {
        actuators,
        joints,
        undetermined,
        conditioning,
        balance,
    })
}

/// One row of an SKC's reaction system for a unit twist of a passive
/// joint: the reaction does no work along it (`ξ·W = 0`).
struct PassiveRow {
    /// The joint's position in the SKC.
    at: usize,
    /// The joint.
    joint: usize,
    /// The twist's power coefficients against the joint's reaction, moments
    /// over the size, and the row over the size for a turn (lever arms
    /// against forces) or as it is for a slide (a unit direction; a
    /// parallelogram's, per radian of its arm, is left in lengths).
    coefficients: Vec<f64>,
    /// What the row was divided by: 1/size for a turn, else 1.
    scale: f64,
}

/// SKC `skc`'s passive rows, a row per unit twist of each passive joint.
fn passive_rows(model: &Model, loops: &velocity::Loops, skc: &SkcParts, size: f64) -> Vec<PassiveRow> {
    let planar = model.planar;
    let d = if planar { 3 } else { 6 };
    let unit = |i: usize| if i >= moments_from(d) { size } else { 1.0 };
    let mut rows = Vec::new();
    for (at, &joint) in skc.joints.iter().enumerate() {
        if model.joints[joint].actuated {
            continue;
        }
        for t in &loops.twists[joint] {
            let scale = if t.w.norm() > 0.0 { 1.0 / size } else { 1.0 };
            let xi = coefficients(planar, t);
            rows.push(PassiveRow {
                at,
                joint,
                coefficients: (0..d).map(|c| xi[c] * unit(c) * scale).collect(),
                scale,
            });
        }
    }
    rows
}

/// SKC `skc`'s kinematic conditioning: σ_r/σ_1 of its passive rows acting
/// on its cut joints' reactions (`G`, [`crate::force_system::tree`]: the
/// transpose of its passive velocity equations), each row scaled to unit
/// length, r their rank less what statics leaves undetermined (for a
/// determined SKC whose bound from an LU is above the least,
/// that bound: [`crate::force_system::conditioning_bound`]); `None` where
/// it does not reduce.
fn kinematic_conditioning(model: &Model, skc: &SkcParts, passive: &[PassiveRow], d: usize) -> Option<f64> {
    let node = |l: usize| skc.links.iter().position(|&x| x == l).unwrap_or(skc.links.len());
    let ends: Vec<[usize; 2]> = skc.joints.iter().map(|&j| model.joints[j].links.map(node)).collect();
    let tree = crate::force_system::tree(&ends, skc.links.len(), d, passive.len())?;
    let m = tree.unknowns(d);
    let at: Vec<usize> = passive.iter().map(|r| r.at).collect();
    let mut g = DMatrix::zeros(m, m);
    for (row, column, c, factor) in tree.g_entries(&at, d) {
        g[(row, column)] = factor * passive[row].coefficients[c];
    }
    crate::force_system::unit_rows(g.as_mut_slice(), m, &mut []);
    // A determined SKC far from a change point: the bound from an LU serves.
    if skc.undetermined == 0 && passive.len() == m {
        if let Some(inverse) = g.clone().full_piv_lu().try_inverse() {
            let bound = crate::force_system::conditioning_bound(g.as_slice(), inverse.as_slice());
            if bound >= crate::force_system::LEAST_IN_MOTION {
                return Some(bound);
            }
        }
    }
    let s = g.singular_values();
    Some(crate::force_system::conditioning_of(
        s.as_slice(),
        m.saturating_sub(skc.undetermined),
    ))
}

/// A parallelogram bar's demand `w` (its inertial wrench less gravity,
/// about the base origin) folded into its joint: the link it passes to,
/// and its power along the bar's twist relative to that link per unit
/// rate of the parallelogram.
///
/// The bars are not links. Bar i takes `H_i` from the arm-carrying link at
/// its hinge and `K_i` from the other link at its far hinge, with
/// `H_i + K_i = D_i`; each hinge is a frictionless revolute, so `H_i`
/// does no work along the bar's turn relative to the arm-carrying link and
/// `K_i` none along its turn relative to the other link. The joint's
/// reaction `W` is what the parallelogram exerts on its second link (`−K`
/// or `−H` summed over the bars, whichever side that link is): the first
/// link receives `−W − Σ D_i`, and the virtual power with the first link
/// held gives the joint's row `W·ξ = −Σ D_i·ξ'_i`, with `ξ` the second
/// link's unit twist relative to the first and `ξ'_i` bar i's (`ξ_b`, the
/// turn about its hinge, with the arm on the first link; `ξ + ξ_b` with
/// the arm on the second).
fn bar_demand(model: &Model, loops: &velocity::Loops, joint: usize, bar: &BarTurn, w: &[f64]) -> (usize, f64) {
    let planar = model.planar;
    let first = model.joints[joint].links[0];
    let relative = if bar.carrier == first {
        bar.xi
    } else {
        let xi = loops.twists[joint][0];
        Twist {
            w: bar.xi.w + xi.w,
            v: bar.xi.v + xi.v,
        }
    };
    let power = coefficients(planar, &relative).iter().zip(w).map(|(x, y)| x * y).sum();
    (first, power)
}

/// How joint `joint`'s reaction acts on link `l`: +1 on its second link
/// (the reaction is what the first exerts on it), −1 on its first, `None`
/// on any other.
fn acting_on(joint: &crate::model::Joint, l: usize) -> Option<f64> {
    if joint.links[1] == l {
        Some(1.0)
    } else if joint.links[0] == l {
        Some(-1.0)
    } else {
        None
    }
}

/// Whether `values` close every loop, to [`crate::consistency::VERIFY_TOL`]
/// (lengths over the mechanism's size, angles in radians).
fn closes(model: &Model, values: &[f64], size: f64) -> Result<(), DynamicsError> {
    let r = crate::kinematics::loop_residual(model, values).map_err(|e| DynamicsError::Velocity(e.into()))?;
    let residual = r
        .iter()
        .enumerate()
        .map(|(i, x)| if i % 6 < 3 { x.abs() / size } else { x.abs() })
        .fold(0.0f64, |a, x| if x.is_nan() { f64::INFINITY } else { a.max(x) });
    if residual > crate::consistency::VERIFY_TOL {
        return Err(DynamicsError::NotClosed { residual });
    }
    Ok(())
}

/// Every joint in exactly one SKC, every moving link in exactly one.
fn check_parts(model: &Model, skcs: &[SkcParts]) -> Result<(), DynamicsError> {
    let within = |list: &[usize], n: usize| list.iter().all(|&x| x < n);
    if !skcs
        .iter()
        .all(|s| within(&s.joints, model.joints.len()) && within(&s.links, model.links.len()))
    {
        return Err(DynamicsError::BadParts(
            "an index past the model's joints or links".into(),
        ));
    }
    let count = |n: usize, each: &dyn Fn(&SkcParts) -> &[usize]| {
        let mut seen = vec![0usize; n];
        for s in skcs {
            for &x in each(s) {
                if let Some(c) = seen.get_mut(x) {
                    *c += 1;
                }
            }
        }
        seen
    };
    let joints = count(model.joints.len(), &|s| &s.joints);
    let links = count(model.links.len(), &|s| &s.links);
    if let Some(j) = joints.iter().position(|&c| c != 1) {
        return Err(DynamicsError::BadParts(format!(
            "joint {} is in {} SKCs",
            model.joints[j].name, joints[j]
        )));
    }
    if let Some(l) = links.iter().skip(1).position(|&c| c != 1) {
        return Err(DynamicsError::BadParts(format!(
            "link {} is in {} SKCs",
            model.links[l + 1],
            links[l + 1]
        )));
    }
    Ok(())
}

/// The largest residual of a link's balance relative to its largest term
/// (forces; moments over the mechanism's size).
fn balance(model: &Model, demand: &[Vec<f64>], reaction: &[Vec<f64>], d: usize, size: f64) -> f64 {
    let scaled = |c: usize, x: f64| if c >= moments_from(d) { x / size } else { x };
    let mut worst = 0.0f64;
    for (l, need) in demand.iter().enumerate().skip(1) {
        let mut sum = need.iter().enumerate().map(|(c, x)| -scaled(c, *x)).collect::<Vec<_>>();
        let mut largest = need
            .iter()
            .enumerate()
            .fold(0.0f64, |a, (c, x)| a.max(scaled(c, *x).abs()));
        for (j, joint) in model.joints.iter().enumerate() {
            let Some(sign) = acting_on(joint, l) else { continue };
            for c in 0..d {
                let term = sign * scaled(c, reaction[j][c]);
                sum[c] += term;
                largest = largest.max(term.abs());
            }
        }
        let r = sum.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        if largest > 0.0 {
            worst = worst.max(r / largest);
        }
    }
    worst
}
