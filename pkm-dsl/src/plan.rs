//! From a κ = 0 mechanism with geometry to a solution plan: the ordered SOCs
//! solved one by one, each as transfers through joints of known value and
//! one closed-form subproblem from the catalogue. When a SOC matches nothing
//! in the catalogue the compiler says so, naming the SOC; it never falls back
//! to iteration.

use crate::analysis::Analysis;
use crate::diagnostics::{Diagnostic, Diagnostics};
use crate::geometry::JointPlace;
use crate::model::JointKind;
use pkm_runtime::model::{Joint, JointType, Model, NamedPoint};
use pkm_runtime::plan::{Plan, Step};
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

/// The forward-position plan.
pub fn forward_plan(a: &Analysis) -> Result<Plan, Diagnostics> {
    let m = &a.mechanism;
    let t = &a.topology;
    let fail = |msg: String| -> Diagnostics { Diagnostic::new(m.name_span(), msg).label("in this mechanism").into() };
    if t.kappa != 0 {
        return Err(fail(format!(
            "a closed-form forward plan needs κ = 0 (κ = {})",
            t.kappa
        )));
    }
    if !m.planar {
        return Err(fail(
            "this is the planar planner: a spatial mechanism's plan comes from `plan3`".to_string(),
        ));
    }
    let inputs: Vec<usize> = (0..m.joints.len()).filter(|&j| m.joints[j].actuated).collect();
    let mut known = vec![false; m.links.len()];
    known[0] = true;
    let mut steps = Vec::new();
    let mut branches = 0;
    for (k, soc) in t.socs.iter().enumerate() {
        // The links along the SOC: ends[0], …, ends[1].
        let mut links = vec![soc.ends[0]];
        for &j in &soc.joints {
            let last = *links.last().expect("non-empty");
            links.push(m.joints[j].other(last));
        }
        let n = soc.joints.len();
        let (mut lo, mut hi) = (0, n);
        // Through known joint values from both ends.
        while lo < hi && m.joints[soc.joints[lo]].actuated && !known[links[lo + 1]] {
            let j = soc.joints[lo];
            steps.push(Step::Transfer {
                joint: j,
                from: links[lo],
                to: links[lo + 1],
                input: input_index(&inputs, j),
            });
            known[links[lo + 1]] = true;
            lo += 1;
        }
        while hi > lo && m.joints[soc.joints[hi - 1]].actuated && !known[links[hi - 1]] {
            let j = soc.joints[hi - 1];
            steps.push(Step::Transfer {
                joint: j,
                from: links[hi],
                to: links[hi - 1],
                input: input_index(&inputs, j),
            });
            known[links[hi - 1]] = true;
            hi -= 1;
        }
        let middle: Vec<usize> = soc.joints[lo..hi].to_vec();
        if middle.is_empty() {
            continue;
        }
        let kinds: String = middle.iter().map(|&j| m.joints[j].kind.symbol()).collect();
        let unsupported = || {
            fail(format!(
                "SOC{} {{{}}}: its unknown part {kinds} ({}) has no decomposition in the catalogue (RRR, RRP)",
                k + 1,
                soc.notation,
                middle
                    .iter()
                    .map(|&j| m.joints[j].name.as_str())
                    .collect::<Vec<_>>()
                    .join("-")
            ))
        };
        if middle.len() != 3 || middle.iter().any(|&j| m.joints[j].actuated) {
            return Err(unsupported());
        }
        let ls = [links[lo], links[lo + 1], links[lo + 2], links[lo + 3]];
        let Some(step) = dyad_step(a, [middle[0], middle[1], middle[2]], ls, branches) else {
            return Err(unsupported());
        };
        steps.push(step);
        branches += 1;
        for l in &ls[1..3] {
            known[*l] = true;
        }
    }
    Ok(Plan {
        steps,
        branches,
        inputs,
    })
}

/// The catalogue's step for the dyad of joints `[a, b, c]` through links
/// `[k1, l1, l2, k2]` (k1 and k2 known), if it has one: RRR, or RRP with the
/// guide on the known link (written from either end).
fn dyad_step(a: &Analysis, joints: [usize; 3], links: [usize; 4], branch: usize) -> Option<Step> {
    let m = &a.mechanism;
    let [x, y, z] = joints;
    let [k1, l1, l2, k2] = links;
    let guide_on = |j: usize, link: usize| matches!(a.place(j, link), JointPlace::Line(..));
    match (m.joints[x].kind, m.joints[y].kind, m.joints[z].kind) {
        (JointKind::R, JointKind::R, JointKind::R) => Some(Step::Rrr { joints, links, branch }),
        (JointKind::R, JointKind::R, JointKind::P) if guide_on(z, k2) => Some(Step::Rrp { joints, links, branch }),
        (JointKind::P, JointKind::R, JointKind::R) if guide_on(x, k1) => Some(Step::Rrp {
            joints: [z, y, x],
            links: [k2, l2, l1, k1],
            branch,
        }),
        _ => None,
    }
}

fn input_index(inputs: &[usize], j: usize) -> usize {
    inputs.iter().position(|&i| i == j).unwrap_or(0)
}

/// The inverse-position plan: the links the outputs fix are placed first,
/// then known-link propagation through joints whose value is an output
/// (transfers) and class II dyads between known links, until every link is
/// known. What is left is named in the error.
pub fn inverse_plan(a: &Analysis) -> Result<Plan, Diagnostics> {
    use crate::geometry::OutputKind;
    let m = &a.mechanism;
    let fail = |msg: String| -> Diagnostics { Diagnostic::new(m.name_span(), msg).label("in this mechanism").into() };
    if !m.planar {
        return Err(fail(
            "this is the planar planner: a spatial mechanism's plan comes from `plan3`".to_string(),
        ));
    }
    if a.geometry.outputs.is_empty() {
        return Err(fail("an inverse solution needs `outputs { … }`".to_string()));
    }
    let mut known = vec![false; m.links.len()];
    known[0] = true;
    let mut value_of: Vec<Option<usize>> = vec![None; m.joints.len()];
    // A link only one joint point of which is known (a point output): it can
    // close a dyad through that joint, which then fixes it.
    let mut pinned: Vec<Option<usize>> = vec![None; m.links.len()];
    let mut steps = Vec::new();
    let mut next_input = 0;
    for o in &a.geometry.outputs {
        match &o.kind {
            OutputKind::Pose { link, point, .. } => {
                steps.push(Step::Place {
                    link: *link,
                    point: *point,
                    input: next_input,
                });
                known[*link] = true;
            }
            OutputKind::Point { link, point } => {
                steps.push(Step::PlacePoint {
                    link: *link,
                    point: *point,
                    input: next_input,
                });
                if let pkm_runtime::plan::PointRef::Joint(j) = point {
                    pinned[*link] = Some(*j);
                }
            }
            OutputKind::Joint(j) => value_of[*j] = Some(next_input),
        }
        next_input += o.names.len();
    }
    let mut solved = vec![false; m.joints.len()];
    let mut branches = 0;
    loop {
        let mut progress = false;
        // Transfers through joints of known value.
        for (j, joint) in m.joints.iter().enumerate() {
            let [u, v] = joint.links;
            if let (Some(input), false) = (value_of[j], solved[j]) {
                if known[u] != known[v] && pinned[if known[u] { v } else { u }].is_none() {
                    let (from, to) = if known[u] { (u, v) } else { (v, u) };
                    steps.push(Step::Transfer {
                        joint: j,
                        from,
                        to,
                        input,
                    });
                    known[to] = true;
                    solved[j] = true;
                    progress = true;
                }
            }
        }
        // A dyad: three unsolved joints through two unknown links between known links.
        'search: for k1 in 0..m.links.len() {
            if !known[k1] {
                continue;
            }
            for (a1, ja) in m.joints.iter().enumerate() {
                if solved[a1] || value_of[a1].is_some() || !ja.links.contains(&k1) {
                    continue;
                }
                let l1 = ja.other(k1);
                if known[l1] || pinned[l1].is_some() {
                    continue;
                }
                for (b1, jb) in m.joints.iter().enumerate() {
                    if b1 == a1 || solved[b1] || value_of[b1].is_some() || !jb.links.contains(&l1) {
                        continue;
                    }
                    let l2 = jb.other(l1);
                    if known[l2] || l2 == k1 {
                        continue;
                    }
                    for (c1, jc) in m.joints.iter().enumerate() {
                        if c1 == a1 || c1 == b1 || solved[c1] || value_of[c1].is_some() || !jc.links.contains(&l2) {
                            continue;
                        }
                        let k2 = jc.other(l2);
                        // A pinned link closes the dyad only at its known point, and a
                        // pinned l2 only where that point is the one k2 fixes.
                        if !(known[k2] || pinned[k2] == Some(c1)) || pinned[l2].is_some_and(|p| p != c1) {
                            continue;
                        }
                        let Some(step) = dyad_step(a, [a1, b1, c1], [k1, l1, l2, k2], branches) else {
                            continue;
                        };
                        steps.push(step);
                        branches += 1;
                        known[l1] = true;
                        known[l2] = true;
                        pinned[l2] = None;
                        // Through a pinned k2 the joint's value stays open (k2's angle is).
                        for j in [a1, b1, c1] {
                            solved[j] = j != c1 || known[k2];
                        }
                        progress = true;
                        break 'search;
                    }
                }
            }
        }
        if known.iter().all(|k| *k) {
            break;
        }
        if !progress {
            let left: Vec<&str> = (0..m.links.len())
                .filter(|&l| !known[l])
                .map(|l| m.links[l].name.as_str())
                .collect();
            return Err(fail(format!(
                "no closed-form inverse plan: links {} are not reached by transfers or RRR/RRP dyads from the outputs",
                left.join(", ")
            )));
        }
    }
    Ok(Plan {
        steps,
        branches,
        inputs: (0..next_input).collect(),
    })
}
