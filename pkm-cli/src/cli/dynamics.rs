//! `pkm dynamics`: inverse dynamics at given inputs, their rates and
//! accelerations, every branch: the actuators' forces and every joint's
//! reaction by Newton–Euler over the ordered SKCs
//! (`pkm_runtime::newton_euler`), and every joint's value, rate and
//! acceleration, as JSON by name; at one state or at every line of a file.

use super::failure::{Failure, Kind};
use super::solve::{input_values, load, sign_text, Request};
use pkm_runtime::newton_euler::{inverse_dynamics, DynamicsError};
use serde_json::{json, Map, Value};

/// What every state's dynamics reads: the loaded file, its loading, its
/// plan's inputs and SKCs, its length unit's name.
struct Setup {
    l: super::solve::Loaded,
    loading: pkm_runtime::mass_properties::Loading,
    plan: pkm_runtime::spatial::Plan,
    inputs: Vec<usize>,
    skcs: Vec<pkm_runtime::newton_euler::SkcParts>,
    unit: &'static str,
}

impl Setup {
    fn new(r: &Request) -> Result<Setup, Failure> {
        let l = load(r)?;
        let a = &l.analysis;
        let Some(units) = a.mass_and_loads.units else {
            return Err(Failure::input(
                "dynamics needs the file's units and masses: `units { length = mm; mass = kg; }` and a `masses` block giving every moving link a mass or declaring it massless",
            ));
        };
        let loading = pkm_dsl::numeric::loading(a, &l.model, &l.values).map_err(|d| r.parse_failure(d))?;
        let plan = pkm_dsl::planner::forward_plan(a).map_err(|d| r.parse_failure(d))?;
        let inputs = plan.input_joints(&l.model);
        let skcs = pkm_dsl::numeric::skc_parts(a);
        let unit = units.length.symbol();
        Ok(Setup {
            l,
            loading,
            plan,
            inputs,
            skcs,
            unit,
        })
    }

    /// The inputs' values, rates and accelerations as the solver takes them.
    fn given(&self, r: &Request, q: &[f64], rates: &[f64], accels: &[f64]) -> Result<Vec<Vec<f64>>, Failure> {
        let zeros = vec![0.0; self.inputs.len()];
        let mut given = Vec::new();
        for (flag, list) in [("--q", q), ("--rates", rates), ("--accels", accels)] {
            // Rates and accelerations not given are zero: statics.
            let list = if list.is_empty() && flag != "--q" { &zeros } else { list };
            given.push(input_values(r, &self.l.model, &self.inputs, flag, list)?);
        }
        Ok(given)
    }

    fn units(&self, r: &Request) -> Value {
        let unit = self.unit;
        json!({
            "force": "N",
            "torque": format!("N·{unit}"),
            "length": unit,
            "angle": if r.degrees { "deg" } else { "rad" },
            "reactions": "force and moment (about the joint's point) that the joint's first link (`by`) exerts on its second (`on`), base axes",
        })
    }

    /// Every joint's value, rate and acceleration by name (a spherical
    /// joint's three as a list), angles in the request's unit.
    fn motion(&self, r: &Request, values: &[f64], given: &[Vec<f64>]) -> Option<Value> {
        let model = &self.l.model;
        let a = pkm_runtime::velocity::accelerations(model, values, &given[1], &given[2]).ok()?;
        let (offsets, _) = model.value_offsets();
        let by_name = |all: &[f64]| -> Map<String, Value> {
            model
                .joints
                .iter()
                .zip(&offsets)
                .map(|(j, &o)| {
                    let k = if r.degrees && super::solve::angular(j.kind) {
                        180.0 / std::f64::consts::PI
                    } else {
                        1.0
                    };
                    let these: Vec<f64> = all[o..o + j.kind.dof()].iter().map(|x| x * k).collect();
                    let v = if these.len() == 1 {
                        json!(these[0])
                    } else {
                        json!(these)
                    };
                    (j.name.clone(), v)
                })
                .collect()
        };
        Some(json!({
            "values": by_name(values),
            "rates": by_name(&a.velocities.rates),
            "accelerations": by_name(&a.rates),
        }))
    }

    /// Every branch's answer at the inputs `given` (values, rates, accelerations).
    fn branches(&self, r: &Request, given: &[Vec<f64>]) -> Result<Vec<Value>, Failure> {
        let model = &self.l.model;
        let names: Vec<&str> = self.inputs.iter().map(|&j| model.joints[j].name.as_str()).collect();
        let mut branches = Vec::new();
        let mut causes = Vec::new();
        for (signs, solution) in pkm_runtime::spatial::run_all(model, &self.plan, &given[0]) {
            // As `pkm fk` writes them.
            let signs = sign_text(&signs);
            let solution = match solution {
                Ok(s) => s,
                Err(e) => {
                    causes.push(format!("branch {}: {e}", signs.concat()));
                    continue;
                }
            };
            match inverse_dynamics(model, &self.loading, &self.skcs, &solution.values, &given[1], &given[2]) {
                Ok(d) => {
                    let actuators: Map<String, Value> = names
                        .iter()
                        .zip(&d.actuators)
                        .map(|(n, v)| (n.to_string(), json!(v)))
                        .collect();
                    let reactions: Map<String, Value> = model
                        .joints
                        .iter()
                        .zip(&d.joints)
                        .map(|(j, w)| {
                            let [first, second] = j.links.map(|k| model.links[k].clone());
                            (
                                j.name.clone(),
                                json!({ "on": second, "by": first, "force": w.force, "moment": w.moment }),
                            )
                        })
                        .collect();
                    branches.push(json!({
                        "signs": signs,
                        "ok": true,
                        "actuators": actuators,
                        "reactions": reactions,
                        "undetermined": d.undetermined,
                        "conditioning": d.conditioning,
                        "motion": self.motion(r, &solution.values, given),
                    }));
                }
                Err(
                    e @ (DynamicsError::ForceSingular { .. }
                    | DynamicsError::Undetermined { .. }
                    | DynamicsError::Unbalanced { .. }),
                ) => {
                    branches.push(json!({ "signs": signs, "ok": false, "reason": e.to_string() }));
                }
                Err(e) => causes.push(format!("branch {}: {e}", signs.concat())),
            }
        }
        if branches.is_empty() {
            return Err(Failure::new(
                Kind::Unreachable,
                format!("no branch gives the dynamics here: {}", causes.join("; ")),
            ));
        }
        Ok(branches)
    }
}

/// Every solved branch's actuator forces and joint reactions at inputs `q`
/// with rates `rates` and accelerations `accels` (zeros where not given),
/// and every joint's value, rate and acceleration (`motion`).
pub fn dynamics(r: &Request, q: &[f64], rates: &[f64], accels: &[f64]) -> Result<Value, Failure> {
    let s = Setup::new(r)?;
    let given = s.given(r, q, rates, accels)?;
    Ok(json!({
        "name": s.l.model.name,
        "units": s.units(r),
        "branches": s.branches(r, &given)?,
    }))
}

/// [`dynamics`] at every state of a file: one state a line, the inputs'
/// values, then their rates, then their accelerations, separated by commas
/// (rates and accelerations may be left out: zeros); blank lines and lines
/// starting with `#` are skipped. A state without an answer holds its
/// `error` instead of `branches`.
pub fn dynamics_states(r: &Request, path: &std::path::Path) -> Result<Value, Failure> {
    let s = Setup::new(r)?;
    let shown = path.display();
    let text =
        std::fs::read_to_string(path).map_err(|e| Failure::new(Kind::Io, format!("cannot read `{shown}`: {e}")))?;
    let n = s.inputs.len();
    let mut states = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let numbers: Vec<f64> = line
            .split(',')
            .map(|x| x.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|e| Failure::input(format!("{shown}:{}: {e}", k + 1)))?;
        if numbers.is_empty() || !numbers.len().is_multiple_of(n) || numbers.len() > 3 * n {
            return Err(Failure::input(format!(
                "{shown}:{}: expected {n}, {} or {} numbers (values, rates, accelerations), found {}",
                k + 1,
                2 * n,
                3 * n,
                numbers.len()
            )));
        }
        let part = |i: usize| numbers.get(i * n..(i + 1) * n).unwrap_or(&[]);
        let state = s
            .given(r, part(0), part(1), part(2))
            .and_then(|given| s.branches(r, &given))
            .map_or_else(|f| json!({ "error": f.message }), |b| json!({ "branches": b }));
        states.push(state);
    }
    Ok(json!({
        "name": s.l.model.name,
        "units": s.units(r),
        "states": states,
    }))
}
