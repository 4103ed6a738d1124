//! `pkm fk` and `pkm ik`: the values given are checked before solving, every
//! branch of the plan comes out by its number, as a table (every 1-DOF
//! joint's value and every declared output, `table`), as JSON by name
//! (`joints`, `inputs`, `outputs`, `points`) or, one input a row, as CSV
//! (`csv`); when no branch solves the failure names the causes.

use super::failure::{Failure, Kind};
use super::table::{self, Branch, Cell, Column};
use pkm_dsl::{Compiled, Diagnostics, InstanceError};
use pkm_runtime::ball_legs::BallLegs;
use pkm_runtime::fk_numeric::RootKind;
use pkm_runtime::interval::Interval;
use pkm_runtime::model::{JointType, Model};
use pkm_runtime::newton::Output;
use pkm_runtime::plan::{Plan, Pose3};
use pkm_runtime::primitives::Sign;
use pkm_runtime::solution::SolveError;
use serde_json::{json, Map, Value};
use std::collections::HashMap;

/// What fk and ik share: the file, the parameter overrides, the angle unit.
pub struct Request<'a> {
    /// The mechanism file's text.
    pub source: &'a str,
    /// The file's path as the user gave it (for diagnostics).
    pub file: &'a str,
    /// `--param name=value`, in the order given.
    pub params: &'a [(String, f64)],
    /// `--degrees`: angles given and printed in degrees.
    pub degrees: bool,
}

impl Request<'_> {
    pub(super) fn parse_failure(&self, d: Diagnostics) -> Failure {
        Failure::parse(&d, self.source, self.file)
    }

    /// A value given on the command line as the solver takes it: radians for an angle.
    pub(super) fn solver_value(&self, v: f64, angular: bool) -> f64 {
        if self.degrees && angular {
            v.to_radians()
        } else {
            v
        }
    }

    /// A value for the JSON, in degrees if it is an angle and degrees were asked for.
    pub(super) fn shown_value(&self, v: f64, angular: bool) -> f64 {
        if self.degrees && angular {
            v.to_degrees()
        } else {
            v
        }
    }
}

/// A mechanism ready to solve: compiled (its analysis, and its plans on
/// first use), its model at the given parameters and its declared outputs
/// at those parameters.
pub(super) struct Loaded {
    pub(super) compiled: Compiled,
    pub(super) model: Model,
    pub(super) outputs: Vec<Output>,
    /// The parameters the command line overrides.
    pub(super) values: HashMap<String, f64>,
}

pub(super) fn load(r: &Request) -> Result<Loaded, Failure> {
    let compiled = pkm_dsl::compile(r.source).map_err(|d| r.parse_failure(d))?;
    let instance = compiled.instance(r.params).map_err(|e| match e {
        InstanceError::Source(d) => r.parse_failure(d),
        InstanceError::Param(e) => Failure::input(e.to_string()),
        InstanceError::Dimension(why) => Failure::input(why),
    })?;
    Ok(Loaded {
        compiled,
        model: instance.model,
        outputs: instance.outputs,
        values: instance.overrides,
    })
}

/// A branch's signs as the JSON writes them: `"+"` or `"-"` per choice.
pub(super) fn sign_text(signs: &[Sign]) -> Vec<&'static str> {
    signs.iter().map(|s| if s.index() == 0 { "+" } else { "-" }).collect()
}

/// An error unless `v` is a number: `what` names the value.
pub(super) fn finite(what: &str, v: f64) -> Result<(), Failure> {
    if v.is_nan() {
        Err(Failure::input(format!("{what} is NaN")))
    } else if v.is_infinite() {
        Err(Failure::input(format!("{what} = {v} is not finite")))
    } else {
        Ok(())
    }
}

/// Whether a joint's value is an angle.
pub(super) fn angular(kind: JointType) -> bool {
    matches!(kind, JointType::R | JointType::Pa)
}

/// One solution: link poses and joint values.
pub(super) struct Configuration {
    pub(super) poses: Vec<Pose3>,
    pub(super) values: Vec<f64>,
}

impl Configuration {
    /// The world position of `local`, a point of `link`.
    fn point(&self, link: usize, local: [f64; 3]) -> [f64; 3] {
        pkm_runtime::plan::at(&self.poses[link], local)
    }

    fn joint_point(&self, model: &Model, j: usize) -> [f64; 3] {
        pkm_runtime::newton::joint_point(model, &self.poses, j)
    }
}

/// Signs of one branch and its configuration or why it has none.
type Run = (Vec<Sign>, Result<Configuration, SolveError>);

/// Every branch of `plan` at the values `given`, with its link poses.
fn run_all(plan: &Plan, model: &Model, given: &[f64]) -> Vec<Run> {
    pkm_runtime::plan::run_all(model, plan, given)
        .into_iter()
        .map(|(signs, r)| {
            let c = r.map(|s| Configuration {
                poses: s.poses,
                values: s.values,
            });
            (signs, c)
        })
        .collect()
}

/// The kind of a branch's failure.
fn kind_of(e: &SolveError) -> Kind {
    match e {
        SolveError::Unreachable { .. } | SolveError::Degenerate { .. } | SolveError::DoubleRoot { .. } => {
            Kind::Unreachable
        }
        SolveError::BadInput { .. } => Kind::Input,
        SolveError::Inconsistent { .. } => Kind::Inconsistent,
    }
}

/// The declared outputs' names in order, each with whether it is an angle
/// (a pose's angle, a revolute joint's value).
pub(super) fn output_names(l: &Loaded) -> Vec<(String, bool)> {
    let mut names = Vec::new();
    for (o, spec) in l.compiled.analysis.geometry.outputs.iter().zip(&l.outputs) {
        let n = o.names.len();
        for (i, name) in o.names.iter().enumerate() {
            let angle = match *spec {
                Output::Pose { about, .. } => about.is_some() && i + 1 == n,
                Output::Point { .. } => false,
                Output::Parts { parts, .. } => parts.given().nth(i).is_some_and(|p| p >= 3),
                Output::Joint(j) => angular(l.model.joints[j].kind),
            };
            names.push((name.clone(), angle));
        }
    }
    names
}

/// The declared outputs' values (radians) in one configuration, in the
/// order of [`output_names`].
pub(super) fn output_values(l: &Loaded, c: &Configuration) -> Vec<f64> {
    let mut values = Vec::new();
    for (o, spec) in l.compiled.analysis.geometry.outputs.iter().zip(&l.outputs) {
        // One value per declared name, whatever the declaration's shape.
        let these = pkm_runtime::plan::output_values(&c.poses, &c.values, l.model.planar, spec);
        values.extend(these.into_iter().chain(std::iter::repeat(f64::NAN)).take(o.names.len()));
    }
    values
}

/// A solved branch by name (radians): joint values (1-DOF joints), the
/// actuated ones, the declared outputs, every joint's and named point's position.
struct Solved {
    joints: Vec<(String, f64, bool)>,
    inputs: Vec<(String, f64, bool)>,
    outputs: Vec<(String, f64, bool)>,
    points: Vec<(String, [f64; 3])>,
    /// A double root: another branch is this solution again.
    tangent: bool,
}

fn solved(l: &Loaded, c: &Configuration) -> Solved {
    let m = &l.model;
    // A spherical joint has three values, not one: it is left out of `joints`.
    let value = |j: usize| (m.joints[j].name.clone(), c.values[j], angular(m.joints[j].kind));
    let joint_points = (0..m.joints.len()).map(|j| (m.joints[j].name.clone(), c.joint_point(m, j)));
    let named_points = m.points.iter().map(|p| (p.name.clone(), c.point(p.link, p.at)));
    Solved {
        joints: one_dof_joints(m).into_iter().map(value).collect(),
        inputs: m.inputs().into_iter().filter(|&j| one_dof(m, j)).map(value).collect(),
        outputs: output_names(l)
            .into_iter()
            .zip(output_values(l, c))
            .map(|((n, angle), v)| (n, v, angle))
            .collect(),
        points: joint_points.chain(named_points).collect(),
        tangent: false,
    }
}

/// Whether joint `j` has one value (a spherical joint has three).
fn one_dof(m: &Model, j: usize) -> bool {
    m.joints[j].kind != JointType::S
}

/// The joints a solution gives one value each, in declaration order.
fn one_dof_joints(m: &Model) -> Vec<usize> {
    (0..m.joints.len()).filter(|&j| one_dof(m, j)).collect()
}

/// Why a solution may not be marked ok although the plan returned it: a
/// value that is not a number.
fn non_finite(s: &Solved) -> Option<String> {
    let scalar = |group: &str, list: &[(String, f64, bool)]| {
        list.iter()
            .find(|(_, v, _)| !v.is_finite())
            .map(|(n, v, _)| format!("the solution's {group} {n} is {v}"))
    };
    scalar("joint", &s.joints)
        .or_else(|| scalar("output", &s.outputs))
        .or_else(|| {
            s.points
                .iter()
                .find(|(_, p)| p.iter().any(|v| !v.is_finite()))
                .map(|(n, p)| format!("the solution's point {n} is {p:?}"))
        })
}

/// A branch's verdict: solved, or the kind and reason of its failure.
type Verdict = Result<Solved, (Kind, String)>;

/// One branch at one input: its number in the plan (bit k set when choice
/// k is `-`), its signs, its verdict, and for `fk_numeric` the virtual
/// variable's value.
struct Found {
    number: usize,
    signs: Vec<Sign>,
    verdict: Verdict,
    virtual_value: Option<f64>,
    /// `fk_numeric`: whether the root is proven, and its interval of the
    /// virtual variable.
    certificate: Option<(RootKind, Interval)>,
    /// By the pose equations: the real root's number and its certificate.
    pose: Option<PoseFound>,
}

/// An assembly's real root of the pose equations ([`pkm_runtime::ball_legs`]).
#[derive(Clone, Copy)]
struct PoseFound {
    /// Its number among the real roots, from 0.
    root: usize,
    /// The box of `(p / size, q)` proven to hold it alone; `None`: possible.
    cert: Option<[Interval; 7]>,
    /// The size `p` is over.
    scale: f64,
}

/// Judges every branch: the plan's error (the runtime verifies what it
/// returns: open joints close, an over-determined pose names the output
/// the others contradict, by its name from `given_names`) or a non-finite
/// value.
fn verdicts(l: &Loaded, runs: Vec<Run>, given_names: &[&str]) -> Vec<Found> {
    // A branch another one names as its twin met a double root.
    let twins: Vec<usize> = runs
        .iter()
        .filter_map(|(_, r)| match r {
            Err(SolveError::DoubleRoot { twin }) => Some(*twin),
            _ => None,
        })
        .collect();
    runs.into_iter()
        .enumerate()
        .map(|(i, (signs, result))| {
            let verdict = result
                .map_err(|e| {
                    let e = pkm_runtime::consistency::name_given(e, given_names);
                    (kind_of(&e), e.to_string())
                })
                .and_then(|c| {
                    let s = Solved {
                        tangent: twins.contains(&i),
                        ..solved(l, &c)
                    };
                    match non_finite(&s) {
                        Some(why) => Err((Kind::Unreachable, why)),
                        None => Ok(s),
                    }
                });
            Found {
                number: table::number_of(&signs),
                signs,
                verdict,
                virtual_value: None,
                certificate: None,
                pose: None,
            }
        })
        .collect()
}

/// The failure of an input at which no branch solves: the distinct
/// reasons of the branches, the gravest kind among them.
fn none_solves(found: &[Found]) -> Option<Failure> {
    if found.iter().any(|f| f.verdict.is_ok()) {
        return None;
    }
    let failures = found.iter().filter_map(|f| f.verdict.as_ref().err());
    let kind = failures.clone().map(|(k, _)| *k).max().unwrap_or(Kind::Unreachable);
    let mut reasons: Vec<&str> = Vec::new();
    for (_, why) in failures {
        if !reasons.contains(&why.as_str()) {
            reasons.push(why);
        }
    }
    let why = if reasons.is_empty() {
        "the plan has no branch".to_string()
    } else {
        reasons.join("; ")
    };
    Some(Failure::new(kind, format!("no branch reaches: {why}")))
}

/// Every branch as JSON (`fk_numeric`'s with the virtual variable's value
/// under `virtual_name`).
fn branches_json(r: &Request, found: &[Found], virtual_name: Option<(&str, bool)>) -> Vec<Value> {
    let named = |list: &[(String, f64, bool)]| -> Map<String, Value> {
        list.iter()
            .map(|(n, v, angle)| (n.clone(), json!(r.shown_value(*v, *angle))))
            .collect()
    };
    found
        .iter()
        .map(|f| {
            let signs = sign_text(&f.signs);
            let mut b = match &f.verdict {
                Ok(s) => {
                    let points: Map<String, Value> = s.points.iter().map(|(n, p)| (n.clone(), json!(p))).collect();
                    json!({
                        "branch": f.number,
                        "signs": signs,
                        "ok": true,
                        "tangent": s.tangent,
                        "joints": named(&s.joints),
                        "inputs": named(&s.inputs),
                        "outputs": named(&s.outputs),
                        "points": points,
                    })
                }
                Err((_, why)) => json!({ "branch": f.number, "signs": signs, "ok": false, "reason": why }),
            };
            if let Some(pf) = f.pose {
                b["assembly"] = json!(pf.root);
                b["certificate"] = match pf.cert {
                    Some(c) => {
                        let p: Vec<[f64; 2]> = c[..3].iter().map(|i| [i.lo * pf.scale, i.hi * pf.scale]).collect();
                        let q: Vec<[f64; 2]> = c[3..].iter().map(|i| [i.lo, i.hi]).collect();
                        json!({ "status": "certified", "platform_origin": p, "platform_quaternion": q })
                    }
                    None => json!({ "status": "possible", "why": POSE_DOUBT }),
                };
            }
            if let (Some((name, angle)), Some(v)) = (virtual_name, f.virtual_value) {
                b["virtual"] = json!({ name: r.shown_value(v, angle) });
                if let Some((kind, cert)) = f.certificate {
                    let interval = [r.shown_value(cert.lo, angle), r.shown_value(cert.hi, angle)];
                    b["certificate"] = match kind {
                        RootKind::Certified => json!({ "status": "certified", name: interval }),
                        RootKind::Possible(d) => json!({ "status": "possible", "why": d.text(), name: interval }),
                    };
                }
            }
            b
        })
        .collect()
}

/// The columns of a position solution's rows: every 1-DOF joint's value,
/// every declared output, whether a step met a double root; with
/// `fk_numeric` (`certified`), whether each root is proven.
fn position_columns(r: &Request, l: &Loaded, certified: bool) -> Vec<Column> {
    let units = Units::of(r, l);
    let m = &l.model;
    let joints = one_dof_joints(m)
        .into_iter()
        .map(|j| Column::new(&m.joints[j].name, units.of_kind(angular(m.joints[j].kind))));
    let outputs = output_names(l)
        .into_iter()
        .map(|(n, angle)| Column::new(n, units.of_kind(angle)));
    let status = certified.then(|| Column::bare("root"));
    joints
        .chain(outputs)
        .chain([Column::bare("tangent")])
        .chain(status)
        .collect()
}

/// Every branch as rows of [`position_columns`].
fn position_rows(r: &Request, found: &[Found]) -> Vec<Branch> {
    let cells = |list: &[(String, f64, bool)]| {
        list.iter()
            .map(|(_, v, angle)| Cell::Num(r.shown_value(*v, *angle)))
            .collect::<Vec<_>>()
    };
    found
        .iter()
        .map(|f| Branch {
            number: f.number,
            signs: f.signs.clone(),
            values: match &f.verdict {
                Ok(s) => {
                    let status = f
                        .certificate
                        .map(|(kind, _)| kind.certified())
                        .or(f.pose.map(|p| p.cert.is_some()))
                        .map(|proven| Cell::Text(if proven { "certified" } else { "possible" }.into()));
                    Ok([
                        cells(&s.joints),
                        cells(&s.outputs),
                        vec![Cell::Flag(s.tangent)],
                        status.into_iter().collect(),
                    ]
                    .concat())
                }
                Err((_, why)) => Err(why.clone()),
            },
        })
        .collect()
}

/// The units a command prints in: lengths in the file's unit (its `units`
/// block), else "file unit"; angles in rad, or deg with `--degrees`.
pub(super) struct Units {
    /// The length unit's symbol, or "file unit".
    pub(super) length: String,
    /// "rad" or "deg".
    pub(super) angle: &'static str,
}

impl Units {
    pub(super) fn of(r: &Request, l: &Loaded) -> Units {
        Units {
            length: l
                .compiled
                .analysis
                .mass_and_loads
                .units
                .map_or("file unit", |u| u.length.symbol())
                .to_string(),
            angle: if r.degrees { "deg" } else { "rad" },
        }
    }

    /// An angle's unit or a length's.
    pub(super) fn of_kind(&self, angle: bool) -> &str {
        if angle {
            self.angle
        } else {
            &self.length
        }
    }

    fn json(&self) -> Value {
        json!({ "length": self.length, "angle": self.angle })
    }
}

/// The values as given, by name, for a title: `R1 = 1, P1 = 20`.
pub(super) fn given_text(names: &[&str], values: &[f64]) -> String {
    names
        .iter()
        .zip(values)
        .map(|(n, v)| {
            // 1e308 as 1e308, not its 309 digits.
            if v.abs() >= 1e16 || (v.abs() < 1e-6 && *v != 0.0) {
                format!("{n} = {v:e}")
            } else {
                format!("{n} = {v}")
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// How many of `found` solve, for a title: `4 branches, 2 ok`; with
/// `fk_numeric`, where a branch may have several assemblies or none,
/// `4 assemblies on the plan's 4 branches`.
fn count_text(found: &[Found], numeric: bool) -> String {
    let ok = found.iter().filter(|f| f.verdict.is_ok()).count();
    let plural = |n: usize| if n == 1 { "" } else { "es" };
    if numeric {
        let branches = found
            .iter()
            .map(|f| f.number)
            .collect::<std::collections::BTreeSet<_>>()
            .len();
        let assemblies = if ok == 1 { "assembly" } else { "assemblies" };
        format!("{ok} {assemblies} on the plan's {branches} branch{}", plural(branches))
    } else {
        format!("{} branch{}, {ok} ok", found.len(), plural(found.len()))
    }
}

/// Values the command line gives per input (`flag`: `--q`, `--rates`, …):
/// as many as the inputs, each finite, angles in radians for the solver.
pub(super) fn input_values(
    r: &Request,
    model: &Model,
    inputs: &[usize],
    flag: &str,
    list: &[f64],
) -> Result<Vec<f64>, Failure> {
    let names: Vec<&str> = inputs.iter().map(|&j| model.joints[j].name.as_str()).collect();
    if list.len() != inputs.len() {
        return Err(Failure::input(format!(
            "{flag}: expected {} input value{} ({}), found {}",
            inputs.len(),
            if inputs.len() == 1 { "" } else { "s" },
            names.join(", "),
            list.len()
        )));
    }
    for (k, (&v, name)) in list.iter().zip(&names).enumerate() {
        finite(&format!("input {name} ({flag} value {})", k + 1), v)?;
    }
    Ok(list
        .iter()
        .zip(inputs)
        .map(|(&v, &j)| r.solver_value(v, angular(model.joints[j].kind)))
        .collect())
}

/// The columns a row of inputs gives: the actuated joints `inputs`, each
/// in its unit.
pub(super) fn input_columns(r: &Request, l: &Loaded, inputs: &[usize]) -> Vec<Column> {
    let units = Units::of(r, l);
    let m = &l.model;
    inputs
        .iter()
        .map(|&j| Column::new(&m.joints[j].name, units.of_kind(angular(m.joints[j].kind))))
        .collect()
}

/// Found assemblies (each its branch's signs and its solution) as the
/// runs [`verdicts`] judges.
fn runs_of<'a>(found: impl Iterator<Item = (&'a Vec<Sign>, &'a pkm_runtime::plan::Solution)>) -> Vec<Run> {
    found
        .map(|(signs, solution)| {
            let c = Configuration {
                poses: solution.poses.clone(),
                values: solution.values.clone(),
            };
            (signs.clone(), Ok(c))
        })
        .collect()
}

/// How the forward position is solved: the closed-form plan, or for a
/// κ = 1 file that asks for `fk_numeric` the virtual variable's plan.
enum Way {
    Plan(Plan),
    Numeric(Box<pkm_runtime::fk_numeric::VirtualPlan>),
    /// A coupled file whose legs each end in a ball: the pose equations,
    /// and the inverse plan that solves each root's joints.
    Balls(Box<(BallLegs, Plan)>),
}

/// Why a real root of the pose equations is only possible.
const POSE_DOUBT: &str =
    "singular: Krawczyk's operator passed on no box about it (a double root, a fold, or too ill-conditioned to prove)";

/// `pkm fk`: the file loaded and planned once, solved at any inputs.
pub struct Forward<'r> {
    r: &'r Request<'r>,
    l: Loaded,
    way: Way,
    /// The actuated joints, in the order `--q` gives them.
    inputs: Vec<usize>,
    /// By the pose equations: what the paths did at the last inputs.
    summary: std::cell::RefCell<Option<String>>,
}

impl<'r> Forward<'r> {
    /// Loads and plans the file of `r`.
    pub fn new(r: &'r Request<'r>) -> Result<Forward<'r>, Failure> {
        let l = load(r)?;
        let numeric = pkm_dsl::planner_numeric::by_virtual_variable(&l.compiled.analysis);
        let (way, inputs) = if numeric {
            let vp =
                pkm_dsl::planner_numeric::forward_numeric_plan(&l.compiled.analysis).map_err(|d| r.parse_failure(d))?;
            let inputs = vp.plan.inputs[..vp.plan.inputs.len() - 1].to_vec();
            (Way::Numeric(Box::new(vp)), inputs)
        } else if let Some(balls) = Self::balls(&l) {
            let inputs = l.model.inputs();
            (Way::Balls(Box::new(balls)), inputs)
        } else {
            let coupled = l.compiled.analysis.topology.kappa != 0 && l.compiled.inverse().is_ok();
            let plan = l.compiled.forward().cloned().map_err(|mut d| {
                // A coupled mechanism with an inverse plan is followed
                // along a trajectory from a known pose.
                if let (true, Some(first)) = (coupled, d.0.first_mut()) {
                    *first = first.clone().note(
                        "along a trajectory from a known pose: `pkm fk FILE --csv TRAJECTORY --follow-from POSE` \
                         (docs/certified.md, \"Trajectories\")",
                    );
                }
                r.parse_failure(d)
            })?;
            let inputs = plan.input_joints(&l.model);
            (Way::Plan(plan), inputs)
        };
        Ok(Forward {
            r,
            l,
            way,
            inputs,
            summary: std::cell::RefCell::new(None),
        })
    }

    /// A coupled file without a closed-form forward plan whose legs each
    /// end in a ball: its legs and its inverse plan.
    fn balls(l: &Loaded) -> Option<(BallLegs, Plan)> {
        if l.compiled.analysis.topology.kappa == 0 || l.compiled.forward().is_ok() {
            return None;
        }
        let inverse = l.compiled.inverse().ok()?.clone();
        let legs = BallLegs::for_outputs(&l.model, &l.outputs).ok()?;
        Some((legs, inverse))
    }

    /// Whether each assembly carries a root's certificate.
    fn certifies(&self) -> bool {
        !matches!(self.way, Way::Plan(_))
    }

    fn names(&self) -> Vec<&str> {
        self.inputs
            .iter()
            .map(|&j| self.l.model.joints[j].name.as_str())
            .collect()
    }

    /// The virtual variable's joint name and whether it is an angle.
    fn virtual_joint(&self) -> Option<(&str, bool)> {
        match &self.way {
            Way::Plan(_) | Way::Balls(_) => None,
            Way::Numeric(vp) => {
                let j = &self.l.model.joints[vp.joint];
                Some((j.name.as_str(), angular(j.kind)))
            }
        }
    }

    /// Every branch at the inputs `q` (as given: degrees with `--degrees`).
    fn found(&self, q: &[f64]) -> Result<Vec<Found>, Failure> {
        let given = input_values(self.r, &self.l.model, &self.inputs, "--q", q)?;
        match &self.way {
            Way::Plan(plan) => Ok(verdicts(&self.l, run_all(plan, &self.l.model, &given), &self.names())),
            Way::Numeric(vp) => self.numeric(vp, &given),
            Way::Balls(b) => self.by_poses(&b.0, &b.1, &given),
        }
    }

    /// Every assembly by the pose equations ([`BallLegs::solve`]): each
    /// under the inverse branch that solves its legs, with its root's
    /// number and certificate; a root no branch meets, and a branch with
    /// no assembly, listed with why.
    fn by_poses(&self, legs: &BallLegs, inverse: &Plan, given: &[f64]) -> Result<Vec<Found>, Failure> {
        let l = &self.l;
        let all = legs
            .solve(&l.model, inverse, &l.outputs, given)
            .map_err(|e| Failure::input(e.to_string()))?;
        let runs = runs_of(all.assemblies.iter().map(|a| (&a.signs, &a.solution)));
        let mut found = verdicts(l, runs, &self.names());
        for (f, a) in found.iter_mut().zip(&all.assemblies) {
            let root = &all.roots.roots[a.root];
            if let Ok(s) = &mut f.verdict {
                s.tangent = root.cert.is_none();
            }
            f.pose = Some(PoseFound {
                root: a.root,
                cert: root.cert,
                scale: legs.scale,
            });
        }
        found.sort_by_key(|f| f.number);
        let choices = inverse.branches;
        let mut unmet: Vec<String> = Vec::new();
        let unit = Units::of(self.r, l).length;
        for &k in &all.unmet {
            let root = &all.roots.roots[k];
            let t = root.pose.translation.vector;
            unmet.push(format!(
                "root {k} ({}, the platform's origin at ({}, {}, {}) {unit}) meets the inputs on no branch",
                if root.cert.is_some() { "certified" } else { "possible" },
                t.x,
                t.y,
                t.z
            ));
        }
        let r = &all.roots;
        let paths = format!(
            "{} paths: {} real roots, {} complex, {} at infinity, {} failed",
            r.paths,
            r.roots.len(),
            r.complex,
            r.infinite,
            r.failed
        );
        let summary = std::iter::once(paths.clone())
            .chain(unmet)
            .collect::<Vec<_>>()
            .join("; ");
        *self.summary.borrow_mut() = Some(summary);
        if found.is_empty() {
            return Err(Failure::new(
                Kind::Unreachable,
                format!("no assembly: the pose equations have no real root ({paths})"),
            ));
        }
        for n in 0..1usize << choices {
            if !found.iter().any(|f| f.number == n) {
                let at = found.iter().position(|f| f.number > n).unwrap_or(found.len());
                found.insert(
                    at,
                    Found {
                        number: n,
                        signs: table::signs_of(n, choices),
                        verdict: Err((
                            Kind::Unreachable,
                            "no assembly on this branch: no real root of the pose equations has its legs".to_string(),
                        )),
                        virtual_value: None,
                        certificate: None,
                        pose: None,
                    },
                );
            }
        }
        Ok(found)
    }

    /// `fk_numeric`: every assembly the virtual variable's compatibility
    /// residual has a root for ([`pkm_runtime::fk_numeric::solve`]), each
    /// under its plan branch's number with the virtual variable's value,
    /// whether its root is certified or only possible (then `tangent`
    /// too), and its certificate; a root without a verified assembly, and
    /// a plan branch with no assembly, listed with why.
    fn numeric(&self, vp: &pkm_runtime::fk_numeric::VirtualPlan, given: &[f64]) -> Result<Vec<Found>, Failure> {
        let l = &self.l;
        let assemblies =
            pkm_runtime::fk_numeric::solve(&l.model, vp, given).map_err(|e| Failure::input(e.to_string()))?;
        let virtual_name = &l.model.joints[vp.joint].name;
        if assemblies.is_empty() && assemblies.unresolved.is_empty() {
            return Err(Failure::new(
                Kind::Unreachable,
                format!(
                    "no assembly: the compatibility residual has no root over {virtual_name}'s range on any branch"
                ),
            ));
        }
        let runs = runs_of(assemblies.iter().map(|a| (&a.signs, &a.solution)));
        let mut found = verdicts(l, runs, &self.names());
        for (f, a) in found.iter_mut().zip(&assemblies) {
            if let Ok(s) = &mut f.verdict {
                s.tangent = !a.kind.certified();
            }
            f.virtual_value = Some(a.virtual_value);
            f.certificate = Some((a.kind, a.cert));
        }
        // A root whose assembly no point of its interval verifies: listed
        // on its branch, with why.
        for u in &assemblies.unresolved {
            let number = table::number_of(&u.signs);
            let at = found.iter().position(|f| f.number > number).unwrap_or(found.len());
            let why = format!(
                "a {} root at {virtual_name} = {} whose assembly fails verification at every point of its interval",
                u.root.kind.text(),
                u.root.x
            );
            found.insert(
                at,
                Found {
                    number,
                    signs: u.signs.clone(),
                    verdict: Err((Kind::Unreachable, why)),
                    virtual_value: Some(u.root.x),
                    certificate: Some((u.root.kind, u.root.cert)),
                    pose: None,
                },
            );
        }
        // The branches without an assembly, in their places.
        let choices = vp.plan.branches;
        for n in 0..1usize << choices {
            if !found.iter().any(|f| f.number == n) {
                let at = found.iter().position(|f| f.number > n).unwrap_or(found.len());
                let why = format!(
                    "no assembly on this branch: the compatibility residual has no root over {virtual_name}'s range here that an earlier branch does not list"
                );
                let f = Found {
                    number: n,
                    signs: table::signs_of(n, choices),
                    verdict: Err((Kind::Unreachable, why)),
                    virtual_value: None,
                    certificate: None,
                    pose: None,
                };
                found.insert(at, f);
            }
        }
        Ok(found)
    }

    /// Every branch at `q`, as JSON (`json`) or as a table.
    pub fn answer(&self, q: &[f64], json: bool) -> Result<String, Failure> {
        let found = self.found(q)?;
        if let Some(f) = none_solves(&found) {
            return Err(f);
        }
        let names = self.names();
        if json {
            let as_given: Map<String, Value> = names.iter().zip(q).map(|(n, v)| (n.to_string(), json!(v))).collect();
            let mut v = json!({
                "name": self.l.model.name,
                "inputs": as_given,
                "units": Units::of(self.r, &self.l).json(),
                "branches": branches_json(self.r, &found, self.virtual_joint()),
            });
            if let Some((name, _)) = self.virtual_joint() {
                v["virtual"] = json!(name);
            }
            if let Some(summary) = self.summary.borrow().as_ref() {
                v["paths"] = json!(summary);
            }
            return Ok(format!("{v}\n"));
        }
        let how = match (&self.way, self.virtual_joint()) {
            (_, Some((name, _))) => format!(" (κ = 1: the assemblies found by the virtual variable {name})"),
            (Way::Balls(_), _) => format!(
                " (κ = {}: every assembly by the pose equations, each leg's ball on its circle or sphere; {})",
                self.l.compiled.analysis.topology.kappa,
                self.summary.borrow().as_deref().unwrap_or("")
            ),
            _ => String::new(),
        };
        let title = format!(
            "{}: forward position at {}{how}; {}\n\n",
            self.l.model.name,
            given_text(&names, q),
            count_text(&found, !how.is_empty())
        );
        let columns = position_columns(self.r, &self.l, self.certifies());
        Ok(title + &table::branch_table(&columns, &position_rows(self.r, &found)))
    }
}

impl super::csv::Solver for Forward<'_> {
    fn given(&self) -> Vec<Column> {
        input_columns(self.r, &self.l, &self.inputs)
    }

    fn columns(&self) -> Vec<Column> {
        position_columns(self.r, &self.l, self.certifies())
    }

    fn choices(&self) -> usize {
        match &self.way {
            Way::Plan(plan) => plan.branches,
            Way::Numeric(vp) => vp.plan.branches,
            Way::Balls(b) => b.1.branches,
        }
    }

    fn branches(&self, given: &[f64]) -> Result<Vec<Branch>, Failure> {
        Ok(position_rows(self.r, &self.found(given)?))
    }
}

/// `pkm ik`: the file loaded and planned once, solved at any pose.
pub struct Inverse<'r> {
    r: &'r Request<'r>,
    l: Loaded,
    plan: Plan,
}

impl<'r> Inverse<'r> {
    /// Loads and plans the file of `r`.
    pub fn new(r: &'r Request<'r>) -> Result<Inverse<'r>, Failure> {
        let l = load(r)?;
        let plan = l.compiled.inverse().cloned().map_err(|d| r.parse_failure(d))?;
        Ok(Inverse { r, l, plan })
    }

    /// Every branch at the declared outputs' values in declaration order,
    /// as the solver takes them (radians).
    fn found(&self, ordered: &[f64]) -> Vec<Found> {
        let declared = output_names(&self.l);
        let names: Vec<&str> = declared.iter().map(|(n, _)| n.as_str()).collect();
        verdicts(&self.l, run_all(&self.plan, &self.l.model, ordered), &names)
    }

    /// Every branch at the declared outputs `pose` (by name), as JSON
    /// (`json`) or as a table.
    pub fn answer(&self, pose: &[(String, f64)], json: bool) -> Result<String, Failure> {
        let ordered = ordered_pose(self.r, &self.l, pose)?;
        let found = self.found(&ordered);
        if let Some(f) = none_solves(&found) {
            return Err(f);
        }
        if json {
            let as_given: Map<String, Value> = pose.iter().map(|(n, v)| (n.clone(), json!(v))).collect();
            let v = json!({
                "name": self.l.model.name,
                "pose": as_given,
                "units": Units::of(self.r, &self.l).json(),
                "branches": branches_json(self.r, &found, None),
            });
            return Ok(format!("{v}\n"));
        }
        let names: Vec<&str> = pose.iter().map(|(n, _)| n.as_str()).collect();
        let values: Vec<f64> = pose.iter().map(|(_, v)| *v).collect();
        let title = format!(
            "{}: inverse position at {}; {}\n\n",
            self.l.model.name,
            given_text(&names, &values),
            count_text(&found, false)
        );
        Ok(title
            + &table::branch_table(
                &position_columns(self.r, &self.l, false),
                &position_rows(self.r, &found),
            ))
    }
}

impl super::csv::Solver for Inverse<'_> {
    fn given(&self) -> Vec<Column> {
        output_columns(self.r, &self.l)
    }

    fn columns(&self) -> Vec<Column> {
        position_columns(self.r, &self.l, false)
    }

    fn choices(&self) -> usize {
        self.plan.branches
    }

    fn branches(&self, given: &[f64]) -> Result<Vec<Branch>, Failure> {
        let ordered = solver_pose(self.r, &self.l, given);
        Ok(position_rows(self.r, &self.found(&ordered)))
    }
}

/// The declared outputs as columns, in declaration order with their units:
/// what an input file of ik or stiffness names.
pub(super) fn output_columns(r: &Request, l: &Loaded) -> Vec<Column> {
    let units = Units::of(r, l);
    output_names(l)
        .into_iter()
        .map(|(n, angle)| Column::new(n, units.of_kind(angle)))
        .collect()
}

/// The declared outputs' values in declaration order as given (degrees
/// with `--degrees`), as the solver takes them.
pub(super) fn solver_pose(r: &Request, l: &Loaded, given: &[f64]) -> Vec<f64> {
    output_names(l)
        .iter()
        .zip(given)
        .map(|((_, angle), &v)| r.solver_value(v, *angle))
        .collect()
}

/// The declared outputs' values as the inverse plan takes them, from
/// `--pose name=value,…`: every declared output once, each finite, angles
/// in radians.
pub(super) fn ordered_pose(r: &Request, l: &Loaded, pose: &[(String, f64)]) -> Result<Vec<f64>, Failure> {
    let declared = output_names(l);
    let list = declared.iter().map(|(n, _)| n.as_str()).collect::<Vec<_>>().join(", ");
    let mut given: HashMap<&str, f64> = HashMap::new();
    for (name, v) in pose {
        if !declared.iter().any(|(n, _)| n == name) {
            return Err(Failure::input(format!(
                "unknown output `{name}`; the outputs are {list}"
            )));
        }
        finite(&format!("output {name}"), *v)?;
        if given.insert(name, *v).is_some() {
            return Err(Failure::input(format!("output {name} is given twice")));
        }
    }
    let mut ordered = Vec::new();
    for (name, angle) in &declared {
        match given.get(name.as_str()) {
            Some(&v) => ordered.push(r.solver_value(v, *angle)),
            None => return Err(Failure::input(format!("missing output `{name}`; give {list}"))),
        }
    }
    Ok(ordered)
}
