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
use crate::model::{JointType, Model};
use crate::skc_reactions::{self, Assembly, Carried, CentroidMotion, Layout, Load, MovingBody, PassiveRow};
use crate::velocity::{self, Screw, Twist, VelocityError};
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
    /// does not reduce to its cut joints; where its passive rows are
    /// independent and it is far from a change point, a lower bound of it:
    /// [`crate::force_system::conditioning_from_bound`]).
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

/// Every joint's reaction and the actuators' forces at joint values
/// `values` with the inputs' rates and accelerations, SKC by SKC in
/// reverse order (`skcs` in the position solution's order). The demands
/// and each SKC's system are [`crate::skc_reactions`]'s, at `f64`.
pub fn inverse_dynamics(
    model: &Model,
    loading: &Loading,
    skcs: &[SkcParts],
    values: &[f64],
    input_rates: &[f64],
    input_accels: &[f64],
) -> Result<Reactions, DynamicsError> {
    check_parts(model, skcs)?;
    let size = crate::kinematics::model_scale(model);
    closes(model, values, size)?;
    let layout = Layout {
        planar: model.planar,
        size,
    };
    let d = layout.d();
    // An S–S link's idle spin does no work (see `Loading::idle_spins_dropped`):
    // its bodies and loads are checked here, its moment dropped in the demand.
    let lines: Vec<Option<([f64; 3], [f64; 3])>> = (0..model.links.len())
        .map(|l| crate::mass_properties::idle_spin_line(model, l).map(|(p, a)| (p.into(), a.into())))
        .collect();
    idle_spins_checked(model, loading, &lines, size)?;
    let loops = velocity::loops(model, values)?;
    let motion = velocity::accelerations_on(&loops, model, values, input_rates, input_accels)?;
    let poses = &loops.poses;
    let twists: Vec<Vec<Vec<f64>>> = loops
        .twists
        .iter()
        .map(|ts| ts.iter().map(|t| layout.coefficients(&screw(t))).collect())
        .collect();
    let mut bodies = Vec::with_capacity(loading.bodies.len());
    for b in &loading.bodies {
        let m = velocity::body_motion(model, &loops, &motion, values, &b.carrier)?;
        let c = (m.pose * Point3::from(b.centroid)).coords;
        let on = match (b.carrier, m.bar) {
            (Carrier::Bar { joint, .. }, Some(bar)) => Carried::Bar {
                joint,
                carrier: bar.carrier,
                xi: screw(&bar.xi),
            },
            (Carrier::Link(l), _) => Carried::Link(l),
            (Carrier::Bar { joint, .. }, None) => return Err(VelocityError::NotABar { joint }.into()),
        };
        bodies.push(MovingBody {
            on,
            pose: crate::plan::frame_of(&m.pose),
            motion: CentroidMotion {
                w: m.twist.w.into(),
                alpha: m.rate.w.into(),
                a_c: velocity::point_acceleration(&m.twist, &m.rate, &c).into(),
            },
            mass: b.mass,
            centroid: b.centroid.into(),
            inertia: core::array::from_fn(|i| core::array::from_fn(|j| b.inertia[(i, j)])),
        });
    }
    let loads: Vec<Load<f64>> = loading
        .loads
        .iter()
        .map(|l| Load {
            link: l.link,
            at: (poses[l.link] * Point3::from(l.at)).coords.into(),
            force: l.force.into(),
            moment: l.moment.into(),
        })
        .collect();
    let links: Vec<[usize; 2]> = model.joints.iter().map(|j| j.links).collect();
    let first: Vec<usize> = links.iter().map(|l| l[0]).collect();
    let demands = skc_reactions::demands(
        &layout,
        model.links.len(),
        &first,
        &lines,
        &twists,
        &bodies,
        &loads,
        loading.gravity.into(),
    );
    let place = skc_reactions::places(skcs, model.joints.len(), d)
        .ok_or_else(|| DynamicsError::BadParts("a joint is in no SKC".into()))?;
    let kinds: Vec<JointType> = model.joints.iter().map(|j| j.kind).collect();
    let actuated: Vec<bool> = model.joints.iter().map(|j| j.actuated).collect();
    let assembly = Assembly {
        layout: &layout,
        links: &links,
        kinds: &kinds,
        actuated: &actuated,
        twists: &twists,
        demands: &demands,
        place: &place,
    };
    // Each SKC's reactions as solved: moments over the size.
    let mut solution: Vec<Vec<f64>> = vec![Vec::new(); skcs.len()];
    let mut undetermined = vec![0; skcs.len()];
    let mut conditioning = vec![1.0; skcs.len()];
    let moving = input_rates.iter().chain(input_accels).any(|&v| v != 0.0);
    for (k, skc) in skcs.iter().enumerate().rev() {
        let system = assembly.system(k, skc);
        let n = system.unknowns;
        // The kinematic conditioning, where the SKC reduces to its cut joints.
        let kinematic = kinematic_conditioning(&assembly, skc, &system.passive);
        if let Some(c) = kinematic {
            near_change_point(c, moving, k, &skc.joints)?;
        }
        // Square, zero rows (or columns) added, so that the decomposition
        // holds the whole null space (the thin one has only min(rows, n)
        // rows of Vᵀ).
        let size_n = system.rows.max(n);
        let mut a = DMatrix::zeros(size_n, size_n);
        for &(r, c, v) in &system.entries {
            a[(r, c)] = v;
        }
        let mut rhs = DVector::zeros(size_n);
        for (r, v) in system.rhs.iter().enumerate() {
            rhs[r] = *v;
        }
        for &(r, j, c, sign) in &system.known {
            let (owner, at) = place[j];
            rhs[r] -= sign * solution[owner][at + c];
        }
        // Each actuator twist's power coefficients against the unknowns.
        let mut actuated = vec![0.0; system.actuated.len() * size_n];
        for (i, row) in system.actuated.iter().enumerate() {
            for &(c, v) in row {
                actuated[i * size_n + c] = v;
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
        solution[k] = x;
    }
    let reaction: Vec<Vec<f64>> = place
        .iter()
        .map(|&(k, at)| (0..d).map(|c| solution[k][at + c] * layout.unit(c)).collect())
        .collect();
    if reaction.iter().flatten().any(|x| !x.is_finite()) {
        return Err(DynamicsError::NotFinite);
    }
    let balance = balance(&assembly, model.links.len(), &solution);
    // Verified: every link balances under the reactions found.
    if balance.is_nan() || balance > UNBALANCED {
        return Err(DynamicsError::Unbalanced { balance });
    }
    let mut actuators = Vec::new();
    for j in model.inputs() {
        for xi in &twists[j] {
            // An actuated parallelogram also drives its bars.
            let own: f64 = (0..d).map(|c| xi[c] * reaction[j][c]).sum();
            actuators.push(loading.to_newtons(own + demands.bar_work[j]));
        }
    }
    let joints = (0..model.joints.len())
        .map(|j| {
            let w = &reaction[j];
            let (f, m_o) = if layout.planar {
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

/// A twist as the generic dynamics takes it.
fn screw(t: &Twist) -> Screw<f64> {
    Screw {
        w: t.w.into(),
        v: t.v.into(),
    }
}

/// The bodies and loads on S–S links (`lines`, per link) checked against
/// their idle spin: a body not symmetric about the line, or a load with a
/// moment about it, is an error naming the link
/// ([`crate::mass_properties::idle_spin_problem`] and
/// [`crate::mass_properties::idle_spin_load_problem`], which generated
/// code calls too).
fn idle_spins_checked(
    model: &Model,
    loading: &Loading,
    lines: &[Option<([f64; 3], [f64; 3])>],
    size: f64,
) -> Result<(), DynamicsError> {
    let problem = |link: usize, problem: String| DynamicsError::MassProperties {
        body: model.links[link].clone().into(),
        problem,
    };
    for b in &loading.bodies {
        let Carrier::Link(l) = b.carrier else { continue };
        let Some((point, axis)) = lines[l] else { continue };
        let (point, axis) = (Vector3::from(point), Vector3::from(axis));
        if let Some(p) = crate::mass_properties::idle_spin_problem(&b.centroid, &b.inertia, &point, &axis, size) {
            return Err(problem(l, p));
        }
    }
    for load in &loading.loads {
        let Some((point, axis)) = lines[load.link] else {
            continue;
        };
        let (point, axis) = (Vector3::from(point), Vector3::from(axis));
        if let Some(p) = crate::mass_properties::idle_spin_load_problem(&load.at, &load.moment, &point, &axis, size) {
            return Err(problem(load.link, p));
        }
    }
    Ok(())
}

/// SKC `skc`'s kinematic conditioning: σ_r/σ_1 of its passive rows acting
/// on its cut joints' reactions (`G`, [`crate::force_system::tree`]: the
/// transpose of its passive velocity equations), each row scaled to unit
/// length, r their rank less what statics leaves undetermined (where the
/// passive rows are independent and a lower bound is above the least, that
/// bound: [`crate::force_system::conditioning_bound`] from `G`'s inverse
/// for a determined SKC, [`crate::force_system::triangular_bound`] from
/// the rows' QR for an overconstrained one); `None` where it does not reduce.
fn kinematic_conditioning(assembly: &Assembly<'_, f64>, skc: &SkcParts, passive: &[PassiveRow<f64>]) -> Option<f64> {
    let d = assembly.layout.d();
    let tree = assembly.tree(skc, passive.len())?;
    let m = tree.unknowns(d);
    let at: Vec<usize> = passive.iter().map(|r| r.at).collect();
    let mut g = DMatrix::zeros(m, m);
    for (row, column, c, factor) in tree.g_entries(&at, d) {
        g[(row, column)] = factor * passive[row].coefficients[c];
    }
    crate::force_system::unit_rows(g.as_mut_slice(), m, &mut []);
    // A determined SKC far from a change point: the bound from its inverse serves.
    if skc.undetermined == 0 && passive.len() == m {
        let bound = g.clone().try_inverse().map_or(0.0, |inverse| {
            crate::force_system::conditioning_bound(g.as_slice(), inverse.as_slice())
        });
        return Some(crate::force_system::conditioning_from_bound(bound, || {
            crate::force_system::conditioning_of(g.singular_values().as_slice(), m)
        }));
    }
    let rank = m.saturating_sub(skc.undetermined);
    let exact = || crate::force_system::conditioning_of(g.singular_values().as_slice(), rank);
    // Independent passive rows: the bound from the R of their QR serves likewise.
    let p = passive.len();
    if p > 0 && p == rank {
        let r = g.rows(0, p).transpose().qr().r();
        let bound = crate::force_system::triangular_bound(&r);
        return Some(crate::force_system::conditioning_from_bound(bound, exact));
    }
    Some(exact())
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
/// (forces; moments over the mechanism's size), each SKC's reactions
/// `solution` as solved: what generated code checks, link by link.
fn balance(assembly: &Assembly<'_, f64>, n_links: usize, solution: &[Vec<f64>]) -> f64 {
    let mut worst = 0.0f64;
    for l in 1..n_links {
        let (need, on) = assembly.balance(l);
        let components: Vec<Vec<f64>> = need
            .iter()
            .enumerate()
            .map(|(c, x)| {
                let reactions = on.iter().map(|&(j, sign)| {
                    let (k, at) = assembly.place[j];
                    sign * solution[k][at + c]
                });
                std::iter::once(-x).chain(reactions).collect()
            })
            .collect();
        worst = worst.max(crate::force_system::relative_residual(&components));
    }
    worst
}
