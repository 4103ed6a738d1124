//! Forward position solutions of a mechanism with coupling degree κ = 1 by
//! a virtual variable (seed 003 §1.1: "求解位置正解时需设定一个虚拟变量"):
//! one joint of the coupled SKC is given a value `v` as if it were an
//! input, the closed-form plan solves the rest of the mechanism as a
//! function of it (every ± branch), and the one loop constraint that plan
//! does not impose is left as a scalar compatibility residual `r(v)`
//! (the miss of the aim that closes the last SOC, a length:
//! [`crate::steps::aim::miss`]; or, where the plan leaves no aim open, an
//! actuated joint the plan is not given, its computed value less the given
//! one: [`Compatibility`]). Every real root of `r` on every branch is an
//! assembly.
//!
//! Every root, and each one proven: the plan's steps run on intervals
//! carrying their derivative ([`crate::interval::Enclosure`]) over a part
//! of the virtual variable's range enclose every value `r` takes there,
//! and [`crate::certify::roots`] drops the parts where the enclosure
//! excludes zero, proves a root by Krawczyk's operator where it holds
//! exactly one, splits the rest, and reports as possible
//! ([`RootKind::Possible`]) a root it cannot prove (a double root, a
//! branch's edge where two branches meet). No root is missed: a part of
//! the range is left only when it is proven to hold none. [`solve`] runs
//! it on a [`VirtualPlan`] with the plan interpreter; generated code runs
//! the same driver ([`solve_with`]) on its own residual, written once
//! generic over the scalar.

use crate::certify::{self, Doubt, Limits};
use crate::interval::{self, Enclosure, Interval};
use crate::model::{JointType, Model};
use crate::plan::{self, Plan, Solution};
use crate::primitives::Sign;
use crate::scalar::Scalar;
use crate::solution::SolveError;

/// Whether a root is proven.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RootKind {
    /// Proven: its certificate ([`Root::cert`]) holds exactly one root of
    /// the residual, and the value found.
    Certified,
    /// Not excluded, not proven (see [`Doubt`]): a double root, a fold
    /// where two assemblies meet, a branch's edge.
    Possible(Doubt),
}

impl RootKind {
    /// Whether proven.
    pub fn certified(self) -> bool {
        self == RootKind::Certified
    }

    /// In words: "certified", or "possible: " and why.
    pub fn text(self) -> String {
        match self {
            RootKind::Certified => "certified".into(),
            RootKind::Possible(d) => format!("possible: {}", d.text()),
        }
    }
}

/// A root of the residual.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Root {
    /// Where.
    pub x: f64,
    /// The residual there (f64).
    pub residual: f64,
    /// Whether proven.
    pub kind: RootKind,
    /// The interval of the virtual variable proven to hold this root and
    /// no other (certified), or the smallest one the search could not
    /// decide (possible).
    pub cert: Interval,
}

/// Where the virtual variable is searched.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VirtualRange {
    /// The range's start.
    pub lo: f64,
    /// The range's end.
    pub hi: f64,
    /// The range is one period (a revolute's turn): `hi` is `lo` again.
    pub periodic: bool,
}

/// What the search may spend, per branch ([`certify::Limits`]).
pub const LIMITS: Limits = Limits {
    boxes: 20_000,
    resolution: 1e-12,
    initial: 16,
};

/// The compatibility residual's enclosure over `v`'s interval, from the
/// residual `raw` the plan's steps computed there (an aim's miss; or the
/// value of the input the plan computes, compared to its given `given`
/// here, an angle's difference wrapped as [`angle_miss`] does), and
/// whether every decision of the steps went one way. `None` where the
/// branch has no real solution anywhere in the interval.
pub fn enclosed(
    compatibility: &Compatibility,
    raw: Option<Enclosure<1>>,
    given: &[f64],
    mut took: bool,
) -> Option<certify::Enclosed<1>> {
    let raw = raw?;
    let r = match *compatibility {
        Compatibility::Miss { .. } => raw,
        Compatibility::Input { input, arc, .. } => {
            let (r, jump) = difference(raw, *given.get(input)?, arc)?;
            took |= jump;
            r
        }
    };
    if r.v.is_empty() {
        return None;
    }
    Some(certify::Enclosed {
        f: [r.v],
        j: [r.d],
        decided: !took && !r.doubt,
    })
}

/// An input's computed value `raw` less its given value `given`, over a
/// box: a slide's difference (`arc` `None`), or an angle's wrapped into
/// (−π, π] by whole turns and measured as the arc of radius `arc`. Where
/// the wrap's jump at ±π lies inside the box, the enclosure is
/// [−π, π]·radius with an unknown derivative and `true` (the box is
/// undecided); `None` where the values, less than a turn wide, stay off
/// zero on both sides of the jump (no root).
pub fn difference<const N: usize>(raw: Enclosure<N>, given: f64, arc: Option<f64>) -> Option<(Enclosure<N>, bool)> {
    let d = raw - Enclosure::c(given);
    let Some(radius) = arc else {
        return Some((d, false));
    };
    let turn = 2.0 * std::f64::consts::PI;
    let pi = std::f64::consts::PI;
    let k = (d.v.mid() / turn).round();
    let w = d - Enclosure::c(k * turn);
    if w.v.lo > -pi && w.v.hi < pi {
        return Some((w * Enclosure::c(radius), false));
    }
    let off = |lo: f64, hi: f64| lo > 0.0 && hi < turn;
    if off(w.v.lo, w.v.hi) || off(w.v.lo + turn, w.v.hi + turn) {
        return None;
    }
    Some((
        Enclosure {
            v: Interval::new(-pi * radius, pi * radius),
            d: [Interval::ENTIRE; N],
            doubt: true,
        },
        true,
    ))
}

/// A forward plan with one virtual variable: the closed-form plan with
/// joint `joint` given as its last input, and which row of which of its
/// checks is the compatibility residual.
#[derive(Debug, Clone, PartialEq)]
pub struct VirtualPlan {
    /// The closed-form plan; its inputs are the mechanism's, then `joint`.
    pub plan: Plan,
    /// The joint whose value is the virtual variable.
    pub joint: usize,
    /// The range it is sampled over.
    pub range: [f64; 2],
    /// Whether the range is a whole turn.
    pub periodic: bool,
    /// What the compatibility residual is.
    pub compatibility: Compatibility,
}

/// What a [`VirtualPlan`]'s compatibility residual is (a length either
/// way).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Compatibility {
    /// Row `row` of the plan's check `check` ([`Plan::checks`]): the miss
    /// of an aim across a revolute's axis that closes the last SOC.
    Miss {
        /// The check.
        check: usize,
        /// Its row.
        row: usize,
    },
    /// An actuated joint the plan is not given: the value the plan
    /// computes for it less its given value (the plan's input `input`).
    /// Where no aim is left open (a leg of given length between two
    /// known joints, as in the 3-RPR), this is the condition the virtual
    /// variable must meet. An angle's difference is wrapped into
    /// (−π, π] ([`angle_miss`]) and measured as the arc at the
    /// mechanism's size ([`crate::kinematics::model_scale`]); a wrap's
    /// jump is a sign change that is not a root, and verification drops
    /// it.
    Input {
        /// The joint.
        joint: usize,
        /// Its index among the plan's inputs (the mechanism's inputs).
        input: usize,
        /// The arc's radius for a revolute (the model's scale), `None`
        /// for a slide.
        arc: Option<f64>,
    },
}

impl Compatibility {
    /// The residual from the joint value the plan computes for an
    /// [`Compatibility::Input`] and the given value.
    pub fn input_residual(arc: Option<f64>, computed: f64, given: f64) -> f64 {
        match arc {
            Some(radius) => angle_miss(computed - given) * radius,
            None => computed - given,
        }
    }
}

/// An angle's difference wrapped into (−π, π].
pub fn angle_miss(d: f64) -> f64 {
    let turn = 2.0 * std::f64::consts::PI;
    let w = d - turn * (d / turn).round();
    if w <= -std::f64::consts::PI {
        w + turn
    } else {
        w
    }
}

/// One assembly found.
#[derive(Debug, Clone, PartialEq)]
pub struct Assembly {
    /// The ± choices of the plan's branch it was found on.
    pub signs: Vec<Sign>,
    /// The virtual variable's value.
    pub virtual_value: f64,
    /// The compatibility residual there.
    pub residual: f64,
    /// Whether proven.
    pub kind: RootKind,
    /// The virtual variable's interval proven to hold it (certified), or
    /// the smallest the search could not decide (possible).
    pub cert: Interval,
    /// Every link's pose and joint's value, verified.
    pub solution: Solution,
}

/// The range a slide's virtual variable is sampled over: the slide's
/// value is a distance between two points the rest of its loop joins, so
/// at most the sum of every link's span (the largest distance of a joint
/// place, a parallelogram's far hinge or a named point from the link's
/// origin, twice) and the slide's own places' offsets; `±` that.
pub fn slide_range(model: &Model) -> f64 {
    let norm = |p: [f64; 3]| (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
    let mut span = vec![0.0f64; model.links.len()];
    for j in &model.joints {
        for (side, &l) in j.links.iter().enumerate() {
            // A parallelogram's far hinge, where its arm reaches, counts
            // as a place of the link carrying the arm.
            let reach = match j.places[side] {
                crate::model::Place::Arm { at, arm, .. } => norm(at) + norm(arm),
                ref place => norm(place.at()),
            };
            span[l] = span[l].max(reach);
        }
    }
    for p in &model.points {
        span[p.link] = span[p.link].max(norm(p.at));
    }
    span.iter().map(|s| 2.0 * s).sum::<f64>().max(1.0)
}

/// The range and periodicity of joint `joint` as a virtual variable.
pub fn range_of(model: &Model, joint: usize) -> ([f64; 2], bool) {
    match model.joints[joint].kind {
        JointType::P => {
            let r = slide_range(model);
            ([-r, r], false)
        }
        _ => ([-std::f64::consts::PI, std::f64::consts::PI], true),
    }
}

/// The compatibility residual of branch `signs` at the mechanism's
/// `inputs` and the virtual variable `v`, by the plan interpreter; `None`
/// where the branch's closed form has no real solution.
pub fn residual(model: &Model, vp: &VirtualPlan, inputs: &[f64], v: f64, signs: &[Sign]) -> Option<f64> {
    residual_with(&crate::steps::Geometry::of(model), model, vp, inputs, v, signs)
}

/// [`residual`] on a prepared geometry.
fn residual_with(
    geometry: &crate::steps::Geometry<f64>,
    model: &Model,
    vp: &VirtualPlan,
    inputs: &[f64],
    v: f64,
    signs: &[Sign],
) -> Option<f64> {
    let raw = raw_residual(geometry, model, vp, inputs, v, signs)?;
    let r = match vp.compatibility {
        Compatibility::Miss { .. } => raw,
        Compatibility::Input { input, arc, .. } => Compatibility::input_residual(arc, raw, *inputs.get(input)?),
    };
    Some(r).filter(|r| r.is_finite())
}

/// What the plan's steps compute for the residual at `v` on any scalar
/// (an f64, an interval with its derivative): the miss's row, or the value
/// of the input the plan computes (compared to its given value by the
/// caller). `None` where a step has no solution.
pub(crate) fn raw_residual<T: Scalar<Choice = Sign>>(
    geometry: &crate::steps::Geometry<T>,
    model: &Model,
    vp: &VirtualPlan,
    inputs: &[f64],
    v: T,
    signs: &[Sign],
) -> Option<T> {
    let mut given: Vec<T> = inputs.iter().map(|&x| T::c(x)).collect();
    given.push(v);
    let name = |_: usize| -> std::borrow::Cow<'static, str> { std::borrow::Cow::Borrowed("") };
    let g = crate::steps::Given {
        values: &given,
        signs,
        name: &name,
        sites: 0,
    };
    let state = crate::steps::run(&vp.plan, geometry, model.links.len(), &g).ok()?;
    Some(match vp.compatibility {
        Compatibility::Miss { check, row } => {
            let checks = vp.plan.checks(geometry.joints.len());
            let check = checks.get(check)?;
            let rows = crate::steps::check_residual(geometry, &vp.plan, &[*check], &state.poses, &given, T::c(1.0));
            *rows.get(row)?
        }
        Compatibility::Input { joint, .. } => crate::steps::value(geometry, &state, joint),
    })
}

/// A solution of the virtual plan at a root, verified: the plan's own
/// checks ([`plan::run`]) and, for an [`Compatibility::Input`], the
/// computed value meets the given one to the verification tolerance
/// ([`zero_of`]).
pub(crate) fn verified(model: &Model, vp: &VirtualPlan, given: &[f64], signs: &[Sign]) -> Option<Solution> {
    let solution = plan::run(model, &vp.plan, given, signs).ok()?;
    if let Compatibility::Input { joint, input, arc } = vp.compatibility {
        let r = Compatibility::input_residual(arc, solution.values[joint], given[input]);
        if r.is_nan() || r.abs() > zero_of(model) {
            return None;
        }
    }
    Some(solution)
}

/// What counts as zero for a model's residual: a length within
/// [`crate::consistency::VERIFY_TOL`] of the mechanism's size, the
/// tolerance a solution's checks are verified to.
pub fn zero_of(model: &Model) -> f64 {
    crate::consistency::VERIFY_TOL * crate::kinematics::model_scale(model)
}

/// `n` inputs, each finite.
///
/// # Errors
/// [`SolveError::BadInput`] for another count or a value not finite.
pub fn check_inputs(inputs: &[f64], n: usize) -> Result<(), SolveError> {
    if inputs.len() != n {
        return Err(SolveError::BadInput {
            what: format!("expected {n} inputs, got {}", inputs.len()).into(),
        });
    }
    if let Some(i) = inputs.iter().position(|v| !v.is_finite()) {
        return Err(SolveError::BadInput {
            what: format!("given value {} is {}", i + 1, inputs[i]).into(),
        });
    }
    Ok(())
}

/// How far apart two solutions place the links: the largest distance
/// between a link's two origins, as a fraction of the mechanism's size
/// `scale`, or between its two orientations, in radians.
pub fn distance(a: &Solution, b: &Solution, scale: f64) -> f64 {
    a.poses
        .iter()
        .zip(&b.poses)
        .map(|(p, q)| {
            ((p.translation.vector - q.translation.vector).norm() / scale).max(p.rotation.angle_to(&q.rotation))
        })
        .fold(0.0, f64::max)
}

/// Every assembly at the mechanism's `inputs`: on every branch, every root
/// of the compatibility residual over the virtual variable's range,
/// certified or possible ([`crate::certify`]), solved and verified by the
/// plan interpreter ([`plan::run`]); an assembly two branches share (where
/// they meet) once.
///
/// # Errors
/// [`SolveError::BadInput`] for inputs of the wrong count or not finite.
pub fn solve(model: &Model, vp: &VirtualPlan, inputs: &[f64]) -> Result<Assemblies<Assembly>, SolveError> {
    check_inputs(inputs, vp.plan.n_inputs - 1)?;
    let geometry = crate::steps::Geometry::of(model);
    let enclosing = crate::steps::Geometry::<Enclosure<1>>::of(model);
    let range = VirtualRange {
        lo: vp.range[0],
        hi: vp.range[1],
        periodic: vp.periodic,
    };
    let scale = crate::kinematics::model_scale(model);
    let given = |v: f64| {
        let mut g = inputs.to_vec();
        g.push(v);
        g
    };
    let found = solve_with(
        &range,
        vp.plan.branches,
        |x, signs| {
            let (raw, took) =
                interval::watch(|| raw_residual(&enclosing, model, vp, inputs, Enclosure::variable(x, 0), signs));
            enclosed(&vp.compatibility, raw, inputs, took)
        },
        |v, signs| residual_with(&geometry, model, vp, inputs, v, signs),
        |v, signs| verified(model, vp, &given(v), signs),
        |a: &Solution, b: &Solution| distance(a, b, scale),
    );
    Ok(Assemblies {
        found: found
            .found
            .into_iter()
            .map(|(signs, r, solution)| {
                let mut a = Assembly {
                    signs,
                    virtual_value: r.x,
                    residual: r.residual,
                    kind: r.kind,
                    cert: r.cert,
                    solution,
                };
                if let Some(p) = polished(model, inputs, &a.solution.values) {
                    a.virtual_value = p.values[vp.joint].clamp(a.cert.lo, a.cert.hi);
                    a.solution = Solution {
                        poses: p.poses,
                        values: p.values,
                    };
                }
                a
            })
            .collect(),
        unresolved: found.unresolved,
    })
}

/// How far [`polished`] may move a joint: of the mechanism's size, or in
/// radians.
pub const POLISH_MOVE: f64 = 1e-9;

/// An assembly's joint values (one per joint) polished on the loop
/// equations at the `inputs` ([`crate::newton::polish`], at most two
/// steps), where a step
/// lowered their residual and no joint moved by more than [`POLISH_MOVE`];
/// `None` otherwise, or where a joint has several values.
///
/// The root is found in the virtual variable and the assembly carried from
/// it by the plan's steps. Near the edge of a branch (two circles nearly
/// tangent in a step) that carry is ill-conditioned: a rounding of the
/// step's square root's argument moves the intersection far, while the
/// loop equations of the pose itself are well conditioned there; Newton's
/// method on them brings the assembly to their accuracy (a 3-RPR's root
/// 10⁻¹⁰ mm off before, 193 ε·cond, is within 1 after). The virtual
/// variable's certificate is unchanged: the polished value is reported
/// inside it.
pub fn polished(model: &Model, inputs: &[f64], values: &[f64]) -> Option<crate::newton::NewtonSolution> {
    if model.joints.iter().any(|j| j.kind.dof() != 1) {
        return None;
    }
    let p = crate::newton::polish(model, inputs, values, 2).ok()?;
    let scale = crate::kinematics::model_scale(model);
    let moved = values
        .iter()
        .zip(&p.values)
        .zip(model.length_values())
        .map(|((a, b), length)| {
            if length {
                (a - b).abs() / scale
            } else {
                crate::solution::wrap_angle(a - b).abs()
            }
        })
        .fold(0.0f64, f64::max);
    (p.iterations > 0 && moved <= POLISH_MOVE).then_some(p)
}

/// An assembly generated code found (`Name::fk_numeric`) at `inputs`,
/// polished on the loop equations of `model` (the mechanism's at the same
/// parameters) as
/// [`polished`] does: its joint values, its points (every joint's, then
/// the named points, `D` coordinates) and its virtual variable's value
/// (`virtual_joint`'s, inside its certificate).
pub fn polish_found<const J: usize, const P: usize, const D: usize, const B: usize>(
    model: &Model,
    virtual_joint: usize,
    inputs: &[f64],
    found: &mut Found<J, P, D, B>,
) {
    if model.joints.len() != J || J + model.points.len() != P {
        return;
    }
    let Some(p) = polished(model, inputs, &found.q) else {
        return;
    };
    let mut points = found.points;
    for (k, point) in points.iter_mut().enumerate() {
        let at = if k < J {
            crate::kinematics::joint_point(model, &p.poses, k)
        } else {
            match crate::kinematics::point(model, &p.poses, &model.points[k - J].name) {
                Some(at) => at,
                None => return,
            }
        };
        point.copy_from_slice(&at[..D]);
    }
    // The same points, moved as little as the joints: else not polished.
    let scale = crate::kinematics::model_scale(model);
    let moved = points
        .iter()
        .zip(&found.points)
        .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs()))
        .fold(0.0f64, f64::max);
    if moved > 10.0 * POLISH_MOVE * scale {
        return;
    }
    found.points = points;
    for (q, v) in found.q.iter_mut().zip(&p.values) {
        *q = *v;
    }
    found.virtual_value = p.values[virtual_joint].clamp(found.cert.lo, found.cert.hi);
}

/// One assembly found by generated code (`Name::fk_numeric`): `J` joint
/// values, `P` points of `D` coordinates, `B` ± choices.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Found<const J: usize, const P: usize, const D: usize, const B: usize> {
    /// The ± choices of the plan's branch it was found on.
    pub signs: [Sign; B],
    /// The virtual variable's value.
    pub virtual_value: f64,
    /// The compatibility residual there.
    pub residual: f64,
    /// Whether proven.
    pub kind: RootKind,
    /// The virtual variable's interval proven to hold it (certified), or
    /// the smallest the search could not decide (possible).
    pub cert: Interval,
    /// Every joint's value.
    pub q: [f64; J],
    /// Every joint's point, then the named points.
    pub points: [[f64; D]; P],
}

/// A root of the residual whose assembly could not be solved and
/// verified at any point of its interval: reported, not dropped.
#[derive(Debug, Clone, PartialEq)]
pub struct Unresolved {
    /// The branch's ± choices.
    pub signs: Vec<Sign>,
    /// The root.
    pub root: Root,
}

/// Every assembly found (`found`, read as a slice), and the roots whose
/// assembly could not be verified (`unresolved`).
#[derive(Debug, Clone, PartialEq)]
pub struct Assemblies<A> {
    /// The assemblies, each verified.
    pub found: Vec<A>,
    /// Roots without a verified assembly.
    pub unresolved: Vec<Unresolved>,
}

impl<A> std::ops::Deref for Assemblies<A> {
    type Target = [A];
    fn deref(&self) -> &[A] {
        &self.found
    }
}

impl<A> IntoIterator for Assemblies<A> {
    type Item = A;
    type IntoIter = std::vec::IntoIter<A>;
    fn into_iter(self) -> Self::IntoIter {
        self.found.into_iter()
    }
}

impl<'a, A> IntoIterator for &'a Assemblies<A> {
    type Item = &'a A;
    type IntoIter = std::slice::Iter<'a, A>;
    fn into_iter(self) -> Self::IntoIter {
        self.found.iter()
    }
}

/// Whether two joint values are one: within `tol`, or a whole number of
/// turns apart to 1e-9 (an angle).
pub fn same_value(x: f64, y: f64, tol: f64) -> bool {
    let d = (x - y).abs();
    let turn = 2.0 * std::f64::consts::PI;
    d <= tol || (d - turn * (d / turn).round()).abs() <= 1e-9
}

/// Two assemblies within this (of the mechanism's size, or radians) are
/// one ([`solve_with`]).
pub const SAME: f64 = 1e-7;

/// How far apart two joint values are (the same where a whole number of
/// turns apart to 1e-9: an angle).
pub fn value_distance(x: f64, y: f64) -> f64 {
    if same_value(x, y, 0.0) {
        0.0
    } else {
        (x - y).abs()
    }
}

/// The driver both the interpreter ([`solve`]) and generated code run: on
/// every branch of a plan with `branches` ± choices, every root of the
/// residual over `range` ([`certify::roots`] on `enclose(x, signs)`, its
/// enclosure over the interval `x`), evaluated at the root by
/// `residual(v, signs)`, solved by `solution(v, signs)` (`None`: the
/// verification failed; a possible root is tried at its interval's ends
/// too, and reported unresolved where none verifies), and kept unless it
/// is one found before (where two branches meet: the certified one kept).
/// Two are one where `far` (their distance, of the mechanism's size or in
/// radians) is within [`SAME`]: near a fold two roots closer than the
/// search can place a possible one stay two rows, and one root at the
/// edge of two branches may be listed on both.
pub fn solve_with<S>(
    range: &VirtualRange,
    branches: usize,
    enclose: impl Fn(Interval, &[Sign]) -> Option<certify::Enclosed<1>>,
    residual: impl Fn(f64, &[Sign]) -> Option<f64>,
    solution: impl Fn(f64, &[Sign]) -> Option<S>,
    far: impl Fn(&S, &S) -> f64,
) -> Assemblies<(Vec<Sign>, Root, S)> {
    let mut out: Vec<(Vec<Sign>, Root, S)> = Vec::new();
    let mut unresolved = Vec::new();
    let period = range.hi - range.lo;
    for (signs, ()) in crate::solution::every_branch(branches, |_| ()) {
        let (mut found, _) = certify::roots([Interval::new(range.lo, range.hi)], &LIMITS, |x| enclose(x[0], &signs));
        found.sort_by(|a, b| a.x[0].total_cmp(&b.x[0]));
        for c in found {
            let kind = match c.doubt {
                None => RootKind::Certified,
                Some(d) => RootKind::Possible(d),
            };
            let mut root = Root {
                x: c.x[0],
                residual: f64::NAN,
                kind,
                cert: c.cert[0],
            };
            let mut tries = vec![root.x];
            if !kind.certified() {
                tries.extend([root.cert.lo, root.cert.hi, root.cert.mid()]);
            }
            let solved = tries.into_iter().find_map(|x| solution(x, &signs).map(|s| (x, s)));
            let Some((x, s)) = solved else {
                root.residual = residual(root.x, &signs).unwrap_or(f64::NAN);
                unresolved.push(Unresolved {
                    signs: signs.clone(),
                    root,
                });
                continue;
            };
            root.x = x;
            root.residual = residual(x, &signs).unwrap_or(f64::NAN);
            if range.periodic && (root.x - range.hi).abs() <= 1e-12 * period {
                // The seam once.
                root.x -= period;
            }
            match out.iter_mut().find(|(_, _, o)| far(o, &s) <= SAME) {
                Some(o) => {
                    if root.kind.certified() && !o.1.kind.certified() {
                        *o = (signs.clone(), root, s);
                    }
                }
                None => out.push((signs.clone(), root, s)),
            }
        }
    }
    Assemblies { found: out, unresolved }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn input_residuals() {
        use std::f64::consts::PI;
        // A slide's: the difference itself.
        assert_eq!(Compatibility::input_residual(None, 7.5, 2.0), 5.5);
        // An angle's: wrapped into (−π, π], as an arc of the given radius.
        for (computed, given, want) in [
            (0.3, 0.1, 0.2),
            (3.0, -3.0, 6.0 - 2.0 * PI),
            (-3.0, 3.0, 2.0 * PI - 6.0),
        ] {
            let r = Compatibility::input_residual(Some(10.0), computed, given);
            assert!((r - 10.0 * want).abs() <= 1e-12, "{computed} {given}: {r}");
        }
        assert_eq!(angle_miss(PI), PI);
        assert_eq!(angle_miss(-PI), PI);
        assert!((angle_miss(5.0 * PI / 2.0) - PI / 2.0).abs() <= 1e-15);
    }

    /// The enclosure of an angle's wrapped difference: shifted by whole
    /// turns, and undecided where the wrap's jump is inside.
    #[test]
    fn input_enclosures() {
        use std::f64::consts::PI;
        let c = Compatibility::Input {
            joint: 0,
            input: 0,
            arc: Some(2.0),
        };
        let x = Enclosure::variable(Interval::new(0.4 + 2.0 * PI, 0.6 + 2.0 * PI), 0);
        let e = enclosed(&c, Some(x), &[0.5], false).unwrap();
        assert!(e.f[0].contains(0.0) && e.f[0].width() < 0.41 && e.decided, "{e:?}");
        assert!(e.j[0][0].contains(2.0) && e.j[0][0].width() < 1e-12);
        // Across the jump, half a turn from the given value: no root.
        let x = Enclosure::variable(Interval::new(0.5 + PI - 0.1, 0.5 + PI + 0.1), 0);
        assert_eq!(enclosed(&c, Some(x), &[0.5], false), None);
        // Across the jump and the given value: undecided.
        let x = Enclosure::variable(Interval::new(0.4, 0.5 + PI + 0.1), 0);
        let e = enclosed(&c, Some(x), &[0.5], false).unwrap();
        assert!(!e.decided && e.f[0].contains(0.0));
        // The wrapped residual's roots: one, certified.
        let found = solve_with(
            &VirtualRange {
                lo: -PI,
                hi: PI,
                periodic: true,
            },
            0,
            |x, _| enclosed(&c, Some(Enclosure::variable(x, 0)), &[0.5], false),
            |v, _| Some(Compatibility::input_residual(Some(2.0), v, 0.5)),
            |v, _| Some(v),
            |a: &f64, b: &f64| (a - b).abs(),
        );
        assert_eq!(found.len(), 1, "{found:?}");
        let (_, root, v) = &found[0];
        assert!(
            root.kind.certified() && (v - 0.5).abs() <= 1e-15 && root.cert.contains(0.5),
            "{root:?}"
        );
    }
}
