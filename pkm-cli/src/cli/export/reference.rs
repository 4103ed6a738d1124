//! The reference configuration the model is built at ([`Reference`]): by
//! the closed-form forward plan, by the virtual variable of `fk_numeric`
//! (κ = 1), or by the inverse plan at a pose, on the branch asked for or the
//! first that assembles.

use super::writer::num;
use super::Options;
use crate::cli::failure::{Failure, Kind};
use crate::cli::solve::{input_values, ordered_pose, output_names, sign_text, Loaded, Request};
use crate::cli::table::{number_of, signs_of};
use pkm_runtime::fk_numeric::VirtualPlan;
use pkm_runtime::model::Model;
use pkm_runtime::newton::Output;
use pkm_runtime::plan::{Plan, Solution};
use pkm_runtime::primitives::Sign;
use pkm_runtime::solution::SolveError;
use serde_json::{json, Map, Value};

/// The reference configuration: the actuated joints (in the order `--q`,
/// `pkm dynamics` and the motors take them) and their values, the branch,
/// the solution, and how each was chosen (for the JSON and the XML's
/// comment).
pub(super) struct Reference {
    /// The actuated joints, in input order.
    pub(super) inputs: Vec<usize>,
    /// Their values at the reference.
    pub(super) given: Vec<f64>,
    pub(super) inputs_from: &'static str,
    pub(super) branch: usize,
    pub(super) signs: Vec<&'static str>,
    pub(super) branch_from: &'static str,
    pub(super) solution: Solution,
    /// `solver`, and the pose (ik) or the virtual variable and the
    /// assembly (`fk_numeric`).
    pub(super) how: Map<String, Value>,
    /// Where it was solved, for the XML's comment.
    pub(super) at: String,
}

/// One branch's signs and its solution or why it has none.
type Run = (Vec<Sign>, Result<Solution, SolveError>);

/// The branch asked for (`--branch`, else the study's), with where it came from.
type Wanted = Option<(usize, &'static str)>;

/// How a reference configuration is solved: by the closed-form forward
/// plan (κ = 0), by the virtual variable (`fk_numeric`, a κ = 1 file that
/// asks for it), or by the inverse plan at a pose.
enum Way {
    Forward(Plan),
    Numeric(Box<VirtualPlan>),
    Inverse(Plan),
}

/// The reference configuration. With `--pose`, the inverse plan there;
/// else, with a forward solution (κ = 0, or κ = 1 and `fk_numeric`), the
/// inputs `--q`, else the study's start, else zeros; else (κ ≠ 0) the
/// inverse plan at the outputs' home ([`inverse_reference`]). The branch is
/// `--branch`, else the study's, else the first that assembles (at the
/// home pose: the best conditioned).
pub(super) fn reference(r: &Request, l: &Loaded, o: &Options) -> Result<Reference, Failure> {
    let (a, model) = (&l.compiled.analysis, &l.model);
    let ast = pkm_dsl::parse(r.source).map_err(|d| r.parse_failure(d.into()))?;
    let names: Vec<String> = model
        .joints
        .iter()
        .filter(|j| j.actuated)
        .map(|j| j.name.clone())
        .collect();
    let values = pkm_dsl::numeric::parameter_values(a, &l.values).map_err(|d| r.parse_failure(d))?;
    let outputs: Vec<String> = a.geometry.outputs.iter().flat_map(|o| o.names.clone()).collect();
    let study = pkm_dsl::study::resolve(&ast.studies, &names, &outputs, &values).map_err(|d| r.parse_failure(d))?;
    let wanted = match (o.branch, study.branch) {
        (Some(b), _) => Some((b, "--branch")),
        (None, Some(b)) => Some((b, "the study's `branch`")),
        (None, None) => None,
    };
    let numeric = pkm_dsl::planner_numeric::by_virtual_variable(a);
    let way = if !o.pose.is_empty() {
        Way::Inverse(l.compiled.inverse().cloned().map_err(|d| r.parse_failure(d))?)
    } else if a.topology.kappa == 0 {
        Way::Forward(l.compiled.forward().cloned().map_err(|d| r.parse_failure(d))?)
    } else if numeric && (!o.q.is_empty() || study.start.is_some() || l.compiled.inverse().is_err()) {
        Way::Numeric(Box::new(
            pkm_dsl::planner_numeric::forward_numeric_plan(a).map_err(|d| r.parse_failure(d))?,
        ))
    } else if !o.q.is_empty() {
        return Err(Failure::input(format!(
            "--q: {} has no forward solution to take inputs (κ = {}{}): give its outputs with --pose",
            model.name,
            a.topology.kappa,
            if a.topology.kappa == 1 {
                ", and it does not ask for `fk_numeric`"
            } else {
                ""
            }
        )));
    } else {
        match l.compiled.inverse().cloned() {
            Ok(plan) => Way::Inverse(plan),
            Err(d) => {
                let why = d.0.first().map(|x| x.message.clone()).unwrap_or_default();
                return Err(Failure::input(format!(
                    "export needs an assembled configuration, and nothing solves {}'s position: it has no \
                     closed-form forward plan (κ = {}), {}, and no inverse plan ({why})",
                    model.name,
                    a.topology.kappa,
                    if a.topology.kappa == 1 {
                        "does not ask for `fk_numeric` (the virtual variable's forward solution)"
                    } else {
                        "and κ > 1 has no numeric forward solution"
                    }
                )));
            }
        }
    };
    if o.assembly.is_some() && !matches!(way, Way::Numeric(_)) {
        return Err(Failure::input(
            "--assembly picks one of a branch's assemblies of `fk_numeric` (κ = 1); this reference is solved in closed form, one assembly per branch",
        ));
    }
    match way {
        Way::Forward(plan) => {
            let inputs = plan.input_joints(model);
            let (given, inputs_from) = given_inputs(r, model, &inputs, &names, &study, o)?;
            let runs = pkm_runtime::plan::run_all(model, &plan, &given);
            let at = format!("inputs ({}) from {inputs_from}", nums_comma(&given));
            let (branch, signs, solution, branch_from) = assembled(runs, wanted, &at, "--q")?;
            let mut how = Map::new();
            how.insert("solver".into(), json!("fk"));
            Ok(Reference {
                inputs,
                given,
                inputs_from,
                branch,
                signs,
                branch_from,
                solution,
                how,
                at,
            })
        }
        Way::Numeric(vp) => numeric_reference(r, l, &vp, &names, &study, o, wanted),
        Way::Inverse(plan) => inverse_reference(r, l, &plan, o, wanted, study.pose.as_deref()),
    }
}

/// The inputs' values: `--q`, else the study's start, else zeros.
fn given_inputs(
    r: &Request,
    model: &Model,
    inputs: &[usize],
    names: &[String],
    study: &pkm_dsl::study::Resolved,
    o: &Options,
) -> Result<(Vec<f64>, &'static str), Failure> {
    Ok(match (o.q.is_empty(), &study.start) {
        (false, _) => (input_values(r, model, inputs, "--q", o.q)?, "--q"),
        // The study's start is in the declaration order of the actuated joints.
        (true, Some(start)) => (
            inputs
                .iter()
                .map(|&j| {
                    let k = names.iter().position(|n| *n == model.joints[j].name).unwrap_or(0);
                    start.get(k).copied().unwrap_or(0.0)
                })
                .collect(),
            "the study's start",
        ),
        (true, None) => (vec![0.0; inputs.len()], "zeros"),
    })
}

fn nums_comma(v: &[f64]) -> String {
    v.iter().map(|&x| num(x)).collect::<Vec<_>>().join(", ")
}

/// A κ = 1 file that asks for `fk_numeric`: the assemblies the virtual
/// variable finds at the inputs, numbered as `pkm fk` lists them (the plan
/// branch they are found on; `--assembly` counts those of one branch, in
/// `pkm fk`'s order).
fn numeric_reference(
    r: &Request,
    l: &Loaded,
    vp: &VirtualPlan,
    names: &[String],
    study: &pkm_dsl::study::Resolved,
    o: &Options,
    wanted: Wanted,
) -> Result<Reference, Failure> {
    let model = &l.model;
    let inputs = vp.plan.inputs[..vp.plan.inputs.len() - 1].to_vec();
    let (given, inputs_from) = given_inputs(r, model, &inputs, names, study, o)?;
    let at = format!("inputs ({}) from {inputs_from}", nums_comma(&given));
    let virtual_name = model.joints[vp.joint].name.clone();
    let found = pkm_runtime::fk_numeric::solve(model, vp, &given).map_err(|e| Failure::input(e.to_string()))?;
    let count = 1usize << vp.plan.branches;
    let listed: Vec<Value> = found
        .iter()
        .map(|f| json!({ "branch": number_of(&f.signs), "signs": sign_text(&f.signs), "virtual": f.virtual_value }))
        .collect();
    let (branch, branch_from) = match (wanted, found.first()) {
        (Some((b, from)), _) if b >= count => {
            return Err(Failure::input(format!(
                "branch {b} ({from}): the plan has {count} branches, 0 to {}",
                count - 1
            )))
        }
        (Some((b, from)), _) => (b, from),
        (None, Some(first)) => (number_of(&first.signs), "the first that assembles"),
        (None, None) => {
            return Err(Failure::new(
                Kind::Unreachable,
                format!(
                    "no assembly at the {at}: the virtual variable {virtual_name}'s compatibility residual has no root on any branch (give --q)"
                ),
            ))
        }
    };
    // The branch's assemblies in `pkm fk`'s order; `--assembly` picks one.
    let on_branch: Vec<&pkm_runtime::fk_numeric::Assembly> =
        found.iter().filter(|f| number_of(&f.signs) == branch).collect();
    let within = o.assembly.unwrap_or(0);
    let Some(&assembly) = on_branch.get(within) else {
        return Err(Failure::new(
            Kind::Unreachable,
            format!(
                "branch {branch} ({branch_from}) has {} assembl{} at the {at}{}; the virtual variable {virtual_name} finds {} in all",
                on_branch.len(),
                if on_branch.len() == 1 { "y" } else { "ies" },
                o.assembly.map_or(String::new(), |k| format!(", no assembly {k} (--assembly)")),
                found.len()
            ),
        ));
    };
    let mut how = Map::new();
    how.insert("solver".into(), json!("fk_numeric"));
    how.insert("virtual".into(), json!({ virtual_name: assembly.virtual_value }));
    how.insert("assembly".into(), json!(within));
    how.insert("tangent".into(), json!(!assembly.kind.certified()));
    how.insert("assemblies".into(), json!(listed));
    Ok(Reference {
        inputs,
        given,
        inputs_from,
        branch,
        signs: sign_text(&assembly.signs),
        branch_from,
        solution: assembly.solution.clone(),
        how,
        at: format!("{at}, assembly {within} of its branch"),
    })
}

/// Values tried for one output when the outputs' home is singular.
const SCAN: usize = 200;

/// The inverse plan at `--pose`, else at the study's `pose`, else at the
/// outputs' home: every output 0, unless no branch is regular there (the
/// actuators cannot hold it).
/// Then one output moves from home to where the forward velocity map of
/// the first branch that assembles (or the one asked for) is best
/// conditioned (σ_min/σ_max of the loop equations' passive columns, 0 at an
/// output singularity): a platform's height z over (0, the mechanism's
/// reach], as `pkm report`'s stiffness map holds its platform level at its
/// best-conditioned height; without a height, the best of each output over
/// (−reach, reach] (an angle over (−π, π]). There the branch is the best
/// conditioned (the first of equals).
fn inverse_reference(
    r: &Request,
    l: &Loaded,
    plan: &Plan,
    o: &Options,
    wanted: Wanted,
    study_pose: Option<&[f64]>,
) -> Result<Reference, Failure> {
    let model = &l.model;
    let inputs = model.inputs();
    let outputs = output_names(l);
    let count = 1usize << plan.branches;
    if let Some((b, from)) = wanted.filter(|(b, _)| *b >= count) {
        return Err(Failure::input(format!(
            "branch {b} ({from}): the inverse plan has {count} branches, 0 to {}",
            count - 1
        )));
    }
    let scale = pkm_runtime::kinematics::model_scale(model);
    let sigma = |pose: &[f64], b: usize| -> Option<f64> {
        let s = pkm_runtime::plan::run(model, plan, pose, &signs_of(b, plan.branches)).ok()?;
        let loops = pkm_runtime::velocity::loops(model, &s.model_values(model)).ok()?;
        Some(loops.passive_sigma(scale))
    };
    // Equal conditionings (branches that differ by a leg's sense) within
    // rounding: the first.
    let better = |s: f64, than: f64| s > than * (1.0 + 1e-9);
    // The best-conditioned (branch, σ) at a pose, on the wanted branch or any.
    let best = |pose: &[f64]| -> Option<(usize, f64)> {
        let branches: Vec<usize> = match wanted {
            Some((b, _)) => vec![b],
            None => (0..count).collect(),
        };
        branches
            .into_iter()
            .filter_map(|b| sigma(pose, b).map(|s| (b, s)))
            .fold(None, |acc: Option<(usize, f64)>, x| match acc {
                Some(a) if !better(x.1, a.1) => Some(a),
                _ => Some(x),
            })
    };
    let (pose, pose_from, preferred) = if let Some(pose) = study_pose.filter(|_| o.pose.is_empty()) {
        // There, the best-conditioned branch, as at the outputs' home.
        (
            pose.to_vec(),
            "the study's `pose`".to_string(),
            best(pose).map(|(b, _)| b),
        )
    } else if o.pose.is_empty() {
        let home = vec![0.0; outputs.len()];
        match best(&home).filter(|(_, s)| *s > pkm_runtime::velocity::SINGULAR) {
            Some((b, _)) => (home, "the outputs' home (every output 0)".to_string(), Some(b)),
            None => {
                // One output moved at a time: the platform's height over
                // (0, R] if an output is one, else each output over (−R, R]
                // (an angle over (−π, π]); R the mechanism's reach.
                let reach = pkm_runtime::kinematics::model_reach(model);
                let moved: Vec<(usize, f64, f64)> = match height_output(l) {
                    Some(z) => vec![(z, 0.0, reach)],
                    None => outputs
                        .iter()
                        .enumerate()
                        .map(|(i, (_, angle))| {
                            let r = if *angle { std::f64::consts::PI } else { reach };
                            (i, -r, r)
                        })
                        .collect(),
                };
                let mut found: Option<(usize, f64, f64)> = None;
                for &(i, low, high) in &moved {
                    for k in 1..=SCAN {
                        let mut pose = home.clone();
                        pose[i] = low + (high - low) * k as f64 / SCAN as f64;
                        // The wanted branch, or the first that assembles.
                        let first = match wanted {
                            Some((b, _)) => sigma(&pose, b),
                            None => (0..count).find_map(|b| sigma(&pose, b)),
                        };
                        if let Some(s) = first.filter(|&s| found.is_none_or(|f| better(s, f.2))) {
                            found = Some((i, pose[i], s));
                        }
                    }
                }
                let mut pose = home;
                // There, the best-conditioned branch.
                match found.and_then(|(i, v, _)| {
                    pose[i] = v;
                    best(&pose).map(|(b, _)| (i, b))
                }) {
                    Some((i, b)) => {
                        let why = format!(
                            "the outputs' home, where no branch is regular, with {} where the forward velocity map of the first branch that assembles is best conditioned{}",
                            outputs[i].0,
                            if moved.len() == 1 { " (the platform's height)" } else { " (each output tried)" }
                        );
                        (pose, why, Some(b))
                    }
                    None => (pose, "the outputs' home (every output 0)".to_string(), None),
                }
            }
        }
    } else {
        (ordered_pose(r, l, o.pose)?, "--pose".to_string(), None)
    };
    let pose_text = outputs
        .iter()
        .zip(&pose)
        .map(|((n, _), v)| format!("{n} = {}", num(*v)))
        .collect::<Vec<_>>()
        .join(", ");
    let at = format!("pose ({pose_text}) from {pose_from}");
    let pose_from = pose_from.as_str();
    let runs = pkm_runtime::plan::run_all(model, plan, &pose);
    // At the home pose without a branch asked for: the best-conditioned one.
    let wanted = wanted.or(preferred.map(|b| (b, "the best conditioned at the pose")));
    let (branch, signs, solution, branch_from) = assembled(runs, wanted, &at, "--pose")?;
    let given = inputs.iter().map(|&j| solution.values[j]).collect();
    let mut how = Map::new();
    how.insert("solver".into(), json!("ik"));
    let by_name: Map<String, Value> = outputs
        .iter()
        .zip(&pose)
        .map(|((n, angle), v)| (n.clone(), json!(r.shown_value(*v, *angle))))
        .collect();
    how.insert("pose".into(), Value::Object(by_name));
    let length = l
        .compiled
        .analysis
        .mass_and_loads
        .units
        .map_or("file unit", |u| u.length.symbol());
    let angle = if r.degrees { "deg" } else { "rad" };
    let units: Map<String, Value> = outputs
        .iter()
        .map(|(n, is_angle)| (n.clone(), json!(if *is_angle { angle } else { length })))
        .collect();
    how.insert("pose_units".into(), Value::Object(units));
    how.insert("pose_from".into(), json!(pose_from));
    Ok(Reference {
        inputs,
        given,
        inputs_from: "the inverse solution at the pose",
        branch,
        signs,
        branch_from,
        solution,
        how,
        at,
    })
}

/// Which declared output value is a platform's height (z of a spatial
/// pose or point output, or a pose part z), if one is.
fn height_output(l: &Loaded) -> Option<usize> {
    let mut at = 0;
    for (declared, o) in l.compiled.analysis.geometry.outputs.iter().zip(&l.outputs) {
        let z = match *o {
            Output::Pose { .. } | Output::Point { .. } if !l.model.planar => Some(2),
            Output::Parts { parts, .. } => parts.given().position(|p| p == 2),
            _ => None,
        };
        if let Some(z) = z.filter(|&z| z < declared.names.len()) {
            return Some(at + z);
        }
        at += declared.names.len();
    }
    None
}

/// The branch to export and its solution: the one asked for (by `--branch`,
/// the study or the best conditioned), else the first that assembles.
fn assembled(
    runs: Vec<Run>,
    wanted: Wanted,
    at: &str,
    flag: &str,
) -> Result<(usize, Vec<&'static str>, Solution, &'static str), Failure> {
    let count = runs.len();
    if let Some((b, from)) = wanted {
        let Some((signs, run)) = runs.into_iter().nth(b) else {
            return Err(Failure::input(format!(
                "branch {b} ({from}): the mechanism has {count} branches, 0 to {}",
                count.saturating_sub(1)
            )));
        };
        return match run {
            Ok(s) => Ok((b, sign_text(&signs), s, from)),
            Err(e) => Err(Failure::new(
                Kind::Unreachable,
                format!("branch {b} ({from}) does not assemble at the {at}: {e}"),
            )),
        };
    }
    let mut reasons = Vec::new();
    for (k, (signs, run)) in runs.into_iter().enumerate() {
        match run {
            Ok(s) => return Ok((k, sign_text(&signs), s, "the first that assembles")),
            Err(e) => reasons.push(format!("branch {k}: {e}")),
        }
    }
    Err(Failure::new(
        Kind::Unreachable,
        format!("no branch assembles at the {at} (give {flag}): {}", reasons.join("; ")),
    ))
}
