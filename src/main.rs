//! The `pkm` command line: analyses `.pkm` mechanism files.

use clap::{Parser, Subcommand};
use pkm::dsl::Analysis;
use serde_json::{json, Value};
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
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Analyze { file, json } => {
            let shown = file.display().to_string();
            let text = match std::fs::read_to_string(&file) {
                Ok(t) => t,
                Err(e) => {
                    eprintln!("error: cannot read `{shown}`: {e}");
                    return ExitCode::FAILURE;
                }
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
