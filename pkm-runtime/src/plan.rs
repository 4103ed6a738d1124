//! Solution plans and their interpreter. A plan is what the compiler derives
//! from a κ = 0 mechanism: the ordered single open chains solved one after
//! the other, each as closed-form steps between links whose poses are known.
//! Generated code and this interpreter walk the same plan.
//!
//! Planar plans only for now: transfers through joints whose values are
//! known, and the class II dyads RRR and RRP (guide on the known link).

use crate::model::{JointType, Model, Place};
use crate::primitives::{rrp, rrr, Error as GeomError, Sign};
use core::fmt;
use std::borrow::Cow;

/// A planar pose: the link frame's origin and the angle of its x axis, with
/// the angle's cosine and sine kept so that moving points costs no trigonometry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose2 {
    /// Origin x.
    pub x: f64,
    /// Origin y.
    pub y: f64,
    /// Angle of the link's x axis from the world's.
    pub angle: f64,
    /// cos(angle).
    pub cos: f64,
    /// sin(angle).
    pub sin: f64,
}

impl Pose2 {
    /// The base's pose.
    pub const IDENTITY: Pose2 = Pose2 {
        x: 0.0,
        y: 0.0,
        angle: 0.0,
        cos: 1.0,
        sin: 0.0,
    };

    /// The pose with origin (x, y) and angle `angle`.
    pub fn new(x: f64, y: f64, angle: f64) -> Pose2 {
        let (sin, cos) = angle.sin_cos();
        Pose2 { x, y, angle, cos, sin }
    }

    /// A local point in the world.
    #[inline]
    pub fn apply(&self, p: [f64; 2]) -> [f64; 2] {
        let r = self.rotate(p);
        [self.x + r[0], self.y + r[1]]
    }

    /// A local direction in the world.
    #[inline]
    pub fn rotate(&self, d: [f64; 2]) -> [f64; 2] {
        [
            self.cos.mul_add(d[0], -self.sin * d[1]),
            self.sin.mul_add(d[0], self.cos * d[1]),
        ]
    }

    /// A world point in local coordinates.
    pub fn inverse_apply(&self, p: [f64; 2]) -> [f64; 2] {
        let (dx, dy) = (p[0] - self.x, p[1] - self.y);
        [
            self.cos.mul_add(dx, self.sin * dy),
            self.cos.mul_add(dy, -self.sin * dx),
        ]
    }

    /// The pose with angle `angle` that carries local point `local` to world point `world`.
    pub fn placing(local: [f64; 2], world: [f64; 2], angle: f64) -> Pose2 {
        Self::placing_rotated(local, world, Pose2::new(0.0, 0.0, angle))
    }

    /// As [`Pose2::placing`], with the orientation of `rotation` (its origin is ignored).
    #[inline]
    pub fn placing_rotated(local: [f64; 2], world: [f64; 2], rotation: Pose2) -> Pose2 {
        let r = rotation.rotate(local);
        Pose2 {
            x: world[0] - r[0],
            y: world[1] - r[1],
            ..rotation
        }
    }
}

/// A point of a link: a joint's place on it, or one of the model's named points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PointRef {
    /// The place of joint `j` on the link.
    Joint(usize),
    /// Named point number `k` of the model.
    Named(usize),
}

/// One step of a plan.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step {
    /// The pose of `link` from known values: its point `point` is at
    /// (`inputs[input]`, `inputs[input + 1]`) with angle `inputs[input + 2]`
    /// (a pose output given to an inverse solution).
    Place {
        /// The link.
        link: usize,
        /// The point whose position is given.
        point: PointRef,
        /// Index of x in the inputs; y and the angle follow.
        input: usize,
    },
    /// A point of `link` alone at (`inputs[input]`, `inputs[input + 1]`) (a
    /// point output): the stored pose has angle 0 and serves only that point,
    /// as the known end of a dyad through it, which then fixes the link.
    PlacePoint {
        /// The link.
        link: usize,
        /// The point whose position is given.
        point: PointRef,
        /// Index of x in the inputs; y follows.
        input: usize,
    },
    /// The pose of link `to` from the known link `from` through `joint`, whose value is input number `input`.
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
    /// RRR dyad: `joints = [a, b, c]` and `links = [k1, l1, l2, k2]`; a joins k1 and l1,
    /// b joins l1 and l2, c joins l2 and k2; k1 and k2 are known. Branch `Plus`: the
    /// middle joint lies to the left of the line from a to c.
    Rrr {
        /// `[a, b, c]`.
        joints: [usize; 3],
        /// `[k1, l1, l2, k2]`.
        links: [usize; 4],
        /// The index of this step's sign in the branch's sign vector.
        branch: usize,
    },
    /// RRP dyad: as [`Step::Rrr`] with c prismatic, its guide on k2. Branch
    /// `Plus`: the larger slider coordinate along the guide.
    Rrp {
        /// `[a, b, c]`.
        joints: [usize; 3],
        /// `[k1, l1, l2, k2]`.
        links: [usize; 4],
        /// The index of this step's sign in the branch's sign vector.
        branch: usize,
    },
}

/// A forward-position plan.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Plan {
    /// Steps in order.
    pub steps: Vec<Step>,
    /// How many ± choices the plan has (2^branches solutions).
    pub branches: usize,
    /// The input joints, in the order of the input vector.
    pub inputs: Vec<usize>,
}

/// Why a branch has no solution.
#[derive(Debug, Clone, PartialEq)]
pub enum SolveError {
    /// A step's existence condition fails by `by` (a length).
    Unreachable {
        /// The step's index.
        step: usize,
        /// The joint whose position cannot be reached, or a dyad's three
        /// joints (`R2–R3–R4`): the loop that cannot close.
        joint: Cow<'static, str>,
        /// The condition, e.g. `centre distance <= r1 + r2`.
        constraint: &'static str,
        /// By how much.
        by: f64,
    },
    /// A step's data are degenerate (coincident centres, a zero-length link, …).
    Degenerate {
        /// The step's index.
        step: usize,
        /// What is degenerate.
        what: &'static str,
    },
    /// The inputs are wrong (count, non-finite values) or the plan does not fit the model.
    BadInput {
        /// What is wrong.
        what: Cow<'static, str>,
    },
    /// The steps ran, but a joint the plan did not solve (or a given point
    /// it moved) does not close: the given values over-determine the
    /// mechanism and disagree (see [`crate::consistency`]).
    Inconsistent {
        /// What does not close, e.g. `joint R11`.
        owner: Cow<'static, str>,
        /// By how much (a length).
        gap: f64,
        /// The given value the others contradict, where the projection onto
        /// consistent values found it.
        contradicted: Option<crate::consistency::Contradicted>,
    },
    /// This branch is the same solution as branch number `twin`: a double
    /// root (tangency) of one step, where its two signs meet.
    DoubleRoot {
        /// The branch (index in `signs_of` order) that keeps the solution.
        twin: usize,
    },
}

impl fmt::Display for SolveError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SolveError::Unreachable {
                joint, constraint, by, ..
            } => {
                write!(
                    f,
                    "the loop through {joint} cannot close: `{constraint}` fails by {}",
                    short(*by)
                )
            }
            SolveError::Degenerate { what, step } => write!(f, "degenerate configuration at step {step}: {what}"),
            SolveError::BadInput { what } => write!(f, "bad input: {what}"),
            SolveError::Inconsistent {
                owner,
                gap,
                contradicted: Some(c),
            } => write!(
                f,
                "the given values are inconsistent: {} = {} cannot be reached with the others, \
                 the nearest reachable value is {} (off by {:.6e}); as given, {owner} misses by {gap:.6e}",
                c.name,
                c.given,
                short(c.nearest),
                c.given - c.nearest
            ),
            SolveError::Inconsistent { owner, gap, .. } => {
                write!(f, "the given values are inconsistent: {owner} misses by {gap:.6e}")
            }
            SolveError::DoubleRoot { twin } => write!(
                f,
                "a double root (tangency): this branch is the same solution as branch {twin}"
            ),
        }
    }
}

impl std::error::Error for SolveError {}

/// The shortest decimal of `v` within 1e-12 of it (relative; a projection's
/// last digits are noise): −299.99999999999994 prints as −300.
fn short(v: f64) -> String {
    let tol = 1e-12 * v.abs().max(1.0);
    (0..17)
        .map(|p| format!("{v:.p$}"))
        .find(|t| t.parse::<f64>().is_ok_and(|x| (x - v).abs() <= tol))
        .unwrap_or_else(|| v.to_string())
}

/// A forward solution: every link's pose and every joint's value.
#[derive(Debug, Clone, PartialEq)]
pub struct FkSolution {
    /// Link poses, indexed like the model's links.
    pub poses: Vec<Pose2>,
    /// Joint values, indexed like the model's joints (planar joints have one value each).
    pub values: Vec<f64>,
}

fn local(place: &Place) -> [f64; 2] {
    let at = place.at();
    [at[0], at[1]]
}

/// The joint's point in the frame of `link` (one of its two links).
fn point_on(model: &Model, joint: usize, link: usize) -> Result<[f64; 2], SolveError> {
    let j = &model.joints[joint];
    let side = j.links.iter().position(|&l| l == link).ok_or_else(|| {
        bad(format!(
            "joint {} does not touch link {}",
            j.name,
            model.links.get(link).map_or("?", |s| s)
        ))
    })?;
    Ok(local(&j.places[side]))
}

fn xy(p: &[f64; 3]) -> [f64; 2] {
    [p[0], p[1]]
}

fn bad(what: String) -> SolveError {
    SolveError::BadInput { what: Cow::Owned(what) }
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

/// An angle wrapped into (−π, π].
///
/// ```
/// use pkm_runtime::plan::wrap_angle;
/// use std::f64::consts::PI;
/// assert_eq!(wrap_angle(0.5), 0.5);
/// assert!((wrap_angle(0.5 + 4.0 * PI) - 0.5).abs() < 1e-12);
/// assert_eq!(wrap_angle(-PI), PI);
/// ```
pub fn wrap_angle(x: f64) -> f64 {
    use core::f64::consts::{PI, TAU};
    if x > -PI && x <= PI {
        return x;
    }
    let w = x.rem_euclid(TAU);
    if w > PI {
        w - TAU
    } else {
        w
    }
}

/// A dyad's joints, named as the loop they close: `R2–R3–R4`.
fn dyad_name(model: &Model, joints: [usize; 3]) -> String {
    joints.map(|j| model.joints[j].name.as_str()).join("–")
}

/// A primitive's error as the error of plan step `step`, at `joint`.
pub fn step_error(step: usize, joint: impl Into<Cow<'static, str>>, e: GeomError<f64>) -> SolveError {
    match e {
        GeomError::Unreachable { constraint, by } => SolveError::Unreachable {
            step,
            joint: joint.into(),
            constraint,
            by,
        },
        GeomError::Degenerate { what } => SolveError::Degenerate { step, what },
    }
}

// Step kernels: the geometry of each step, shared by the interpreter and
// generated code, which differ only in where the local coordinates come from.

/// The pose of a link whose local point `local` is at (x, y) and whose angle is `angle`.
pub fn place_at(local: [f64; 2], x: f64, y: f64, angle: f64) -> Pose2 {
    Pose2::placing(local, [x, y], angle)
}

/// The pose of a link reached from the known pose `from` through a revolute
/// joint at `at_from` (on the known link) and `at_to` (on the new link),
/// turned by `turn` (the joint value, negated when the joint is written from
/// the new link).
pub fn through_revolute(from: Pose2, at_from: [f64; 2], at_to: [f64; 2], turn: f64) -> Pose2 {
    Pose2::placing(at_to, from.apply(at_from), from.angle + turn)
}

/// The pose of a slider reached from the known guide link `from`: the guide
/// runs `through` a point `along` a direction on the known link, the slider's
/// point is `slider` on the new link, and `s` is the joint value.
pub fn along_guide(from: Pose2, through: [f64; 2], along: [f64; 2], slider: [f64; 2], s: f64) -> Pose2 {
    let n = along[0].hypot(along[1]);
    Pose2::placing(
        slider,
        from.apply([through[0] + s * along[0] / n, through[1] + s * along[1] / n]),
        from.angle,
    )
}

/// The pose of a guide link reached from the known slider link `from`: the
/// known link's point `point` sits at `through + s·along` on the new link.
pub fn onto_guide(from: Pose2, through: [f64; 2], along: [f64; 2], point: [f64; 2], s: f64) -> Pose2 {
    let n = along[0].hypot(along[1]);
    Pose2::placing(
        [through[0] + s * along[0] / n, through[1] + s * along[1] / n],
        from.apply(point),
        from.angle,
    )
}

/// The rotation taking the link's local vector `local` onto the world vector
/// `world`: its cosine and sine from their dot and cross products, its angle
/// by one atan2.
fn rotation_onto(local: [f64; 2], world: [f64; 2]) -> Result<Pose2, GeomError<f64>> {
    let dot = local[0].mul_add(world[0], local[1] * world[1]);
    let cross = local[0].mul_add(world[1], -local[1] * world[0]);
    let norm = dot.hypot(cross);
    if norm.is_nan() || norm <= 0.0 {
        return Err(GeomError::Degenerate {
            what: "two joints of a dyad link coincide",
        });
    }
    Ok(Pose2 {
        x: 0.0,
        y: 0.0,
        angle: cross.atan2(dot),
        cos: dot / norm,
        sin: cross / norm,
    })
}

/// The RRR dyad: joint a at `a_k1` on the known link k1 (pose `k1`) and `a_l1`
/// on l1; joint b at `b_l1` on l1 and `b_l2` on l2; joint c at `c_l2` on l2 and
/// `c_k2` on the known link k2. Returns the poses of l1 and l2. `Plus`: b to
/// the left of the line from a to c.
#[allow(clippy::too_many_arguments)]
pub fn rrr_dyad(
    k1: Pose2,
    a_k1: [f64; 2],
    a_l1: [f64; 2],
    b_l1: [f64; 2],
    b_l2: [f64; 2],
    c_l2: [f64; 2],
    c_k2: [f64; 2],
    k2: Pose2,
    sign: Sign,
) -> Result<(Pose2, Pose2), GeomError<f64>> {
    let pa = k1.apply(a_k1);
    let pc = k2.apply(c_k2);
    let (r1, r2) = (sub(b_l1, a_l1), sub(c_l2, b_l2));
    let pb = rrr(pa, r1[0].hypot(r1[1]), pc, r2[0].hypot(r2[1]))?.branch(sign);
    let l1 = Pose2::placing_rotated(a_l1, pa, rotation_onto(r1, sub(pb, pa))?);
    let l2 = Pose2::placing_rotated(b_l2, pb, rotation_onto(r2, sub(pc, pb))?);
    Ok((l1, l2))
}

/// The RRP dyad: as [`rrr_dyad`], with c prismatic: its guide runs `through`
/// a point `along` a direction on the known link k2, its slider point is
/// `slider` on l2. `Plus`: the larger slider coordinate along the guide.
#[allow(clippy::too_many_arguments)]
pub fn rrp_dyad(
    k1: Pose2,
    a_k1: [f64; 2],
    a_l1: [f64; 2],
    b_l1: [f64; 2],
    b_l2: [f64; 2],
    slider: [f64; 2],
    through: [f64; 2],
    along: [f64; 2],
    k2: Pose2,
    sign: Sign,
) -> Result<(Pose2, Pose2), GeomError<f64>> {
    let pa = k1.apply(a_k1);
    let r1 = sub(b_l1, a_l1);
    // The slider keeps k2's orientation, so b's point runs along a parallel to
    // the guide, offset by b's place relative to the slider point.
    let offset = k2.rotate(sub(b_l2, slider));
    let q = k2.apply(through);
    let hit = rrp(
        pa,
        r1[0].hypot(r1[1]),
        [q[0] + offset[0], q[1] + offset[1]],
        k2.rotate(along),
    )?
    .branch(sign);
    let l1 = Pose2::placing_rotated(a_l1, pa, rotation_onto(r1, sub(hit.point, pa))?);
    Ok((l1, Pose2::placing_rotated(b_l2, hit.point, k2)))
}

/// A revolute joint's value: the angle of v from u, in (−π, π].
pub fn revolute_value(u: Pose2, v: Pose2) -> f64 {
    wrap_angle(v.angle - u.angle)
}

/// A prismatic joint's value: where the slider's point lies along the guide.
pub fn prismatic_value(
    guide_pose: Pose2,
    through: [f64; 2],
    along: [f64; 2],
    slider_pose: Pose2,
    slider: [f64; 2],
) -> f64 {
    guide_coordinates(guide_pose, through, along, slider_pose, slider)[0]
}

/// The slider point's coordinates along the guide and across it (to its
/// left), in the guide link's frame, from the guide's point `through`.
fn guide_coordinates(
    guide_pose: Pose2,
    through: [f64; 2],
    along: [f64; 2],
    slider_pose: Pose2,
    slider: [f64; 2],
) -> [f64; 2] {
    let p = guide_pose.inverse_apply(slider_pose.apply(slider));
    let n = along[0].hypot(along[1]);
    let d = [p[0] - through[0], p[1] - through[1]];
    [
        (d[0] * along[0] + d[1] * along[1]) / n,
        (d[1] * along[0] - d[0] * along[1]) / n,
    ]
}

impl Step {
    /// The joints this step solves (and so closes).
    pub fn joints(&self) -> &[usize] {
        match self {
            Step::Place { .. } | Step::PlacePoint { .. } => &[],
            Step::Transfer { joint, .. } => core::slice::from_ref(joint),
            Step::Rrr { joints, .. } | Step::Rrp { joints, .. } => joints,
        }
    }
}

impl Plan {
    /// The joints no step solves: the loops the plan never needed, whose
    /// closure [`run`] checks after the last step.
    pub fn open_joints(&self, n_joints: usize) -> Vec<usize> {
        let mut solved = vec![false; n_joints];
        for &j in self.steps.iter().flat_map(Step::joints) {
            if let Some(s) = solved.get_mut(j) {
                *s = true;
            }
        }
        (0..n_joints).filter(|&j| !solved[j]).collect()
    }

    /// Which given values are angles: a pose's angle, a revolute's value.
    pub fn angular_inputs(&self, model: &Model) -> Vec<bool> {
        let n = self
            .steps
            .iter()
            .map(|s| match *s {
                Step::Place { input, .. } => input + 3,
                Step::PlacePoint { input, .. } => input + 2,
                Step::Transfer { input, .. } => input + 1,
                _ => 0,
            })
            .max()
            .unwrap_or(0)
            .max(self.inputs.len());
        let mut angular = vec![false; n];
        for s in &self.steps {
            match *s {
                Step::Place { input, .. } => angular[input + 2] = true,
                Step::Transfer { joint, input, .. } => angular[input] = model.joints[joint].kind == JointType::R,
                _ => {}
            }
        }
        angular
    }
}

/// A planar joint's closure residual: R joints, the difference of its two
/// places' world points; P joints, the slider point's signed distance from
/// the guide line and the two links' angle difference times `extent`.
pub fn closure_residual(j: &crate::model::Joint, poses: &[Pose2], extent: f64) -> [f64; 2] {
    let (tu, tv) = (poses[j.links[0]], poses[j.links[1]]);
    match (j.kind, &j.places[0], &j.places[1]) {
        (JointType::P, Place::Line { through, along }, other) => {
            prismatic_residual(tu, xy(through), xy(along), tv, local(other), extent)
        }
        (JointType::P, other, Place::Line { through, along }) => {
            prismatic_residual(tv, xy(through), xy(along), tu, local(other), extent)
        }
        _ => point_residual(tu.apply(local(&j.places[0])), tv.apply(local(&j.places[1]))),
    }
}

/// Where a point is minus where it should be: a residual of two rows.
pub fn point_residual(at: [f64; 2], want: [f64; 2]) -> [f64; 2] {
    [at[0] - want[0], at[1] - want[1]]
}

/// A prismatic joint's closure residual (see [`closure_residual`]).
pub fn prismatic_residual(
    guide_pose: Pose2,
    through: [f64; 2],
    along: [f64; 2],
    slider_pose: Pose2,
    slider: [f64; 2],
    extent: f64,
) -> [f64; 2] {
    let [_, off] = guide_coordinates(guide_pose, through, along, slider_pose, slider);
    [off, wrap_angle(slider_pose.angle - guide_pose.angle) * extent]
}

/// The residual of a planar solution: every open joint's (2 rows each), then
/// each given point's distance from where the solution put it (2 rows each
/// `PlacePoint`, whose link a later dyad turns), with the extent they are
/// measured against; and the owner of each row.
fn residual(
    model: &Model,
    plan: &Plan,
    open: &[usize],
    poses: &[Pose2],
    inputs: &[f64],
) -> (Vec<f64>, f64, Vec<String>) {
    let points: Vec<[f64; 2]> = (0..model.joints.len()).map(|j| joint_point(model, poses, j)).collect();
    let extent = crate::consistency::extent(&points);
    let mut rows = Vec::new();
    let mut owners = Vec::new();
    for &j in open {
        rows.extend(closure_residual(&model.joints[j], poses, extent));
        owners.extend(std::iter::repeat_n(format!("joint {}", model.joints[j].name), 2));
    }
    for s in &plan.steps {
        if let Step::PlacePoint { link, point, input } = *s {
            let at = match point {
                PointRef::Joint(j) => point_on(model, j, link).unwrap_or([f64::NAN; 2]),
                PointRef::Named(n) => model.points.get(n).map_or([f64::NAN; 2], |p| [p.at[0], p.at[1]]),
            };
            rows.extend(point_residual(
                poses[link].apply(at),
                [inputs[input], inputs[input + 1]],
            ));
            owners.extend(std::iter::repeat_n(
                format!("the given point of link {}", model.links[link]),
                2,
            ));
        }
    }
    (rows, extent, owners)
}

/// Runs the plan for one branch (`signs[k]` for the plan's k-th choice) and
/// verifies the solution ([`crate::consistency`]): every open joint closes,
/// every given point stays where it was given; where not, the error names
/// the given value the others contradict (`#k`).
pub fn run(model: &Model, plan: &Plan, inputs: &[f64], signs: &[Sign]) -> Result<FkSolution, SolveError> {
    let open = plan.open_joints(model.joints.len());
    let sol = run_unverified(model, plan, inputs, signs)?;
    let (rows, extent, owners) = residual(model, plan, &open, &sol.poses, inputs);
    let owners: Vec<&str> = owners.iter().map(String::as_str).collect();
    crate::consistency::verify_rows(
        &rows,
        extent,
        &owners,
        inputs,
        &plan.angular_inputs(model),
        &[],
        |given| {
            let s = run_unverified(model, plan, given, signs).ok()?;
            Some(residual(model, plan, &open, &s.poses, given).0)
        },
    )?;
    Ok(sol)
}

/// One branch's solution, unverified.
fn run_unverified(model: &Model, plan: &Plan, inputs: &[f64], signs: &[Sign]) -> Result<FkSolution, SolveError> {
    if inputs.len() != plan.inputs.len() || signs.len() != plan.branches {
        return Err(bad(format!(
            "expected {} inputs and {} signs",
            plan.inputs.len(),
            plan.branches
        )));
    }
    if let Some(i) = inputs.iter().position(|v| !v.is_finite()) {
        return Err(bad(format!("given value {} is {}", i + 1, inputs[i])));
    }
    let mut poses: Vec<Option<Pose2>> = vec![None; model.links.len()];
    poses[0] = Some(Pose2::IDENTITY);
    let known = |poses: &[Option<Pose2>], l: usize| {
        poses[l].ok_or_else(|| bad(format!("link {} is used before it is solved", model.links[l])))
    };
    for (k, step) in plan.steps.iter().enumerate() {
        match *step {
            Step::Place { link, point, input } | Step::PlacePoint { link, point, input } => {
                let local = match point {
                    PointRef::Joint(j) => point_on(model, j, link)?,
                    PointRef::Named(n) => {
                        let p = model.points.get(n).ok_or_else(|| bad(format!("no named point {n}")))?;
                        [p.at[0], p.at[1]]
                    }
                };
                // A point alone: angle 0 until a dyad through the point fixes the link.
                let angle = match step {
                    Step::Place { .. } => inputs[input + 2],
                    _ => 0.0,
                };
                poses[link] = Some(place_at(local, inputs[input], inputs[input + 1], angle));
            }
            Step::Transfer { joint, from, to, input } => {
                let j = &model.joints[joint];
                let tf = known(&poses, from)?;
                let forward = j.links[0] == from;
                let value = inputs[input];
                let pose = match j.kind {
                    JointType::R => {
                        let (pf, pt) = (point_on(model, joint, from)?, point_on(model, joint, to)?);
                        through_revolute(tf, pf, pt, if forward { value } else { -value })
                    }
                    JointType::P => {
                        let side_from = if forward { 0 } else { 1 };
                        match (&j.places[side_from], &j.places[1 - side_from]) {
                            (Place::Line { through, along }, other) => {
                                along_guide(tf, xy(through), xy(along), local(other), value)
                            }
                            (other, Place::Line { through, along }) => {
                                onto_guide(tf, xy(through), xy(along), local(other), value)
                            }
                            _ => return Err(bad(format!("joint {} has no guide line", j.name))),
                        }
                    }
                    JointType::S | JointType::Pa => return Err(bad(format!("joint {} has no planar plan", j.name))),
                };
                poses[to] = Some(pose);
            }
            Step::Rrr {
                joints: [a, b, c],
                links: [k1, l1, l2, k2],
                branch,
            } => {
                let (t1, t2) = (known(&poses, k1)?, known(&poses, k2)?);
                let (p1, p2) = rrr_dyad(
                    t1,
                    point_on(model, a, k1)?,
                    point_on(model, a, l1)?,
                    point_on(model, b, l1)?,
                    point_on(model, b, l2)?,
                    point_on(model, c, l2)?,
                    point_on(model, c, k2)?,
                    t2,
                    signs[branch],
                )
                .map_err(|e| step_error(k, dyad_name(model, [a, b, c]), e))?;
                poses[l1] = Some(p1);
                poses[l2] = Some(p2);
            }
            Step::Rrp {
                joints: [a, b, c],
                links: [k1, l1, l2, k2],
                branch,
            } => {
                let (t1, t2) = (known(&poses, k1)?, known(&poses, k2)?);
                let jc = &model.joints[c];
                let guide_side = jc.links.iter().position(|&l| l == k2).unwrap_or(0);
                let Place::Line { through, along } = jc.places[guide_side] else {
                    return Err(bad(format!(
                        "joint {} has no guide on link {}",
                        jc.name, model.links[k2]
                    )));
                };
                let (p1, p2) = rrp_dyad(
                    t1,
                    point_on(model, a, k1)?,
                    point_on(model, a, l1)?,
                    point_on(model, b, l1)?,
                    point_on(model, b, l2)?,
                    local(&jc.places[1 - guide_side]),
                    xy(&through),
                    xy(&along),
                    t2,
                    signs[branch],
                )
                .map_err(|e| step_error(k, dyad_name(model, [a, b, c]), e))?;
                poses[l1] = Some(p1);
                poses[l2] = Some(p2);
            }
        }
    }
    let poses: Vec<Pose2> = poses
        .into_iter()
        .enumerate()
        .map(|(l, p)| p.ok_or_else(|| bad(format!("the plan leaves link {} unsolved", model.links[l]))))
        .collect::<Result<_, _>>()?;
    let values = model.joints.iter().map(|j| joint_value(j, &poses)).collect();
    Ok(FkSolution { poses, values })
}

/// A planar joint's value from the poses of its two links.
pub fn joint_value(j: &crate::model::Joint, poses: &[Pose2]) -> f64 {
    let (tu, tv) = (poses[j.links[0]], poses[j.links[1]]);
    match j.kind {
        JointType::R => revolute_value(tu, tv),
        JointType::P => match (&j.places[0], &j.places[1]) {
            (Place::Line { through, along }, other) => prismatic_value(tu, xy(through), xy(along), tv, local(other)),
            (other, Place::Line { through, along }) => prismatic_value(tv, xy(through), xy(along), tu, local(other)),
            _ => f64::NAN,
        },
        JointType::S | JointType::Pa => f64::NAN,
    }
}

/// Every branch of the plan: the signs and the solution or the reason there is none.
/// A branch that repeats an earlier one's solution (a double root) says so
/// ([`SolveError::DoubleRoot`]).
pub fn run_all(model: &Model, plan: &Plan, inputs: &[f64]) -> Vec<(Vec<Sign>, Result<FkSolution, SolveError>)> {
    let mut all = every_branch(plan.branches, |signs| run(model, plan, inputs, signs));
    let revolute: Vec<bool> = model.joints.iter().map(|j| j.kind == JointType::R).collect();
    crate::consistency::mark_double_roots_in(&mut all, &revolute, |s: &FkSolution| &s.values);
    all
}

/// `solve` for each of the 2^`choices` sign vectors, in [`signs_of`] order
/// (bit k set: choice k is `Minus`), with its signs.
pub fn every_branch<S>(choices: usize, mut solve: impl FnMut(&[Sign]) -> S) -> Vec<(Vec<Sign>, S)> {
    (0..1usize << choices)
        .map(|bits| {
            let signs: Vec<Sign> = (0..choices)
                .map(|k| if bits >> k & 1 == 0 { Sign::Plus } else { Sign::Minus })
                .collect();
            let result = solve(&signs);
            (signs, result)
        })
        .collect()
}

/// The world position of joint `j`'s point: its place on its first link, or
/// for a prismatic joint the slider's point.
pub fn joint_point(model: &Model, poses: &[Pose2], j: usize) -> [f64; 2] {
    let joint = &model.joints[j];
    let side = joint.point_side();
    poses[joint.links[side]].apply(local(&joint.places[side]))
}

/// One branch of a generated solver: its ± choices and its solution, or why it has none.
#[derive(Debug, Clone, PartialEq)]
pub struct Branch<S, const D: usize> {
    /// The sign of each ± choice of the plan, in plan order.
    pub signs: [Sign; D],
    /// The solution, or why this branch has none.
    pub result: Result<S, SolveError>,
    /// Whether a step met a double root here (tangency): another branch
    /// that would be the same solution says [`SolveError::DoubleRoot`].
    pub tangent: bool,
}

/// The sign vector of branch number `index` (bit k set: choice k is `Minus`),
/// the order in which generated solvers and [`run_all`] list branches.
pub const fn signs_of<const D: usize>(index: usize) -> [Sign; D] {
    let mut signs = [Sign::Plus; D];
    let mut k = 0;
    while k < D {
        if index >> k & 1 == 1 {
            signs[k] = Sign::Minus;
        }
        k += 1;
    }
    signs
}

/// The distance between two joint-value vectors, with the differences of
/// revolute joints wrapped to (−π, π] (so 3.1 and −3.1 rad are close).
pub fn joint_distance(a: &[f64], b: &[f64], revolute: &[bool]) -> f64 {
    a.iter()
        .zip(b)
        .zip(revolute)
        .map(|((x, y), r)| if *r { wrap_angle(x - y) } else { x - y })
        .fold(0.0, |acc, d| d.mul_add(d, acc))
        .sqrt()
}

/// The index of the solved branch nearest `previous` (by [`joint_distance`]
/// of the values `values` reads from a solution), if any branch is solved.
pub fn nearest_branch<S, const D: usize>(
    branches: &[Branch<S, D>],
    previous: &[f64],
    revolute: &[bool],
    values: impl Fn(&S) -> &[f64],
) -> Option<usize> {
    let mut best: Option<(usize, f64)> = None;
    for (i, b) in branches.iter().enumerate() {
        if let Ok(s) = &b.result {
            let d = joint_distance(values(s), previous, revolute);
            if best.is_none_or(|(_, bd)| d < bd) {
                best = Some((i, d));
            }
        }
    }
    best.map(|(i, _)| i)
}

/// The joint values a smooth trajectory reaches next: `previous` plus the
/// last step `previous − before` (revolute steps wrapped), a linear
/// predictor. Near a tangency, where two branches meet, the branch nearest
/// this prediction is the one that continues; the nearest to `previous` may not be.
pub fn extrapolate<const J: usize>(previous: &[f64; J], before: &[f64; J], revolute: &[bool; J]) -> [f64; J] {
    let mut out = *previous;
    for k in 0..J {
        let step = previous[k] - before[k];
        out[k] += if revolute[k] { wrap_angle(step) } else { step };
    }
    out
}
