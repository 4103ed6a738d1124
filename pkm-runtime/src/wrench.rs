//! Wrench analysis at a solved configuration: each limb's actuation and
//! constraint wrenches, found as null spaces of its joints' twists under the
//! reciprocal product, and their stack, the m×6 wrench Jacobian `J`
//! (docs/stiffness.md).
//!
//! # Conventions
//! - A twist `(ω, v)` is as in [`crate::velocity`]: angular velocity and the
//!   velocity of the body point at the base origin, base axes.
//! - A wrench `(f, m)` is a force and its moment about the base origin, base
//!   axes. Its reciprocal product with a twist is `f·v + m·ω`, the power it
//!   does on that motion.
//! - A limb is a path of joints from the base link to the platform link
//!   whose inner links carry no other joint ([`limbs`]). A U joint is two
//!   revolutes (its cross is an inner link), an S joint three rotations about
//!   its centre, a P joint one translation, a parallelogram (Pa) one
//!   translation.
//! - The constraint wrenches of a limb are reciprocal to every joint twist of
//!   it; the actuation wrench of an actuated joint is reciprocal to every
//!   other twist of its limb (the passive ones and any other actuated one),
//!   not to its own. A row of `J` applied to a small platform displacement
//!   `δX = (δp, δθ)` (`δp` the displacement of the platform point at the base
//!   origin, `δθ` the small rotation) is `f·δp + m·δθ`.
//!
//! # Canonical basis
//! The null spaces are those of the SVD of the limb's twists (decided by a
//! pivoted QR where it certifies the SVD's rank, [`qr`]), each written at
//! the limb's distal joint centre `p` (the point of its joint on the
//! platform) and made dimensionless: `t̂ = (v + ω × p, s·ω)` normalised, `s`
//! the model's size ([`crate::kinematics::model_scale`]); a wrench in the
//! same coordinates is `ŵ = (f, m_p / s)`, `m_p = m − p × f` its moment about
//! `p`, and the product is `ŵ·t̂`. A singular value counts as zero below
//! [`RANK_TOL`] times the largest. In these coordinates:
//! - the constraint space splits into its couples (`f = 0`) and the
//!   orthogonal rest (forces, through `p` where they can be); each part's
//!   basis is built greedily from the projections of the base axes (x, y, z
//!   forces, then x, y, z moments about `p`): the longest projection first,
//!   then the longest of what is orthogonal to the ones chosen. A force so
//!   found through `p` is the force along that line; with one constraint
//!   force (a 3-RPS leg) it is the force along the R axis through the S
//!   centre (seed 004 eq. 10), its sign making its largest component along
//!   the chosen axis positive.
//! - an actuation wrench is the part of its space orthogonal to the limb's
//!   constraint space: for an R-P-S, U-P-S or U-P-U leg, the force along the
//!   leg through the distal centre (seed 004 eq. 8), for an R–S leg on a
//!   slide (3-PRS) the force along the R–S link. Its sign makes its product
//!   with its joint's unit twist (the transmission, [`Row::transmission`])
//!   positive, so that with a unit force the row is `d(leg length)/dX` for
//!   an actuated slide along the leg.
//!
//! Each wrench is normalised: a force to unit `f`, a couple (`f = 0`) to unit
//! `m`.
//!
//! # Singularities
//! `J` (rows scaled to `(f, m/s)` for forces, `(0, m)` for couples) must
//! have rank 6. When it has not, the constraint wrenches of all limbs either
//! span less than `6 − (number of actuation wrenches)` — a constraint
//! singularity: the platform gains a freedom with the actuators locked — or
//! they do and the actuation wrenches are dependent given them: an actuation
//! singularity. A limb whose actuated joint's twist falls in the span of its
//! other joints' twists has no actuation wrench (the actuator cannot move its
//! limb): an actuation singularity of that limb.

use crate::bounded::{Bounded, Full};
use crate::kinematics::{joint_point, model_scale};
use crate::model::{JointType, Model};
use crate::velocity::{joint_twists, Twist};
use nalgebra::{DMatrix, Isometry3, Matrix6, SMatrix, Vector3, Vector6};
use qr::PivotedQr;
use std::fmt;

/// Relative singular value below which a direction counts as lost (limb
/// twist matrices with unit columns, and the scaled `J`).
pub const RANK_TOL: f64 = 1e-9;

/// The most limbs a wrench analysis takes.
pub const MAX_LIMBS: usize = 8;
/// The most joints on one limb.
pub const MAX_LIMB_JOINTS: usize = 8;
/// The most joint variables on one limb (an S joint has three).
pub const MAX_LIMB_VARIABLES: usize = 12;
/// The most rows of `J`: a limb's wrenches are at most six (its
/// constraint wrenches span `6 − rank` of its twists, and each actuation
/// wrench needs an actuated twist independent of the others).
pub const MAX_ROWS: usize = 6 * MAX_LIMBS;

/// A wrench: a force and its moment about the base origin, base axes.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Wrench {
    /// The force.
    pub f: Vector3<f64>,
    /// Its moment about the base origin.
    pub m: Vector3<f64>,
}

impl Wrench {
    /// The reciprocal product `f·v + m·ω` with a twist: the power this
    /// wrench does on that motion.
    pub fn on(&self, t: &Twist) -> f64 {
        self.f.dot(&t.v) + self.m.dot(&t.w)
    }

    /// The moment about the point `p`: `m − p × f`.
    pub fn moment_about(&self, p: &Vector3<f64>) -> Vector3<f64> {
        self.m - p.cross(&self.f)
    }

    /// `[f, m]`: the row of `J`.
    pub fn row(&self) -> [f64; 6] {
        [self.f.x, self.f.y, self.f.z, self.m.x, self.m.y, self.m.z]
    }

    /// Whether it is a couple (`f = 0`).
    pub fn is_couple(&self) -> bool {
        self.f == Vector3::zeros()
    }
}

/// What a row of `J` is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RowKind {
    /// The actuation wrench of actuated joint `joint`'s variable `variable`
    /// (0 but for an actuated S joint).
    Actuation {
        /// The joint.
        joint: usize,
        /// Its variable.
        variable: usize,
    },
    /// A constraint force.
    ConstraintForce,
    /// A constraint couple.
    ConstraintCouple,
}

/// A row of `J`: a wrench, its kind and its limb.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Row {
    /// The wrench (normalised).
    pub wrench: Wrench,
    /// Its kind.
    pub kind: RowKind,
    /// Its limb (index in [`WrenchAnalysis::limbs`]).
    pub limb: usize,
    /// For an actuation wrench, its product with its joint's unit twist
    /// (positive; 1 for a force along an actuated slide); 0 for a
    /// constraint. A joint rate `q̇` of it gives the row's rate `transmission · q̇`.
    pub transmission: f64,
}

impl Default for Row {
    fn default() -> Self {
        Row {
            wrench: Wrench::default(),
            kind: RowKind::ConstraintForce,
            limb: 0,
            transmission: 0.0,
        }
    }
}

/// A limb: a serial path of joints from the base to the platform.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Limb {
    /// Its joints, from the base to the platform.
    pub joints: Bounded<usize, MAX_LIMB_JOINTS>,
    /// The world position of its distal joint's point (the joint on the
    /// platform: an S joint's centre, a U's centre).
    pub distal: Vector3<f64>,
    /// The world position of the proximal centre of its leg: the point of
    /// the first R or S joint met going from the distal joint towards the
    /// base whose point is not the distal centre (P and Pa joints have no
    /// centre); `None` if there is none.
    pub proximal: Option<Vector3<f64>>,
}

impl Limb {
    /// The leg length `L = |distal − proximal|`, if the limb has a proximal centre.
    pub fn length(&self) -> Option<f64> {
        self.proximal.map(|p| (self.distal - p).norm())
    }
}

/// The wrench analysis at one configuration (held inline: no heap).
#[derive(Debug, Clone, PartialEq)]
pub struct WrenchAnalysis {
    /// The limbs, ordered by their base joint's declaration order.
    pub limbs: Bounded<Limb, MAX_LIMBS>,
    /// The rows of `J`: every actuation wrench (limb by limb, joints in limb
    /// order), then every constraint wrench (limb by limb, couples first).
    pub rows: Bounded<Row, MAX_ROWS>,
    /// The number of actuation rows (the first ones).
    pub actuation: usize,
    /// The size scale `s` the rank tests use (mm for a model in mm).
    pub scale: f64,
}

impl WrenchAnalysis {
    /// σ_min/σ_max of the scaled `J` (see the module's header), by its SVD
    /// when asked (the analysis itself certifies `J`'s rank by a QR).
    pub fn sigma(&self) -> f64 {
        scaled_rank(&self.rows, self.scale).1
    }

    /// `J`: one row `[f, m]` per wrench (m×6).
    pub fn jacobian(&self) -> DMatrix<f64> {
        DMatrix::from_fn(self.rows.len(), 6, |r, c| self.rows[r].wrench.row()[c])
    }

    /// `J` with the moments taken about `point` instead of the base origin:
    /// the rows `[f, m − point × f]`, which act on the displacement of the
    /// platform point at `point`.
    pub fn jacobian_at(&self, point: [f64; 3]) -> DMatrix<f64> {
        let p = Vector3::from(point);
        DMatrix::from_fn(self.rows.len(), 6, |r, c| {
            let w = &self.rows[r].wrench;
            if c < 3 {
                w.f[c]
            } else {
                w.moment_about(&p)[c - 3]
            }
        })
    }
}

/// Why a wrench analysis has no answer.
#[derive(Debug, Clone, PartialEq)]
pub enum WrenchError {
    /// The input does not fit the model (lengths, the platform index,
    /// non-finite poses or values).
    BadInput {
        /// What is wrong.
        what: String,
    },
    /// The model's links and joints are not limbs from the base to the
    /// platform: `link` is where the structure breaks.
    NotLimbs {
        /// The link.
        link: usize,
        /// What is wrong there.
        what: &'static str,
    },
    /// Constraint singularity: the limbs' constraint wrenches span only
    /// `rank` of the `needed` = 6 − (actuation wrenches) directions; the
    /// platform moves with the actuators locked.
    ConstraintSingularity {
        /// The constraint wrenches' rank.
        rank: usize,
        /// What they must span.
        needed: usize,
        /// σ_min/σ_max of the scaled constraint rows (0 without any).
        sigma: f64,
    },
    /// Actuation singularity: the actuation wrenches are dependent given the
    /// constraint wrenches (`limb: None`), or limb `limb`'s actuated joint
    /// moves within its other joints' twists and has no actuation wrench.
    ActuationSingularity {
        /// The limb, where one limb is the cause.
        limb: Option<usize>,
        /// σ_min/σ_max of the scaled `J`, or for one limb the product of its
        /// best candidate wrench with its actuated twist in the
        /// dimensionless coordinates (0 where there is none).
        sigma: f64,
    },
}

impl fmt::Display for WrenchError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            WrenchError::BadInput { what } => write!(f, "bad input: {what}"),
            WrenchError::NotLimbs { link, what } => write!(f, "not limbs from base to platform at link {link}: {what}"),
            WrenchError::ConstraintSingularity { rank, needed, sigma } => write!(
                f,
                "constraint singularity: the constraint wrenches span {rank} of the {needed} directions needed \
                 (σ_min/σ_max = {sigma:e})"
            ),
            WrenchError::ActuationSingularity { limb: Some(l), sigma } => write!(
                f,
                "actuation singularity: limb {l}'s actuated joint moves within its other joints' twists ({sigma:e})"
            ),
            WrenchError::ActuationSingularity { limb: None, sigma } => write!(
                f,
                "actuation singularity: the actuation wrenches are dependent given the constraints \
                 (σ_min/σ_max = {sigma:e})"
            ),
        }
    }
}

impl std::error::Error for WrenchError {}

fn bad(what: String) -> WrenchError {
    WrenchError::BadInput { what }
}

/// `x` appended to `list`, or a [`WrenchError::BadInput`] saying that there
/// are more `what` than it holds.
fn put<T: Copy + Default, const N: usize>(list: &mut Bounded<T, N>, x: T, what: &str) -> Result<(), WrenchError> {
    list.push(x)
        .map_err(|Full { capacity }| bad(format!("more than {capacity} {what}")))
}

/// The limbs of `model` from the base (link 0) to `platform`: for each joint
/// on the base, in declaration order, the path that follows it through
/// links with exactly two joints until the platform. Every joint must be on
/// one limb.
pub fn limbs(model: &Model, platform: usize) -> Result<Vec<Vec<usize>>, WrenchError> {
    let n = model.links.len();
    if platform == 0 || platform >= n {
        return Err(bad(format!(
            "platform link {platform} is not a link of the model other than the base"
        )));
    }
    let mut at: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (j, joint) in model.joints.iter().enumerate() {
        let [u, v] = joint.links;
        if u >= n || v >= n {
            return Err(bad(format!("joint {} names a link that does not exist", joint.name)));
        }
        if u == v {
            return Err(WrenchError::NotLimbs {
                link: u,
                what: "a joint connects the link to itself",
            });
        }
        at[u].push(j);
        at[v].push(j);
    }
    let mut used = vec![false; model.joints.len()];
    let mut out = Vec::new();
    for &first in &at[0] {
        if used[first] {
            continue;
        }
        let mut path = vec![first];
        used[first] = true;
        let other = |j: usize, l: usize| {
            let [u, v] = model.joints[j].links;
            if u == l {
                v
            } else {
                u
            }
        };
        let mut link = other(first, 0);
        let mut last = first;
        while link != platform {
            if link == 0 {
                return Err(WrenchError::NotLimbs {
                    link,
                    what: "a chain from the base returns to it without reaching the platform",
                });
            }
            if at[link].len() != 2 {
                return Err(WrenchError::NotLimbs {
                    link,
                    what: "an inner link of a limb must carry exactly two joints",
                });
            }
            let next = if at[link][0] == last { at[link][1] } else { at[link][0] };
            if used[next] {
                return Err(WrenchError::NotLimbs {
                    link,
                    what: "a joint is on two limbs",
                });
            }
            used[next] = true;
            path.push(next);
            link = other(next, link);
            last = next;
        }
        out.push(path);
    }
    if let Some(j) = used.iter().position(|u| !u) {
        return Err(WrenchError::NotLimbs {
            link: model.joints[j].links[0],
            what: "a joint is on no limb from the base to the platform",
        });
    }
    if out.is_empty() {
        return Err(WrenchError::NotLimbs {
            link: 0,
            what: "no joint on the base",
        });
    }
    Ok(out)
}

/// A 6×6 matrix with the singular values and right singular vectors of
/// the n×6 matrix whose rows are `row(0..n)`: those rows with zero rows
/// added for n ≤ 6; else the `R` of its QR, folded in six rows at a time
/// (`AᵀA = RᵀR`). On the stack.
fn six_by_six(n: usize, row: impl Fn(usize) -> Vector6<f64>) -> Matrix6<f64> {
    let mut acc = Matrix6::from_fn(|r, c| if r < n { row(r)[c] } else { 0.0 });
    let mut next = 6;
    while next < n {
        let stacked = SMatrix::<f64, 12, 6>::from_fn(|r, c| match r {
            0..6 => acc[(r, c)],
            _ if next + r - 6 < n => row(next + r - 6)[c],
            _ => 0.0,
        });
        acc = stacked.qr().r();
        next += 6;
    }
    acc
}

/// An orthonormal basis of the vectors `x` with `rows · x = 0` (6 columns):
/// `Q`'s last columns from a pivoted QR where its rank is certified
/// ([`qr`]), else [`svd_null_space`]'s. Either is the space of the right
/// singular vectors whose singular value is at most [`RANK_TOL`] times the
/// largest.
fn null_space(rows: &[Vector6<f64>]) -> Bounded<Vector6<f64>, 6> {
    if !rows.is_empty() && rows.len() <= MAX_LIMB_VARIABLES {
        let (qr, rank) = PivotedQr::<MAX_LIMB_VARIABLES>::relative(rows.len(), |j| rows[j].into());
        if let Some(r) = rank {
            let mut out = Bounded::new();
            for j in r..6 {
                // Six at most: never full.
                let _ = out.push(Vector6::from(qr.column(j)));
            }
            return out;
        }
    }
    svd_null_space(rows)
}

/// An orthonormal basis of the vectors `x` with `rows · x = 0` (6 columns),
/// by SVD: the right singular vectors whose singular value is at most
/// [`RANK_TOL`] times the largest (every one if all are zero).
fn svd_null_space(rows: &[Vector6<f64>]) -> Bounded<Vector6<f64>, 6> {
    let svd = six_by_six(rows.len(), |r| rows[r]).svd(false, true);
    let vt = svd.v_t.expect("v_t requested");
    let smax = svd.singular_values.max();
    let mut out = Bounded::new();
    for i in (0..6).filter(|&i| svd.singular_values[i] <= RANK_TOL * smax) {
        // Six at most: never full.
        let _ = out.push(Vector6::from_fn(|c, _| vt[(i, c)]));
    }
    out
}

/// `x` without its components along the orthonormal `basis`.
fn reject(x: &Vector6<f64>, basis: &[Vector6<f64>]) -> Vector6<f64> {
    basis.iter().fold(*x, |acc, b| acc - b * b.dot(&acc))
}

/// A canonical orthonormal basis of the span of the orthonormal `space`:
/// greedily the longest projection of the unit vectors `axes` onto what is
/// orthogonal to the vectors already chosen.
fn canonical(space: &[Vector6<f64>], axes: [usize; 3]) -> Bounded<Vector6<f64>, 6> {
    let mut chosen: Bounded<Vector6<f64>, 6> = Bounded::new();
    for _ in 0..space.len() {
        let projections = axes.map(|a| {
            let e = Vector6::ith(a, 1.0);
            let p = space.iter().fold(Vector6::zeros(), |acc, q| acc + q * q.dot(&e));
            reject(&p, &chosen)
        });
        // The first of the longest, ties (to 1e-9) to the earlier axis, so
        // that rounding does not reorder equal projections.
        let longest = projections.iter().map(|p| p.norm()).fold(0.0, f64::max);
        let best = *projections
            .iter()
            .find(|p| p.norm() >= (1.0 - 1e-9) * longest)
            .expect("a longest projection");
        if best.norm() <= RANK_TOL {
            break;
        }
        // At most `space.len()` ≤ 6: never full.
        let _ = chosen.push(best.normalize());
    }
    chosen
}

/// The constraint space `c` (orthonormal) split into a canonical basis of
/// its couples, then one of the rest (see the module's header).
fn constraint_basis(c: &[Vector6<f64>]) -> (Bounded<Vector6<f64>, 6>, Bounded<Vector6<f64>, 6>) {
    let (mut couples, mut forces) = (Bounded::<Vector6<f64>, 6>::new(), Bounded::<Vector6<f64>, 6>::new());
    let k = c.len();
    // Where a pivoted QR of the force parts' three rows (k-vectors)
    // certifies their rank r: Q's first r columns combine c into the
    // forces, its others into the couples.
    if (1..=6).contains(&k) {
        let qr = PivotedQr::<3>::new(3, |i| std::array::from_fn(|kk| if kk < k { c[kk][i] } else { 0.0 }));
        if let Some(r) = qr.rank(RANK_TOL, RANK_TOL) {
            for j in 0..k {
                let q = qr.column(j);
                let combo = (0..k).fold(Vector6::zeros(), |acc, kk| acc + c[kk] * q[kk]);
                // At most six: never full.
                let _ = if j < r { forces.push(combo) } else { couples.push(combo) };
            }
            return (canonical(&couples, [3, 4, 5]), canonical(&forces, [0, 1, 2]));
        }
    }
    // Else by SVD. The force parts as rows of a c-column matrix (at least 3 × c): its
    // null space gives the couples. One arm per size, on the stack.
    macro_rules! split {
        ($($k:literal $r:literal),*) => {
            match c.len() {
                $($k => {
                    let f = SMatrix::<f64, $r, $k>::from_fn(|r, k| if r < 3 { c[k][r] } else { 0.0 });
                    let svd = f.svd(false, true);
                    let vt = svd.v_t.expect("v_t requested");
                    for i in 0..$k {
                        let combo = (0..$k).fold(Vector6::zeros(), |acc, k| acc + c[k] * vt[(i, k)]);
                        // The basis is orthonormal, so the singular values
                        // are at most 1. At most six: never full.
                        let _ = if svd.singular_values[i] <= RANK_TOL {
                            couples.push(combo)
                        } else {
                            forces.push(combo)
                        };
                    }
                })*
                // No constraint (or, impossibly, more than six).
                _ => {}
            }
        };
    }
    split!(1 3, 2 3, 3 3, 4 4, 5 5, 6 6);
    (canonical(&couples, [3, 4, 5]), canonical(&forces, [0, 1, 2]))
}

/// A wrench from its dimensionless coordinates `ŵ = (f, m_p/s)` at `p`,
/// normalised: unit `f`, or unit `m` for a couple.
fn from_hat(w: &Vector6<f64>, p: &Vector3<f64>, s: f64, couple: bool) -> Wrench {
    let f = Vector3::new(w[0], w[1], w[2]);
    let mp = Vector3::new(w[3], w[4], w[5]) * s;
    if couple {
        Wrench {
            f: Vector3::zeros(),
            m: mp.normalize(),
        }
    } else {
        let k = 1.0 / f.norm();
        Wrench {
            f: f * k,
            m: (mp + p.cross(&f)) * k,
        }
    }
}

/// The wrench analysis of `model` at the configuration `solution` (link
/// poses and joint values as [`crate::plan::run`] returns them; an S
/// joint's value is not read) with `platform` the platform link.
pub fn analyse(
    model: &Model,
    solution: &crate::plan::Solution,
    platform: usize,
) -> Result<WrenchAnalysis, WrenchError> {
    analyse_poses(model, &solution.poses, &solution.values, platform)
}

/// [`analyse`] from the link poses and the per-joint values (one per joint,
/// as [`crate::plan::Solution::values`]; only a parallelogram's is read,
/// and an S joint's, which has no one value, need not be finite).
pub fn analyse_poses(
    model: &Model,
    poses: &[Isometry3<f64>],
    values: &[f64],
    platform: usize,
) -> Result<WrenchAnalysis, WrenchError> {
    if poses.len() != model.links.len() {
        return Err(bad(format!(
            "{} link poses for {} links",
            poses.len(),
            model.links.len()
        )));
    }
    if values.len() != model.joints.len() {
        return Err(bad(format!(
            "{} joint values for {} joints",
            values.len(),
            model.joints.len()
        )));
    }
    if let Some(l) = poses.iter().position(|p| {
        !(p.translation.vector.iter().all(|x| x.is_finite()) && p.rotation.coords.iter().all(|x| x.is_finite()))
    }) {
        return Err(bad(format!("the pose of link {} is not finite", model.links[l])));
    }
    // An S joint has no one value (the interpreter leaves it NaN): not read.
    if let Some(j) = (0..values.len()).find(|&j| model.joints[j].kind != JointType::S && !values[j].is_finite()) {
        return Err(bad(format!(
            "the value of joint {} is not finite",
            model.joints[j].name
        )));
    }
    let paths = limbs(model, platform)?;
    let mut inputs = Vec::with_capacity(paths.len());
    for path in &paths {
        let last = *path.last().expect("a limb has a joint");
        let joints = Bounded::from_slice(path)
            .map_err(|Full { capacity }| bad(format!("a limb has more than {capacity} joints")))?;
        let mut centres = Bounded::new();
        for j in centre_joints(model, path) {
            put(
                &mut centres,
                Vector3::from(joint_point(model, poses, j)),
                "joints on a limb",
            )?;
        }
        let mut variables = Bounded::new();
        for &j in path {
            let tu = &poses[model.joints[j].links[0]];
            for (k, twist) in joint_twists(model, j, &values[j..=j], tu).into_iter().enumerate() {
                if !(twist.w.iter().chain(twist.v.iter()).all(|x| x.is_finite())) {
                    return Err(bad(format!("joint {}'s twist is not finite", model.joints[j].name)));
                }
                let variable = LimbVariable {
                    joint: j,
                    variable: k,
                    actuated: model.joints[j].actuated,
                    twist,
                };
                put(&mut variables, variable, "joint variables on a limb")?;
            }
        }
        inputs.push(LimbTwists {
            joints,
            variables,
            distal: Vector3::from(joint_point(model, poses, last)),
            centres,
        });
    }
    analyse_twists(&inputs, model_scale(model))
}

/// The joints of the limb `path` whose points are the candidates for its
/// proximal centre ([`LimbTwists::centres`]): its R and S joints but the
/// distal one, from the distal end towards the base.
pub fn centre_joints<'a>(model: &'a Model, path: &'a [usize]) -> impl Iterator<Item = usize> + 'a {
    path.iter()
        .rev()
        .skip(1)
        .copied()
        .filter(|&j| matches!(model.joints[j].kind, JointType::R | JointType::S))
}

/// One joint variable of a limb at a configuration: its unit twist and
/// whose it is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LimbVariable {
    /// The joint.
    pub joint: usize,
    /// Which of its variables (0 but for an S or U joint's).
    pub variable: usize,
    /// Whether the joint is actuated.
    pub actuated: bool,
    /// The joint's unit twist along this variable (second link relative to
    /// the first, as [`crate::velocity::joint_twists`]).
    pub twist: Twist,
}

impl Default for LimbVariable {
    fn default() -> Self {
        LimbVariable {
            joint: 0,
            variable: 0,
            actuated: false,
            twist: Twist {
                w: Vector3::zeros(),
                v: Vector3::zeros(),
            },
        }
    }
}

/// A limb at a configuration, as [`analyse_twists`] reads it (inline: the
/// generated `stiffness` builds these on the stack).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LimbTwists {
    /// Its joints, from the base to the platform.
    pub joints: Bounded<usize, MAX_LIMB_JOINTS>,
    /// Every joint variable of the limb, joints in limb order.
    pub variables: Bounded<LimbVariable, MAX_LIMB_VARIABLES>,
    /// The world position of the distal joint's point.
    pub distal: Vector3<f64>,
    /// The world positions of the limb's other R and S joints' points,
    /// from the distal end towards the base: the first one apart from
    /// `distal` is the leg's proximal centre ([`Limb::proximal`]).
    pub centres: Bounded<Vector3<f64>, MAX_LIMB_JOINTS>,
}

/// The wrench analysis from the limbs' twists (the core of
/// [`analyse_poses`], for a caller that has the twists already, as the
/// generated `stiffness` has), `scale` the model's size
/// ([`crate::kinematics::model_scale`]). Allocates nothing but an error's
/// text.
pub fn analyse_twists(inputs: &[LimbTwists], scale: f64) -> Result<WrenchAnalysis, WrenchError> {
    let s = scale;
    if !(s > 0.0 && s.is_finite()) {
        return Err(bad(format!("the size scale {s} is not positive and finite")));
    }
    if inputs.is_empty() {
        return Err(WrenchError::NotLimbs {
            link: 0,
            what: "no joint on the base",
        });
    }
    if inputs.len() > MAX_LIMBS {
        return Err(bad(format!(
            "{} limbs: a wrench analysis takes at most {MAX_LIMBS}",
            inputs.len()
        )));
    }
    let mut limbs_out = Bounded::new();
    // The actuation rows, then (appended at the end) the constraint rows.
    let mut rows = Bounded::<Row, MAX_ROWS>::new();
    let mut constraints = Bounded::<Row, MAX_ROWS>::new();
    for (li, limb) in inputs.iter().enumerate() {
        let p = limb.distal;
        if !p
            .iter()
            .chain(limb.centres.iter().flat_map(|c| c.iter()))
            .all(|x| x.is_finite())
        {
            return Err(bad(format!("a joint point of limb {li} is not finite")));
        }
        let proximal = limb.centres.iter().copied().find(|c| (c - p).norm() > RANK_TOL * s);
        // Every variable's twist, dimensionless at p, unit.
        let mut hats: Bounded<Vector6<f64>, MAX_LIMB_VARIABLES> = Bounded::new();
        for var in &limb.variables {
            let t = &var.twist;
            let vp = t.v + t.w.cross(&p);
            let h = Vector6::new(vp.x, vp.y, vp.z, s * t.w.x, s * t.w.y, s * t.w.z);
            let norm = h.norm();
            if !(norm > 0.0 && norm.is_finite()) {
                return Err(bad(format!(
                    "the twist of joint {} (limb {li}) is zero or not finite",
                    var.joint
                )));
            }
            put(&mut hats, h / norm, "joint variables on a limb")?;
        }
        let c = null_space(&hats);
        for (col, var) in limb.variables.iter().enumerate() {
            if !var.actuated {
                continue;
            }
            let w = actuation_wrench(&hats, col, &c)
                .map_err(|sigma| WrenchError::ActuationSingularity { limb: Some(li), sigma })?;
            let couple = Vector3::new(w[0], w[1], w[2]).norm() <= RANK_TOL;
            let wrench = from_hat(&w, &p, s, couple);
            let row = Row {
                transmission: wrench.on(&var.twist),
                wrench,
                kind: RowKind::Actuation {
                    joint: var.joint,
                    variable: var.variable,
                },
                limb: li,
            };
            put(&mut rows, row, "rows of J")?;
        }
        let (couples, forces) = constraint_basis(&c);
        let kinds = couples
            .iter()
            .map(|w| (w, RowKind::ConstraintCouple))
            .chain(forces.iter().map(|w| (w, RowKind::ConstraintForce)));
        for (w, kind) in kinds {
            let row = Row {
                wrench: from_hat(w, &p, s, kind == RowKind::ConstraintCouple),
                kind,
                limb: li,
                transmission: 0.0,
            };
            put(&mut constraints, row, "rows of J")?;
        }
        let out = Limb {
            joints: limb.joints,
            distal: p,
            proximal,
        };
        put(&mut limbs_out, out, "limbs")?;
    }
    let n_a = rows.len();
    for &row in constraints.iter() {
        put(&mut rows, row, "rows of J")?;
    }
    full_rank(&rows, n_a, s)?;
    Ok(WrenchAnalysis {
        limbs: limbs_out,
        rows,
        actuation: n_a,
        scale: s,
    })
}

/// That `J` (`rows`, the first `n_a` the actuation wrenches) has rank 6,
/// certified by a QR ([`certified_full_rank`]) or found by the SVD; else
/// the singularity, by the SVD's ranks.
fn full_rank(rows: &[Row], n_a: usize, s: f64) -> Result<(), WrenchError> {
    if certified_full_rank(rows, s) {
        return Ok(());
    }
    let (rank, sigma) = scaled_rank(rows, s);
    if rank >= 6 {
        return Ok(());
    }
    let (rank_c, sigma_c) = scaled_rank(&rows[n_a..], s);
    let needed = 6usize.saturating_sub(n_a);
    if rank_c < needed {
        return Err(WrenchError::ConstraintSingularity {
            rank: rank_c,
            needed,
            sigma: sigma_c,
        });
    }
    Err(WrenchError::ActuationSingularity { limb: None, sigma })
}

/// Row `r` scaled to `(f, m/s)` (a force) or `(0, m)` (a couple).
fn scaled_row(row: &Row, s: f64) -> Vector6<f64> {
    let w = &row.wrench;
    let m = if w.is_couple() { w.m } else { w.m / s };
    Vector6::new(w.f.x, w.f.y, w.f.z, m.x, m.y, m.z)
}

/// Whether a pivoted QR of the scaled rows certifies rank 6 (what
/// [`scaled_rank`]'s SVD would find; see [`qr`]).
fn certified_full_rank(rows: &[Row], s: f64) -> bool {
    if rows.len() < 6 || rows.len() > MAX_ROWS {
        return false;
    }
    let column = |r: usize| scaled_row(&rows[r], s).into();
    // Most mechanisms have at most 12 rows: a smaller array to clear.
    let rank = if rows.len() <= 12 {
        PivotedQr::<12>::relative(rows.len(), column).1
    } else {
        PivotedQr::<MAX_ROWS>::relative(rows.len(), column).1
    };
    rank == Some(6)
}

/// The actuation wrench of variable `col` of a limb whose unit twists
/// (dimensionless, at its distal centre) are `hats` and whose constraint
/// space is `c`: the unit `ŵ` reciprocal to the other twists and orthogonal
/// to `c`, its product with its own twist positive; or, where there is
/// none, the σ of [`WrenchError::ActuationSingularity`]. Certified by
/// [`certified_actuation`] where it can, else by SVD.
fn actuation_wrench(hats: &[Vector6<f64>], col: usize, c: &[Vector6<f64>]) -> Result<Vector6<f64>, f64> {
    certified_actuation(hats, col, c.len()).map_or_else(|| svd_actuation(hats, col, c), Ok)
}

/// [`actuation_wrench`] by SVD: the reciprocal wrenches of the other
/// twists ([`svd_null_space`]), the longest of their parts orthogonal to
/// `c`; none where they are no more than `c` or that part's product with
/// the actuated twist is at most [`RANK_TOL`].
fn svd_actuation(hats: &[Vector6<f64>], col: usize, c: &[Vector6<f64>]) -> Result<Vector6<f64>, f64> {
    let mut others: Bounded<Vector6<f64>, MAX_LIMB_VARIABLES> = Bounded::new();
    for i in (0..hats.len()).filter(|&i| i != col) {
        // One fewer than the limb's variables: never full.
        let _ = others.push(hats[i]);
    }
    let candidates = svd_null_space(&others);
    let best = candidates.iter().map(|n| reject(n, c)).fold(
        Vector6::zeros(),
        |b: Vector6<f64>, r| if r.norm() > b.norm() { r } else { b },
    );
    let sigma = if best.norm() > RANK_TOL {
        best.normalize().dot(&hats[col]).abs()
    } else {
        0.0
    };
    if candidates.len() <= c.len() || sigma <= RANK_TOL {
        return Err(sigma);
    }
    let w = best.normalize();
    Ok(if w.dot(&hats[col]) < 0.0 { -w } else { w })
}

/// The actuation wrench where a pivoted QR of the other twists certifies
/// their rank as one less than the limb's (`6 − nullity`): the reciprocal
/// wrenches of the others are `c` and one more direction, the part of the
/// actuated twist `h` orthogonal to the others' span, `u = (I − Q₁Q₁ᵀ) h`
/// normalised (its product with `h` is `|u|`, the SVD path's σ). `None`
/// where the rank is not certified or `|u|` is within a factor 2 of
/// [`RANK_TOL`].
fn certified_actuation(hats: &[Vector6<f64>], col: usize, nullity: usize) -> Option<Vector6<f64>> {
    let n = hats.len().checked_sub(1)?;
    if n > MAX_LIMB_VARIABLES {
        return None;
    }
    let (qr, rank) = PivotedQr::<MAX_LIMB_VARIABLES>::relative(n, |j| hats[if j < col { j } else { j + 1 }].into());
    let r = rank?;
    if r + 1 + nullity != 6 {
        return None;
    }
    let mut y = qr.qt(hats[col].into());
    for e in y.iter_mut().take(r) {
        *e = 0.0;
    }
    let rho = y.iter().map(|e| e * e).sum::<f64>().sqrt();
    if rho.is_nan() || rho <= 2.0 * RANK_TOL {
        return None;
    }
    Some(Vector6::from(qr.q(y)) / rho)
}

/// The rank of rows scaled to `(f, m/s)` (forces) or `(0, m)` (couples) and
/// their σ_min/σ_max over min(rows, 6) values (0 without rows).
fn scaled_rank(rows: &[Row], s: f64) -> (usize, f64) {
    if rows.is_empty() {
        return (0, 0.0);
    }
    let m = six_by_six(rows.len(), |r| scaled_row(&rows[r], s));
    let sv = m.svd(false, false).singular_values;
    let smax = sv.max();
    let considered = rows.len().min(6);
    let mut sorted: [f64; 6] = sv.into();
    sorted.sort_by(|a, b| b.total_cmp(a));
    let rank = sorted.iter().take(considered).filter(|&&x| x > RANK_TOL * smax).count();
    let sigma = if smax > 0.0 { sorted[considered - 1] / smax } else { 0.0 };
    (rank, sigma)
}

pub(crate) mod qr;

#[cfg(test)]
pub(crate) mod tests;
