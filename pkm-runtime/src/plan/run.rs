//! The interpreter: a plan's steps run at `f64` for one branch and the
//! solution verified ([`run`]), every branch at once ([`run_all`]), the
//! [`Solution`] they give, and the conversions between nalgebra's poses and
//! the steps' frames ([`pose_of`], [`frame_of`]).

use super::{v3, Plan, Pose3};
use crate::model::{JointType, Model};
use crate::primitives::Sign;
use crate::solution::{PointRef, SolveError};
use nalgebra::{Isometry3, Rotation3};
use std::borrow::Cow;

/// A solution: every link's pose and every joint's value.
#[derive(Debug, Clone, PartialEq)]
pub struct Solution {
    /// Link poses.
    pub poses: Vec<Pose3>,
    /// Joint values.
    pub values: Vec<f64>,
}

fn bad(what: String) -> SolveError {
    SolveError::BadInput { what: Cow::Owned(what) }
}

impl Solution {
    /// The joint values in the model's layout ([`Model::value_offsets`]):
    /// one per R, P or Pa joint ([`Solution::values`]), three per
    /// spherical joint, which has no one value there: the rotation vector
    /// between its two links' poses (`T_u⁻¹·T_v`'s rotation, as
    /// [`crate::kinematics::joint_pose`] turns it). An S–S link's idle
    /// spin is in its joints' rotation vectors as the plan's convention
    /// placed it.
    pub fn model_values(&self, model: &Model) -> Vec<f64> {
        model
            .joints
            .iter()
            .zip(&self.values)
            .flat_map(|(j, &v)| match j.kind {
                JointType::S => {
                    let [u, w] = j.links;
                    let r = (self.poses[u].rotation.inverse() * self.poses[w].rotation).scaled_axis();
                    vec![r.x, r.y, r.z]
                }
                _ => vec![v],
            })
            .collect()
    }
}

/// The values of one declared output at link poses `poses` and joint
/// values `values` (one per joint, a solution's): a point's coordinates
/// (x, y, and z if `planar` is false), a pose's point then its angle about
/// its axis where it has one, a pose's given parts (of x, y, z, rx, ry, rz
/// with `R = R_z(rz)·R_y(ry)·R_x(rx)`), a joint's value.
pub fn output_values(poses: &[Pose3], values: &[f64], planar: bool, output: &crate::newton::Output) -> Vec<f64> {
    use crate::newton::Output;
    let dim = if planar { 2 } else { 3 };
    match *output {
        Output::Pose { link, local, about } => {
            let mut v = super::at(&poses[link], local)[..dim].to_vec();
            v.extend(about.map(|k| super::angle_about(&poses[link], k)));
            v
        }
        Output::Point { link, local } => super::at(&poses[link], local)[..dim].to_vec(),
        Output::Parts { link, local, parts } => {
            let six = crate::steps::place::pose_values(&frame_of(&poses[link]), local);
            parts.given().map(|i| six[i]).collect()
        }
        Output::Joint(j) => vec![values[j]],
    }
}

/// A point of a link of the model, in that link's frame.
pub fn local_point(model: &Model, point: PointRef, link: usize) -> Result<[f64; 3], SolveError> {
    match point {
        PointRef::Joint(j) => {
            let joint = model.joints.get(j).ok_or_else(|| bad(format!("no joint {j}")))?;
            let side = joint
                .links
                .iter()
                .position(|&l| l == link)
                .ok_or_else(|| bad(format!("joint {} does not touch link {link}", joint.name)))?;
            Ok(joint.places[side].at())
        }
        PointRef::Named(n) => model
            .points
            .get(n)
            .map(|p| p.at)
            .ok_or_else(|| bad(format!("no named point {n}"))),
    }
}

/// Runs the plan for one branch and verifies the solution: every open
/// joint must close ([`crate::consistency`]); where one does not, the error
/// names the given value the others contradict (`#k`: the plan knows no
/// names for the given values, see [`crate::consistency::name_given`]).
/// [`Prepared`] runs one plan many times.
pub fn run(model: &Model, plan: &Plan, inputs: &[f64], signs: &[Sign]) -> Result<Solution, SolveError> {
    Prepared::new(model, plan).run(inputs, signs)
}

/// A plan with what every run of it needs read off the model once: the
/// joints' geometry and the checks of its open joints.
pub struct Prepared<'a> {
    model: &'a Model,
    plan: &'a Plan,
    geometry: crate::steps::Geometry<f64>,
    checks: Vec<super::Check>,
}

impl<'a> Prepared<'a> {
    /// `plan` on `model`, prepared.
    pub fn new(model: &'a Model, plan: &'a Plan) -> Prepared<'a> {
        let geometry = crate::steps::Geometry::of(model);
        let checks = plan.checks(geometry.joints.len());
        Prepared {
            model,
            plan,
            geometry,
            checks,
        }
    }

    /// One branch run and verified, as [`run`].
    pub fn run(&self, inputs: &[f64], signs: &[Sign]) -> Result<Solution, SolveError> {
        let Prepared {
            model,
            plan,
            geometry,
            checks,
        } = self;
        let state = run_frames(model, geometry, plan, inputs, signs)?;
        let extent = crate::consistency::extent(&plan.measured(&state.poses.iter().map(|p| p.t).collect::<Vec<_>>()));
        let residual = crate::steps::check_residual(geometry, plan, checks, &state.poses, inputs, extent);
        let rows = crate::steps::RESIDUAL_ROWS;
        if let Some((row, gap)) = crate::consistency::worst(&residual, extent) {
            let owner = checks[row / rows].owner(plan, |j| model.joints[j].name.clone(), |l| model.links[l].clone());
            let angular = plan.angular_inputs(model);
            let e = crate::consistency::inconsistent(Cow::Owned(owner), gap, inputs, &angular, extent, |g| {
                let s = run_frames(model, geometry, plan, g, signs).ok()?;
                Some(crate::steps::check_residual(
                    geometry, plan, checks, &s.poses, g, extent,
                ))
            });
            return Err(crate::consistency::name_given(e, &[]));
        }
        let values = (0..geometry.joints.len())
            .map(|j| crate::steps::value(geometry, &state, j))
            .collect();
        Ok(Solution {
            poses: state.poses.iter().map(pose_of).collect(),
            values,
        })
    }
}

/// A frame as an isometry.
pub fn pose_of(f: &crate::frame::Frame<f64>) -> Pose3 {
    let m = nalgebra::Matrix3::from_fn(|i, j| f.r[i][j]);
    let r = Rotation3::from_matrix_unchecked(m);
    Isometry3::from_parts(v3(f.t).into(), nalgebra::UnitQuaternion::from_rotation_matrix(&r))
}

/// An isometry as a frame (the steps' pose algebra).
pub fn frame_of(p: &Pose3) -> crate::frame::Frame<f64> {
    let m = p.rotation.to_rotation_matrix();
    let m = m.matrix();
    crate::frame::Frame {
        r: core::array::from_fn(|i| core::array::from_fn(|j| m[(i, j)])),
        t: [p.translation.x, p.translation.y, p.translation.z],
    }
}

/// The steps of one branch, unverified.
fn run_frames(
    model: &Model,
    geometry: &crate::steps::Geometry<f64>,
    plan: &Plan,
    inputs: &[f64],
    signs: &[Sign],
) -> Result<crate::steps::Solved<f64>, SolveError> {
    if inputs.len() != plan.n_inputs || signs.len() != plan.branches {
        return Err(bad(format!(
            "expected {} inputs and {} signs",
            plan.n_inputs, plan.branches
        )));
    }
    if let Some(i) = inputs.iter().position(|v| !v.is_finite()) {
        return Err(bad(format!("given value {} is {}", i + 1, inputs[i])));
    }
    let name = |k: usize| -> Cow<'static, str> {
        Cow::Owned(crate::steps::loop_name(&plan.steps[k], |j| {
            model.joints[j].name.clone()
        }))
    };
    let given = crate::steps::Given {
        values: inputs,
        signs,
        name: &name,
        sites: 0,
    };
    crate::steps::run(plan, geometry, model.links.len(), &given)
}

/// Every branch of the plan.
/// Every branch of the plan; a branch that repeats an earlier one's solution
/// (a double root) says so ([`SolveError::DoubleRoot`]).
pub fn run_all(model: &Model, plan: &Plan, inputs: &[f64]) -> Vec<(Vec<Sign>, Result<Solution, SolveError>)> {
    let mut all = crate::solution::every_branch(plan.branches, |signs| run(model, plan, inputs, signs));
    let revolute: Vec<bool> = model
        .joints
        .iter()
        .map(|j| matches!(j.kind, JointType::R | JointType::Pa))
        .collect();
    crate::consistency::mark_double_roots_in(&mut all, &revolute, |s: &Solution| &s.values);
    all
}
