//! Velocity and acceleration analysis, exact to rounding: the loop-closure
//! equations differentiated in closed form (joint twists from the link poses),
//! never finite differences.
//!
//! A twist `(ω, v)` is a link's angular velocity and the velocity of the
//! link point at the world origin, both in world axes; a point `p` of the
//! link moves at `v + ω × p`. Every joint contributes, per unit rate of each
//! of its variables, the twist of its second link relative to its first;
//! a link's twist is the sum along the spanning tree of [`crate::kinematics`],
//! and each cut joint closes a loop: `V_v − V_u − Σ q̇ ξ = 0` (six rows per
//! loop). With the actuated rates given, the passive rates follow by least
//! squares, which is exact while the passive columns keep full rank (no
//! output singularity). An S–S link turns freely about the line through its
//! two balls, which the loop rows leave open: one more row per such link
//! takes its spin about that line as zero, the state the dynamics assume
//! (`Loops::spins`).
//!
//! An S joint's three rates are its angular velocity about the world x, y, z
//! axes (not the derivative of its rotation vector).
//!
//! This file holds the loop-closure equations ([`Loops`]), their solve and
//! the velocities; the twists and the joints' unit twists are in `twist.rs`,
//! accelerations and the motion of bodies and points in `motion.rs`, the
//! outputs' rates, the Jacobians and the singularities in `jacobians.rs`.

use crate::kinematics::{link_poses, spanning_tree, ModelError};
use crate::model::Model;
use nalgebra::{DMatrix, DVector, Dyn, Isometry3, Vector3, SVD};
use std::fmt;

mod jacobians;
mod motion;
mod twist;

pub use jacobians::{angle_rates, jacobians, output_rates, Jacobians, Singularity};
pub use motion::{
    accelerations, accelerations_on, body_motion, point_acceleration, point_accelerations, point_velocities,
    Accelerations, BarTurn, BodyMotion,
};
pub use twist::{joint_twist_rates, joint_twists, unit_twists, Screw, Twist};

/// Why a velocity or acceleration analysis has no answer.
#[derive(Debug, Clone, PartialEq)]
pub enum VelocityError {
    /// The model or the values are unusable.
    Model(ModelError),
    /// The wrong number of rates.
    BadLength {
        /// What was expected.
        expected: usize,
        /// What was given.
        got: usize,
    },
    /// With the inputs' rates fixed, the passive joints can still move: an
    /// output (forward) singularity, `sigma` the smallest relative singular
    /// value of the passive columns.
    OutputSingular {
        /// σ_min / σ_max of the passive columns.
        sigma: f64,
    },
    /// A body is a bar of joint `joint`, which is not a parallelogram with
    /// an arm (or not a joint of the model).
    NotABar {
        /// The joint named.
        joint: usize,
    },
    /// A link that turns freely about its S–S line carries a body or a
    /// load that would make the forces depend on that turn
    /// ([`crate::mass_properties::Loading::idle_spins_dropped`]).
    IdleSpin {
        /// The link.
        link: String,
        /// What is wrong.
        problem: String,
    },
}

impl fmt::Display for VelocityError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            VelocityError::Model(e) => write!(f, "{e}"),
            VelocityError::BadLength { expected, got } => write!(f, "expected {expected} rates, got {got}"),
            VelocityError::OutputSingular { sigma } => write!(
                f,
                "output singularity: the passive joints move with the inputs held (σ_min/σ_max = {sigma:e})"
            ),
            VelocityError::IdleSpin { link, problem } => write!(f, "link `{link}`: {problem}"),
            VelocityError::NotABar { joint } => {
                write!(
                    f,
                    "a body is a bar of joint {joint}, which is not a parallelogram with an arm"
                )
            }
        }
    }
}

impl std::error::Error for VelocityError {}

impl From<ModelError> for VelocityError {
    fn from(e: ModelError) -> Self {
        VelocityError::Model(e)
    }
}

/// The loop-closure velocity equations at one configuration.
#[derive(Debug, Clone)]
pub struct Loops {
    /// Link poses.
    pub poses: Vec<Isometry3<f64>>,
    /// Per joint, its twists per unit rate (world).
    pub twists: Vec<Vec<Twist>>,
    /// Each link's twist as a linear map of the rates: `paths[l]` lists
    /// (rate index, ±1) along the tree from the base.
    pub paths: Vec<Vec<(usize, f64)>>,
    /// `A q̇ = 0`: six rows per cut joint (the first [`Loops::loop_rows`]),
    /// then one row per S–S link ([`Loops::spins`]), one column per rate.
    pub a: DMatrix<f64>,
    /// How many of `a`'s rows are loop rows: six per cut joint.
    pub loop_rows: usize,
    /// Each S–S link and its line's unit direction (world): the link turns
    /// freely about that line, the loop rows leave its spin undetermined,
    /// and its row in `a` takes it as zero (`ω·â = 0`; `ω̇·â = 0` for the
    /// accelerations), the state the dynamics assume
    /// ([`crate::mass_properties::Loading::idle_spins_dropped`]).
    pub spins: Vec<(usize, Vector3<f64>)>,
    /// The first rate of each joint.
    pub offsets: Vec<usize>,
    /// The rates of the actuated joints, in input order.
    pub actuated: Vec<usize>,
    /// The others.
    pub passive: Vec<usize>,
    /// Which rates are lengths (P joints).
    pub prismatic: Vec<bool>,
}

/// The velocity equations at `values` (joint values as [`Model::value_offsets`]).
pub fn loops(model: &Model, values: &[f64]) -> Result<Loops, VelocityError> {
    let tree = spanning_tree(model)?;
    let poses = link_poses(model, values)?;
    let (offsets, n) = model.value_offsets();
    let twists: Vec<Vec<Twist>> = (0..model.joints.len())
        .map(|j| {
            let joint = &model.joints[j];
            let vals = &values[offsets[j]..offsets[j] + joint.kind.dof()];
            joint_twists(model, j, vals, &poses[joint.links[0]])
        })
        .collect();
    let mut paths: Vec<Vec<(usize, f64)>> = vec![Vec::new(); model.links.len()];
    for &link in &tree.order {
        let Some(j) = tree.parent[link] else { continue };
        let joint = &model.joints[j];
        let (parent, sign) = if joint.links[1] == link {
            (joint.links[0], 1.0)
        } else {
            (joint.links[1], -1.0)
        };
        let mut p = paths[parent].clone();
        p.extend((0..joint.kind.dof()).map(|k| (offsets[j] + k, sign)));
        paths[link] = p;
    }
    let spins: Vec<(usize, Vector3<f64>)> = (0..model.links.len())
        .filter_map(|l| crate::mass_properties::idle_spin_line(model, l).map(|(_, axis)| (l, poses[l].rotation * axis)))
        .collect();
    let loop_rows = 6 * tree.cut.len();
    let mut a = DMatrix::zeros(loop_rows + spins.len(), n);
    for (row, &c) in tree.cut.iter().enumerate() {
        let [u, v] = model.joints[c].links;
        let mut add = |col: usize, t: &Twist, k: f64| {
            for (i, x) in t.rows().iter().enumerate() {
                a[(6 * row + i, col)] += k * x;
            }
        };
        for &(col, s) in &paths[v] {
            let t = twist_of_rate(&twists, &offsets, col);
            add(col, &t, s);
        }
        for &(col, s) in &paths[u] {
            let t = twist_of_rate(&twists, &offsets, col);
            add(col, &t, -s);
        }
        for (k, t) in twists[c].iter().enumerate() {
            add(offsets[c] + k, t, -1.0);
        }
    }
    // An S–S link's spin about its line: `â·ω = 0`.
    for (k, (link, axis)) in spins.iter().enumerate() {
        for &(col, sign) in &paths[*link] {
            a[(loop_rows + k, col)] += sign * twist_of_rate(&twists, &offsets, col).w.dot(axis);
        }
    }
    let mut actuated = Vec::new();
    for j in model.inputs() {
        actuated.extend(offsets[j]..offsets[j] + model.joints[j].kind.dof());
    }
    let passive = (0..n).filter(|i| !actuated.contains(i)).collect();
    Ok(Loops {
        prismatic: model.length_values(),
        poses,
        twists,
        paths,
        a,
        loop_rows,
        spins,
        offsets,
        actuated,
        passive,
    })
}

fn twist_of_rate(twists: &[Vec<Twist>], offsets: &[usize], col: usize) -> Twist {
    let j = offsets.partition_point(|&o| o <= col) - 1;
    twists[j][col - offsets[j]]
}

impl Loops {
    /// The twist of `link` for the rates `qd`.
    pub fn link_twist(&self, link: usize, qd: &[f64]) -> Twist {
        self.paths[link].iter().fold(Twist::zero(), |acc, &(col, s)| {
            acc.add(&twist_of_rate(&self.twists, &self.offsets, col).scale(s * qd[col]))
        })
    }

    /// Relative smallest singular value of the passive columns (0 at an
    /// output singularity), lengths scaled by `scale`.
    pub fn passive_sigma(&self, scale: f64) -> f64 {
        self.passive_svd(scale).1
    }

    /// The passive columns' SVD (`None` without passive joints) and their
    /// relative smallest singular value: one decomposition for the measure
    /// and for every solve at this configuration.
    fn passive_svd(&self, scale: f64) -> (Option<SVD<f64, Dyn, Dyn>>, f64) {
        if self.passive.is_empty() {
            return (None, 1.0);
        }
        let svd = self.scaled_columns(&self.passive, scale).svd(true, true);
        let sigma = relative_of(&svd.singular_values);
        (Some(svd), sigma)
    }

    /// `a` in the units of the loop residual: a length's rate per unit of
    /// the size `scale` (like the angles' radians), position rows in sizes.
    pub fn scaled(&self, scale: f64) -> DMatrix<f64> {
        self.scaled_columns(&(0..self.a.ncols()).collect::<Vec<_>>(), scale)
    }

    fn scaled_columns(&self, cols: &[usize], scale: f64) -> DMatrix<f64> {
        let mut m = DMatrix::zeros(self.a.nrows(), cols.len());
        for (k, &c) in cols.iter().enumerate() {
            // A length rate per unit of the size, like the angles' radians.
            let unit = if self.prismatic[c] { scale } else { 1.0 };
            m.set_column(k, &(self.a.column(c) * unit));
        }
        // Position rows in units of the mechanism's size, as the loop residual.
        for r in 0..self.loop_rows {
            if r % 6 >= 3 {
                m.row_mut(r).scale_mut(1.0 / scale);
            }
        }
        m
    }

    /// Every joint rate per unit rate of each input, one vector per input:
    /// the columns of the map from the inputs' rates to every rate (the
    /// virtual velocities of the principle of virtual work).
    pub fn input_columns(&self, scale: f64) -> Result<Vec<Vec<f64>>, VelocityError> {
        let (svd, sigma) = self.passive_svd(scale);
        let zero = DVector::zeros(self.a.nrows());
        (0..self.actuated.len())
            .map(|k| {
                let unit: Vec<f64> = (0..self.actuated.len()).map(|i| f64::from(u8::from(i == k))).collect();
                self.solve_with(svd.as_ref(), sigma, &unit, &zero, scale)
            })
            .collect()
    }

    /// Every rate from the actuated ones (`input_rates` in input order),
    /// with `bias` added to the right-hand side (`A q̇ = −bias`; zero for
    /// velocities, the velocity-product terms for accelerations), on the
    /// passive columns' decomposition ([`Loops::passive_svd`]).
    fn solve_with(
        &self,
        svd: Option<&SVD<f64, Dyn, Dyn>>,
        sigma: f64,
        input_rates: &[f64],
        bias: &DVector<f64>,
        scale: f64,
    ) -> Result<Vec<f64>, VelocityError> {
        if input_rates.len() != self.actuated.len() {
            return Err(VelocityError::BadLength {
                expected: self.actuated.len(),
                got: input_rates.len(),
            });
        }
        let n = self.a.ncols();
        let mut q = vec![0.0; n];
        for (&i, &x) in self.actuated.iter().zip(input_rates) {
            q[i] = x;
        }
        let mut rhs = -bias.clone();
        for (&i, &x) in self.actuated.iter().zip(input_rates) {
            rhs -= self.a.column(i) * x;
        }
        let Some(svd) = svd else {
            return Ok(q);
        };
        for r in 0..self.loop_rows {
            if r % 6 >= 3 {
                rhs[r] /= scale;
            }
        }
        if sigma < SINGULAR {
            return Err(VelocityError::OutputSingular { sigma });
        }
        let smax = svd.singular_values.max();
        let matrix = self.scaled_columns(&self.passive, scale);
        let x = refined_solve(svd, &matrix, &rhs, 1e-13 * smax).ok_or(VelocityError::OutputSingular { sigma })?;
        for (k, &i) in self.passive.iter().enumerate() {
            q[i] = x[k] * if self.prismatic[i] { scale } else { 1.0 };
        }
        Ok(q)
    }
}

/// Below this relative singular value a configuration counts as singular.
pub const SINGULAR: f64 = 1e-10;

/// `svd.solve(rhs, tolerance)` (singular values above `tolerance`) refined
/// against `matrix`, the matrix `svd` decomposes: `x ← x + A⁺ (rhs − A x)`
/// while the residual falls, at most 4 steps. nalgebra's SVD does not
/// always reproduce its matrix to rounding (dimforge/nalgebra#1172; 4.6e-7
/// of ‖A‖ on one of the 3-UPU's reaction systems, docs/dynamics.md), and an
/// answer from it alone keeps only the digits it does.
fn refined_solve(
    svd: &SVD<f64, Dyn, Dyn>,
    matrix: &DMatrix<f64>,
    rhs: &DVector<f64>,
    tolerance: f64,
) -> Option<DVector<f64>> {
    let mut x = svd.solve(rhs, tolerance).ok()?;
    let mut r = rhs - matrix * &x;
    let mut last = r.norm_squared();
    for _ in 0..4 {
        if last.is_nan() || last <= 0.0 {
            break;
        }
        let dx = svd.solve(&r, tolerance).ok()?;
        let trial = &x + dx;
        let now_r = rhs - matrix * &trial;
        let now = now_r.norm_squared();
        if now.is_nan() || now >= last {
            break;
        }
        (x, r, last) = (trial, now_r, now);
    }
    Some(x)
}

/// σ_min/σ_max from a decomposition's singular values (min(rows, columns)
/// of them); zero rows (the out-of-plane rows of a planar loop) do not
/// change them.
fn relative_of(s: &DVector<f64>) -> f64 {
    if s.is_empty() {
        return 1.0;
    }
    let max = s.max();
    if max.is_nan() || max <= 0.0 {
        return 0.0;
    }
    s.iter().fold(f64::INFINITY, |a, &b| a.min(b)) / max
}

/// A configuration's rates: every joint's, every link's twist.
#[derive(Debug, Clone)]
pub struct Velocities {
    /// Every joint rate (as [`Model::value_offsets`]).
    pub rates: Vec<f64>,
    /// Every link's twist.
    pub twists: Vec<Twist>,
    /// σ_min/σ_max of the passive columns (lengths over the mechanism's
    /// size; 1 without passive joints): the kinematic conditioning c. Next
    /// to a change point, where two assemblies meet, a position solved
    /// there carries ε/c, its rates ε/c² and its accelerations ε/c³
    /// (docs/dynamics.md): below
    /// [`crate::force_system::LEAST_AT_REST`] the rates, below
    /// [`crate::force_system::LEAST_IN_MOTION`] the accelerations keep
    /// fewer than six digits. Inverse dynamics refuses there; these
    /// analyses return the number for the caller to judge.
    pub conditioning: f64,
}

/// Every joint rate and link twist from the inputs' rates.
pub fn velocities(model: &Model, values: &[f64], input_rates: &[f64]) -> Result<Velocities, VelocityError> {
    let l = loops(model, values)?;
    let scale = crate::kinematics::model_scale(model);
    let (svd, conditioning) = l.passive_svd(scale);
    let rates = l.solve_with(
        svd.as_ref(),
        conditioning,
        input_rates,
        &DVector::zeros(l.a.nrows()),
        scale,
    )?;
    let twists = (0..model.links.len()).map(|k| l.link_twist(k, &rates)).collect();
    Ok(Velocities {
        rates,
        twists,
        conditioning,
    })
}
