//! `pkm dynamics`: inverse dynamics at given inputs, their rates and
//! accelerations, every branch: the actuators' forces and every joint's
//! reaction by Newton–Euler over the ordered SKCs
//! (`pkm_runtime::newton_euler`), as JSON by name.

use super::failure::{Failure, Kind};
use super::solve::{input_values, load, Request};
use pkm_runtime::newton_euler::{inverse_dynamics, DynamicsError};
use serde_json::{json, Map, Value};

/// Every solved branch's actuator forces and joint reactions at inputs `q`
/// with rates `rates` and accelerations `accels` (zeros where not given).
pub fn dynamics(r: &Request, q: &[f64], rates: &[f64], accels: &[f64]) -> Result<Value, Failure> {
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
    let names: Vec<&str> = inputs.iter().map(|&j| l.model.joints[j].name.as_str()).collect();
    let zeros = vec![0.0; inputs.len()];
    let mut given = Vec::new();
    for (flag, list) in [("--q", q), ("--rates", rates), ("--accels", accels)] {
        // Rates and accelerations not given are zero: statics.
        let list = if list.is_empty() && flag != "--q" { &zeros } else { list };
        given.push(input_values(r, &l.model, &inputs, flag, list)?);
    }
    let skcs = pkm_dsl::numeric::skc_parts(a);
    let unit = match units.length {
        pkm_dsl::mass_and_loads::LengthUnit::M => "m",
        pkm_dsl::mass_and_loads::LengthUnit::Cm => "cm",
        pkm_dsl::mass_and_loads::LengthUnit::Mm => "mm",
    };
    let mut branches = Vec::new();
    let mut causes = Vec::new();
    for (signs, solution) in pkm_runtime::spatial::run_all(&l.model, &plan, &given[0]) {
        // As `pkm fk` writes them.
        let signs: Vec<&str> = signs.iter().map(|s| if s.index() == 0 { "+" } else { "-" }).collect();
        let solution = match solution {
            Ok(s) => s,
            Err(e) => {
                causes.push(format!("branch {}: {e}", signs.concat()));
                continue;
            }
        };
        match inverse_dynamics(&l.model, &loading, &skcs, &solution.values, &given[1], &given[2]) {
            Ok(d) => {
                let actuators: Map<String, Value> = names
                    .iter()
                    .zip(&d.actuators)
                    .map(|(n, v)| (n.to_string(), json!(v)))
                    .collect();
                let reactions: Map<String, Value> = l
                    .model
                    .joints
                    .iter()
                    .zip(&d.joints)
                    .map(|(j, w)| {
                        let [first, second] = j.links.map(|k| l.model.links[k].clone());
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
    Ok(json!({
        "name": l.model.name,
        "units": {
            "force": "N",
            "torque": format!("N·{unit}"),
            "length": unit,
            "angle": if r.degrees { "deg" } else { "rad" },
            "reactions": "force and moment (about the joint's point) that the joint's first link (`by`) exerts on its second (`on`), base axes",
        },
        "branches": branches,
    }))
}
