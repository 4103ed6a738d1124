//! The description in numbers: every parameter's value ([`parameter_values`]),
//! the numeric model the interpreter and Newton's method run on ([`model`]),
//! and the declared outputs for Newton's inverse solution ([`newton_outputs`]).

use crate::analysis::Analysis;
use crate::diagnostics::{Diagnostic, Diagnostics};
use crate::mechanism::JointKind;
use pkm_runtime::model::{Joint, JointType, Model, NamedPoint};
use std::collections::HashMap;

/// The declared outputs in numbers (for Newton's inverse solution) at the
/// given parameter values, points read from `model`.
pub fn newton_outputs(
    a: &Analysis,
    model: &Model,
    values: &HashMap<String, f64>,
) -> Result<Vec<pkm_runtime::newton::Output>, Diagnostics> {
    use crate::geometry::OutputKind;
    use pkm_runtime::newton::Output;
    // Derived parameters follow the overrides, as in `model`.
    let all = parameter_values(a, values)?;
    let local = |point, link| {
        pkm_runtime::spatial::local_point(model, point, link)
            .map_err(|e| Diagnostics::from(Diagnostic::new(a.mechanism.name_span(), e.to_string())))
    };
    a.geometry
        .outputs
        .iter()
        .map(|o| {
            Ok(match &o.kind {
                OutputKind::Pose { link, point, about } => Output::Pose {
                    link: *link,
                    local: local(*point, *link)?,
                    about: match about {
                        Some(k) => Some(crate::geometry::eval_vec3(k, &all)),
                        None if a.mechanism.planar => Some([0.0, 0.0, 1.0]),
                        None => None,
                    },
                },
                OutputKind::Point { link, point } => Output::Point {
                    link: *link,
                    local: local(*point, *link)?,
                },
                OutputKind::Joint(j) => Output::Joint(*j),
            })
        })
        .collect()
}

/// Every parameter's value: those in `values` as given, the others computed
/// from their expressions (so a parameter that reads an overridden one
/// follows it). A value that is not a finite number is an error naming the
/// parameter and its expression.
pub fn parameter_values(a: &Analysis, values: &HashMap<String, f64>) -> Result<HashMap<String, f64>, Diagnostics> {
    let g = &a.geometry;
    if values.is_empty() {
        return Ok(g.nominal());
    }
    if let Some(k) = values.keys().find(|k| !g.parameters.iter().any(|p| &p.name == *k)) {
        return Err(Diagnostic::global(format!("unknown parameter `{k}`")).into());
    }
    let definitions: Vec<crate::expr::Definition> = g
        .parameters
        .iter()
        .map(|p| crate::expr::Definition {
            name: &p.name,
            span: p.span,
            expr: &p.expr,
        })
        .collect();
    let (params, errors) = crate::expr::resolve(&definitions, values);
    Diagnostics(errors).into_result(params)
}

/// The numeric model at the given parameter values (the nominal ones for
/// names not in `values`).
pub fn model(a: &Analysis, values: &HashMap<String, f64>) -> Result<Model, Diagnostics> {
    let m = &a.mechanism;
    let g = &a.geometry;
    if !g.complete {
        return Err(
            Diagnostic::new(m.joints[0].span, format!("mechanism `{}` has no geometry", m.name))
                .label("add a `parameters` and a `geometry` block")
                .into(),
        );
    }
    let params = parameter_values(a, values)?;
    let eval = |v: &crate::geometry::Vec3| crate::geometry::eval_vec3(v, &params);
    let mut joints = Vec::new();
    for (j, joint) in m.joints.iter().enumerate() {
        let kind = match joint.kind {
            JointKind::R => JointType::R,
            JointKind::P => JointType::P,
            JointKind::S => JointType::S,
            JointKind::Pa => JointType::Pa,
            k => {
                return Err(
                    Diagnostic::new(joint.span, format!("{} joints have no numeric model yet", k.symbol()))
                        .label("not supported by the solvers yet")
                        .into(),
                )
            }
        };
        let place = |s: usize| {
            g.places[j][s]
                .as_ref()
                .expect("complete geometry places every joint")
                .place(eval)
        };
        joints.push(Joint {
            name: joint.name.clone(),
            kind,
            links: joint.links,
            places: [place(0), place(1)],
            actuated: joint.actuated,
        });
    }
    Ok(Model {
        name: m.name.clone(),
        planar: m.planar,
        links: m.links.iter().map(|l| l.name.clone()).collect(),
        joints,
        points: g
            .points
            .iter()
            .map(|p| NamedPoint {
                name: p.name.clone(),
                link: p.link,
                at: eval(&p.at),
            })
            .collect(),
    })
}
