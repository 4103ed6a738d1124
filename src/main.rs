//! The `pkm` command line: analyses `.pkm` mechanism files.

use clap::{Parser, Subcommand};
use pkm::dsl::Analysis;
use serde_json::{json, Value};
use std::collections::HashMap;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "pkm",
    version,
    about = "Topology and kinematics of parallel mechanisms (POC method)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Prints the topology report of a mechanism: POC sets, DOF, ξ_L, Δ, SKCs, κ.
    Analyze {
        /// The mechanism file (.pkm).
        file: PathBuf,
        /// Print one JSON object instead of the text report.
        #[arg(long)]
        json: bool,
    },
    /// Forward position solution, every branch, by the plan interpreter.
    Fk {
        /// The mechanism file (.pkm), with parameters and geometry.
        file: PathBuf,
        /// Input values (actuated joints in declaration order): radians and lengths.
        #[arg(long, value_delimiter = ',', allow_hyphen_values = true, required = true)]
        q: Vec<f64>,
        /// Override a parameter: `--param l1=120`.
        #[arg(long = "param", value_parser = pkm::report::parse_param)]
        params: Vec<(String, f64)>,
        /// Print one JSON object (the text form is the same JSON, indented).
        #[arg(long)]
        json: bool,
    },
    /// One HTML page: topology, position solutions, singularities, workspace, velocity and acceleration.
    Report {
        /// The mechanism file (.pkm), with parameters, geometry and outputs.
        file: PathBuf,
        /// The directory the page and its figures (PNG, SVG, CSV) go to.
        #[arg(long)]
        out: PathBuf,
        // Boxed: the options are many, the other commands' few.
        #[command(flatten)]
        options: Box<pkm::report::ReportOptions>,
    },
    /// Inverse position solution, every branch, by the plan interpreter.
    Ik {
        /// The mechanism file (.pkm), with parameters, geometry and outputs.
        file: PathBuf,
        /// The outputs by name: `--pose x=10,y=20,phi=0.2` (radians and lengths).
        #[arg(long, value_delimiter = ',', allow_hyphen_values = true, required = true, value_parser = parse_pose)]
        pose: Vec<(String, f64)>,
        /// Override a parameter: `--param l1=120`.
        #[arg(long = "param", value_parser = pkm::report::parse_param)]
        params: Vec<(String, f64)>,
        /// Print one JSON object (the text form is the same JSON, indented).
        #[arg(long)]
        json: bool,
    },
}

/// Reads a mechanism file, runs a solver on it, prints its JSON or its
/// diagnostics (on stderr, with a failure code).
fn solve(file: &PathBuf, run: impl FnOnce(&str) -> Result<Value, pkm::dsl::Diagnostics>) -> ExitCode {
    let (text, shown) = match read(file) {
        Ok(t) => t,
        Err(code) => return code,
    };
    match run(&text) {
        Ok(v) => {
            println!("{}", serde_json::to_string_pretty(&v).expect("JSON of plain values"));
            ExitCode::SUCCESS
        }
        Err(d) => {
            eprint!("{}", d.render(&text, &shown));
            ExitCode::FAILURE
        }
    }
}

fn parse_pose(s: &str) -> Result<(String, f64), String> {
    pkm::report::parse_param(s)
}

fn read(file: &PathBuf) -> Result<(String, String), ExitCode> {
    let shown = file.display().to_string();
    match std::fs::read_to_string(file) {
        Ok(t) => Ok((t, shown)),
        Err(e) => {
            eprintln!("error: cannot read `{shown}`: {e}");
            Err(ExitCode::FAILURE)
        }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Ik {
            file,
            pose,
            params,
            json: _,
        } => solve(&file, |text| ik(text, &pose, &params)),
        Command::Fk {
            file,
            q,
            params,
            json: _,
        } => solve(&file, |text| fk(text, &q, &params)),
        Command::Report { file, out, options } => {
            let (text, shown) = match read(&file) {
                Ok(t) => t,
                Err(code) => return code,
            };
            match pkm::report::write_report(&text, &shown, &options, &out) {
                Ok(page) => {
                    println!("{}", page.display());
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    // The error's text is complete: one `error:`, the file's path in it.
                    eprintln!("{e}");
                    ExitCode::FAILURE
                }
            }
        }
        Command::Analyze { file, json } => {
            let (text, shown) = match read(&file) {
                Ok(t) => t,
                Err(code) => return code,
            };
            match pkm::dsl::analyze_source(&text) {
                Ok(a) => {
                    if json {
                        println!(
                            "{}",
                            serde_json::to_string_pretty(&to_json(&a)).expect("JSON of plain values")
                        );
                    } else {
                        print!("{}", a.report());
                    }
                    ExitCode::SUCCESS
                }
                Err(d) => {
                    eprint!("{}", d.render(&text, &shown));
                    ExitCode::FAILURE
                }
            }
        }
    }
}

fn fk(text: &str, q: &[f64], params: &[(String, f64)]) -> Result<Value, pkm::dsl::Diagnostics> {
    use pkm::dsl::Diagnostic;
    let a = pkm::dsl::analyze_source(text)?;
    let values = params.iter().cloned().collect();
    let model = pkm::dsl::plan::model(&a, &values)?;
    if !model.planar {
        let plan = pkm::dsl::plan3::forward_plan(&a)?;
        if q.len() != plan.n_inputs {
            return Err(
                Diagnostic::global(format!("expected {} input values, found {}", plan.n_inputs, q.len())).into(),
            );
        }
        let branches = spatial_branches_json(&a, &model, &plan, q);
        return Ok(json!({ "name": model.name, "inputs": q, "branches": branches }));
    }
    let plan = pkm::dsl::plan::forward_plan(&a)?;
    if q.len() != plan.inputs.len() {
        let names: Vec<&str> = plan.inputs.iter().map(|&j| model.joints[j].name.as_str()).collect();
        return Err(Diagnostic::global(format!(
            "expected {} input values ({}), found {}",
            plan.inputs.len(),
            names.join(", "),
            q.len()
        ))
        .into());
    }
    let branches = branches_json(&model, &plan, q);
    Ok(json!({ "name": model.name, "inputs": q, "branches": branches }))
}

/// A solved branch as JSON needs: every joint value, every point (joints,
/// then named points) and, for spatial plans, the declared pose outputs.
struct Solved {
    values: Vec<f64>,
    points: Vec<[f64; 3]>,
    pose: Option<Value>,
}

/// One branch as JSON: signs, ok, and the reason, or the inputs `q`, every
/// joint value (`outputs`), every point, and `pose` where known.
fn branch_json(
    model: &pkm::runtime::model::Model,
    signs: &[pkm::runtime::primitives::Sign],
    result: Result<Solved, pkm::runtime::plan::SolveError>,
) -> Value {
    let signs: Vec<&str> = signs.iter().map(|s| if s.index() == 0 { "+" } else { "-" }).collect();
    match result {
        Ok(sol) => {
            let outputs: serde_json::Map<String, Value> = model
                .joints
                .iter()
                .zip(&sol.values)
                .map(|(j, v)| (j.name.clone(), json!(v)))
                .collect();
            let names = model
                .joints
                .iter()
                .map(|j| &j.name)
                .chain(model.points.iter().map(|p| &p.name));
            let points: serde_json::Map<String, Value> =
                names.zip(&sol.points).map(|(n, p)| (n.clone(), json!(p))).collect();
            let q: Vec<f64> = model.inputs().iter().map(|&j| sol.values[j]).collect();
            let mut out = json!({ "signs": signs, "ok": true, "q": q, "outputs": outputs, "points": points });
            if let Some(pose) = sol.pose {
                out["pose"] = pose;
            }
            out
        }
        Err(e) => json!({ "signs": signs, "ok": false, "reason": e.to_string() }),
    }
}

/// Every branch of a planar plan as JSON (see [`branch_json`]; z = 0).
fn branches_json(model: &pkm::runtime::model::Model, plan: &pkm::runtime::plan::Plan, given: &[f64]) -> Vec<Value> {
    pkm::runtime::plan::run_all(model, plan, given)
        .into_iter()
        .map(|(signs, result)| {
            let solved = result.map(|sol| {
                let joints = (0..model.joints.len()).map(|j| pkm::runtime::plan::joint_point(model, &sol.poses, j));
                let named = model.points.iter().map(|p| sol.poses[p.link].apply([p.at[0], p.at[1]]));
                Solved {
                    points: joints.chain(named).map(|w| [w[0], w[1], 0.0]).collect(),
                    values: sol.values,
                    pose: None,
                }
            });
            branch_json(model, &signs, solved)
        })
        .collect()
}

/// Every branch of a spatial plan as JSON (see [`branch_json`]), with the
/// declared pose outputs (`pose`: name → value) of each solution.
fn spatial_branches_json(
    a: &Analysis,
    model: &pkm::runtime::model::Model,
    plan: &pkm::runtime::spatial::Plan,
    given: &[f64],
) -> Vec<Value> {
    use pkm::runtime::spatial;
    spatial::run_all(model, plan, given)
        .into_iter()
        .map(|(signs, result)| {
            let solved = result.map(|sol| {
                let joints = (0..model.joints.len()).map(|j| pkm::runtime::newton::joint_point(model, &sol.poses, j));
                let named = model.points.iter().map(|p| spatial::at(&sol.poses[p.link], p.at));
                Solved {
                    points: joints.chain(named).collect(),
                    pose: Some(pose_outputs(a, model, &sol.poses)),
                    values: sol.values,
                }
            });
            branch_json(model, &signs, solved)
        })
        .collect()
}

/// The declared outputs of a spatial solution: a pose's point and its angle
/// about the declared axis; a joint's value.
fn pose_outputs(a: &Analysis, model: &pkm::runtime::model::Model, poses: &[pkm::runtime::spatial::Pose3]) -> Value {
    use pkm::dsl::geometry::OutputKind;
    use pkm::runtime::spatial;
    let nominal = a.geometry.nominal();
    let mut out = serde_json::Map::new();
    for o in &a.geometry.outputs {
        let values: Vec<f64> = match &o.kind {
            OutputKind::Pose { link, point, .. } | OutputKind::Point { link, point } => {
                let about = match &o.kind {
                    OutputKind::Pose { about, .. } => about.as_deref(),
                    _ => None,
                };
                let local = spatial::local_point(model, *point, *link).unwrap_or([f64::NAN; 3]);
                let mut v = spatial::at(&poses[*link], local).to_vec();
                if let Some(k) = about {
                    let k = pkm::dsl::geometry::eval_vec3(k, &nominal);
                    v.push(spatial::angle_about(&poses[*link], k));
                }
                v
            }
            OutputKind::Joint(j) => {
                let joint = &model.joints[*j];
                vec![spatial::joint_value(
                    &spatial::Joint3::of(joint),
                    &poses[joint.links[0]],
                    &poses[joint.links[1]],
                )]
            }
        };
        for (n, v) in o.names.iter().zip(values) {
            out.insert(n.clone(), json!(v));
        }
    }
    Value::Object(out)
}

fn ik(text: &str, pose: &[(String, f64)], params: &[(String, f64)]) -> Result<Value, pkm::dsl::Diagnostics> {
    use pkm::dsl::Diagnostic;
    let a = pkm::dsl::analyze_source(text)?;
    let values = params.iter().cloned().collect();
    let model = pkm::dsl::plan::model(&a, &values)?;
    // Planar plans and spatial plans (the latter in `Err`).
    let plan = if model.planar {
        Ok(pkm::dsl::plan::inverse_plan(&a)?)
    } else {
        Err(pkm::dsl::plan3::inverse_plan(&a)?)
    };
    let names: Vec<&str> = a
        .geometry
        .outputs
        .iter()
        .flat_map(|o| o.names.iter().map(String::as_str))
        .collect();
    let given: HashMap<&str, f64> = pose.iter().map(|(k, v)| (k.as_str(), *v)).collect();
    if let Some(extra) = pose.iter().find(|(k, _)| !names.contains(&k.as_str())) {
        return Err(Diagnostic::global(format!(
            "unknown output `{}`; the outputs are {}",
            extra.0,
            names.join(", ")
        ))
        .into());
    }
    let mut ordered = Vec::new();
    for n in &names {
        match given.get(n) {
            Some(v) => ordered.push(*v),
            None => return Err(Diagnostic::global(format!("missing output `{n}`; give {}", names.join(", "))).into()),
        }
    }
    let branches = match &plan {
        Ok(plan) => branches_json(&model, plan, &ordered),
        Err(plan) => spatial_branches_json(&a, &model, plan, &ordered),
    };
    Ok(json!({ "name": model.name, "pose": given, "branches": branches }))
}

fn to_json(a: &Analysis) -> Value {
    let m = &a.mechanism;
    let t = &a.topology;
    let socs: Vec<Value> = t
        .socs
        .iter()
        .map(|s| {
            json!({
                "joints": a.names(&s.joints),
                "notation": s.notation,
                "ends": [m.links[s.ends[0]].name, m.links[s.ends[1]].name],
                "f": s.dof,
                "actuators": s.actuators,
                "xi": s.xi,
                "delta": s.delta,
            })
        })
        .collect();
    let skcs: Vec<Value> = t
        .skcs
        .iter()
        .map(|k| json!({ "socs": k.socs.clone().collect::<Vec<_>>(), "kappa": k.kappa, "poc": k.kind }))
        .collect();
    let joints: Vec<Value> = m
        .joints
        .iter()
        .zip(&t.joint_poc)
        .map(|(j, p)| json!({ "name": j.name, "type": j.kind.symbol(), "f": j.kind.dof(), "actuated": j.actuated, "poc": p.unicode() }))
        .collect();
    let branches: Vec<Value> = m
        .branches
        .iter()
        .zip(&t.branch_poc)
        .map(|(b, p)| json!({ "name": b.name, "poc": p.unicode(), "dim": p.dim }))
        .collect();
    let decoupling: serde_json::Map<String, Value> = t
        .decoupling
        .iter()
        .map(|d| (d.output.clone(), json!(a.names(&d.inputs))))
        .collect();
    json!({
        "name": m.name,
        "title": m.title,
        "dof": t.dof,
        "total_f": t.total_f,
        "loops": t.loops,
        "xi": t.xi(),
        "delta": t.delta(),
        "kappa": t.kappa,
        "skc_count": t.skcs.len(),
        "platform_poc": a.platform_poc(),
        "platform_poc_ascii": t.platform_poc.as_ref().map(|p| p.ascii()),
        "base_point": t.base_point.map(|j| m.joints[j].name.clone()),
        "socs": socs,
        "skcs": skcs,
        "joints": joints,
        "branches": branches,
        "expression": t.expression,
        "expression_ascii": pkm::dsl::topology::to_ascii(&t.expression),
        "decoupling": decoupling,
        "cross_check": { "xi_poc_formula": t.xi_by_poc_formula, "xi_loop_rank": t.xi() },
    })
}
