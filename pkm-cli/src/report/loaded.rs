//! A `.pkm` file ready to solve: its analysis, its numeric model at the
//! given parameters, its declared outputs and its forward and inverse plans;
//! and what the sections read off it (points by name, units, outputs).

use super::{invalid, ReportError};
use pkm_runtime::model::{JointType, Model};
use pkm_runtime::newton::{self, Output};
pub(super) use pkm_runtime::plan::Plan;
use pkm_runtime::plan::Pose3;
use pkm_runtime::primitives::Sign;
use std::collections::HashMap;

/// A `.pkm` file ready to solve: its analysis, numeric model, outputs and plans.
pub(super) struct Loaded {
    pub(super) analysis: pkm_dsl::analysis::Analysis,
    pub(super) model: Model,
    pub(super) outputs: Vec<Output>,
    /// The forward plan, or why there is none (κ ≠ 0).
    pub(super) forward: Result<Plan, String>,
    /// The inverse plan from the declared outputs, or why there is none.
    pub(super) inverse: Result<Plan, String>,
    /// The parameter values used.
    pub(super) values: HashMap<String, f64>,
}

/// The first line of a diagnostic's message (without `error: `).
fn headline(d: &pkm_dsl::Diagnostics) -> String {
    d.0.first().map(|x| x.message.clone()).unwrap_or_default()
}

/// The analysis and parameter values of a file; `Ok(None)` for the model
/// when the file has no geometry.
pub(super) fn load(
    text: &str,
    file: &str,
    params: &[(String, f64)],
) -> Result<(pkm_dsl::analysis::Analysis, Option<Loaded>), ReportError> {
    let render = |d: pkm_dsl::Diagnostics| ReportError::source(d, text, file);
    let compiled = pkm_dsl::compile(text).map_err(render)?;
    let a = &compiled.analysis;
    // Only the overrides: the others, derived ones included, are resolved from them.
    let param = |e: pkm_dsl::params::ParamError| {
        invalid(match e {
            pkm_dsl::params::ParamError::Unknown { name, known, .. } => {
                format!(
                    "{file}: --param {name}: no such parameter (the parameters: {})",
                    known.join(", ")
                )
            }
            pkm_dsl::params::ParamError::NotFinite { name, value } => {
                format!("--param {name}={value}: not a finite number")
            }
            e => format!("{file}: --param {}: {e}", e.name()),
        })
    };
    if !a.geometry.complete {
        pkm_dsl::params::overrides(a, params).map_err(param)?;
        return Ok((compiled.analysis, None));
    }
    let pkm_dsl::Instance {
        model,
        outputs,
        overrides: values,
    } = compiled.instance(params).map_err(|e| match e {
        pkm_dsl::InstanceError::Source(d) => render(d),
        pkm_dsl::InstanceError::Param(e) => param(e),
        pkm_dsl::InstanceError::Dimension(why) => invalid(format!("{file}: {why}")),
    })?;
    // Every parameter's value, for the study block's expressions.
    let values = pkm_dsl::numeric::parameter_values(a, &values).map_err(render)?;
    let forward = compiled.forward().cloned().map_err(|d| headline(&d));
    let inverse = if a.geometry.outputs.is_empty() {
        Err("the file declares no outputs".to_string())
    } else {
        compiled.inverse().cloned().map_err(|d| headline(&d))
    };
    Ok((
        a.clone(),
        Some(Loaded {
            analysis: compiled.analysis,
            model,
            outputs,
            forward,
            inverse,
            values,
        }),
    ))
}

/// The signs of branch `index` of a plan with `choices` ± choices (bit k set: choice k is −).
pub(super) fn signs(choices: usize, index: usize) -> Vec<Sign> {
    (0..choices)
        .map(|k| if index >> k & 1 == 1 { Sign::Minus } else { Sign::Plus })
        .collect()
}

/// A point of the model by name: a named point or a joint's point.
pub(super) fn point_of(model: &Model, name: &str) -> Option<(usize, [f64; 3])> {
    if let Some(p) = model.points.iter().find(|p| p.name == name) {
        return Some((p.link, p.at));
    }
    let j = model.joints.iter().position(|j| j.name == name)?;
    let joint = &model.joints[j];
    let side = joint.point_side();
    Some((joint.links[side], joint.places[side].at()))
}

/// The world position of `local`, a point of `link`, at the joint values `values`.
pub(super) fn world(model: &Model, values: &[f64], link: usize, local: [f64; 3]) -> Option<[f64; 3]> {
    let poses = newton::link_poses(model, values).ok()?;
    let p = poses[link].transform_point(&local.into());
    Some([p.x, p.y, p.z])
}

/// The mechanism's size ([`pkm_runtime::kinematics::model_reach`]: an
/// upper bound of its reach).
pub(super) fn reach(model: &Model) -> f64 {
    pkm_runtime::kinematics::model_reach(model)
}

/// The unit of joint `j`'s value.
pub(super) fn joint_unit(model: &Model, j: usize, unit: &str) -> String {
    match model.joints[j].kind {
        JointType::P => unit.to_string(),
        _ => "rad".into(),
    }
}

/// The default followed point: the first pose or point output's point; with
/// no outputs, the last slider's point, else the last joint off the base.
pub(super) fn default_point(l: &Loaded) -> String {
    let a = &l.analysis;
    let model = &l.model;
    let named = a.geometry.outputs.iter().find_map(|out| match &out.kind {
        pkm_dsl::geometry::OutputKind::Pose { point, .. }
        | pkm_dsl::geometry::OutputKind::Point { point, .. }
        | pkm_dsl::geometry::OutputKind::Parts { point, .. } => Some(match point {
            pkm_runtime::solution::PointRef::Named(k) => a.geometry.points[*k].name.clone(),
            pkm_runtime::solution::PointRef::Joint(j) => model.joints[*j].name.clone(),
        }),
        _ => None,
    });
    named
        .or_else(|| {
            model
                .joints
                .iter()
                .rev()
                .find(|j| j.kind == JointType::P)
                .map(|j| j.name.clone())
        })
        .or_else(|| {
            model
                .joints
                .iter()
                .rev()
                .find(|j| !j.links.contains(&0))
                .map(|j| j.name.clone())
        })
        .unwrap_or_else(|| model.joints.last().map(|j| j.name.clone()).unwrap_or_default())
}

/// The names and units of the declared outputs' values, in order.
pub(super) fn output_columns(l: &Loaded, unit: &str) -> Vec<String> {
    let mut cols = Vec::new();
    for out in &l.analysis.geometry.outputs {
        for (k, name) in out.names.iter().enumerate() {
            let u = match &out.kind {
                pkm_dsl::geometry::OutputKind::Pose { .. } => {
                    let positions = if l.model.planar { 2 } else { 3 };
                    if k < positions {
                        unit.to_string()
                    } else {
                        "rad".into()
                    }
                }
                pkm_dsl::geometry::OutputKind::Point { .. } => unit.to_string(),
                pkm_dsl::geometry::OutputKind::Parts { parts, .. } => {
                    if parts.given().nth(k).is_some_and(|p| p >= 3) {
                        "rad".into()
                    } else {
                        unit.to_string()
                    }
                }
                pkm_dsl::geometry::OutputKind::Joint(j) => joint_unit(&l.model, *j, unit),
            };
            cols.push(format!("{name} ({u})"));
        }
    }
    cols
}

/// The declared outputs' values from link poses.
pub(super) fn pose_outputs(model: &Model, poses: &[Pose3], outputs: &[Output]) -> Vec<f64> {
    let mut v = Vec::new();
    for o in outputs {
        match *o {
            Output::Pose { link, local, about } => {
                let p = pkm_runtime::plan::at(&poses[link], local);
                v.extend_from_slice(if model.planar { &p[..2] } else { &p[..] });
                if let Some(k) = about {
                    v.push(pkm_runtime::plan::angle_about(&poses[link], k));
                }
            }
            Output::Point { link, local } => {
                let p = pkm_runtime::plan::at(&poses[link], local);
                v.extend_from_slice(if model.planar { &p[..2] } else { &p[..] });
            }
            Output::Parts { link, local, parts } => {
                let frame = pkm_runtime::plan::frame_of(&poses[link]);
                let six = pkm_runtime::steps::place::pose_values(&frame, local);
                v.extend(parts.given().map(|i| six[i]));
            }
            Output::Joint(j) => {
                let joint = &model.joints[j];
                let g = pkm_runtime::steps::JointGeometry::new(joint.kind, joint.links, joint.places);
                let frame = |l: usize| pkm_runtime::plan::frame_of(&poses[l]);
                v.push(g.value_between(&frame(joint.links[0]), &frame(joint.links[1])));
            }
        }
    }
    v
}
