//! The reference forward-kinematics solver: a slow, general, numeric second
//! path that closed-form solvers are checked against.
//!
//! # Method
//! [`solve_fk`] fixes the actuated joints' values to the inputs and drives
//! the loop residual of [`crate::kinematics`] to zero over all other joint
//! values by Gauss–Newton: Jacobian by central finite differences, step by an
//! SVD least-squares solve (the residual has redundant rows, e.g. the z rows
//! of a planar model, and the unknowns may be redundant, e.g. the spin of an
//! S–S rod), step halving while the residual norm does not decrease.
//! [`solve_ik`] solves the model whose inputs are the outputs
//! ([`with_outputs_as_inputs`]) the same way.

use crate::solution::wrap_angle;
use std::f64::consts::PI;
use std::fmt;

use nalgebra::{DMatrix, DVector, Isometry3};

use crate::kinematics::{Kinematics, ModelError};
use crate::model::{Joint, JointType, Model, Place};

// The model's kinematics lived here before `crate::kinematics`; generated
// code and the command line still name them through this module.
pub use crate::kinematics::{joint_point, link_poses, loop_residual, model_scale, point, spanning_tree, Tree};

/// Options of [`solve_fk`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonOptions {
    /// Convergence threshold on the scaled residual norm (see [`NewtonSolution::residual`]):
    /// position mismatches relative to [`model_scale`], orientation mismatches in radians.
    /// Default `1e-12`.
    pub tolerance: f64,
    /// Maximum number of Gauss–Newton steps. Default 100.
    pub max_iterations: usize,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        NewtonOptions {
            tolerance: 1e-12,
            max_iterations: 100,
        }
    }
}

/// A converged forward-kinematics solution.
#[derive(Debug, Clone, PartialEq)]
pub struct NewtonSolution {
    /// All joint values (inputs included). R angles that were solved for are
    /// wrapped into (−π, π], S rotation vectors to a length ≤ π.
    pub values: Vec<f64>,
    /// Every link's world pose, as by [`link_poses`].
    pub poses: Vec<Isometry3<f64>>,
    /// The scaled residual norm `‖r‖` at `values`, where `r` is [`loop_residual`]
    /// with its position rows divided by [`model_scale`] (dimensionless).
    pub residual: f64,
    /// The number of Gauss–Newton steps taken.
    pub iterations: usize,
}

/// Why [`solve_fk`] failed.
#[derive(Debug, Clone, PartialEq)]
pub enum NewtonError {
    /// The model, inputs, guess or options are unusable.
    BadInput {
        /// What is wrong.
        what: String,
    },
    /// The residual did not fall below the tolerance: after `max_iterations`
    /// steps, or earlier because no step (even halved 60 times) decreased it,
    /// typically when the inputs admit no assembly.
    NoConvergence {
        /// The smallest scaled residual norm reached.
        residual: f64,
        /// The steps taken.
        iterations: usize,
    },
    /// The Jacobian is numerically zero while the residual is not.
    Singular,
}

impl fmt::Display for NewtonError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            NewtonError::BadInput { what } => write!(f, "bad input: {what}"),
            NewtonError::NoConvergence { residual, iterations } => {
                write!(f, "no convergence: residual {residual:e} after {iterations} iterations")
            }
            NewtonError::Singular => write!(f, "the loop-closure Jacobian is singular"),
        }
    }
}

impl std::error::Error for NewtonError {}

impl From<ModelError> for NewtonError {
    fn from(e: ModelError) -> Self {
        NewtonError::BadInput { what: e.to_string() }
    }
}

fn bad(what: impl Into<String>) -> NewtonError {
    NewtonError::BadInput { what: what.into() }
}

/// Singular values below this fraction of the largest count as zero.
const RCOND: f64 = 1e-10;
/// How many times a step may be halved.
const MAX_HALVINGS: usize = 60;

/// The data [`solve_fk`] evaluates the residual with.
struct Problem<'a> {
    kinematics: Kinematics<'a, f64>,
    scale: f64,
}

impl Problem<'_> {
    /// The scaled residual (position rows divided by the scale).
    fn residual(&self, values: &[f64]) -> Result<DVector<f64>, ModelError> {
        Ok(DVector::from_vec(self.kinematics.scaled_residual(values, self.scale)?))
    }

    /// The residual's Jacobian by the `unknowns` at `values`, by central
    /// differences with each unknown's `steps`.
    fn jacobian(&self, values: &[f64], unknowns: &[usize], steps: &[f64]) -> Result<DMatrix<f64>, ModelError> {
        let mut probe = values.to_vec();
        let mut jac = DMatrix::zeros(0, 0);
        for (k, &i) in unknowns.iter().enumerate() {
            probe[i] = values[i] + steps[i];
            let plus = self.residual(&probe)?;
            probe[i] = values[i] - steps[i];
            let minus = self.residual(&probe)?;
            probe[i] = values[i];
            if k == 0 {
                jac = DMatrix::zeros(plus.len(), unknowns.len());
            }
            jac.set_column(k, &((plus - minus) / (2.0 * steps[i])));
        }
        Ok(jac)
    }
}

/// Finite-difference step of each joint value: `h` of the size for a
/// slide, `h` radians for an angle.
fn difference_steps(model: &Model, h: f64, scale: f64) -> Vec<f64> {
    model
        .length_values()
        .iter()
        .map(|&l| if l { h * scale } else { h })
        .collect()
}

/// A scaled loop residual's norm at rounding: [`polish`] takes no step
/// below it.
pub const ROUNDING: f64 = 32.0 * f64::EPSILON;

/// An assembly `values` (every joint's) polished on the loop equations at
/// the `inputs` (as [`solve_fk`]'s; the actuated joints are set to them,
/// where a closed form may have left one a rounding away): full
/// Gauss–Newton steps over the other joints (the Jacobian as [`solve_fk`]'s) while each lowers the scaled
/// residual's norm, at most `max_steps`. Where a closed form or a virtual
/// variable carried the assembly through a step that is ill-conditioned
/// there (two circles nearly tangent: their intersection moves far for a
/// small change), while the loop equations themselves are not, this brings
/// it to their accuracy; where it is already there (the norm at
/// [`ROUNDING`], or no step lowers it) `values` come back as they were.
///
/// # Errors
/// As [`solve_fk`]'s model errors; [`NewtonError::Singular`] where the
/// Jacobian vanishes.
pub fn polish(model: &Model, inputs: &[f64], values: &[f64], max_steps: usize) -> Result<NewtonSolution, NewtonError> {
    let kinematics = Kinematics::new(model)?;
    kinematics.check(values).map_err(|e| bad(format!("values: {e}")))?;
    let offsets = kinematics.offsets.clone();
    let n = values.len();
    let (solved, actuated) = split_entries(model, &offsets, n, inputs)?;
    let unknowns: Vec<usize> = (0..n).filter(|&i| solved[i]).collect();
    let scale = model_scale(model);
    let steps = difference_steps(model, 6e-6, scale);
    let problem = Problem { kinematics, scale };
    let mut values = values.to_vec();
    for (&i, &x) in actuated.iter().zip(inputs) {
        values[i] = x;
    }
    let mut norm = problem.residual(&values)?.norm();
    let mut iterations = 0;
    // At rounding already: no step can lower it (and the Jacobian is not made).
    while iterations < max_steps && !unknowns.is_empty() && norm > ROUNDING {
        let r = problem.residual(&values)?;
        let jac = problem.jacobian(&values, &unknowns, &steps)?;
        let delta = least_squares_step(&jac, &r).ok_or(NewtonError::Singular)?;
        let mut trial = values.clone();
        for (k, &i) in unknowns.iter().enumerate() {
            trial[i] += delta[k];
        }
        match problem.residual(&trial) {
            Ok(t) if t.norm() < norm => {
                norm = t.norm();
                values = trial;
                iterations += 1;
            }
            _ => break,
        }
    }
    let poses = problem.kinematics.poses(&values)?;
    Ok(NewtonSolution {
        values,
        poses: poses.into_iter().map(Isometry3::from).collect(),
        residual: norm,
        iterations,
    })
}

fn norm3(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// Wraps solved-for R angles into (−π, π] and S rotation vectors to length ≤ π
/// (the same rotations).
fn normalise(model: &Model, offsets: &[usize], solved: &[bool], values: &mut [f64]) {
    for (j, joint) in model.joints.iter().enumerate() {
        let o = offsets[j];
        if !solved[o] {
            continue;
        }
        match joint.kind {
            JointType::R | JointType::Pa => values[o] = wrap_angle(values[o]),
            JointType::S => {
                let n = norm3([values[o], values[o + 1], values[o + 2]]);
                if n > PI {
                    let k = wrap_angle(n) / n;
                    values[o..o + 3].iter_mut().for_each(|x| *x *= k);
                }
            }
            JointType::P => {}
        }
    }
}

/// The least-squares solution `δ` of `J δ = −r` of minimum norm, by SVD (with
/// U and V), ignoring all-zero rows and singular values below `RCOND · σ_max`;
/// `None` if `J` is numerically zero. The solution is checked against the
/// normal equations; if it fails the check, they are solved directly by SVD.
fn least_squares_step(jac: &DMatrix<f64>, r: &DVector<f64>) -> Option<DVector<f64>> {
    let rows: Vec<usize> = (0..jac.nrows())
        .filter(|&i| jac.row(i).iter().any(|&x| x != 0.0))
        .collect();
    if rows.is_empty() {
        return None;
    }
    let j = jac.select_rows(rows.iter());
    let minus_r = -r.select_rows(rows.iter());
    let svd = j.clone().svd(true, true);
    let smax = svd.singular_values.max();
    if !(smax > 0.0 && smax.is_finite()) {
        return None;
    }
    let step = svd
        .solve(&minus_r, RCOND * smax)
        .ok()
        .filter(|d| d.iter().all(|x| x.is_finite()));
    // Normal equations Jᵀ(Jδ + r) = 0, up to the dropped singular values.
    let jt_minus_r = j.tr_mul(&minus_r);
    let optimal = |d: &DVector<f64>| {
        let g = j.tr_mul(&(&j * d)) - &jt_minus_r;
        g.norm() <= 1e-8 * smax * (minus_r.norm() + smax * d.norm())
    };
    match step {
        Some(d) if optimal(&d) => Some(d),
        _ => {
            let normal = j.tr_mul(&j).svd(true, true);
            let d = normal.solve(&jt_minus_r, RCOND * smax * smax).ok()?;
            d.iter().all(|x| x.is_finite()).then_some(d)
        }
    }
}

/// Which entries of a joint-value vector of length `n` are solved for, and
/// the actuated entries in input order; checks `inputs` against them.
pub(crate) fn split_entries(
    model: &Model,
    offsets: &[usize],
    n: usize,
    inputs: &[f64],
) -> Result<(Vec<bool>, Vec<usize>), NewtonError> {
    let mut solved = vec![true; n];
    let mut actuated = Vec::new();
    for j in model.inputs() {
        let range = offsets[j]..offsets[j] + model.joints[j].kind.dof();
        solved[range.clone()].iter_mut().for_each(|s| *s = false);
        actuated.extend(range);
    }
    if inputs.len() != actuated.len() {
        return Err(bad(format!(
            "expected {} input values, got {}",
            actuated.len(),
            inputs.len()
        )));
    }
    if let Some(i) = inputs.iter().position(|x| !x.is_finite()) {
        return Err(bad(format!("input {i} is not finite")));
    }
    Ok((solved, actuated))
}

/// Solves the forward kinematics: the joint values that close every loop with
/// the actuated joints' values fixed.
///
/// `inputs` holds the actuated joints' values, joint after joint in the order
/// of [`Model::inputs`] ([`JointType::dof`] values each). `guess` is a full
/// joint-value vector (see [`Model::value_offsets`]) the iteration starts from;
/// its actuated entries are replaced by `inputs`. Which assembly branch is
/// found depends on the guess.
///
/// Gauss–Newton on the scaled loop residual (see [`NewtonSolution::residual`]):
/// central-difference Jacobian (step `6e-6` rad for angles, `6e-6 · L` for P
/// joints, `L` = [`model_scale`]), minimum-norm least-squares step by SVD,
/// halved while the residual norm does not decrease. Stops when the scaled
/// residual norm is ≤ `options.tolerance`.
///
/// # Errors
/// [`NewtonError::BadInput`] for wrong lengths, non-finite numbers, a
/// malformed or disconnected model or a negative tolerance;
/// [`NewtonError::NoConvergence`] if the tolerance is not reached (e.g. no
/// assembly exists); [`NewtonError::Singular`] if the Jacobian vanishes.
///
/// # Example
/// A four-bar with crank 1, coupler 3, rocker 2, base 3, crank at 60°:
/// ```
/// use pkm_runtime::model::{Joint, JointType, Model, Place};
/// use pkm_runtime::newton::{joint_point, solve_fk, NewtonOptions};
///
/// let z = |x: f64| Place::Axis { at: [x, 0.0, 0.0], axis: [0.0, 0.0, 1.0] };
/// let r = |name: &str, links, places, actuated| Joint { name: name.into(), kind: JointType::R, links, places, actuated };
/// let model = Model {
///     name: "four_bar".into(),
///     planar: true,
///     links: vec!["base".into(), "crank".into(), "coupler".into(), "rocker".into()],
///     joints: vec![
///         r("R1", [0, 1], [z(0.0), z(0.0)], true),
///         r("R2", [1, 2], [z(1.0), z(0.0)], false),
///         r("R3", [2, 3], [z(3.0), z(2.0)], false),
///         r("R4", [0, 3], [z(3.0), z(0.0)], false),
///     ],
///     points: vec![],
/// };
/// let theta = std::f64::consts::FRAC_PI_3;
/// // Guess: coupler roughly along x, rocker pointing up.
/// let sol = solve_fk(&model, &[theta], &[0.0, -1.0, 1.5, 1.5], &NewtonOptions::default()).unwrap();
/// assert!(sol.residual < 1e-12);
/// let (b, c) = (joint_point(&model, &sol.poses, 1), joint_point(&model, &sol.poses, 2));
/// assert!((b[0] - theta.cos()).abs() < 1e-12 && (b[1] - theta.sin()).abs() < 1e-12);
/// assert!(((c[0] - b[0]).hypot(c[1] - b[1]) - 3.0).abs() < 1e-9); // coupler length
/// assert!(((c[0] - 3.0).hypot(c[1]) - 2.0).abs() < 1e-9); // rocker length
/// ```
pub fn solve_fk(
    model: &Model,
    inputs: &[f64],
    guess: &[f64],
    options: &NewtonOptions,
) -> Result<NewtonSolution, NewtonError> {
    if !(options.tolerance >= 0.0 && options.tolerance.is_finite()) {
        return Err(bad(format!(
            "tolerance {} is not a finite non-negative number",
            options.tolerance
        )));
    }
    let kinematics = Kinematics::new(model)?;
    kinematics.check(guess).map_err(|e| bad(format!("guess: {e}")))?;
    let offsets = kinematics.offsets.clone();
    let n = guess.len();
    let (solved, actuated) = split_entries(model, &offsets, n, inputs)?;
    let mut values = guess.to_vec();
    for (&i, &x) in actuated.iter().zip(inputs) {
        values[i] = x;
    }
    normalise(model, &offsets, &solved, &mut values);
    let unknowns: Vec<usize> = (0..n).filter(|&i| solved[i]).collect();
    let scale = model_scale(model);
    // Finite-difference step of each unknown: P joints are lengths, the rest angles.
    let steps = difference_steps(model, 6e-6, scale);
    let problem = Problem { kinematics, scale };
    let finish = |values: Vec<f64>, residual: f64, iterations: usize| -> Result<NewtonSolution, NewtonError> {
        let poses = problem.kinematics.poses(&values)?;
        Ok(NewtonSolution {
            values,
            poses: poses.into_iter().map(Isometry3::from).collect(),
            residual,
            iterations,
        })
    };

    let mut r = problem.residual(&values)?;
    let mut norm = r.norm();
    let mut iterations = 0;
    loop {
        if norm <= options.tolerance {
            return finish(values, norm, iterations);
        }
        if iterations >= options.max_iterations || unknowns.is_empty() {
            return Err(NewtonError::NoConvergence {
                residual: norm,
                iterations,
            });
        }
        let jac = problem.jacobian(&values, &unknowns, &steps)?;
        let delta = least_squares_step(&jac, &r).ok_or(NewtonError::Singular)?;
        // Step halving until the residual norm decreases.
        let mut t = 1.0;
        let mut accepted = None;
        for _ in 0..=MAX_HALVINGS {
            let mut trial = values.clone();
            for (k, &i) in unknowns.iter().enumerate() {
                trial[i] += t * delta[k];
            }
            if let Ok(rt) = problem.residual(&trial) {
                if rt.norm() < norm {
                    accepted = Some(trial);
                    break;
                }
            }
            t *= 0.5;
        }
        let Some(mut next) = accepted else {
            return Err(NewtonError::NoConvergence {
                residual: norm,
                iterations,
            });
        };
        iterations += 1;
        normalise(model, &offsets, &solved, &mut next);
        values = next;
        r = problem.residual(&values)?;
        norm = r.norm();
    }
}

/// What an inverse solution is given, in numbers: the declared outputs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Output {
    /// Link `link`'s point `local` (in its frame) at the given x, y (and z if
    /// spatial), then the link's angle about `about` (a planar pose turns
    /// about z); without `about` the link keeps the base's orientation.
    Pose {
        /// The link.
        link: usize,
        /// The point, in the link's frame.
        local: [f64; 3],
        /// The world axis the link turns about, if it turns.
        about: Option<[f64; 3]>,
    },
    /// Link `link`'s point `local` at the given coordinates; its orientation free.
    Point {
        /// The link.
        link: usize,
        /// The point, in the link's frame.
        local: [f64; 3],
    },
    /// Link `link`'s pose at its point `local`, in part: the given of x, y,
    /// z, rx, ry, rz (`R = R_z(rz)·R_y(ry)·R_x(rx)`) in that order; the
    /// others are the mechanism's.
    Parts {
        /// The link.
        link: usize,
        /// The point, in the link's frame.
        local: [f64; 3],
        /// Which values are given.
        parts: crate::steps::place::PoseParts,
    },
    /// A joint's value.
    Joint(usize),
}

impl Output {
    /// How many values it takes.
    pub fn len(&self, planar: bool) -> usize {
        let point = if planar { 2 } else { 3 };
        match self {
            Output::Pose { about: Some(_), .. } => point + 1,
            Output::Pose { about: None, .. } | Output::Point { .. } => point,
            Output::Parts { parts, .. } => parts.count(),
            Output::Joint(_) => 1,
        }
    }

    /// The link and the point on it (in its frame) that the output places,
    /// if it places one (a joint's value does not).
    pub fn point(&self) -> Option<(usize, [f64; 3])> {
        match *self {
            Output::Pose { link, local, .. } | Output::Point { link, local } | Output::Parts { link, local, .. } => {
                Some((link, local))
            }
            Output::Joint(_) => None,
        }
    }
}

/// The model with the outputs as its inputs: the mechanism's actuators are
/// released, joint outputs become actuated, and each pose or point output
/// hangs its link from the base by a chain of virtual joints whose values
/// are the output's numbers (P along x, y, z to the point, then R about the
/// output axis; a point alone ends in a free S, or R when planar). Newton's
/// forward solution of this model is the inverse solution of the original,
/// found from any configuration near the wanted branch. Also returns, for
/// each input of the new model in order, the index of its given value.
pub fn with_outputs_as_inputs(model: &Model, outputs: &[Output]) -> (Model, Vec<usize>) {
    let mut m = model.clone();
    for j in &mut m.joints {
        j.actuated = false;
    }
    let origin = [0.0; 3];
    let mut given_of: Vec<Option<usize>> = vec![None; m.joints.len()];
    let mut next = 0;
    let axes = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for (k, o) in outputs.iter().enumerate() {
        match *o {
            Output::Joint(j) => {
                m.joints[j].actuated = true;
                given_of[j] = Some(next);
            }
            Output::Parts { link, local, parts } => {
                // P along x, y, z, then R about z, y, x: R = R_z·R_y·R_x.
                let mut from = 0;
                let mut given = parts
                    .given()
                    .enumerate()
                    .map(|(i, part)| (part, next + i))
                    .collect::<Vec<_>>();
                let order = [0, 1, 2, 5, 4, 3];
                for (n, &part) in order.iter().enumerate() {
                    let last = n == order.len() - 1;
                    let to = if last { link } else { m.links.len() };
                    let name = crate::steps::place::PoseParts::NAMES[part];
                    if !last {
                        m.links.push(format!("output {k} {name}"));
                    }
                    let (kind, axis) = if part < 3 {
                        (JointType::P, axes[part])
                    } else {
                        (JointType::R, axes[part - 3])
                    };
                    let places = match kind {
                        JointType::P => [
                            Place::Line {
                                through: origin,
                                along: axis,
                            },
                            Place::Point { at: origin },
                        ],
                        _ => [
                            Place::Axis { at: origin, axis },
                            Place::Axis {
                                at: if last { local } else { origin },
                                axis,
                            },
                        ],
                    };
                    let at = given.iter().position(|(p, _)| *p == part).map(|i| given.remove(i).1);
                    m.joints.push(Joint {
                        name: format!("output {k} {name}"),
                        kind,
                        links: [from, to],
                        places,
                        actuated: at.is_some(),
                    });
                    given_of.push(at);
                    from = to;
                }
            }
            Output::Pose { link, local, .. } | Output::Point { link, local } => {
                let n_coords = if model.planar { 2 } else { 3 };
                let mut from = 0;
                for (i, along) in axes.iter().take(n_coords).enumerate() {
                    let to = m.links.len();
                    m.links.push(format!("output {k} along {}", ["x", "y", "z"][i]));
                    m.joints.push(Joint {
                        name: format!("output {k} {}", ["x", "y", "z"][i]),
                        kind: JointType::P,
                        links: [from, to],
                        places: [
                            Place::Line {
                                through: origin,
                                along: *along,
                            },
                            Place::Point { at: origin },
                        ],
                        actuated: true,
                    });
                    given_of.push(Some(next + i));
                    from = to;
                }
                let (kind, axis, actuated) = match *o {
                    Output::Pose { about: Some(k), .. } => (JointType::R, k, true),
                    // Translation only: a revolute held at 0 about any axis.
                    Output::Pose { about: None, .. } => (JointType::R, [0.0, 0.0, 1.0], true),
                    _ if model.planar => (JointType::R, [0.0, 0.0, 1.0], false),
                    _ => (JointType::S, [0.0, 0.0, 1.0], false),
                };
                let place = |at| match kind {
                    JointType::S => Place::Point { at },
                    _ => Place::Axis { at, axis },
                };
                m.joints.push(Joint {
                    name: format!("output {k} turn"),
                    kind,
                    links: [from, link],
                    places: [place(origin), place(local)],
                    actuated,
                });
                // A held revolute's value is 0, appended after the given ones.
                given_of.push(match *o {
                    Output::Pose { about: Some(_), .. } => Some(next + n_coords),
                    Output::Pose { about: None, .. } => Some(usize::MAX),
                    _ => None,
                });
            }
        }
        next += o.len(model.planar);
    }
    let order = m
        .inputs()
        .into_iter()
        .map(|j| given_of[j].expect("an input has a value"))
        .collect();
    (m, order)
}

/// The forward problem whose solution is the inverse solution of `model`
/// with the outputs at `given`: the model of [`with_outputs_as_inputs`], its
/// input values, and a joint-value vector of it that starts from `guess` (the
/// virtual joints at the outputs' links' places in the guess).
///
/// # Errors
/// [`NewtonError::BadInput`] if `given` has the wrong length or `guess` is unusable.
pub fn ik_problem(
    model: &Model,
    outputs: &[Output],
    given: &[f64],
    guess: &[f64],
) -> Result<(Model, Vec<f64>, Vec<f64>), NewtonError> {
    let wanted: usize = outputs.iter().map(|o| o.len(model.planar)).sum();
    if given.len() != wanted {
        return Err(bad(format!("expected {wanted} output values, got {}", given.len())));
    }
    let (m, order) = with_outputs_as_inputs(model, outputs);
    let inputs: Vec<f64> = order.iter().map(|&i| given.get(i).copied().unwrap_or(0.0)).collect();
    // The virtual joints' starting values: the link's place in the guess.
    let poses = link_poses(model, guess).map_err(|e| bad(format!("guess: {e}")))?;
    let mut start = guess.to_vec();
    let mut next = 0;
    for o in outputs {
        match *o {
            Output::Joint(_) => {}
            Output::Parts { link, local, .. } => {
                let p = poses[link].transform_point(&local.into());
                let (rx, ry, rz) = poses[link].rotation.euler_angles();
                start.extend_from_slice(&[p.x, p.y, p.z, rz, ry, rx]);
            }
            Output::Pose { link, local, .. } | Output::Point { link, local } => {
                let p = poses[link].transform_point(&local.into());
                let n = if model.planar { 2 } else { 3 };
                start.extend_from_slice(&[p.x, p.y, p.z][..n]);
                let rotation = poses[link].rotation;
                match *o {
                    Output::Pose { about: Some(_), .. } => start.push(given[next + n]),
                    Output::Pose { about: None, .. } => start.push(0.0),
                    _ if model.planar => start.push(rotation.euler_angles().2),
                    _ => start.extend_from_slice(rotation.scaled_axis().as_slice()),
                }
            }
        }
        next += o.len(model.planar);
    }
    Ok((m, inputs, start))
}

/// The inverse position by Newton: the joint values that close every loop
/// with the outputs at `given` (in the order of `outputs`), from `guess` (a
/// joint-value vector of `model`, near the wanted branch). See
/// [`with_outputs_as_inputs`] and [`solve_fk`].
///
/// # Errors
/// As [`solve_fk`]; also [`NewtonError::BadInput`] if `given` has the wrong length.
///
/// # Example
/// The four-bar of [`solve_fk`] (crank 1, coupler 3, rocker 2, base 3)
/// inverted from the coupler's midpoint alone: with the midpoint where the
/// crank at 60° puts it, Newton from a nearby guess returns the crank to 60°.
/// ```
/// use pkm_runtime::model::{Joint, JointType, Model, Place};
/// use pkm_runtime::newton::{joint_point, solve_ik, NewtonOptions, Output};
///
/// let z = |x: f64| Place::Axis { at: [x, 0.0, 0.0], axis: [0.0, 0.0, 1.0] };
/// let r = |name: &str, links, places, actuated| Joint { name: name.into(), kind: JointType::R, links, places, actuated };
/// let model = Model {
///     name: "four_bar".into(),
///     planar: true,
///     links: vec!["base".into(), "crank".into(), "coupler".into(), "rocker".into()],
///     joints: vec![
///         r("R1", [0, 1], [z(0.0), z(0.0)], true),
///         r("R2", [1, 2], [z(1.0), z(0.0)], false),
///         r("R3", [2, 3], [z(3.0), z(2.0)], false),
///         r("R4", [0, 3], [z(3.0), z(0.0)], false),
///     ],
///     points: vec![],
/// };
/// // B = (cos 60°, sin 60°), C = (23/7, 1.97948…) by hand; M = (B + C) / 2.
/// let m = [(0.5 + 23.0 / 7.0) / 2.0, (0.75f64.sqrt() + 1.9794866372215738) / 2.0];
/// let outputs = [Output::Point { link: 2, local: [1.5, 0.0, 0.0] }];
/// let sol = solve_ik(&model, &outputs, &m, &[1.0, -0.6, 1.0, 1.4], &NewtonOptions::default()).unwrap();
/// assert!((sol.values[0] - std::f64::consts::FRAC_PI_3).abs() < 1e-9);
/// let (b, c) = (joint_point(&model, &sol.poses, 1), joint_point(&model, &sol.poses, 2));
/// assert!(((b[0] + c[0]) / 2.0 - m[0]).abs() < 1e-9 && ((b[1] + c[1]) / 2.0 - m[1]).abs() < 1e-9);
/// assert!((b[0].hypot(b[1]) - 1.0).abs() < 1e-9); // crank length
/// assert!(((c[0] - 3.0).hypot(c[1]) - 2.0).abs() < 1e-9); // rocker length
/// ```
pub fn solve_ik(
    model: &Model,
    outputs: &[Output],
    given: &[f64],
    guess: &[f64],
    options: &NewtonOptions,
) -> Result<NewtonSolution, NewtonError> {
    let (m, inputs, start) = ik_problem(model, outputs, given, guess)?;
    let mut solution = solve_fk(&m, &inputs, &start, options)?;
    solution.values.truncate(guess.len());
    solution.poses.truncate(model.links.len());
    Ok(solution)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::tests::{four_bar, joint, model, z_axis};
    use crate::kinematics::ModelError;
    use crate::model::NamedPoint;
    use nalgebra::{Point3, UnitQuaternion, Vector3};

    const OPTS: NewtonOptions = NewtonOptions {
        tolerance: 1e-12,
        max_iterations: 100,
    };

    /// Hand derivation: the intersection of the circles (b, rb) and (d, rd) on
    /// the left of b→d (`up`) or on its right, by the chord construction.
    fn circle_circle(b: [f64; 2], rb: f64, d: [f64; 2], rd: f64, up: bool) -> Option<[f64; 2]> {
        let (dx, dy) = (d[0] - b[0], d[1] - b[1]);
        let dist = dx.hypot(dy);
        let a = (rb * rb - rd * rd + dist * dist) / (2.0 * dist);
        let h2 = rb * rb - a * a;
        if h2 < 0.0 {
            return None;
        }
        let h = if up { h2.sqrt() } else { -h2.sqrt() };
        let (ex, ey) = (dx / dist, dy / dist);
        Some([b[0] + a * ex - h * ey, b[1] + a * ey + h * ex])
    }

    fn wrapped_diff(x: f64, y: f64) -> f64 {
        let d = x - y;
        d.sin().atan2(d.cos()).abs()
    }

    #[test]
    fn four_bar_matches_circle_intersection_on_both_branches() {
        let (l1, l2, l3, l4) = (100.0, 250.0, 200.0, 300.0);
        let m = four_bar(l1, l2, l3, l4);
        let check = |theta: f64, up: bool, kick: f64| {
            // Hand derivation: B = l1(cos θ, sin θ), D = (l4, 0); C = R3 on both circles.
            let b = [l1 * theta.cos(), l1 * theta.sin()];
            let d = [l4, 0.0];
            let c = circle_circle(b, l2, d, l3, up).expect("assembles");
            let alpha = (c[1] - b[1]).atan2(c[0] - b[0]); // coupler's world angle
            let beta = (c[1] - d[1]).atan2(c[0] - d[0]); // rocker's world angle
                                                         // Guess near the branch: world angles kicked by `kick` and -0.8 `kick` rad.
            let (ag, bg) = (alpha + kick, beta - 0.8 * kick);
            let guess = [0.0, ag - theta, bg - ag, bg];
            let sol = solve_fk(&m, &[theta], &guess, &OPTS).unwrap_or_else(|e| panic!("θ={theta} up={up}: {e}"));
            let r3 = joint_point(&m, &sol.poses, 2);
            let msg = format!("θ={theta} up={up}: {r3:?} vs {c:?}, {sol:?}");
            assert!(
                (r3[0] - c[0]).abs() < 1e-9 && (r3[1] - c[1]).abs() < 1e-9 && r3[2] == 0.0,
                "{msg}"
            );
            // The rocker's own view of R3 agrees.
            let r3_rocker = sol.poses[3].transform_point(&Point3::new(l3, 0.0, 0.0));
            assert!(
                (r3_rocker.x - c[0]).abs() < 1e-9 && (r3_rocker.y - c[1]).abs() < 1e-9,
                "{msg}"
            );
            assert!(sol.residual < 1e-12, "{msg}");
            assert_eq!(sol.values[0], theta, "{msg}");
            assert!(wrapped_diff(sol.values[1], alpha - theta) < 1e-10, "{msg}");
            assert!(wrapped_diff(sol.values[2], beta - alpha) < 1e-10, "{msg}");
            assert!(wrapped_diff(sol.values[3], beta) < 1e-10, "{msg}");
            assert!(sol.values[1..].iter().all(|x| x.abs() <= PI), "{msg}");
            let raw = loop_residual(&m, &sol.values).unwrap();
            assert_eq!(raw.len(), 6, "{msg}");
            assert!(raw.iter().all(|x| x.abs() < 1e-12 * l4), "{msg}: {raw:?}");
        };
        for theta in [0.0, 0.4, 1.0, PI / 2.0, 2.5, PI, -2.0, -0.7, 5.9] {
            for up in [true, false] {
                for kick in [0.25, -0.3, 0.0] {
                    check(theta, up, kick);
                }
            }
        }
    }

    /// Slider-crank: R1 base–crank (actuated), R2 crank–rod, R3 rod–slider,
    /// P1 base–slider with the guide on the base.
    fn slider_crank(r: f64, l: f64) -> Model {
        use JointType::{P, R};
        let joints = vec![
            joint("R1", R, [0, 1], [z_axis(0.0, 0.0), z_axis(0.0, 0.0)], true),
            joint("R2", R, [1, 2], [z_axis(r, 0.0), z_axis(0.0, 0.0)], false),
            joint("R3", R, [2, 3], [z_axis(l, 0.0), z_axis(0.0, 0.0)], false),
            joint(
                "P1",
                P,
                [0, 3],
                [
                    Place::Line {
                        through: [0.0; 3],
                        along: [1.0, 0.0, 0.0],
                    },
                    Place::Point { at: [0.0; 3] },
                ],
                false,
            ),
        ];
        let tip = NamedPoint {
            name: "tip".into(),
            link: 3,
            at: [0.0, 0.0, 0.0],
        };
        model(
            "slider_crank",
            true,
            &["base", "crank", "rod", "slider"],
            joints,
            vec![tip],
        )
    }

    #[test]
    fn slider_crank_matches_closed_form() {
        let (r, l) = (50.0, 180.0);
        let m = slider_crank(r, l);
        // forward: slider on the +x side (rod guess horizontal, pointing +x), else on −x.
        let check = |theta: f64, forward: bool| {
            let root = (l * l - r * r * theta.sin().powi(2)).sqrt();
            let s = if forward {
                r * theta.cos() + root
            } else {
                r * theta.cos() - root
            };
            let (phi, s0) = if forward { (0.0, l) } else { (PI, -l) };
            let guess = [0.0, phi - theta, -phi, s0];
            let sol = solve_fk(&m, &[theta], &guess, &OPTS).unwrap_or_else(|e| panic!("θ={theta}: {e}"));
            let msg = format!("θ={theta} forward={forward}: s={s}, {sol:?}");
            assert!((sol.values[3] - s).abs() < 1e-9, "{msg}");
            let tip = point(&m, &sol.poses, "tip").unwrap();
            assert!(
                (tip[0] - s).abs() < 1e-9 && tip[1].abs() < 1e-9 && tip[2] == 0.0,
                "{msg}"
            );
            assert_eq!(joint_point(&m, &sol.poses, 3), tip, "{msg}");
            assert!(sol.residual < 1e-12, "{msg}");
        };
        for theta in [0.0, 0.3, 1.2, PI / 2.0, 2.0, PI, 4.0, -1.0] {
            check(theta, true);
            check(theta, false);
        }
        assert_eq!(point(&m, &link_poses(&m, &[0.0; 4]).unwrap(), "nowhere"), None);
    }

    #[test]
    fn unreachable_inputs_give_typed_errors() {
        let check = |m: &Model, theta: f64, guess: [f64; 4], reachable: bool| {
            let out = solve_fk(m, &[theta], &guess, &OPTS);
            match out {
                Ok(sol) => assert!(reachable && sol.residual < 1e-12, "{}: θ={theta}: {sol:?}", m.name),
                Err(NewtonError::NoConvergence { residual, iterations }) => {
                    assert!(!reachable, "{}: θ={theta}: {residual} {iterations}", m.name);
                    assert!(residual.is_finite() && residual > 1e-6 && iterations <= OPTS.max_iterations);
                }
                Err(e) => assert!(!reachable && e == NewtonError::Singular, "{}: θ={theta}: {e}", m.name),
            }
        };
        let up = [0.0, -0.5, 2.0, 1.5];
        // Coupler + rocker (120 + 60) shorter than the smallest B–D distance (200): never closes.
        let short = four_bar(100.0, 120.0, 60.0, 300.0);
        for theta in [0.0, 1.0, 2.5, PI] {
            check(&short, theta, up, false);
        }
        // Crank 200, coupler 150, rocker 150, base 300: closes while |B − D| ≤ 300,
        // i.e. 200² + 300² − 2·200·300 cos θ ≤ 300², cos θ ≥ 1/3, |θ| ≤ 1.2310 rad.
        let partial = four_bar(200.0, 150.0, 150.0, 300.0);
        for (theta, reachable) in [
            (0.3, true),
            (1.2, true),
            (1.3, false),
            (2.0, false),
            (PI, false),
            (-1.1, true),
        ] {
            check(&partial, theta, up, reachable);
        }
        // Slider-crank with rod 30 < crank 50: no assembly when 50 |sin θ| > 30.
        let sc = slider_crank(50.0, 30.0);
        for (theta, reachable) in [(0.2, true), (PI / 2.0, false), (-2.0, false)] {
            check(&sc, theta, [0.0, -theta, 0.0, 60.0], reachable);
        }
    }

    #[test]
    fn bad_inputs_are_reported() {
        let m = four_bar(100.0, 250.0, 200.0, 300.0);
        let guess = [0.0, -0.5, 2.0, 1.5];
        let is_bad = |r: Result<NewtonSolution, NewtonError>| matches!(r, Err(NewtonError::BadInput { .. }));
        assert!(is_bad(solve_fk(&m, &[], &guess, &OPTS)));
        assert!(is_bad(solve_fk(&m, &[0.1, 0.2], &guess, &OPTS)));
        assert!(is_bad(solve_fk(&m, &[f64::NAN], &guess, &OPTS)));
        assert!(is_bad(solve_fk(&m, &[0.1], &guess[..3], &OPTS)));
        assert!(is_bad(solve_fk(&m, &[0.1], &[0.0, f64::INFINITY, 2.0, 1.5], &OPTS)));
        let neg = NewtonOptions {
            tolerance: -1.0,
            ..OPTS
        };
        assert!(is_bad(solve_fk(&m, &[0.1], &guess, &neg)));
        // A link reached by no joint.
        let mut lonely = m.clone();
        lonely.links.push("lonely".into());
        assert_eq!(spanning_tree(&lonely), Err(ModelError::Disconnected { link: 4 }));
        assert!(is_bad(solve_fk(&lonely, &[0.1], &guess, &OPTS)));
        // A joint naming a missing link.
        let mut dangling = m.clone();
        dangling.joints[3].links[1] = 9;
        assert_eq!(
            link_poses(&dangling, &guess),
            Err(ModelError::BadLink { joint: 3, link: 9 })
        );
        // A zero-length axis gives NaN poses: reported, not propagated.
        let mut zero = m.clone();
        zero.joints[1].places[0] = Place::Axis {
            at: [100.0, 0.0, 0.0],
            axis: [0.0; 3],
        };
        assert!(matches!(link_poses(&zero, &guess), Err(ModelError::NonFinite { .. })));
        assert!(is_bad(solve_fk(&zero, &[0.1], &guess, &OPTS)));
        assert_eq!(
            link_poses(&m, &guess[..2]),
            Err(ModelError::BadLength { expected: 4, got: 2 })
        );
        // Too few iterations allowed.
        let one = NewtonOptions {
            max_iterations: 1,
            ..OPTS
        };
        assert!(matches!(
            solve_fk(&m, &[0.1], &guess, &one),
            Err(NewtonError::NoConvergence { iterations: 1, .. })
        ));
    }

    /// A spatial RSSR four-bar: crank R1 about the base z axis (radius a),
    /// coupler S1–S2 of length b, rocker R4 about a base axis along y through
    /// D = (dx, 0, dz), radius c; named point C on the rocker at S2.
    fn rssr(a: f64, b: f64, c: f64, dx: f64, dz: f64) -> Model {
        use JointType::{R, S};
        let y_axis = |at| Place::Axis {
            at,
            axis: [0.0, 1.0, 0.0],
        };
        let joints = vec![
            joint("R1", R, [0, 1], [z_axis(0.0, 0.0), z_axis(0.0, 0.0)], true),
            joint(
                "S1",
                S,
                [1, 2],
                [Place::Point { at: [a, 0.0, 0.0] }, Place::Point { at: [0.0; 3] }],
                false,
            ),
            joint(
                "S2",
                S,
                [2, 3],
                [Place::Point { at: [b, 0.0, 0.0] }, Place::Point { at: [c, 0.0, 0.0] }],
                false,
            ),
            joint("R4", R, [0, 3], [y_axis([dx, 0.0, dz]), y_axis([0.0; 3])], false),
        ];
        let points = vec![NamedPoint {
            name: "C".into(),
            link: 3,
            at: [c, 0.0, 0.0],
        }];
        model("rssr", false, &["base", "crank", "coupler", "rocker"], joints, points)
    }

    #[test]
    fn spatial_rssr_matches_hand_relation() {
        let (a, b, c, dx, dz) = (40.0, 120.0, 80.0, 100.0, 30.0);
        let m = rssr(a, b, c, dx, dz);
        // Hand derivation: B = a(cos θ, sin θ, 0), C = D + c(cos ψ, 0, sin ψ), |C − B| = b:
        // with E = dx − a cos θ, 2Ec cos ψ + 2dz c sin ψ = b² − E² − c² − a² sin² θ − dz²,
        // i.e. P cos ψ + Q sin ψ = K, ψ = atan2(Q, P) ± acos(K / √(P² + Q²)).
        let candidates = |theta: f64| {
            let e = dx - a * theta.cos();
            let (p, q) = (2.0 * e * c, 2.0 * dz * c);
            let k = b * b - e * e - c * c - (a * theta.sin()).powi(2) - dz * dz;
            let (base, half) = (q.atan2(p), (k / p.hypot(q)).acos());
            [base + half, base - half].map(|psi| [dx + c * psi.cos(), 0.0, dz + c * psi.sin()])
        };
        let check = |theta: f64, branch: usize| {
            let cand = candidates(theta);
            let want = cand[branch];
            // Guess near the wanted branch: the coupler's x axis turned roughly
            // towards C, the rocker 0.2 rad off (its angle about +y is −ψ), S2 the
            // rotation left over, all kicked by 0.1 rad.
            let psi = (want[2] - dz).atan2(want[0] - dx);
            let bp = Vector3::new(a * theta.cos(), a * theta.sin(), 0.0);
            let crank = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), theta);
            let towards = crank.inverse() * (Vector3::from(want) - bp);
            let s1 = UnitQuaternion::rotation_between(&Vector3::x(), &towards)
                .unwrap()
                .scaled_axis();
            let rocker = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), -psi + 0.2);
            let s2 = ((crank * UnitQuaternion::from_scaled_axis(s1)).inverse() * rocker).scaled_axis();
            let guess = [
                0.0,
                s1.x + 0.1,
                s1.y - 0.1,
                s1.z + 0.1,
                s2.x - 0.1,
                s2.y + 0.1,
                s2.z,
                -psi + 0.2,
            ];
            let sol = solve_fk(&m, &[theta], &guess, &OPTS).unwrap_or_else(|e| panic!("θ={theta}: {e}"));
            let got = point(&m, &sol.poses, "C").unwrap();
            let msg = format!("θ={theta} branch {branch}: {got:?} vs {cand:?}, {sol:?}");
            assert!(
                norm3([cand[0][0] - cand[1][0], 0.0, cand[0][2] - cand[1][2]]) > 1.0,
                "{msg}"
            );
            assert!(
                norm3([got[0] - want[0], got[1] - want[1], got[2] - want[2]]) < 1e-9,
                "{msg}"
            );
            let bp = [a * theta.cos(), a * theta.sin(), 0.0];
            assert!(
                (norm3([got[0] - bp[0], got[1] - bp[1], got[2] - bp[2]]) - b).abs() < 1e-9,
                "{msg}"
            );
            assert!(sol.residual < 1e-12, "{msg}");
        };
        for theta in [0.0, 0.7, PI / 2.0, 2.2, PI, -1.0] {
            check(theta, 0);
            check(theta, 1);
        }
    }
}
