//! Forward positions along a trajectory of a coupled mechanism, without
//! a silent jump to another assembly: from the previous assembly, Newton's
//! method at the next inputs, then a certificate that no other assembly
//! lies between the two ([`certify::near`]); where the certificate fails,
//! the full forward solution ([`fk_numeric::solve`], κ = 1) and the
//! assembly nearest the previous one, said so ([`How::Resolved`]). Where no
//! full solution exists (κ ≥ 2), a tracked assembly without the
//! certificate is reported possible ([`How::Possible`]), never as tracked.
//!
//! Two unknowns serve: the virtual variable of a κ = 1 plan on the
//! previous assembly's branch ([`by_virtual`]), or the pose the inverse
//! plan is given, on the previous assembly's inverse branch ([`by_pose`],
//! any mechanism with an inverse plan whose outputs fix every link: the
//! Stewart platform's six pose values, a 3-RPS's height and two tilts).
//! The residual is the actuated joints' values the inverse plan computes
//! less the given ones, an angle's difference wrapped and measured as the
//! arc at the mechanism's size ([`fk_numeric::Compatibility::input_residual`]).

pub use crate::fk_numeric::distance;

use crate::certify::{self, Limits, Lost};
use crate::fk_numeric::{self, Assembly, VirtualPlan};
use crate::interval::{self, Enclosure, Interval};
use crate::model::{JointType, Model};
use crate::plan::{self, Plan, Solution};
use crate::primitives::Sign;
use crate::scalar::Scalar;
use crate::solution::SolveError;

/// How an assembly of a trajectory was reached.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum How {
    /// Newton's method from the previous assembly, and a certificate
    /// that no other assembly lies between them: the same assembly mode.
    Tracked,
    /// The certificate failed (a fold near, or a step too long): the full
    /// forward solution found `assemblies` assemblies, and this is the one
    /// nearest the previous (by every link's pose).
    Resolved {
        /// How many the full solution found.
        assemblies: usize,
    },
    /// Newton's method reached a verified assembly, but nothing proves it
    /// is the previous one's continuation, and no full solution exists to
    /// choose from (κ ≥ 2): why.
    Possible(Lost),
}

impl How {
    /// In words.
    pub fn text(self) -> String {
        match self {
            How::Tracked => "tracked".into(),
            How::Resolved { assemblies } => {
                format!("resolved: the certificate failed, the nearest of {assemblies} assemblies")
            }
            How::Possible(Lost::Diverged) => "possible: Newton's method did not converge".into(),
            How::Possible(Lost::NotAlone) => {
                "possible: not proven the previous assembly's continuation (another assembly or a fold may lie between them, or the enclosures are too wide to tell)".into()
            }
        }
    }
}

/// One assembly of a trajectory.
#[derive(Debug, Clone, PartialEq)]
pub struct Followed {
    /// The branch of the plan the unknowns run on (the virtual plan's, or
    /// the inverse plan's).
    pub signs: Vec<Sign>,
    /// The unknowns: the virtual variable, or the inverse plan's given
    /// values (the declared outputs).
    pub unknowns: Vec<f64>,
    /// Their certificate: proven to hold this assembly and no other
    /// (tracked), or the full solution's (resolved), or the unknowns as
    /// points (possible).
    pub cert: Vec<Interval>,
    /// How it was reached.
    pub how: How,
    /// Every link's pose and joint's value, verified.
    pub solution: Solution,
}

/// Why a step of a trajectory has no assembly.
#[derive(Debug, Clone, PartialEq)]
pub enum FollowError {
    /// The inputs are not valid (count, finiteness).
    Input(SolveError),
    /// The full forward solution has no assembly at these inputs.
    NoAssembly,
    /// Newton's method from the previous assembly did not reach a verified
    /// one and there is no full forward solution to fall back on (κ ≥ 2, or
    /// a κ = 1 mechanism without a virtual-variable plan).
    Lost(Lost),
}

impl std::fmt::Display for FollowError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FollowError::Input(e) => write!(f, "{e}"),
            FollowError::NoAssembly => write!(f, "no assembly at these inputs"),
            FollowError::Lost(Lost::Diverged) => write!(
                f,
                "Newton's method from the previous assembly did not converge, and there is no full forward solution to fall back on"
            ),
            FollowError::Lost(Lost::NotAlone) => write!(f, "the assembly reached could not be verified"),
        }
    }
}

impl std::error::Error for FollowError {}

/// The search a certificate may spend, over the box from the previous
/// unknowns to the new: 64 boxes (a short, well-conditioned step is
/// decided by one Krawczyk test), the box's resolution 10⁻¹⁰ of its side.
pub const LIMITS: Limits = Limits {
    boxes: 64,
    resolution: 1e-10,
    initial: 1,
};

/// The certificate's box is widened by this fraction of each unknown's
/// range beyond the span from the previous unknowns to the new.
pub const MARGIN: f64 = 1e-6;

/// [`fk_numeric::check_inputs`] as a step's error.
fn check_inputs(inputs: &[f64], n: usize) -> Result<(), FollowError> {
    fk_numeric::check_inputs(inputs, n).map_err(FollowError::Input)
}

impl Followed {
    /// A start from an assembly of the full forward solution (κ = 1).
    pub fn from_assembly(a: &Assembly) -> Self {
        Followed {
            signs: a.signs.clone(),
            unknowns: vec![a.virtual_value],
            cert: vec![a.cert],
            how: How::Tracked,
            solution: a.solution.clone(),
        }
    }
}

/// The next assembly at `inputs` after `previous` (a κ = 1 mechanism's
/// virtual plan `vp`): tracked on the previous branch and certified, or
/// resolved by the full solution ([`fk_numeric::solve`]) as the nearest.
///
/// # Errors
/// [`FollowError::Input`] for inputs of the wrong count or not finite;
/// [`FollowError::NoAssembly`] where the full solution finds none.
pub fn by_virtual(
    model: &Model,
    vp: &VirtualPlan,
    inputs: &[f64],
    previous: &Followed,
) -> Result<Followed, FollowError> {
    check_inputs(inputs, vp.plan.n_inputs - 1)?;
    let enclosing = crate::steps::Geometry::<Enclosure<1>>::of(model);
    let signs = previous.signs.clone();
    let region = [Interval::new(vp.range[0], vp.range[1])];
    let from = previous.unknowns.first().copied().unwrap_or(f64::NAN);
    let given = |v: f64| {
        let mut g = inputs.to_vec();
        g.push(v);
        g
    };
    let actuated = &vp.plan.inputs[..vp.plan.n_inputs - 1];
    if from.is_finite() {
        let tracked = substepped(model, actuated, &previous.solution, [from], inputs, |q, x| {
            certify::near(x, &region, MARGIN, &LIMITS, |b| {
                let (raw, took) = interval::watch(|| {
                    fk_numeric::raw_residual(&enclosing, model, vp, q, Enclosure::variable(b[0], 0), &signs)
                });
                fk_numeric::enclosed(&vp.compatibility, raw, q, took)
            })
        });
        if let Ok(root) = tracked {
            if let Some(solution) = fk_numeric::verified(model, vp, &given(root.x[0]), &signs) {
                return Ok(Followed {
                    signs,
                    unknowns: vec![root.x[0]],
                    cert: vec![root.cert[0]],
                    how: How::Tracked,
                    solution,
                });
            }
        }
    }
    let all = fk_numeric::solve(model, vp, inputs).map_err(FollowError::Input)?;
    let nearest = nearest(model, &all, |a| &a.solution, previous).ok_or(FollowError::NoAssembly)?;
    Ok(Followed {
        how: How::Resolved { assemblies: all.len() },
        ..Followed::from_assembly(nearest)
    })
}

/// The step from the actuated joints' values in the solution `before`
/// (`actuated`, in the inputs' order) to the inputs `after`, in 1, then 4,
/// then 16 equal parts (an angle's part of its wrapped difference), each
/// part `step(inputs, from)` from the last part's root: the last root
/// where every part of one subdivision passes, or the last failure.
fn substepped<const N: usize>(
    model: &Model,
    actuated: &[usize],
    before: &Solution,
    from: [f64; N],
    after: &[f64],
    mut step: impl FnMut(&[f64], [f64; N]) -> Result<certify::Root<N>, Lost>,
) -> Result<certify::Root<N>, Lost> {
    let before: Vec<f64> = actuated.iter().map(|&j| before.values[j]).collect();
    let turns: Vec<bool> = actuated.iter().map(|&j| model.joints[j].kind != JointType::P).collect();
    let mut last = Err(Lost::Diverged);
    for parts in SUBSTEPS {
        let mut x = from;
        let mut done = None;
        for k in 1..=parts {
            let s = k as f64 / parts as f64;
            let q: Vec<f64> = before
                .iter()
                .zip(after)
                .zip(&turns)
                .map(|((&a, &b), &turn)| {
                    let d = if turn { fk_numeric::angle_miss(b - a) } else { b - a };
                    if k == parts {
                        b
                    } else {
                        a + s * d
                    }
                })
                .collect();
            match step(&q, x) {
                Ok(r) => {
                    x = r.x;
                    done = Some(r);
                }
                Err(e) => {
                    last = Err(e);
                    done = None;
                    break;
                }
            }
        }
        if let Some(r) = done {
            return Ok(r);
        }
    }
    last
}

/// The subdivisions [`substepped`] tries: a step whose certificate fails
/// whole may pass in parts (the box from each part's start to its root is
/// smaller, the Jacobian's enclosure over it tighter).
pub const SUBSTEPS: [usize; 3] = [1, 4, 16];

/// The range each of the inverse plan's given values is searched over:
/// an angle (`angles[i]`) two turns about zero, a length the model's
/// reach ([`fk_numeric::slide_range`]) and the driven slides' values
/// (`inputs`) either side.
fn pose_region(model: &Model, angles: &[bool], inputs: &[f64]) -> Vec<Interval> {
    // The links' spans, and as far as the driven slides carry them.
    let slides: f64 = model
        .inputs()
        .iter()
        .zip(inputs)
        .filter(|(&j, _)| model.joints[j].kind == JointType::P)
        .map(|(_, q)| q.abs())
        .sum();
    let reach = fk_numeric::slide_range(model) + slides;
    let turn = 2.0 * std::f64::consts::PI;
    angles
        .iter()
        .map(|&a| {
            if a {
                Interval::new(-turn, turn)
            } else {
                Interval::new(-reach, reach)
            }
        })
        .collect()
}

/// The start of a trajectory at a pose: the inverse plan's branch
/// `branch` at the given values `pose` (the declared outputs), verified.
///
/// # Errors
/// The inverse solution's error on that branch.
pub fn at_pose(model: &Model, inverse: &Plan, pose: &[f64], branch: usize) -> Result<Followed, SolveError> {
    if branch >= 1usize << inverse.branches {
        return Err(SolveError::BadInput {
            what: format!("branch {branch}: the inverse plan has {}", 1usize << inverse.branches).into(),
        });
    }
    // Bit k set: choice k is `Minus` (the order of every listing).
    let signs: Vec<Sign> = (0..inverse.branches)
        .map(|k| if branch >> k & 1 == 0 { Sign::Plus } else { Sign::Minus })
        .collect();
    let solution = plan::run(model, inverse, pose, &signs)?;
    Ok(Followed {
        signs,
        unknowns: pose.to_vec(),
        cert: pose.iter().map(|&p| Interval::point(p)).collect(),
        how: How::Tracked,
        solution,
    })
}

/// The next assembly at `inputs` (the actuated joints in declaration
/// order) after `previous`, by the pose the inverse plan `inverse` is
/// given (`angles[i]`: whether its given value `i` is an angle): tracked
/// on the previous inverse branch and certified, or reported possible.
/// Any mechanism with an inverse plan; κ ≥ 2 has no full forward solution
/// to resolve a failed certificate.
///
/// # Errors
/// [`FollowError::Input`] for inputs of the wrong count or not finite, or
/// a plan with more than six given values; [`FollowError::Lost`] where
/// Newton's method reaches no verified assembly.
pub fn by_pose(
    model: &Model,
    inverse: &Plan,
    angles: &[bool],
    inputs: &[f64],
    previous: &Followed,
) -> Result<Followed, FollowError> {
    let actuated = model.inputs();
    check_inputs(inputs, actuated.len())?;
    if angles.len() != inverse.n_inputs || previous.unknowns.len() != inverse.n_inputs {
        return Err(FollowError::Input(SolveError::BadInput {
            what: format!("the inverse plan takes {} values", inverse.n_inputs).into(),
        }));
    }
    let region = pose_region(model, angles, inputs);
    let tracked = match inverse.n_inputs {
        1 => pose_step::<1>(model, inverse, &region, &actuated, inputs, previous),
        2 => pose_step::<2>(model, inverse, &region, &actuated, inputs, previous),
        3 => pose_step::<3>(model, inverse, &region, &actuated, inputs, previous),
        4 => pose_step::<4>(model, inverse, &region, &actuated, inputs, previous),
        5 => pose_step::<5>(model, inverse, &region, &actuated, inputs, previous),
        6 => pose_step::<6>(model, inverse, &region, &actuated, inputs, previous),
        n => {
            return Err(FollowError::Input(SolveError::BadInput {
                what: format!("the inverse plan takes {n} values, more than a pose's six").into(),
            }))
        }
    };
    tracked.map_err(FollowError::Lost)
}

/// Of the inverse plan's branches whose assembly at the same pose meets
/// the inputs (`verify`), the one nearest the previous assembly, `own` (the
/// previous step's branch) unless another is nearer: a branch's ± label
/// may name the other configuration of a leg's passive joints across a
/// line where the plan's choice flips (an Orthoglide leg's revolute turned
/// half a turn with its parallelogram the other way, the platform where it
/// was), and the mechanism does not jump there.
fn continued(
    inverse: &Plan,
    previous: &Solution,
    scale: f64,
    own: (Vec<Sign>, Solution),
    verify: impl Fn(&[Sign]) -> Option<Solution>,
) -> (Vec<Sign>, Solution) {
    let from_own = fk_numeric::distance(&own.1, previous, scale);
    if from_own <= 1e-6 {
        return own;
    }
    crate::solution::every_branch(inverse.branches, |s| verify(s))
        .into_iter()
        .filter_map(|(s, solution)| solution.map(|x| (fk_numeric::distance(&x, previous, scale), s, x)))
        .filter(|(d, _, _)| *d < from_own)
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map_or(own, |(_, s, x)| (s, x))
}

/// [`by_pose`] for a plan given `N` values.
fn pose_step<const N: usize>(
    model: &Model,
    inverse: &Plan,
    region: &[Interval],
    actuated: &[usize],
    inputs: &[f64],
    previous: &Followed,
) -> Result<Followed, Lost> {
    let enclosing = crate::steps::Geometry::<Enclosure<N>>::of(model);
    let scale = crate::kinematics::model_scale(model);
    let signs = previous.signs.clone();
    let region: [Interval; N] = core::array::from_fn(|i| region[i]);
    let from: [f64; N] = core::array::from_fn(|i| previous.unknowns[i]);
    let name = |_: usize| -> std::borrow::Cow<'static, str> { std::borrow::Cow::Borrowed("") };
    let enclose = |inputs: &[f64], x: &[Interval; N]| -> Option<certify::Enclosed<N>> {
        let (rows, took) = interval::watch(|| {
            let given: Vec<Enclosure<N>> = (0..N).map(|i| Enclosure::variable(x[i], i)).collect();
            let g = crate::steps::Given {
                values: &given,
                signs: &signs,
                name: &name,
                sites: 0,
            };
            let state = crate::steps::run(inverse, &enclosing, model.links.len(), &g).ok()?;
            let mut rows = [Enclosure::<N>::c(0.0); N];
            for (k, row) in rows.iter_mut().enumerate() {
                let raw = crate::steps::value(&enclosing, &state, *actuated.get(k)?);
                let arc = (model.joints[actuated[k]].kind != JointType::P).then_some(scale);
                // A jump of the wrap marks the row in doubt.
                let (r, _) = fk_numeric::difference(raw, inputs[k], arc)?;
                *row = r;
            }
            Some(rows)
        });
        let rows = rows?;
        if rows.iter().any(|r| r.v.is_empty()) {
            return None;
        }
        Some(certify::Enclosed {
            f: rows.map(|r| r.v),
            j: rows.map(|r| r.d),
            decided: !took && rows.iter().all(|r| !r.doubt),
        })
    };
    let verify_on = |x: &[f64; N], signs: &[Sign]| -> Option<Solution> {
        let solution = plan::run(model, inverse, x, signs).ok()?;
        let zero = fk_numeric::zero_of(model);
        actuated
            .iter()
            .zip(inputs)
            .all(|(&j, &q)| {
                let arc = (model.joints[j].kind != JointType::P).then_some(scale);
                fk_numeric::Compatibility::input_residual(arc, solution.values[j], q).abs() <= zero
            })
            .then_some(solution)
    };
    // The assembly at a pose, on the branch that continues the previous.
    let verify = |x: &[f64; N]| -> Option<(Vec<Sign>, Solution)> {
        let own = verify_on(x, &signs)?;
        Some(continued(
            inverse,
            &previous.solution,
            scale,
            (signs.clone(), own),
            |s| verify_on(x, s),
        ))
    };
    let tracked = substepped(model, actuated, &previous.solution, from, inputs, |q, x| {
        certify::near(x, &region, MARGIN, &LIMITS, |b| enclose(q, b))
    });
    match tracked {
        Ok(root) => {
            let (signs, solution) = verify(&root.x).ok_or(Lost::NotAlone)?;
            Ok(Followed {
                signs,
                unknowns: root.x.to_vec(),
                cert: root.cert.to_vec(),
                how: How::Tracked,
                solution,
            })
        }
        Err(Lost::NotAlone) => {
            // Newton converged: its point, verified, is possible.
            let (x, _) = certify::newton(from, &region, &mut |b| enclose(inputs, b)).ok_or(Lost::Diverged)?;
            let (signs, solution) = verify(&x).ok_or(Lost::Diverged)?;
            Ok(Followed {
                signs,
                unknowns: x.to_vec(),
                cert: x.iter().map(|&v| Interval::point(v)).collect(),
                how: How::Possible(Lost::NotAlone),
                solution,
            })
        }
        Err(lost) => Err(lost),
    }
}

/// [`by_pose`], and where the step is not proven (possible, or Newton's
/// method lost) on a mechanism with a closed-form forward plan `forward`
/// (a coupled one its steps close all the same: a translating platform on
/// three spheres), the forward solution's assembly nearest the previous
/// by every link's pose, said so ([`How::Resolved`]), on the inverse
/// branch that gives it: a trajectory then never stays unproven where
/// every assembly is at hand. The inverse plan must be given its values
/// by placed, unturned links' points (a translating platform's position);
/// otherwise, and where the forward solution has no assembly, `by_pose`'s
/// answer stands.
///
/// # Errors
/// As [`by_pose`].
pub fn by_pose_or_forward(
    model: &Model,
    inverse: &Plan,
    forward: &Plan,
    angles: &[bool],
    inputs: &[f64],
    previous: &Followed,
) -> Result<Followed, FollowError> {
    let step = by_pose(model, inverse, angles, inputs, previous);
    if settled(&step) {
        return step;
    }
    let scale = crate::kinematics::model_scale(model);
    let all: Vec<Solution> = plan::run_all(model, forward, inputs)
        .into_iter()
        .filter_map(|(_, r)| r.ok())
        .collect();
    let Some(nearest) = nearest(model, &all, |a| a, previous) else {
        return step;
    };
    let Some(pose) = placed_values(model, inverse, nearest) else {
        return step;
    };
    let same = crate::solution::every_branch(inverse.branches, |s| plan::run(model, inverse, &pose, s))
        .into_iter()
        .filter_map(|(s, r)| r.ok().map(|x| (distance(&x, nearest, scale), s, x)))
        .filter(|(d, ..)| *d <= 1e-9)
        .min_by(|a, b| a.0.total_cmp(&b.0));
    let Some((_, signs, solution)) = same else {
        return step;
    };
    Ok(Followed {
        signs,
        cert: pose.iter().map(|&p| Interval::point(p)).collect(),
        unknowns: pose,
        how: How::Resolved { assemblies: all.len() },
        solution,
    })
}

/// [`by_pose`], and where the step is not proven (possible, or Newton's
/// method lost) on a mechanism whose legs each end in a ball, every
/// assembly by the pose equations ([`crate::ball_legs`]) and the one
/// nearest the previous by every link's pose, said so
/// ([`How::Resolved`]): a trajectory then never stays unproven where
/// every assembly is at hand. Where the pose equations give no assembly,
/// `by_pose`'s answer stands.
///
/// # Errors
/// As [`by_pose`].
pub fn by_pose_or_balls(
    model: &Model,
    inverse: &Plan,
    legs: &crate::ball_legs::BallLegs,
    outputs: &[crate::newton::Output],
    angles: &[bool],
    inputs: &[f64],
    previous: &Followed,
) -> Result<Followed, FollowError> {
    let step = by_pose(model, inverse, angles, inputs, previous);
    if settled(&step) {
        return step;
    }
    let Ok(all) = legs.solve(model, inverse, outputs, inputs) else {
        return step;
    };
    let Some(nearest) = nearest(model, &all.assemblies, |a| &a.solution, previous) else {
        return step;
    };
    let pose = legs.given_values(model, outputs, &all.roots.roots[nearest.root].pose);
    Ok(Followed {
        signs: nearest.signs.clone(),
        cert: pose.iter().map(|&p| Interval::point(p)).collect(),
        unknowns: pose,
        how: How::Resolved {
            assemblies: all.assemblies.len(),
        },
        solution: nearest.solution.clone(),
    })
}

/// Of the assemblies `all` (each one's solution by `solution`), the one
/// nearest the previous step's by every link's pose ([`distance`]).
fn nearest<'a, A>(
    model: &Model,
    all: &'a [A],
    solution: impl Fn(&A) -> &Solution,
    previous: &Followed,
) -> Option<&'a A> {
    let scale = crate::kinematics::model_scale(model);
    all.iter()
        .map(|a| (distance(solution(a), &previous.solution, scale), a))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, a)| a)
}

/// Whether `by_pose`'s step stands as it is: tracked (proven), or refused
/// for its inputs; otherwise a full forward solution may resolve it.
fn settled(step: &Result<Followed, FollowError>) -> bool {
    matches!(step, Ok(f) if f.how == How::Tracked) || matches!(step, Err(FollowError::Input(_)))
}

/// The values the inverse plan is given, read off a solution, where each
/// comes from a [`plan::Step::Place`] of an unturned link (a point's
/// world position); `None` for any other given value.
fn placed_values(model: &Model, inverse: &Plan, solution: &Solution) -> Option<Vec<f64>> {
    let mut out = vec![f64::NAN; inverse.n_inputs];
    for step in &inverse.steps {
        if let plan::Step::Place {
            link,
            point,
            input,
            planar: false,
            turn: plan::Turn::Fixed,
        } = *step
        {
            let x = plan::local_point(model, point, link).ok()?;
            let p = solution.poses.get(link)? * nalgebra::Point3::from(x);
            out.get_mut(input..input + 3)?.copy_from_slice(&[p.x, p.y, p.z]);
        }
    }
    out.iter().all(|v| v.is_finite()).then_some(out)
}
