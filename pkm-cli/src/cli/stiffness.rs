//! `pkm stiffness`: the platform's static stiffness at a pose, every
//! branch of the inverse solution: each limb's actuation and constraint
//! wrenches (`pkm_runtime::wrench`), their stack `J`, the springs `K_p`
//! from the file's `limbs` block, `K = Jᵀ K_p J` at the platform's
//! reference point, the directional stiffnesses and, under a given wrench,
//! the platform's deflection (`pkm_runtime::stiffness`), as JSON.

use super::failure::{Failure, Kind};
use super::solve::{finite, load, ordered_pose, sign_text, Request};
use pkm_runtime::newton::Output;
use pkm_runtime::wrench::RowKind;
use serde_json::{json, Value};

fn kind_name(kind: RowKind) -> &'static str {
    match kind {
        RowKind::Actuation { .. } => "actuation",
        RowKind::ConstraintForce => "constraint force",
        RowKind::ConstraintCouple => "constraint couple",
    }
}

/// Every solved branch's stiffness at the declared outputs `pose` (by
/// name), and its deflection under `wrench` (f, then its moment about the
/// reference point) if one is given.
pub fn stiffness(r: &Request, pose: &[(String, f64)], wrench: &[f64]) -> Result<Value, Failure> {
    let l = load(r)?;
    let a = &l.analysis;
    let Some(units) = a.mass_and_loads.units else {
        return Err(Failure::input(
            "stiffness needs the file's units and limbs: `units { length = mm; mass = kg; }` and a `limbs` block giving every limb's E, A, I (or its springs)",
        ));
    };
    let limbs = pkm_dsl::limb_properties::limb_properties(a, &l.values).map_err(|d| r.parse_failure(d))?;
    if limbs.is_empty() {
        return Err(Failure::input(
            "stiffness needs a `limbs` block giving every limb's E, A, I (or its springs)",
        ));
    }
    if !wrench.is_empty() && wrench.len() != 6 {
        return Err(Failure::input(format!(
            "--wrench takes 6 values (fx, fy, fz, mx, my, mz), not {}",
            wrench.len()
        )));
    }
    for (k, &w) in wrench.iter().enumerate() {
        finite(&format!("wrench component {}", k + 1), w)?;
    }
    let Some((link, local)) = l.outputs.iter().find_map(Output::point) else {
        return Err(Failure::input(
            "stiffness needs the platform's pose or a point of it among the outputs",
        ));
    };
    let plan = pkm_dsl::planner::inverse_plan(a).map_err(|d| r.parse_failure(d))?;
    let given = ordered_pose(r, &l, pose)?;
    let model = &l.model;
    let unit = units.length.symbol();
    let mut branches = Vec::new();
    let mut causes = Vec::new();
    for (signs, solution) in pkm_runtime::spatial::run_all(model, &plan, &given) {
        let signs = sign_text(&signs);
        let solution = match solution {
            Ok(s) => s,
            Err(e) => {
                causes.push(format!("branch {}: {e}", signs.concat()));
                continue;
            }
        };
        let point = pkm_runtime::spatial::at(&solution.poses[link], local);
        let analysis = match pkm_runtime::wrench::analyse(model, &solution, link) {
            Ok(w) => w,
            Err(e) => {
                branches.push(json!({ "signs": signs, "ok": false, "reason": e.to_string() }));
                continue;
            }
        };
        let declared = pkm_dsl::limb_properties::in_analysis_order(&limbs, &analysis.limbs).map_err(|k| {
            let path: Vec<&str> = analysis.limbs[k]
                .joints
                .iter()
                .map(|&j| model.joints[j].name.as_str())
                .collect();
            Failure::input(format!("the limb {} has no entry in the `limbs` block", path.join("–")))
        })?;
        let properties: Vec<_> = declared.iter().map(|d| d.properties()).collect();
        let names: Vec<&str> = declared.iter().map(|d| d.name.as_str()).collect();
        // The stiffness, its directional values and the deflection: a
        // failure of any (a singular K) is this branch's, not the command's.
        let solved = pkm_runtime::stiffness::PlatformStiffness::new(analysis, &properties, point).and_then(|k| {
            let directional = k.directional()?;
            let deflection = match <&[f64; 6]>::try_from(wrench) {
                Ok(w) => Some(k.deflection(w)?),
                Err(_) => None,
            };
            Ok((k, directional, deflection))
        });
        let (k, directional, deflection) = match solved {
            Ok(x) => x,
            Err(e) => {
                branches.push(json!({ "signs": signs, "ok": false, "reason": e.to_string() }));
                continue;
            }
        };
        let deflection = deflection.map_or(Value::Null, |d| json!({ "translation": &d[..3], "rotation": &d[3..] }));
        let at = k.k();
        let matrix: Vec<Vec<f64>> = (0..6).map(|i| (0..6).map(|j| at[(i, j)]).collect()).collect();
        let analysis = &k.wrenches;
        let p = pkm_runtime::nalgebra::Vector3::from(point);
        let rows: Vec<Value> = analysis
            .rows
            .iter()
            .zip(&k.stiffness.springs)
            .map(|(row, spring)| {
                json!({
                    "kind": kind_name(row.kind),
                    "limb": names[row.limb],
                    "force": row.wrench.f.as_slice(),
                    "moment": row.wrench.moment_about(&p).as_slice(),
                    "spring": spring,
                })
            })
            .collect();
        let legs: Vec<Value> = analysis
            .limbs
            .iter()
            .zip(&names)
            .map(|(limb, name)| {
                let joints: Vec<Value> = limb
                    .joints
                    .iter()
                    .map(|&j| {
                        let joint = &model.joints[j];
                        let first = &solution.poses[joint.links[0]];
                        let axis = first.rotation * pkm_runtime::nalgebra::Vector3::from(joint.places[0].axis());
                        json!({
                            "name": joint.name,
                            "kind": format!("{:?}", joint.kind),
                            "point": pkm_runtime::kinematics::joint_point(model, &solution.poses, j),
                            "axis": axis.normalize().as_slice(),
                        })
                    })
                    .collect();
                json!({ "name": name, "joints": joints, "length": limb.length() })
            })
            .collect();
        branches.push(json!({
            "signs": signs,
            "ok": true,
            "reference": point,
            "limbs": legs,
            "rows": rows,
            "K": matrix,
            "directional": {
                "x": directional[0], "y": directional[1], "z": directional[2],
                "rx": directional[3], "ry": directional[4], "rz": directional[5],
            },
            "deflection": deflection,
            "conditioning": analysis.sigma,
        }));
    }
    if branches.is_empty() {
        return Err(Failure::new(
            Kind::Unreachable,
            format!("no branch reaches the pose: {}", causes.join("; ")),
        ));
    }
    // Every assembly singular: no stiffness to give.
    if branches.iter().all(|b| b["ok"] == false) {
        let mut reasons: Vec<&str> = Vec::new();
        for b in &branches {
            let why = b["reason"].as_str().unwrap_or("");
            if !reasons.contains(&why) {
                reasons.push(why);
            }
        }
        return Err(Failure::new(
            Kind::Unreachable,
            format!("no branch has a stiffness here: {}", reasons.join("; ")),
        ));
    }
    let as_given: serde_json::Map<String, Value> = pose.iter().map(|(n, v)| (n.clone(), json!(v))).collect();
    Ok(json!({
        "name": model.name,
        "pose": as_given,
        "units": {
            "length": unit,
            "force": "N",
            "moment": format!("N·{unit}"),
            "angle": if r.degrees { "deg (given)" } else { "rad" },
            "K": format!("about the reference point, (δx, δy, δz, δθx, δθy, δθz) ↦ (Fx, Fy, Fz, Mx, My, Mz): N/{unit}, N, N·{unit}/rad blocks"),
            "directional": format!("1/(eᵢᵀ K⁻¹ eᵢ): N/{unit} along x, y, z; N·{unit}/rad about them"),
            "deflection": format!("{unit} and rad, of the reference point, under --wrench (N, N·{unit} about the reference point)"),
        },
        "branches": branches,
    }))
}
