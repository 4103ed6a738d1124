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

use crate::frame::Frame;
use crate::kinematics::{link_poses, spanning_tree, ModelError};
use crate::model::{canonical_frame, JointType, Model, Place};
use crate::newton::Output;
use crate::scalar::{cross, unit, Scalar};
use crate::steps::{place_axis, JointGeometry, JointValue};
use nalgebra::{DMatrix, DVector, Dyn, Isometry3, Vector3, SVD};
use std::fmt;

/// A twist: angular velocity and the velocity of the body point at the
/// world origin, world axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Twist {
    /// Angular velocity.
    pub w: Vector3<f64>,
    /// Velocity of the body point at the world origin.
    pub v: Vector3<f64>,
}

impl Twist {
    /// The zero twist.
    pub fn zero() -> Self {
        Twist {
            w: Vector3::zeros(),
            v: Vector3::zeros(),
        }
    }

    /// The velocity of the body point at `p`.
    pub fn at(&self, p: &Vector3<f64>) -> Vector3<f64> {
        self.v + self.w.cross(p)
    }

    /// `self · k`.
    pub fn scale(&self, k: f64) -> Twist {
        Twist {
            w: self.w * k,
            v: self.v * k,
        }
    }

    /// The Lie bracket `[self, other]`: the rate of change of `other`, carried
    /// by a body moving with `self`.
    pub fn bracket(&self, other: &Twist) -> Twist {
        Twist {
            w: self.w.cross(&other.w),
            v: self.w.cross(&other.v) - other.w.cross(&self.v),
        }
    }

    fn add(&self, o: &Twist) -> Twist {
        Twist {
            w: self.w + o.w,
            v: self.v + o.v,
        }
    }

    fn rows(&self) -> [f64; 6] {
        [self.w.x, self.w.y, self.w.z, self.v.x, self.v.y, self.v.z]
    }
}

/// A twist over any [`Scalar`]: the angular velocity `w` and the velocity
/// `v` of the body point at the world origin, world axes, as arrays. The
/// generic dynamics ([`crate::skc_reactions`]) and the code generator's
/// traces compute with it; [`Twist`] is its `f64` form on nalgebra's vectors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Screw<T> {
    /// Angular velocity.
    pub w: [T; 3],
    /// Velocity of the body point at the world origin.
    pub v: [T; 3],
}

impl From<Screw<f64>> for Twist {
    fn from(s: Screw<f64>) -> Twist {
        Twist {
            w: Vector3::from(s.w),
            v: Vector3::from(s.v),
        }
    }
}

/// The unit twists of joint `jg`'s second link relative to its first, per
/// unit rate of each of its variables, world axes, its first link at `pu`
/// and its value `value` (a parallelogram's turn; `None` reads as 0): a
/// turn about the hinge's z axis (R), the guide's unit direction (P, its
/// sign from the side that holds the guide), the other hinge point's rate
/// on its circle (Pa, `d/dθ` of the arm turned by θ), and the three world
/// axes through the ball's centre (S: an S joint's rates are its angular
/// velocity). Written once over [`Scalar`]: [`joint_twists`] evaluates it
/// at `f64`, the code generator traces it.
pub fn unit_twists<T: Scalar>(jg: &JointGeometry<T>, value: Option<JointValue<T>>, pu: &Frame<T>) -> Vec<Screw<T>> {
    let z = T::c(0.0);
    let zero = [z; 3];
    let column = |f: &Frame<T>, i: usize| [f.r[0][i], f.r[1][i], f.r[2][i]];
    match jg.kind {
        JointType::R => {
            let w = pu.rotate(column(&jg.frames[0], 2));
            let p = pu.apply(jg.frames[0].t);
            vec![Screw { w, v: cross(p, w) }]
        }
        JointType::P => {
            let (guide, sign) = match jg.places[0] {
                Place::Line { along, .. } => (along, 1.0),
                _ => (
                    match jg.places[1] {
                        Place::Line { along, .. } => along,
                        other => place_axis(&other),
                    },
                    -1.0,
                ),
            };
            // Both links keep one orientation, so u's axes serve for a guide on v too.
            let d = pu.rotate(unit(guide)).map(|x| x * T::c(sign));
            vec![Screw { w: zero, v: d }]
        }
        JointType::Pa => {
            let (c, s) = match value {
                Some(JointValue::Turn(c, s, _)) => (c, s),
                Some(JointValue::Slide(t)) => (t.cos(), t.sin()),
                None => (T::c(1.0), z),
            };
            // d/dθ of the arm turned by θ about the hinge's z: ẑ × Rz(θ)·a.
            let rate = |f: &Frame<T>, arm: [T; 3]| {
                let local = f.rotate_back(arm);
                let turned = [c * local[0] - s * local[1], s * local[0] + c * local[1], local[2]];
                f.rotate([-turned[1], turned[0], z])
            };
            let (fu, fv) = (&jg.frames[0], &jg.frames[1]);
            let v = match (jg.places[0], jg.places[1]) {
                (Place::Arm { arm, .. }, _) => rate(fu, arm),
                // The arm on v: T_v = T_u·F_u·Trans(−R(θ)a)·F_v⁻¹ in v's (parallel) axes.
                (_, Place::Arm { arm, .. }) => fu.rotate(fv.rotate_back(rate(fv, arm))).map(|x| -x),
                _ => zero,
            };
            vec![Screw {
                w: zero,
                v: pu.rotate(v),
            }]
        }
        JointType::S => {
            // The centre on u stays still: about axis i in world axes through it.
            let c = pu.apply(jg.places[0].at());
            (0..3)
                .map(|i| {
                    let e: [T; 3] = core::array::from_fn(|k| T::c(if k == i { 1.0 } else { 0.0 }));
                    Screw { w: e, v: cross(c, e) }
                })
                .collect()
        }
    }
}

/// The twist of joint `j`'s second link relative to its first, per unit rate
/// of each of its variables, at its values, in world axes given the first
/// link's pose `tu`: [`unit_twists`] at `f64`.
pub fn joint_twists(model: &Model, j: usize, values: &[f64], tu: &Isometry3<f64>) -> Vec<Twist> {
    let joint = &model.joints[j];
    let jg = JointGeometry::new(joint.kind, joint.links, joint.places);
    let value = (joint.kind == JointType::Pa).then(|| JointValue::given(JointType::Pa, values[0]));
    unit_twists(&jg, value, &crate::plan::frame_of(tu))
        .into_iter()
        .map(Twist::from)
        .collect()
}

/// The time derivative of joint `j`'s unit twists (world), given the
/// twist `vu` of its first link and its own rates: a twist mounted on the
/// first link is carried by it (`[V_u, ξ]`); a parallelogram's also turns
/// with its own value; an S joint's are fixed world axes through a centre
/// that moves with the first link.
pub fn joint_twist_rates(
    model: &Model,
    j: usize,
    values: &[f64],
    rates: &[f64],
    tu: &Isometry3<f64>,
    vu: &Twist,
) -> Vec<Twist> {
    let joint = &model.joints[j];
    let xi = joint_twists(model, j, values, tu);
    match joint.kind {
        JointType::S => {
            let c = tu.transform_point(&joint.places[0].at().into()).coords;
            let cd = vu.at(&c);
            (0..3)
                .map(|i| Twist {
                    w: Vector3::zeros(),
                    v: -Vector3::ith(i, 1.0).cross(&cd),
                })
                .collect()
        }
        JointType::Pa => {
            // ∂ξ/∂θ: the arm's rate turns a further quarter turn, ẑ × (ẑ × a) = −a⊥.
            let frame = |p: &Place| canonical_frame(p.at(), p.axis());
            let axis = tu.rotation * (frame(&joint.places[0]).rotation * Vector3::z());
            let own = Twist {
                w: Vector3::zeros(),
                v: axis.cross(&xi[0].v) * rates[0],
            };
            vec![vu.bracket(&xi[0]).add(&own)]
        }
        _ => xi.iter().map(|x| vu.bracket(x)).collect(),
    }
}

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
    let mut prismatic = vec![false; n];
    for (j, joint) in model.joints.iter().enumerate() {
        prismatic[offsets[j]] = joint.kind == JointType::P;
    }
    Ok(Loops {
        prismatic,
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

/// The rates of the declared outputs for a link twist map.
pub fn output_rates(
    model: &Model,
    poses: &[Isometry3<f64>],
    outputs: &[Output],
    rates: &[f64],
    twists: &[Twist],
) -> Vec<f64> {
    let (offsets, _) = model.value_offsets();
    let mut out = Vec::new();
    for o in outputs {
        let (link, local, about) = match *o {
            Output::Pose { link, local, about } => (link, local, about),
            Output::Point { link, local } => (link, local, None),
            Output::Joint(j) => {
                out.push(rates[offsets[j]]);
                continue;
            }
            Output::Parts { link, local, parts } => {
                let p = poses[link].transform_point(&local.into()).coords;
                let v = twists[link].at(&p);
                let w = angle_rates(&poses[link].rotation, &twists[link].w);
                let six = [v.x, v.y, v.z, w[0], w[1], w[2]];
                out.extend(parts.given().map(|i| six[i]));
                continue;
            }
        };
        let p = poses[link].transform_point(&local.into()).coords;
        let v = twists[link].at(&p);
        out.extend_from_slice(if model.planar { &v.as_slice()[..2] } else { v.as_slice() });
        if let Some(k) = about {
            out.push(Vector3::from(k).normalize().dot(&twists[link].w));
        }
    }
    out
}

/// The rates `[ṙx, ṙy, ṙz]` of the angles of `R = R_z(rz)·R_y(ry)·R_x(rx)`
/// for the angular velocity `w` (world frame): `w = ṙz·e_z + ṙy·R_z·e_y +
/// ṙx·R_z·R_y·e_x`, so `ṙx = (w_x cos rz + w_y sin rz)/cos ry`,
/// `ṙy = −w_x sin rz + w_y cos rz`, `ṙz = w_z + ṙx sin ry` (infinite at
/// `ry = ±π/2`, where the angles lose a freedom).
pub fn angle_rates(rotation: &nalgebra::UnitQuaternion<f64>, w: &Vector3<f64>) -> [f64; 3] {
    let (_, ry, rz) = rotation.euler_angles();
    let (sz, cz) = rz.sin_cos();
    let rx_rate = (w.x * cz + w.y * sz) / ry.cos();
    [rx_rate, -w.x * sz + w.y * cz, w.z + rx_rate * ry.sin()]
}

/// Which singularity a configuration is at (Gosselin and Angeles).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Singularity {
    /// Neither.
    None,
    /// Input (inverse): the actuators can move while the outputs stay
    /// (`det J_i = 0`).
    Input,
    /// Output (forward): the outputs can move with the actuators held
    /// (`det J_o = 0`).
    Output,
    /// Both at once.
    Combined,
}

/// The velocity maps at one configuration and how far it is from each
/// singularity.
#[derive(Debug, Clone)]
pub struct Jacobians {
    /// Output rates per unit input rate (rows: outputs, columns: inputs);
    /// `None` at an output singularity.
    pub forward: Option<DMatrix<f64>>,
    /// Input rates per unit output rate (rows: inputs, columns: outputs),
    /// the inverse velocity map; `None` at an input singularity.
    pub inverse: Option<DMatrix<f64>>,
    /// The loop equations' passive columns, σ_min/σ_max (lengths scaled
    /// by the mechanism's size): 0 at an output singularity.
    pub output_sigma: f64,
    /// The loop and output equations over every rate, σ_min/σ_max: 0 when
    /// some motion leaves the outputs still (an input singularity).
    pub input_sigma: f64,
    /// The classification at the threshold [`SINGULAR`].
    pub singularity: Singularity,
}

/// The rows of the outputs' rates, one column per joint rate.
fn output_matrix(model: &Model, l: &Loops, outputs: &[Output]) -> DMatrix<f64> {
    let n = l.a.ncols();
    let mut columns = Vec::with_capacity(n);
    for i in 0..n {
        let mut e = vec![0.0; n];
        e[i] = 1.0;
        let twists: Vec<Twist> = (0..model.links.len()).map(|k| l.link_twist(k, &e)).collect();
        columns.push(output_rates(model, &l.poses, outputs, &e, &twists));
    }
    let rows = columns.first().map_or(0, Vec::len);
    DMatrix::from_fn(rows, n, |r, c| columns[c][r])
}

/// The velocity maps and singularity measures at `values`.
pub fn jacobians(model: &Model, values: &[f64], outputs: &[Output]) -> Result<Jacobians, VelocityError> {
    let l = loops(model, values)?;
    let scale = crate::kinematics::model_scale(model);
    let (passive, output_sigma) = l.passive_svd(scale);
    let c = output_matrix(model, &l, outputs);
    // Loop rows and output rows over every rate, lengths in units of the size.
    let all: Vec<usize> = (0..l.a.ncols()).collect();
    let a = l.scaled_columns(&all, scale);
    let mut stacked = DMatrix::zeros(a.nrows() + c.nrows(), a.ncols());
    stacked.rows_mut(0, a.nrows()).copy_from(&a);
    stacked.rows_mut(a.nrows(), c.nrows()).copy_from(&c);
    let angle_rows = output_angle_rows(model, outputs);
    for (r, angle) in angle_rows.iter().enumerate() {
        if !angle {
            stacked.row_mut(a.nrows() + r).scale_mut(1.0 / scale);
        }
    }
    // A slide's rate per unit of the size in the output rows too (the loop
    // rows have it from `scaled_columns`).
    for (i, &p) in l.prismatic.iter().enumerate() {
        if p {
            stacked.view_mut((a.nrows(), i), (c.nrows(), 1)).scale_mut(scale);
        }
    }
    let rows = stacked.nrows();
    let matrix = stacked.clone();
    let stacked = stacked.svd(true, true);
    let input_sigma = relative_of(&stacked.singular_values);
    let inverse = if input_sigma < SINGULAR {
        None
    } else {
        inverse_map(&l, &stacked, &matrix, rows, a.nrows(), &angle_rows, scale)
    };
    let forward = if output_sigma < SINGULAR {
        None
    } else {
        let f = l.actuated.len();
        let mut jf = DMatrix::zeros(c.nrows(), f);
        for k in 0..f {
            let mut unit = vec![0.0; f];
            unit[k] = 1.0;
            let rates = l.solve_with(
                passive.as_ref(),
                output_sigma,
                &unit,
                &DVector::zeros(l.a.nrows()),
                scale,
            )?;
            jf.set_column(k, &(&c * DVector::from_vec(rates)));
        }
        Some(jf)
    };
    let singularity = match (input_sigma < SINGULAR, output_sigma < SINGULAR) {
        (false, false) => Singularity::None,
        (true, false) => Singularity::Input,
        (false, true) => Singularity::Output,
        (true, true) => Singularity::Combined,
    };
    Ok(Jacobians {
        forward,
        inverse,
        output_sigma,
        input_sigma,
        singularity,
    })
}

/// The input rates per unit output rate: the scaled loop-and-output stack
/// (its decomposition, `rows` rows) solved for every rate with the loop rows'
/// right side zero.
fn inverse_map(
    l: &Loops,
    svd: &SVD<f64, Dyn, Dyn>,
    matrix: &DMatrix<f64>,
    rows: usize,
    loop_rows: usize,
    angle_rows: &[bool],
    scale: f64,
) -> Option<DMatrix<f64>> {
    let tolerance = 1e-13 * svd.singular_values.max();
    let outputs = rows - loop_rows;
    let mut ji = DMatrix::zeros(l.actuated.len(), outputs);
    for k in 0..outputs {
        let mut rhs = DVector::zeros(rows);
        rhs[loop_rows + k] = if angle_rows[k] { 1.0 } else { 1.0 / scale };
        let y = refined_solve(svd, matrix, &rhs, tolerance)?;
        for (r, &i) in l.actuated.iter().enumerate() {
            ji[(r, k)] = y[i] * if l.prismatic[i] { scale } else { 1.0 };
        }
    }
    Some(ji)
}

/// Which output rows are angles.
fn output_angle_rows(model: &Model, outputs: &[Output]) -> Vec<bool> {
    let point = if model.planar { 2 } else { 3 };
    outputs
        .iter()
        .flat_map(|o| match *o {
            Output::Pose { about, .. } => {
                let mut v = vec![false; point];
                if about.is_some() {
                    v.push(true);
                }
                v
            }
            Output::Point { .. } => vec![false; point],
            Output::Parts { parts, .. } => parts.given().map(|i| i >= 3).collect(),
            Output::Joint(j) => vec![model.joints[j].kind != JointType::P],
        })
        .collect()
}
