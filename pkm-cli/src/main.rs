//! The `pkm` command line: analyses `.pkm` mechanism files.

mod cli;

use clap::{Parser, Subcommand};
use cli::failure::{answer, fail, write_out, Failure, Kind};
use cli::solve::Request;
use pkm_dsl::Analysis;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "pkm",
    version,
    about = "Topology and kinematics of parallel mechanisms (POC method)",
    after_help = "Exit codes: 0 success, 1 failure (the message names the cause), 2 usage error."
)]
struct Cli {
    /// Print one JSON object, on success and on failure (`{"error": {"kind", "message", …}}`); fk, ik and stiffness print a table without it.
    #[arg(long, global = true)]
    json: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Prints the topology report of a mechanism: POC sets, DOF, ξ_L, Δ, SKCs, κ; exits 1 if the file does not meet what its capabilities need, as the macro refuses it.
    Analyze {
        /// The mechanism file (.pkm).
        file: PathBuf,
    },
    /// Forward position solution, every branch, by the plan interpreter: a table (--json: JSON, --csv: many inputs).
    Fk {
        /// The mechanism file (.pkm), with parameters and geometry.
        file: PathBuf,
        /// Input values (actuated joints in declaration order): radians (degrees with --degrees) and lengths.
        #[arg(
            long,
            value_delimiter = ',',
            allow_hyphen_values = true,
            required_unless_present = "csv",
            conflicts_with = "csv"
        )]
        q: Vec<f64>,
        #[command(flatten)]
        many: Many,
        /// With --csv, a trajectory: start at the assembly of this pose (the outputs by name, as `pkm ik --pose`) and follow it row by row, each row the previous row's assembly continued (`tracked`: proven the same assembly mode; `resolved`: the certificate failed, the nearest of the full forward solution's; `possible`: not proven).
        #[arg(long, value_delimiter = ',', allow_hyphen_values = true, requires = "csv", value_parser = pkm_cli::report::parse_param)]
        follow_from: Vec<(String, f64)>,
        /// With --follow-from: the inverse branch the start pose is assembled on (as `pkm ik` numbers them; the first that solves if not given).
        #[arg(long, requires = "follow_from")]
        branch: Option<usize>,
        /// Override a parameter: `--param l1=120`.
        #[arg(long = "param", value_parser = pkm_cli::report::parse_param)]
        params: Vec<(String, f64)>,
        /// Angles in degrees: the revolute (R, Pa) values given to --q, and every revolute joint value and angular output printed.
        #[arg(long)]
        degrees: bool,
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
        options: Box<pkm_cli::report::ReportOptions>,
    },
    /// Inverse dynamics, every branch: the actuators' forces (N, N·length unit) and every joint's reaction, by Newton–Euler over the ordered SKCs.
    Dynamics {
        /// The mechanism file (.pkm), with parameters, geometry, units and masses.
        file: PathBuf,
        /// Input values (actuated joints in declaration order): radians (degrees with --degrees) and lengths.
        #[arg(
            long,
            value_delimiter = ',',
            allow_hyphen_values = true,
            required_unless_present_any = ["states", "csv"],
            conflicts_with = "csv"
        )]
        q: Vec<f64>,
        /// Many states from a file instead of --q/--rates/--accels: one a line, the inputs' values, rates and accelerations separated by commas; JSON streamed out, a state at a time.
        #[arg(long, conflicts_with_all = ["q", "rates", "accels", "csv"])]
        states: Option<PathBuf>,
        #[command(flatten)]
        many: Many,
        /// The inputs' rates (per second); zeros if not given.
        #[arg(long, value_delimiter = ',', allow_hyphen_values = true, conflicts_with = "csv")]
        rates: Vec<f64>,
        /// The inputs' accelerations (per second²); zeros if not given.
        #[arg(long, value_delimiter = ',', allow_hyphen_values = true, conflicts_with = "csv")]
        accels: Vec<f64>,
        /// Override a parameter: `--param l1=120`.
        #[arg(long = "param", value_parser = pkm_cli::report::parse_param)]
        params: Vec<(String, f64)>,
        /// Angles, angular rates and accelerations of revolute inputs in degrees.
        #[arg(long)]
        degrees: bool,
    },
    /// Writes a simulation model: `--mjcf`, MuJoCo's XML (bodies with masses and inertias, joints, loops closed by equality constraints, motors on the actuated joints).
    Export {
        /// The mechanism file (.pkm), with parameters, geometry, units and masses.
        file: PathBuf,
        /// MuJoCo's MJCF, the one format so far.
        #[arg(long, required = true)]
        mjcf: bool,
        /// The reference configuration's inputs (as for fk); default the study's start, else zeros (κ ≠ 0 without a forward solution: the outputs' home).
        #[arg(long, value_delimiter = ',', allow_hyphen_values = true, conflicts_with = "pose")]
        q: Vec<f64>,
        /// The reference configuration's outputs by name, solved by the inverse plan (as for ik): `--pose x=0,y=0,z=300,…`.
        #[arg(long, value_delimiter = ',', allow_hyphen_values = true, value_parser = pkm_cli::report::parse_param)]
        pose: Vec<(String, f64)>,
        /// The assembly branch, by index (as `branch` in a study; ik's numbering with --pose); default the study's, else the first that assembles.
        #[arg(long)]
        branch: Option<usize>,
        /// With fk_numeric (κ = 1), which of the branch's assemblies, from 0 in `pkm fk`'s order; default the first.
        #[arg(long)]
        assembly: Option<usize>,
        /// The inputs' rates at the reference (as for dynamics): the keyframe's qvel, and its ctrl the forces of that motion; default at rest.
        #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
        rates: Vec<f64>,
        /// The inputs' accelerations at the reference (as for dynamics), which the keyframe's ctrl gives; default zero.
        #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
        accels: Vec<f64>,
        /// The simulation timestep (s); the loops' constraints relax in two timesteps.
        #[arg(long, default_value_t = 0.001)]
        timestep: f64,
        /// Write the XML to this file, not to standard output.
        #[arg(long, short)]
        out: Option<PathBuf>,
        /// Override a parameter: `--param l1=120`.
        #[arg(long = "param", value_parser = pkm_cli::report::parse_param)]
        params: Vec<(String, f64)>,
        /// Reference inputs given to --q, and angular outputs to --pose, in degrees.
        #[arg(long)]
        degrees: bool,
    },
    /// Static stiffness at a pose, every branch: the limbs' actuation and constraint wrenches, K = Jᵀ K_p J at the platform's reference point, directional stiffnesses, and the deflection under --wrench; branches that are one assembly computed once.
    Stiffness {
        /// The mechanism file (.pkm), with parameters, geometry, outputs, units and limbs.
        file: PathBuf,
        /// The outputs by name, as for ik: `--pose ZA=75,alpha=0,beta=0`.
        #[arg(long, value_delimiter = ',', allow_hyphen_values = true, required_unless_present = "csv", conflicts_with = "csv", value_parser = pkm_cli::report::parse_param)]
        pose: Vec<(String, f64)>,
        #[command(flatten)]
        many: Many,
        /// A wrench on the platform: fx, fy, fz (N), mx, my, mz (N·length unit, about the reference point).
        #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
        wrench: Vec<f64>,
        /// Override a parameter: `--param l1=120`.
        #[arg(long = "param", value_parser = pkm_cli::report::parse_param)]
        params: Vec<(String, f64)>,
        /// Angular outputs given to --pose in degrees.
        #[arg(long)]
        degrees: bool,
    },
    /// Inverse position solution, every branch, by the plan interpreter: a table (--json: JSON, --csv: many poses).
    Ik {
        /// The mechanism file (.pkm), with parameters, geometry and outputs.
        file: PathBuf,
        /// The outputs by name: `--pose x=10,y=20,phi=0.2` (radians, degrees with --degrees, and lengths).
        #[arg(long, value_delimiter = ',', allow_hyphen_values = true, required_unless_present = "csv", conflicts_with = "csv", value_parser = pkm_cli::report::parse_param)]
        pose: Vec<(String, f64)>,
        #[command(flatten)]
        many: Many,
        /// Override a parameter: `--param l1=120`.
        #[arg(long = "param", value_parser = pkm_cli::report::parse_param)]
        params: Vec<(String, f64)>,
        /// Angles in degrees: the angular outputs given to --pose, and every revolute joint value and angular output printed.
        #[arg(long)]
        degrees: bool,
    },
}

/// Many inputs from a CSV file, every branch of each as CSV (README, "Many inputs").
#[derive(clap::Args)]
struct Many {
    /// Read the inputs from this CSV file (`-`: standard input): a header row naming them (fk: the actuated joints; ik, stiffness: the outputs; dynamics: the actuated joints, then `NAME rate` and `NAME accel` for each), then one input a row; write every branch of every row as CSV.
    #[arg(long)]
    csv: Option<PathBuf>,
    /// With --csv: write the CSV to this file, not to standard output.
    #[arg(long, short, requires = "csv")]
    out: Option<PathBuf>,
}

/// A mechanism file's text and its path as shown in messages.
fn read(file: &Path) -> Result<(String, String), Failure> {
    let shown = file.display().to_string();
    let io = |e: std::io::Error| Failure::new(Kind::Io, format!("cannot read `{shown}`: {e}"));
    // The size limit before the read: a huge file is refused, not loaded.
    let limit = pkm_dsl::limits::MAX_FILE_BYTES;
    let size = std::fs::metadata(file).map_err(io)?.len();
    if size > limit as u64 {
        return Err(Failure::input(format!(
            "`{shown}` is {size} bytes; the limit is {limit} bytes (pkm_dsl::limits::MAX_FILE_BYTES)"
        )));
    }
    std::fs::read_to_string(file)
        .map(|text| (text, shown.clone()))
        .map_err(io)
}

/// Reads a mechanism file and hands `then` the request on it, or prints
/// the failure to read it.
fn with_request(
    json: bool,
    file: &Path,
    params: &[(String, f64)],
    degrees: bool,
    then: impl FnOnce(&Request) -> ExitCode,
) -> ExitCode {
    let (source, shown) = match read(file) {
        Ok(t) => t,
        Err(f) => return fail(json, &f),
    };
    then(&Request {
        source: &source,
        file: &shown,
        params,
        degrees,
    })
}

/// A command of many inputs: prepares its solver on the file, then answers
/// at the one input given (`one`: a table, or JSON with `--json`, each
/// ending in a newline) or at
/// every row of `--csv` (CSV).
fn solve_many<'r, S: cli::csv::Solver>(
    json: bool,
    request: &'r Request<'r>,
    many: &Many,
    prepare: impl FnOnce(&'r Request<'r>) -> Result<S, Failure>,
    one: impl FnOnce(&S) -> Result<String, Failure>,
) -> ExitCode {
    let solver = match prepare(request) {
        Ok(s) => s,
        Err(f) => return fail(json, &f),
    };
    let done = match &many.csv {
        Some(inputs) => cli::csv::run(&solver, inputs, many.out.as_deref()).map(|()| ExitCode::SUCCESS),
        None => one(&solver).map(|text| write_out(&text)),
    };
    done.unwrap_or_else(|f| fail(json, &f))
}

/// `--follow-from` without `--csv`, which clap refuses before this runs.
fn unreachable_follow() -> Result<String, Failure> {
    Err(Failure::input(
        "--follow-from needs --csv: the trajectory's inputs, one a row".to_string(),
    ))
}

/// `pkm analyze`: the topology report, once the file meets what its
/// capabilities need, as the macro checks it (`pkm_dsl::check_capabilities`
/// and the position plans the capabilities ask for).
fn analyze(json: bool, file: &Path) -> ExitCode {
    let (text, shown) = match read(file) {
        Ok(t) => t,
        Err(f) => return fail(json, &f),
    };
    let compiled = match pkm_dsl::compile(&text) {
        Ok(c) => c,
        Err(d) => return fail(json, &Failure::parse(&d, &text, &shown)),
    };
    if let Err(d) = capabilities_met(&compiled) {
        return fail(json, &Failure::parse(&d, &text, &shown));
    }
    let a = &compiled.analysis;
    let special = compiled
        .model()
        .ok()
        .and_then(|model| pkm_dsl::lowering::mobility::special_mobility(a, model));
    if json {
        let mut value = to_json(a);
        if let (Some(s), Some(map)) = (&special, value.as_object_mut()) {
            map.insert(
                "special_geometry".into(),
                json!({
                    "generic_dof": s.generic,
                    "declared_dof": s.declared,
                    "loop_rank": s.rank[0],
                    "generic_loop_rank": s.rank[1],
                    "followed": a.mechanism.joints[s.followed].name,
                    "steps": s.steps,
                    "finite": s.finite(),
                }),
            );
        }
        // The analysis's JSON stays indented, as it always was.
        write_out(&format!(
            "{}\n",
            serde_json::to_string_pretty(&value).unwrap_or_default()
        ))
    } else {
        let mut report = a.report();
        if let Some(s) = &special {
            report += &special_text(a, s);
        }
        write_out(&report)
    }
}

/// The report's paragraph on mobility from special geometry.
fn special_text(a: &Analysis, s: &pkm_dsl::lowering::mobility::SpecialMobility) -> String {
    use pkm_dsl::lowering::mobility::{FOLLOW_STEP, FOLLOW_STEPS};
    let joint = &a.mechanism.joints[s.followed].name;
    let [rank, generic_rank] = s.rank;
    let followed = if s.finite() {
        format!(
            "the motion was followed through {FOLLOW_STEPS} steps of {FOLLOW_STEP} rad (or sizes) of {joint}, \
             the rank staying {rank}: the declared mechanism moves with {} DOF, not F = {}, by its special \
             geometry (its dimensions meet a condition the declared axis relations do not state)",
            s.declared, s.generic
        )
    } else {
        format!(
            "the lower rank held for {} of {FOLLOW_STEPS} steps of {joint}: a shaky configuration, not a \
             finite motion, so F = {} stands",
            s.steps, s.generic
        )
    };
    format!(
        "\nspecial geometry: at an assembly of the declared dimensions the loops' rank is {rank}, where generic \
         instances of the declared axis relations give {generic_rank}; {followed}. The plans and solvers use \
         the topology's F; declare `mobility by geometry;` to count the topology at these dimensions.\n"
    )
}

/// What `pkm::mechanism!` refuses besides the analysis: a capability whose
/// needs the file does not meet, and for `fk` or `ik` with a geometry, a
/// position plan that does not exist.
fn capabilities_met(c: &pkm_dsl::Compiled) -> Result<(), pkm_dsl::Diagnostics> {
    use pkm_dsl::mechanism::Capability;
    let checks = pkm_dsl::check_capabilities(&c.analysis);
    if !checks.is_empty() {
        return Err(checks);
    }
    let m = &c.analysis.mechanism;
    if c.analysis.geometry.complete {
        if m.wants(Capability::Fk) {
            c.forward()?;
        }
        if m.wants(Capability::Ik) {
            c.inverse()?;
        }
    }
    Ok(())
}

/// `pkm dynamics --states`: every state written as it is solved; the exit
/// code says whether any line was not a state (input), or no state had an
/// answer (unreachable), or reading stopped (io), after the list is out.
fn dynamics_states(json: bool, r: &Request, path: &Path) -> ExitCode {
    let mut out = std::io::stdout().lock();
    let (summary, interrupted) = match cli::dynamics::dynamics_states(r, path, &mut out, !json) {
        Ok(done) => done,
        Err(f) => return fail(json, &f),
    };
    let failure = interrupted.or_else(|| {
        if summary.malformed > 0 {
            Some(Failure::input(format!(
                "{} of {} lines are not states (their `error` says why)",
                summary.malformed, summary.states
            )))
        } else if summary.states > 0 && summary.answered == 0 {
            Some(Failure::new(
                Kind::Unreachable,
                format!(
                    "none of the {} states has an answer (each one's `error` says why)",
                    summary.states
                ),
            ))
        } else {
            None
        }
    });
    match failure {
        // The list is out: the failure goes to stderr only.
        Some(f) => {
            cli::failure::write_err(&format!("error: {}\n", f.message));
            ExitCode::from(f.kind.exit_code())
        }
        None => ExitCode::SUCCESS,
    }
}

/// `pkm export --mjcf`: the XML on stdout, or in `out` with its path
/// printed; with `--json` an object with the XML (or the path) and how the
/// model maps to the mechanism.
fn export(
    json: bool,
    file: &Path,
    params: &[(String, f64)],
    degrees: bool,
    options: &cli::export::Options,
    out: Option<&Path>,
) -> ExitCode {
    with_request(json, file, params, degrees, |request| {
        match cli::export::mjcf(request, options) {
            Ok(exported) => write_export(json, exported, out),
            Err(f) => fail(json, &f),
        }
    })
}

/// What `pkm export` writes: the XML or the object, to `out` or standard output.
fn write_export(json: bool, exported: cli::export::Exported, out: Option<&Path>) -> ExitCode {
    let mut info = exported.info;
    match out {
        Some(path) => {
            if let Err(e) = std::fs::write(path, &exported.xml) {
                let f = Failure::new(Kind::Io, format!("cannot write `{}`: {e}", path.display()));
                return fail(json, &f);
            }
            info.insert("file".into(), json!(path.display().to_string()));
            if json {
                answer(true, &Value::Object(info))
            } else {
                write_out(&format!("{}\n", path.display()))
            }
        }
        None if json => {
            info.insert("mjcf".into(), json!(exported.xml));
            answer(true, &Value::Object(info))
        }
        None => write_out(&exported.xml),
    }
}

/// A command line clap rejects: as clap prints it, or with `--json` as an
/// error object; exit code 2. Help and version print as usual.
fn usage(e: clap::Error) -> ExitCode {
    let wants_json = std::env::args_os().skip(1).any(|a| a == "--json");
    if !e.use_stderr() || !wants_json {
        e.exit();
    }
    // Clap's paragraph before the usage line, on one line.
    let text = e.render().to_string();
    let paragraph: Vec<&str> = text
        .lines()
        .take_while(|l| !l.trim().is_empty())
        .map(str::trim)
        .collect();
    let message = paragraph.join(" ");
    let message = message.strip_prefix("error: ").unwrap_or(&message);
    fail(true, &Failure::new(Kind::Usage, message))
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return usage(e),
    };
    let json = cli.json;
    match cli.command {
        Command::Ik {
            file,
            pose,
            many,
            params,
            degrees,
        } => with_request(json, &file, &params, degrees, |r| {
            solve_many(json, r, &many, cli::solve::Inverse::new, |s| s.answer(&pose, json))
        }),
        Command::Stiffness {
            file,
            pose,
            many,
            wrench,
            params,
            degrees,
        } => with_request(json, &file, &params, degrees, |r| {
            solve_many(
                json,
                r,
                &many,
                |r| cli::stiffness::Stiffness::new(r, &wrench),
                |s| s.answer(&pose, json),
            )
        }),
        Command::Fk {
            file,
            q,
            many,
            follow_from,
            branch,
            params,
            degrees,
        } => with_request(json, &file, &params, degrees, |r| {
            if follow_from.is_empty() {
                solve_many(json, r, &many, cli::solve::Forward::new, |s| s.answer(&q, json))
            } else {
                solve_many(
                    json,
                    r,
                    &many,
                    |r| cli::follow::Follow::new(r, &follow_from, branch),
                    |_| unreachable_follow(),
                )
            }
        }),
        Command::Dynamics {
            file,
            q,
            states,
            many,
            rates,
            accels,
            params,
            degrees,
        } => with_request(json, &file, &params, degrees, |r| match &states {
            Some(path) => dynamics_states(json, r, path),
            None => solve_many(json, r, &many, cli::dynamics::Dynamics::new, |s| {
                s.answer(&q, &rates, &accels, json)
            }),
        }),
        Command::Export {
            file,
            mjcf: _,
            q,
            pose,
            branch,
            assembly,
            rates,
            accels,
            timestep,
            out,
            params,
            degrees,
        } => {
            let options = cli::export::Options {
                q: &q,
                pose: &pose,
                branch,
                assembly,
                rates: &rates,
                accels: &accels,
                timestep,
            };
            export(json, &file, &params, degrees, &options, out.as_deref())
        }
        Command::Report { file, out, options } => {
            let (text, shown) = match read(&file) {
                Ok(t) => t,
                Err(f) => return fail(json, &f),
            };
            match pkm_cli::report::write_report(&text, &shown, &options, &out) {
                Ok(page) if json => answer(json, &json!({ "page": page })),
                Ok(page) => write_out(&format!("{}\n", page.display())),
                Err(pkm_cli::report::ReportError::Source { diagnostics, .. }) => {
                    fail(json, &Failure::parse(&diagnostics, &text, &shown))
                }
                Err(e) => fail(json, &Failure::new(Kind::Report, e.message())),
            }
        }
        Command::Analyze { file } => analyze(json, &file),
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
        .zip(&t.branch_own_poc)
        .map(|((b, p), own)| {
            let own = own
                .as_ref()
                .map(|(j, q)| json!({ "joint": m.joints[*j].name, "poc": q.unicode(), "dim": q.dim }));
            json!({ "name": b.name, "poc": p.unicode(), "dim": p.dim, "own": own })
        })
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
        "output_link": m.platform.is_none().then(|| m.output_link.map(|(l, _)| m.links[l].name.clone())).flatten(),
        "generic_dof": t.generic_dof,
        "parasitic": t.decoupling.iter().filter(|d| d.parasitic).map(|d| d.output.clone()).collect::<Vec<_>>(),
        "socs": socs,
        "skcs": skcs,
        "joints": joints,
        "branches": branches,
        "expression": t.expression,
        "expression_ascii": pkm_dsl::topology::to_ascii(&t.expression),
        "decoupling": decoupling,
        "cross_check": { "xi_poc_formula": t.xi_by_poc_formula, "xi_loop_rank": t.xi() },
    })
}
