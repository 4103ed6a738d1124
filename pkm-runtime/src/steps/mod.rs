//! The steps of a solution plan, generic over [`Scalar`]: with `f64` they
//! are the plan interpreter (the oracle), traced by the code generator they
//! are the generated straight-line solvers.
//!
//! One file per step kind, named as its [`crate::plan::Step`] variant,
//! holds what it does (`execute`: it finds its problem in the geometry and
//! hands it to a kernel of [`crate::subproblems`]), its structural match
//! (`find`: when the planner may use it) and its derivative factor
//! (`factor`, for [`crate::singular`]): [`place`], [`transfer`], [`aim`],
//! [`align`], [`pa_plane`], [`guide`], [`beyond`], [`slide_to_line`],
//! [`cone`], [`rod`] (a link with a spherical joint: the sphere about its
//! centre, an S–S link's placing), [`plane_through`] (a U's first half in a
//! leg with both ends known), [`two_turns`] (two revolutes whose axes meet
//! carrying a point to a known one: IK-Geo's subproblem 2, a U's first half
//! before a link that reaches a known point), [`parasitic`] (a pose given
//! in part, from limbs that hold a point on a plane either way round: the
//! planner's start, not in `FIND_ORDER`), and [`locus`], one file per
//! surface a point can be held to (`Constraint::{Sphere, Plane, Cylinder,
//! Slider, Pin}`: [`locus::sphere`], [`locus::plane`], [`locus::cylinder`],
//! [`locus::slider`], [`locus::pin`], each with its `find` and its surface's `normal`; the
//! locus step's own match and factor are here). Every kernel is written
//! for every [`Scalar`], so generated code writes it out, and its
//! derivatives with it. `FIND_ORDER` lists the kinds in the order the
//! planner tries them ([`search`]: what it knows while it searches);
//! [`execute`] and `factor` have one arm per kind. Adding a step kind
//! touches its file and those lists.
//!
//! Geometry that depends on the parameters alone ([`Geometry`]: each joint's
//! places, frames and zero transforms; `geometry.rs`) is prepared once, not
//! per call.

pub mod aim;
pub mod aim_along;
pub mod align;
pub mod beyond;
pub mod cone;
pub mod guide;
pub mod locus;
pub mod pa_plane;
pub mod parasitic;
pub mod place;
pub mod plane_through;
pub mod rod;
pub mod search;
pub mod slide_to_line;
pub mod transfer;
pub mod trilaterate;
pub mod two_turns;

use crate::frame::Frame;
use crate::model::JointType;
use crate::plan::{Check, Plan, Step};
use crate::primitives::Error as GeomError;
use crate::scalar::{dot, norm, scale, sub, Scalar};
use crate::solution::{step_error, PointRef, SolveError};
use std::borrow::Cow;

mod geometry;
pub use geometry::{canonical_frame, place_axis, Geometry, JointGeometry, JointValue, Motion, RESIDUAL_ROWS};

fn degenerate(what: &'static str) -> GeomError<f64> {
    GeomError::Degenerate { what }
}

/// The state of a plan's run: every link's pose and every solved joint's value.
#[derive(Debug, Clone, PartialEq)]
pub struct Solved<T> {
    /// Link poses (the base at the identity; unsolved links too).
    pub poses: Vec<Frame<T>>,
    /// Joint values, where a step solved the joint.
    pub values: Vec<Option<JointValue<T>>>,
}

/// What a step needs besides the geometry: the given values, the ± choices,
/// and the names of the steps' loops for errors.
pub struct Given<'a, T: Scalar> {
    /// The given values (inputs, or output coordinates).
    pub values: &'a [T],
    /// The ± choices, one per branching step.
    pub signs: &'a [T::Choice],
    /// The name of the loop step `k` closes ([`crate::plan::Step::loop_joints`]), for errors.
    pub name: &'a dyn Fn(usize) -> Cow<'static, str>,
    /// Where this plan's steps start among the sites a kernel is called
    /// from (step `k`'s site is `sites + k`): the code generator names the
    /// sites of two plans in one table; the interpreter's is 0.
    pub sites: usize,
}

/// The name of a step's loop: its joints, `R2–R3–R4`; a step that closes
/// no loop (a place or pose given) is "the given position".
pub fn loop_name(step: &Step, joint: impl Fn(usize) -> String) -> String {
    let joints = step.loop_joints();
    if joints.is_empty() {
        return "the given position".into();
    }
    joints.into_iter().map(joint).collect::<Vec<_>>().join("–")
}

/// How far from the origin a given length (a slide's value, a position)
/// may reach, in the mechanism's sizes ([`Geometry::scale`]):
/// `1/VERIFY_TOL`. Beyond it the verification's tolerance (`VERIFY_TOL` of
/// the solution's extent) would exceed the mechanism itself, and rounding
/// the coordinates (1e308 ± 150 is 1e308) would merge its assemblies: such
/// a value is out of reach (refused at the step that takes it), never a
/// wrong ok, a NaN or a false double root.
pub const REACH: f64 = 1.0 / crate::consistency::VERIFY_TOL;

/// Refuses step `k`'s given lengths beyond [`REACH`] sizes as out of reach:
/// a slide given to a transfer (or across which a point is carried), the
/// position a place or a pose given in part puts its point at. Angles are not limited: a turn is its cosine
/// and sine, which any finite angle has.
fn in_reach<T: Scalar>(k: usize, step: &Step, geometry: &Geometry<T>, given: &Given<'_, T>) -> Result<(), SolveError> {
    let lengths: Vec<usize> = match *step {
        Step::Transfer { joint, input, .. }
        | Step::Beyond {
            given: joint, input, ..
        }
        | Step::Guide {
            carried: Some((joint, input)),
            ..
        } if geometry.joints[joint].kind == JointType::P => {
            vec![input]
        }
        Step::Place { input, planar, .. } => (input..input + if planar { 2 } else { 3 }).collect(),
        Step::Parasitic { input, parts, .. } => parts
            .given()
            .enumerate()
            .filter(|&(_, part)| part < 3)
            .map(|(i, _)| input + i)
            .collect(),
        _ => return Ok(()),
    };
    let far = T::c(REACH) * geometry.scale();
    for i in lengths {
        let v = given.values[i].abs();
        let beyond = crate::scalar::Failure::Unreachable("|given length| <= 1e10 sizes of the mechanism", v - far);
        T::require(v, far, beyond, [k, given.sites + k]).map_err(|e| step_error(k, (given.name)(k), e))?;
    }
    Ok(())
}

/// Executes step number `k`: sets the pose of the link it solves and the
/// value of the joint it solves.
pub fn execute<T: Scalar>(
    k: usize,
    step: &Step,
    geometry: &Geometry<T>,
    state: &mut Solved<T>,
    given: &Given<'_, T>,
) -> Result<(), SolveError> {
    use crate::plan::Constraint;
    in_reach(k, step, geometry, given)?;
    // A step that places its link from the given values alone.
    let (Some((joint, from)), to) = step.solves() else {
        match *step {
            Step::Place {
                link,
                point,
                input,
                planar,
                turn,
            } => {
                state.poses[link] = place::execute(link, point, input, planar, turn, geometry, given);
            }
            Step::Trilaterate {
                link,
                ref spheres,
                branch,
            } => {
                state.poses[link] = trilaterate::execute(k, link, spheres, branch, geometry, &state.poses, given)?;
            }
            Step::Parasitic {
                link,
                point,
                input,
                parts,
                ref limbs,
                branch,
            } => {
                state.poses[link] = parasitic::execute(
                    k,
                    link,
                    point,
                    input,
                    parts,
                    limbs,
                    branch,
                    geometry,
                    &state.poses,
                    given,
                )?;
            }
            _ => {}
        }
        return Ok(());
    };
    let mv = Move {
        k,
        joint,
        from,
        to,
        geometry,
        state,
        given,
    };
    let (joint, to, pose, value) = match step {
        Step::Place { .. } | Step::Parasitic { .. } | Step::Trilaterate { .. } => return Ok(()),
        Step::Transfer { input, .. } => transfer::execute(&mv, *input),
        Step::Aim { point, target, .. } => aim::execute(&mv, *point, target)?,
        Step::Align { group, target, .. } => align::execute(&mv, group, target)?,
        Step::PaPlane { pa, target, branch, .. } => pa_plane::execute(&mv, *pa, target, *branch)?,
        Step::Guide {
            carried,
            slide,
            point,
            target,
            branch,
            ..
        } => guide::execute(&mv, *carried, *slide, *point, target, *branch)?,
        Step::AimAlong {
            slide, point, target, ..
        } => aim_along::execute(&mv, *slide, *point, target)?,
        Step::Beyond {
            given: q,
            input,
            point,
            constraint,
            branch,
            ..
        } => beyond::execute(&mv, *q, *input, *point, constraint, *branch)?,
        Step::SlideToLine { slide, point, meet, .. } => slide_to_line::execute(&mv, *slide, *point, meet)?,
        Step::Cone {
            across, target, branch, ..
        } => cone::execute(&mv, *across, target, *branch)?,
        Step::Rod { other, target, .. } => rod::execute(&mv, *other, target)?,
        Step::PlaneThrough {
            across,
            slide,
            point,
            target,
            branch,
            ..
        } => plane_through::execute(&mv, *across, *slide, *point, target, *branch)?,
        Step::TwoTurns {
            across,
            point,
            target,
            branch,
            ..
        } => two_turns::execute(&mv, *across, *point, target, *branch)?,
        Step::Locus {
            point,
            constraint,
            branch,
            ..
        } => match constraint {
            Constraint::Sphere { centre, radius } => locus::sphere::execute(&mv, *point, centre, *radius, *branch)?,
            Constraint::Plane { normal, anchor } => locus::plane::execute(&mv, *point, normal, anchor, *branch)?,
            Constraint::Cylinder { hops, joint: h, link } => {
                locus::cylinder::execute(&mv, *point, hops, *h, *link, *branch)?
            }
            Constraint::Slider { hops, joint: h, link } => {
                locus::slider::execute(&mv, *point, hops, *h, *link, *branch)?
            }
            Constraint::Pin {
                hops,
                link,
                pin,
                sphere,
            } => locus::pin::execute(&mv, *point, hops, *link, *pin, *sphere, *branch)?,
        },
    };
    state.poses[to] = pose;
    state.values[joint] = Some(value);
    Ok(())
}

/// One step solving `joint` between the known link `from` and the new link
/// `to`: what every step kind's `execute` starts from.
pub struct Move<'a, T: Scalar> {
    /// The step's number in the plan (for errors).
    pub k: usize,
    /// The joint it solves.
    pub joint: usize,
    /// The known link.
    pub from: usize,
    /// The new link.
    pub to: usize,
    /// The mechanism's geometry.
    pub geometry: &'a Geometry<T>,
    /// The poses and values found so far.
    pub state: &'a Solved<T>,
    /// The given values and choices.
    pub given: &'a Given<'a, T>,
}

impl<T: Scalar> Move<'_, T> {
    /// The joint's geometry.
    pub fn joint(&self) -> &JointGeometry<T> {
        &self.geometry.joints[self.joint]
    }

    /// Whether the known link is the joint's first.
    pub fn forward(&self) -> bool {
        self.joint().links[0] == self.from
    }

    /// A point of the new link (in its frame) and how the joint moves it.
    pub fn motion(&self, point: PointRef) -> ([T; 3], Motion<T>) {
        let x = self.geometry.local(point, self.to);
        (x, self.joint().motion(&self.state.poses[self.from], self.forward(), x))
    }

    /// The axis a revolute turns the new link about, and the new link's pose
    /// at value 0; `what` names the step kind when the joint does not turn.
    pub fn turning(&self, what: &'static str) -> Result<([T; 3], Frame<T>), SolveError> {
        let (j, f) = (self.joint(), &self.state.poses[self.from]);
        let axis = j
            .turning_axis(f, self.forward())
            .ok_or_else(|| self.fail(degenerate(what)))?;
        Ok((axis, f.then(&j.zero[usize::from(!self.forward())])))
    }

    /// The step's site for kernels: the step, and its index among the sites ([`Given::sites`]).
    pub fn site(&self) -> [usize; 2] {
        [self.k, self.given.sites + self.k]
    }

    /// A kernel's failure as this step's.
    pub fn fail(&self, e: GeomError<f64>) -> SolveError {
        step_error(self.k, (self.given.name)(self.k), e)
    }

    /// The root choice of branching step number `branch`.
    pub fn choice(&self, branch: Option<usize>) -> T::Choice {
        T::choice(self.given.signs, branch)
    }

    /// The new link's pose at the value a kernel found (a turn for R and Pa
    /// joints, a slide for P).
    pub fn found(&self, r: [T; 2]) -> Found<T> {
        self.at(as_value(self.joint().kind, r))
    }

    /// The new link's pose at `value`.
    pub fn at(&self, value: JointValue<T>) -> Found<T> {
        found(self.geometry, self.state, self.joint, self.from, self.to, value)
    }
}

/// What a turning or sliding step found: the joint, the new link, its pose and the value.
pub(crate) type Found<T> = (usize, usize, Frame<T>, JointValue<T>);

/// The new link's pose across `joint` from `from` at `value`.
pub(crate) fn found<T: Scalar>(
    geometry: &Geometry<T>,
    state: &Solved<T>,
    joint: usize,
    from: usize,
    to: usize,
    value: JointValue<T>,
) -> Found<T> {
    let j = &geometry.joints[joint];
    let forward = j.links[0] == from;
    (joint, to, j.transfer(&state.poses[from], forward, value), value)
}

/// A kernel's two results as a joint value: a turn for R and Pa joints, a slide for P.
pub(crate) fn as_value<T: Scalar>(kind: JointType, r: [T; 2]) -> JointValue<T> {
    match kind {
        JointType::P => JointValue::Slide(r[0]),
        _ => JointValue::Turn(r[0], r[1], None),
    }
}

/// Runs every step of `plan` from the base (link 0 at the identity) for
/// `n_links` links; unverified (see [`check_residual`]).
pub fn run<T: Scalar>(
    plan: &crate::plan::Plan,
    geometry: &Geometry<T>,
    n_links: usize,
    given: &Given<'_, T>,
) -> Result<Solved<T>, SolveError> {
    let mut state = Solved {
        poses: vec![Frame::identity(); n_links],
        values: vec![None; geometry.joints.len()],
    };
    for (k, step) in plan.steps.iter().enumerate() {
        execute(k, step, geometry, &mut state, given)?;
    }
    Ok(state)
}

/// What tells one branch's solution from another's: for each step that
/// chooses a root, in plan order, what it solved (a turn's cosine and
/// sine, a slide; for a pose given in part, the placed link's origin and
/// first two axes). Every other step is a function of the given values and
/// of these, so two branches whose choices' values agree are one solution
/// (a double root), and two whose results agree while these do not are two
/// assemblies (the two postures of a parallelogram's leg reach the same
/// platform).
pub fn choice_values<T: Scalar>(plan: &Plan, state: &Solved<T>) -> Vec<T> {
    let mut out = Vec::new();
    for step in plan.steps.iter().filter(|s| s.branch().is_some()) {
        match step {
            Step::Trilaterate { link, .. } => out.extend(state.poses[*link].t),
            Step::Parasitic { link, .. } => {
                let p = &state.poses[*link];
                out.extend(p.t);
                out.extend(p.column(0));
                out.extend(p.column(1));
            }
            _ => match step.joint().and_then(|j| state.values[j]) {
                Some(JointValue::Turn(c, s, _)) => out.extend([c, s]),
                Some(JointValue::Slide(t)) => out.push(t),
                None => {}
            },
        }
    }
    out
}

/// Joint `j`'s value in a solution: the step's where a step solved it,
/// otherwise from its links' poses.
pub fn value<T: Scalar>(geometry: &Geometry<T>, state: &Solved<T>, j: usize) -> T {
    match state.values[j] {
        Some(v) => v.value(),
        None => {
            let joint = &geometry.joints[j];
            joint.value_between(&state.poses[joint.links[0]], &state.poses[joint.links[1]])
        }
    }
}

/// A spherical joint's rotation in the runtime model's form
/// ([`crate::model`]: `T_v = T_u · Trans(c_u) · Rot(r) · Trans(−c_v)`): the
/// rotation vector `r = θ·n` of `R = R_uᵀ·R_v` between its two links'
/// poses (`joint.links` order), θ in [0, π], and θ. With `v = (R₃₂ − R₂₃,
/// R₁₃ − R₃₁, R₂₁ − R₁₂) = 2 sin θ·n` and `cos θ = (tr R − 1)/2`, θ is
/// `atan2(|v|/2, cos θ)`; where cos θ ≥ 0, `r = v·θ/|v|` (½·v at θ = 0);
/// beyond a quarter turn, where `v` fades towards the half turn, `n` is
/// the column of `(R + Rᵀ)/2 − cos θ·I = (1 − cos θ)·n·nᵀ` with the largest
/// diagonal, normalised, signed along `v`. For every [`Scalar`]: generated
/// solutions give the same numbers as [`crate::plan::Solution::model_values`].
pub fn ball_rotation<T: Scalar>(geometry: &Geometry<T>, state: &Solved<T>, j: usize) -> ([T; 3], T) {
    let [u, w] = geometry.joints[j].links;
    rotation_vector(state.poses[u].inverse().then(&state.poses[w]).r)
}

/// The rotation vector of the rotation matrix `m` and its angle θ in
/// [0, π] ([`ball_rotation`]).
pub fn rotation_vector<T: Scalar>(m: [[T; 3]; 3]) -> ([T; 3], T) {
    let (zero, half) = (T::c(0.0), T::c(0.5));
    let v = [m[2][1] - m[1][2], m[0][2] - m[2][0], m[1][0] - m[0][1]];
    let c = (m[0][0] + m[1][1] + m[2][2] - T::c(1.0)) * half;
    let nv = norm(v);
    let theta = (nv * half).atan2(c);
    let f = T::if_less(zero, nv, theta / nv, half);
    let near = scale(f, v);
    let d = [m[0][0] - c, m[1][1] - c, m[2][2] - c];
    let column =
        |k: usize| -> [T; 3] { core::array::from_fn(|i| if i == k { d[k] } else { (m[i][k] + m[k][i]) * half }) };
    let pick = |a: T, b: T, x: [T; 3], y: [T; 3]| -> [T; 3] { core::array::from_fn(|i| T::if_less(a, b, x[i], y[i])) };
    let b01 = pick(d[0], d[1], column(1), column(0));
    let d01 = crate::scalar::max(d[0], d[1]);
    let b = pick(d01, d[2], column(2), b01);
    let along = dot(b, v);
    let signed = T::if_less(along, zero, -theta, theta) / norm(b);
    let far = scale(signed, b);
    (pick(c, zero, far, near), theta)
}

/// The residual of every check ([`RESIDUAL_ROWS`] rows each): an open
/// joint's closure ([`JointGeometry::closure_residual`]), a pinned point's
/// distance from where it was given (3 lengths, then zeros).
pub fn check_residual<T: Scalar>(
    geometry: &Geometry<T>,
    plan: &Plan,
    checks: &[Check],
    poses: &[Frame<T>],
    given: &[T],
    extent: T,
) -> Vec<T> {
    let zero = T::c(0.0);
    checks
        .iter()
        .flat_map(|check| match *check {
            Check::Joint(k) => {
                // The aim that left it open left only its miss (the same
                // vector, to rounding, without the turn's pose).
                if let Some(by) = plan.by_miss.iter().find(|b| b.joint == k) {
                    return aim::closure(geometry, poses, &plan.steps, by, extent);
                }
                let j = &geometry.joints[k];
                j.closure_residual(&poses[j.links[0]], &poses[j.links[1]], extent)
            }
            Check::Pin(k) => match &plan.steps[k] {
                Step::Place {
                    link,
                    point,
                    input,
                    planar,
                    ..
                } => {
                    let local = geometry.local(*point, *link);
                    let (want, _) = place::given_point(given, *input, *planar, local[2]);
                    let d = sub(poses[*link].apply(local), want);
                    [d[0], d[1], d[2], zero, zero, zero, zero, zero, zero]
                }
                _ => [zero; RESIDUAL_ROWS],
            },
        })
        .collect()
}

/// The step kinds' matches in the order the planner tries them
/// ([`search::Search::step`] takes the first that finds a step): a given
/// value first, then aim, align, the parallelogram plane, a locus without
/// a branch, a line along the turning axis through a known point (an aim
/// seen along the axis, one root, where a locus's circle would only touch
/// its cylinder, [`aim_along::find`]), a locus with one, a guide through a known point (an RPR
/// dyad, which nothing before it solves), a point beyond a joint whose
/// value is given on a cylinder (an input between two moving links), a
/// slide bringing a point onto a line (the PRP and RPP dyads), an axis
/// kept at its angle from a known axis through one centre (a spherical RRR
/// dyad), a link with a spherical joint (an S–S link placed between its
/// two known centres, or the sphere about a known centre that a point of
/// the link keeps met by a point of the new link, [`rod::find`]),
/// a revolute turning the plane a revolute and a slide beyond it sweep
/// through a known point (a U's first half in a U-P-S or U-P-U leg,
/// [`plane_through::find`]), and last two revolutes whose axes meet
/// carrying a point of the link beyond the second to a known point (the
/// first angle of IK-Geo's subproblem 2: a U's first half before a link
/// that reaches a known point, [`two_turns::find`]; tried last so that
/// plans that need none are unchanged).
pub(crate) const FIND_ORDER: [fn(&mut search::Search<'_>) -> bool; 15] = [
    transfer::find,
    aim::find,
    align::find,
    pa_plane::find,
    |s| find_locus(s, false),
    aim_along::find,
    |s| find_locus(s, true),
    guide::find,
    beyond::find,
    slide_to_line::find,
    cone::find,
    rod::find,
    plane_through::find,
    two_turns::find,
    trilaterate::find,
];

/// The planner's match for a locus step: a point of the new link that the
/// rest of the mechanism holds on a sphere, plane, cylinder or slider plane
/// ([`constraints`]), the first whose step branches as `want_branch` says.
fn find_locus(s: &mut search::Search<'_>, want_branch: bool) -> bool {
    find_locus_by(s, want_branch, false)
}

/// [`find_locus`] among the loci of `rods` (the spheres about a link's
/// known spherical centre, [`rod::find_sphere`]) or of the other
/// joints.
pub(crate) fn find_locus_by(s: &mut search::Search<'_>, want_branch: bool, rods: bool) -> bool {
    // Slides first: a slide's value is found along its line directly
    // (t₀ ± √((d − e)(d + e))), where a turn's would reach it only through
    // an angle and a composed rotation, a few roundings more.
    let mut candidates = s.candidates();
    candidates.sort_by_key(|&(j, ..)| s.kind(j) != JointType::P);
    for (j, from, to) in candidates {
        for (point, x) in s.points_of(to, j) {
            let found = constraints(s, j, to, point, x, rods)
                .into_iter()
                .find(|(_, two)| *two == want_branch);
            if let Some((constraint, two)) = found {
                let branch = if two {
                    s.branches += 1;
                    Some(s.branches - 1)
                } else {
                    None
                };
                let step = Step::Locus {
                    joint: j,
                    from,
                    to,
                    point,
                    constraint,
                    branch,
                };
                s.push(step, to, j);
                return true;
            }
        }
    }
    false
}

/// Constraints on point `x` of `to` from the rest of the mechanism, moved
/// by joint `j`, with whether each step branches: along each reach out of
/// `to` that keeps the point put, the loci the joints met there hold it on
/// (a parallelogram's sphere, a revolute's cylinder, a slide's plane), in
/// the order of those joints, then the reach's plane. The order decides
/// the plans. With `rods`, only the spheres links with a known spherical
/// centre hold it on ([`rod::find_sphere`]).
fn constraints(
    s: &search::Search<'_>,
    j: usize,
    to: usize,
    point: PointRef,
    x: nalgebra::Vector3<f64>,
    rods: bool,
) -> Vec<(crate::plan::Constraint, bool)> {
    let mut out = Vec::new();
    let circle = s.kind(j) != JointType::P;
    // The motion's axis (circle) or direction (line) in `to`'s frame.
    let k = s.axis(j, to);
    for r in s.fixed_reach(to, x, &[j]) {
        if s.known[r.link] {
            continue;
        }
        let rot = s.rotation(&r.hops);
        // The hops that carry the point must turn about the motion's axis too.
        let turning = circle && s.hops_about(to, &r.hops, k);
        for (q, joint) in s.model.joints.iter().enumerate() {
            if q == j || !joint.links.contains(&r.link) || r.hops.iter().any(|h| h.joint == q) {
                continue;
            }
            let found = match joint.kind {
                _ if rods => rod::find_sphere(s, j, &r, q),
                JointType::Pa => locus::sphere::find(s, j, &r, q),
                JointType::R if circle => locus::cylinder::find(s, &r, q, k, rot, turning),
                JointType::R => locus::cylinder::find_slide(s, to, &r, q, k, rot),
                JointType::P => locus::slider::find(s, &r, q, k, rot, turning),
                JointType::S => None,
            };
            out.extend(found.map(|c| (c, true)));
        }
        if !rods {
            out.extend(locus::plane::find(s, j, point, &r, k, circle));
            out.extend(locus::pin::find(s, to, &r, k, rot, turning, circle).map(|c| (c, true)));
        }
    }
    // Last, links that are one body seen along the motion's axis: across a
    // slide along it the point keeps its distance from a revolute's axis
    // parallel to it, the cylinder about that revolute.
    if circle && !rods {
        for r in s.axial_reach(to, x, &[j], k) {
            if s.known[r.link] {
                continue;
            }
            let (rot, turning) = (s.rotation(&r.hops), s.hops_about(to, &r.hops, k));
            for (q, joint) in s.model.joints.iter().enumerate() {
                // A point on q's axis would meet a cylinder of radius 0 (a
                // line through a point: a guide's one root, not a circle's two).
                if q != j
                    && joint.kind == JointType::R
                    && joint.links.contains(&r.link)
                    && r.hops.iter().all(|h| h.joint != q)
                    && !s.on_axis(q, r.link, r.x)
                {
                    out.extend(locus::cylinder::find(s, &r, q, k, rot, turning).map(|c| (c, true)));
                }
            }
        }
    }
    out
}

/// Step number `k`'s factor at the configuration `at`: its kind's
/// `factor`; none for the steps that only place a link from given values
/// (inputs or a pose).
pub(crate) fn factor(at: &crate::singular::Configuration, k: usize, step: &Step) -> Option<crate::singular::Factor> {
    Some(match step {
        // The free parts' factor is not written yet: the singularity map
        // of an inverse plan with a pose given in part misses that step's.
        // Nor the three spheres' (their tangency, a forward singularity).
        Step::Place { .. } | Step::Parasitic { .. } | Step::Trilaterate { .. } | Step::Transfer { .. } => return None,
        Step::Aim {
            joint,
            from,
            to,
            point,
            target,
        } => aim::factor(at, k, *joint, *from, *to, *point, target),
        Step::Align {
            joint,
            from,
            to,
            group,
            target,
        } => align::factor(at, k, *joint, *from, *to, group, target),
        Step::PaPlane {
            joint,
            from,
            to,
            pa,
            target,
            ..
        } => pa_plane::factor(at, k, *joint, *from, *to, *pa, target),
        Step::Guide {
            joint,
            from,
            to,
            carried,
            slide,
            target,
            ..
        } => guide::factor(at, k, *joint, *from, *to, *carried, *slide, target),
        Step::Beyond { .. } => return beyond::factor(at, k, step),
        Step::AimAlong { .. } => return aim_along::factor(at, k, step),
        Step::SlideToLine { .. } => return slide_to_line::factor(at, k, step),
        Step::Cone {
            joint,
            from,
            to,
            across,
            target,
            ..
        } => cone::factor(at, k, *joint, *from, *to, *across, target),
        // Placing an S–S link between known centres solves no equation.
        Step::Rod { .. } => return None,
        Step::PlaneThrough {
            joint,
            from,
            to,
            across,
            slide,
            target,
            ..
        } => plane_through::factor(at, k, *joint, *from, *to, *across, *slide, target),
        Step::TwoTurns {
            joint,
            from,
            to,
            across,
            target,
            ..
        } => two_turns::factor(at, k, *joint, *from, *to, *across, target),
        Step::Locus {
            joint,
            from,
            to,
            point,
            constraint,
            ..
        } => locus_factor(at, k, *joint, *from, *to, *point, constraint),
    })
}

/// A locus step's factor: the cosine between the moving point's path and
/// the normal of the surface it must reach (its constraint's `normal`).
fn locus_factor(
    at: &crate::singular::Configuration,
    k: usize,
    joint: usize,
    from: usize,
    to: usize,
    point: PointRef,
    constraint: &crate::plan::Constraint,
) -> crate::singular::Factor {
    use crate::plan::Constraint;
    use crate::singular::{crossing, joint_point, Factor, LinkPoint};
    let (p, t) = at.path(joint, from, to, point);
    let (n, condition, other) = match constraint {
        Constraint::Sphere { centre, .. } => locus::sphere::normal(at, p, centre),
        Constraint::Plane { normal, anchor } => locus::plane::normal(at, normal, anchor),
        Constraint::Cylinder { joint: h, link, .. } => locus::cylinder::normal(at, p, *h, *link),
        Constraint::Slider { joint: h, link, .. } => locus::slider::normal(at, joint, from, *h, *link),
        Constraint::Pin { link, pin, sphere, .. } => locus::pin::normal(at, p, *link, *pin, *sphere),
    };
    Factor {
        step: k,
        joint,
        condition,
        points: [joint_point(joint, from), LinkPoint { link: to, point }, other],
        value: crossing(t, n, at.scale),
    }
}

#[cfg(test)]
mod tests {
    use super::rotation_vector;
    use nalgebra::{Rotation3, Vector3};

    /// The rotation vector back from the matrix nalgebra builds of a known
    /// one (the ground truth is the vector itself): angles from 0 through
    /// a quarter turn (where the kernel changes form) to a hair short of
    /// the half turn, about 200 axes; within 4 ulps of π.
    #[test]
    fn rotation_vector_of_known_rotations() {
        use std::f64::consts::{FRAC_PI_2, PI};
        let mut rng = crate::random::SplitMix::new(0x9e37_79b9_7f4a_7c15);
        let mut next = || rng.symmetric();
        let angles = [
            0.0,
            1e-300,
            1e-12,
            1e-6,
            0.3,
            1.5,
            FRAC_PI_2 - 1e-9,
            FRAC_PI_2 + 1e-9,
            2.5,
            3.0,
            PI - 1e-6,
            PI - 1e-12,
        ];
        let mut worst = 0.0f64;
        for _ in 0..200 {
            let n = Vector3::new(next(), next(), next()).normalize();
            for &theta in &angles {
                let r = n * theta;
                let m = Rotation3::from_scaled_axis(r);
                let m = core::array::from_fn(|i| core::array::from_fn(|j| m[(i, j)]));
                let (got, angle) = rotation_vector::<f64>(m);
                let d = (0..3).map(|c| (got[c] - r[c]).abs()).fold(0.0, f64::max);
                worst = worst.max(d).max((angle - theta).abs());
            }
        }
        assert!(worst <= 4.0 * PI * f64::EPSILON, "{worst:e}");
    }
}
