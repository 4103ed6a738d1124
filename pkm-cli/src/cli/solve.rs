//! `pkm fk` and `pkm ik`: the values given are checked before solving, every
//! branch comes out as JSON by name (`joints`, `inputs`, `outputs`,
//! `points`), and when no branch solves the failure names the causes.

use super::failure::{Failure, Kind};
use pkm_dsl::{Analysis, Diagnostics};
use pkm_runtime::model::{JointType, Model, Place};
use pkm_runtime::newton::Output;
use pkm_runtime::primitives::Sign;
use pkm_runtime::solution::SolveError;
use pkm_runtime::spatial::{Plan, Pose3};
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
    fn shown_value(&self, v: f64, angular: bool) -> f64 {
        if self.degrees && angular {
            v.to_degrees()
        } else {
            v
        }
    }

    fn units(&self) -> Value {
        json!({ "length": "file unit", "angle": if self.degrees { "deg" } else { "rad" } })
    }
}

/// A mechanism ready to solve: its analysis, its model at the given
/// parameters and its declared outputs at those parameters.
pub(super) struct Loaded {
    pub(super) analysis: Analysis,
    pub(super) model: Model,
    pub(super) outputs: Vec<Output>,
    /// The parameters the command line overrides.
    pub(super) values: HashMap<String, f64>,
}

pub(super) fn load(r: &Request) -> Result<Loaded, Failure> {
    let analysis = pkm_dsl::compile(r.source).map_err(|d| r.parse_failure(d))?.analysis;
    let nominal = pkm_dsl::numeric::model(&analysis, &HashMap::new()).map_err(|d| r.parse_failure(d))?;
    let values = pkm_dsl::params::overrides(&analysis, r.params).map_err(|e| Failure::input(e.to_string()))?;
    check_lengths(&analysis, &nominal, &values)?;
    let model = pkm_dsl::numeric::model(&analysis, &values).map_err(|d| r.parse_failure(d))?;
    if let Some(why) = non_finite_place(&model) {
        return Err(Failure::input(format!("at the given parameters {why}")));
    }
    let outputs = pkm_dsl::numeric::newton_outputs(&analysis, &model, &values).map_err(|d| r.parse_failure(d))?;
    Ok(Loaded {
        analysis,
        model,
        outputs,
        values,
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

/// A joint place or named point that is not a number (a parameter
/// expression such as `sqrt(a - 100)` out of its domain), if any.
fn non_finite_place(model: &Model) -> Option<String> {
    let bad = |v: [f64; 3]| v.iter().any(|x| !x.is_finite());
    let joint = model.joints.iter().find_map(|j| {
        (0..2).find_map(|s| {
            let (at, axis) = (j.places[s].at(), j.places[s].axis());
            (bad(at) || bad(axis)).then(|| {
                format!(
                    "joint {}'s place on link {} is not finite ({at:?} along {axis:?})",
                    j.name, model.links[j.links[s]]
                )
            })
        })
    });
    joint.or_else(|| {
        let p = model.points.iter().find(|p| bad(p.at))?;
        Some(format!("point {} is not finite ({:?})", p.name, p.at))
    })
}

/// The points of `link` a parameter can set the distances between: its
/// joints' places (not guide lines: any point of a line stands for it) and
/// its named points, in a fixed order.
fn link_points(model: &Model, link: usize) -> Vec<(&str, [f64; 3])> {
    let joints = model.joints.iter().flat_map(|j| {
        (0..2)
            .filter(move |&s| j.links[s] == link && !matches!(j.places[s], Place::Line { .. }))
            .map(move |s| (j.name.as_str(), j.places[s].at()))
    });
    let named = model
        .points
        .iter()
        .filter(|p| p.link == link)
        .map(|p| (p.name.as_str(), p.at));
    joints.chain(named).collect()
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// Rejects an override that takes a length of the mechanism through zero.
/// Each override is applied alone to the declared dimensions; a distance
/// between two points of one link that becomes zero, or (on a moving link)
/// turns to point the opposite way along the same line, went through zero
/// on the way: `l2 = -5` for a link declared `l2` long. Base points are
/// positions, which may change sides, so only their coincidence counts.
fn check_lengths(a: &Analysis, nominal: &Model, values: &HashMap<String, f64>) -> Result<(), Failure> {
    let declared = a.geometry.nominal();
    let mut names: Vec<&String> = values.keys().collect();
    names.sort();
    for name in names {
        let v = values[name];
        // A model that does not build fails later with its own diagnostics.
        let Ok(changed) = pkm_dsl::numeric::model(a, &HashMap::from([(name.clone(), v)])) else {
            continue;
        };
        for (link, link_name) in nominal.links.iter().enumerate() {
            let (before, after) = (link_points(nominal, link), link_points(&changed, link));
            for i in 0..before.len() {
                for k in i + 1..before.len().min(after.len()) {
                    let (d0, d1) = (sub(before[k].1, before[i].1), sub(after[k].1, after[i].1));
                    let (n0, n1) = (norm(d0), norm(d1));
                    if n0 == 0.0 {
                        continue;
                    }
                    let (p, q) = (before[i].0, before[k].0);
                    let at_declared = format!("at the declared {name} = {}", declared[name]);
                    if n1 <= 1e-9 * n0 {
                        return Err(Failure::input(format!(
                            "parameter {name} = {v} puts {p} and {q} of link {link_name} at one point \
                             (they are {n0} apart {at_declared})"
                        )));
                    }
                    if link != 0 && dot(d0, d1) < 0.0 && norm(cross(d0, d1)) <= 1e-9 * n0 * n1 {
                        let rule = match declared[name] {
                            d if d > 0.0 => "must be positive",
                            d if d < 0.0 => "must be negative",
                            _ => "is out of range",
                        };
                        return Err(Failure::input(format!(
                            "parameter {name} = {v} {rule}: the distance {p}–{q} on link {link_name} \
                             ({n0} {at_declared}) would pass through zero"
                        )));
                    }
                }
            }
        }
    }
    Ok(())
}

/// Whether a joint's value is an angle.
pub(super) fn angular(kind: JointType) -> bool {
    matches!(kind, JointType::R | JointType::Pa)
}

/// One solution: link poses and joint values.
struct Configuration {
    poses: Vec<Pose3>,
    values: Vec<f64>,
}

impl Configuration {
    /// The world position of `local`, a point of `link`.
    fn point(&self, link: usize, local: [f64; 3]) -> [f64; 3] {
        pkm_runtime::spatial::at(&self.poses[link], local)
    }

    /// The angle `link` has turned about world axis `k` (planar: about z).
    fn angle(&self, link: usize, k: [f64; 3]) -> f64 {
        pkm_runtime::spatial::angle_about(&self.poses[link], k)
    }

    fn joint_point(&self, model: &Model, j: usize) -> [f64; 3] {
        pkm_runtime::newton::joint_point(model, &self.poses, j)
    }
}

/// Signs of one branch and its configuration or why it has none.
type Run = (Vec<Sign>, Result<Configuration, SolveError>);

/// Every branch of `plan` at the values `given`, with its link poses.
fn run_all(plan: &Plan, model: &Model, given: &[f64]) -> Vec<Run> {
    pkm_runtime::spatial::run_all(model, plan, given)
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
fn output_names(l: &Loaded) -> Vec<(String, bool)> {
    let mut names = Vec::new();
    for (o, spec) in l.analysis.geometry.outputs.iter().zip(&l.outputs) {
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
fn output_values(l: &Loaded, c: &Configuration) -> Vec<f64> {
    let dim = if l.model.planar { 2 } else { 3 };
    let mut values = Vec::new();
    for (o, spec) in l.analysis.geometry.outputs.iter().zip(&l.outputs) {
        let these: Vec<f64> = match *spec {
            Output::Pose { link, local, about } => {
                let mut v = c.point(link, local)[..dim].to_vec();
                v.extend(about.map(|k| c.angle(link, k)));
                v
            }
            Output::Point { link, local } => c.point(link, local)[..dim].to_vec(),
            Output::Parts { link, local, parts } => {
                let frame = pkm_runtime::spatial::frame_of(&c.poses[link]);
                let six = pkm_runtime::steps::place::pose_values(&frame, local);
                parts.given().map(|i| six[i]).collect()
            }
            Output::Joint(j) => vec![c.values[j]],
        };
        // One value per declared name, whatever the declaration's shape.
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
    let one_dof = |j: &usize| m.joints[*j].kind != JointType::S;
    let value = |j: usize| (m.joints[j].name.clone(), c.values[j], angular(m.joints[j].kind));
    let joint_points = (0..m.joints.len()).map(|j| (m.joints[j].name.clone(), c.joint_point(m, j)));
    let named_points = m.points.iter().map(|p| (p.name.clone(), c.point(p.link, p.at)));
    Solved {
        joints: (0..m.joints.len()).filter(one_dof).map(value).collect(),
        inputs: m.inputs().into_iter().filter(one_dof).map(value).collect(),
        outputs: output_names(l)
            .into_iter()
            .zip(output_values(l, c))
            .map(|((n, angle), v)| (n, v, angle))
            .collect(),
        points: joint_points.chain(named_points).collect(),
        tangent: false,
    }
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

/// Judges every branch: the plan's error (the runtime verifies what it
/// returns: open joints close, an over-determined pose names the output
/// the others contradict, by its name from `given_names`) or a non-finite
/// value.
fn verdicts(l: &Loaded, runs: Vec<Run>, given_names: &[&str]) -> Vec<(Vec<Sign>, Verdict)> {
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
            (signs, verdict)
        })
        .collect()
}

/// Every branch as JSON, or the failure when none solved: the distinct
/// reasons of the branches, the gravest kind among them.
fn branches_json(r: &Request, verdicts: &[(Vec<Sign>, Verdict)]) -> Result<Vec<Value>, Failure> {
    if verdicts.iter().all(|(_, v)| v.is_err()) {
        let failures = verdicts.iter().filter_map(|(_, v)| v.as_ref().err());
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
        return Err(Failure::new(kind, format!("no branch reaches: {why}")));
    }
    let named = |list: &[(String, f64, bool)]| -> Map<String, Value> {
        list.iter()
            .map(|(n, v, angle)| (n.clone(), json!(r.shown_value(*v, *angle))))
            .collect()
    };
    Ok(verdicts
        .iter()
        .map(|(signs, verdict)| {
            let signs = sign_text(signs);
            match verdict {
                Ok(s) => {
                    let points: Map<String, Value> = s.points.iter().map(|(n, p)| (n.clone(), json!(p))).collect();
                    json!({
                        "signs": signs,
                        "ok": true,
                        "tangent": s.tangent,
                        "joints": named(&s.joints),
                        "inputs": named(&s.inputs),
                        "outputs": named(&s.outputs),
                        "points": points,
                    })
                }
                Err((_, why)) => json!({ "signs": signs, "ok": false, "reason": why }),
            }
        })
        .collect())
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

/// `pkm fk`: every branch at input values `q` (actuated joints in the plan's order).
pub fn fk(r: &Request, q: &[f64]) -> Result<Value, Failure> {
    let l = load(r)?;
    if l.analysis.topology.kappa != 0 && l.analysis.mechanism.wants(pkm_dsl::mechanism::Capability::FkNumeric) {
        return fk_numeric(r, &l, q);
    }
    let plan = pkm_dsl::planner::forward_plan(&l.analysis).map_err(|d| r.parse_failure(d))?;
    let inputs = plan.input_joints(&l.model);
    let names: Vec<&str> = inputs.iter().map(|&j| l.model.joints[j].name.as_str()).collect();
    let given = input_values(r, &l.model, &inputs, "--q", q)?;
    let verdicts = verdicts(&l, run_all(&plan, &l.model, &given), &names);
    let as_given: Map<String, Value> = names.iter().zip(q).map(|(n, v)| (n.to_string(), json!(v))).collect();
    Ok(json!({
        "name": l.model.name,
        "inputs": as_given,
        "units": r.units(),
        "branches": branches_json(r, &verdicts)?,
    }))
}

/// `pkm fk` of a κ = 1 file that asks for `fk_numeric`: every assembly
/// the virtual variable's compatibility residual has a root for
/// ([`pkm_runtime::fk_numeric::solve`]), each as a branch with its plan
/// branch's signs, the virtual variable's value, and `tangent` where the
/// root was a tangency (found, not certified by a sign change).
fn fk_numeric(r: &Request, l: &Loaded, q: &[f64]) -> Result<Value, Failure> {
    let vp = pkm_dsl::planner_numeric::forward_numeric_plan(&l.analysis).map_err(|d| r.parse_failure(d))?;
    let inputs = &vp.plan.inputs[..vp.plan.inputs.len() - 1];
    let names: Vec<&str> = inputs.iter().map(|&j| l.model.joints[j].name.as_str()).collect();
    let given = input_values(r, &l.model, inputs, "--q", q)?;
    let found = pkm_runtime::fk_numeric::solve(&l.model, &vp, &given).map_err(|e| Failure::input(e.to_string()))?;
    let virtual_name = l.model.joints[vp.joint].name.clone();
    let virtual_angle = angular(l.model.joints[vp.joint].kind);
    if found.is_empty() {
        return Err(Failure::new(
            Kind::Unreachable,
            format!("no assembly: the compatibility residual has no root over {virtual_name}'s range on any branch"),
        ));
    }
    let runs: Vec<Run> = found
        .iter()
        .map(|a| {
            let c = Configuration {
                poses: a.solution.poses.clone(),
                values: a.solution.values.clone(),
            };
            (a.signs.clone(), Ok(c))
        })
        .collect();
    let mut verdicts = verdicts(l, runs, &names);
    for ((_, v), a) in verdicts.iter_mut().zip(&found) {
        if let Ok(s) = v {
            s.tangent = a.kind == pkm_runtime::fk_numeric::RootKind::Tangency;
        }
    }
    let mut branches = branches_json(r, &verdicts)?;
    for (b, a) in branches.iter_mut().zip(&found) {
        b["virtual"] = json!({ virtual_name.clone(): r.shown_value(a.virtual_value, virtual_angle) });
    }
    let as_given: Map<String, Value> = names.iter().zip(q).map(|(n, v)| (n.to_string(), json!(v))).collect();
    Ok(json!({
        "name": l.model.name,
        "inputs": as_given,
        "units": r.units(),
        "virtual": virtual_name,
        "branches": branches,
    }))
}

/// `pkm ik`: every branch at the declared outputs `pose` (by name).
pub fn ik(r: &Request, pose: &[(String, f64)]) -> Result<Value, Failure> {
    let l = load(r)?;
    let plan = pkm_dsl::planner::inverse_plan(&l.analysis).map_err(|d| r.parse_failure(d))?;
    let ordered = ordered_pose(r, &l, pose)?;
    let declared = output_names(&l);
    let names: Vec<&str> = declared.iter().map(|(n, _)| n.as_str()).collect();
    let verdicts = verdicts(&l, run_all(&plan, &l.model, &ordered), &names);
    let as_given: Map<String, Value> = pose.iter().map(|(n, v)| (n.clone(), json!(v))).collect();
    Ok(json!({
        "name": l.model.name,
        "pose": as_given,
        "units": r.units(),
        "branches": branches_json(r, &verdicts)?,
    }))
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
