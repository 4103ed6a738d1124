//! `pkm export --mjcf`: the mechanism as a MuJoCo model (MJCF XML) that
//! MuJoCo's viewer opens and simulates: one body per moving link with its
//! mass and inertia, the joints of a spanning tree, every loop closed by
//! equality constraints at a cut joint, a motor on every actuated joint,
//! the file's loads as constant forces, and a keyframe `reference` whose
//! motor inputs hold the mechanism still there (pkm's inverse dynamics at
//! rest; with `--rates`/`--accels`, in that motion).
//!
//! The model is built at a reference configuration (an assembled position
//! of the mechanism, on the study's branch: by the closed-form forward
//! plan, by the virtual variable of `fk_numeric` for κ = 1, or by the
//! inverse plan at a pose) and each joint's `ref` is pkm's value there, so
//! that a hinge's `qpos` is pkm's angle and a slide's is pkm's length in
//! metres. A link without mass carries no body where its joints can go to
//! the next body down the tree (MuJoCo composes several joints in one body
//! as a serial chain): the spanning tree is chosen so that the loops are
//! cut between links with mass, and a U joint's cross that would hang at a
//! cut is cut whole. docs/export.md gives every convention and unit.
//!
//! This file holds the command's options and `mjcf`, which puts the model
//! together; the spanning tree is in `tree.rs`, the bodies along it in
//! `bodies.rs`, the reference configuration in `reference.rs`, the motion
//! there and the forces that hold it in `holding.rs`, the XML in `writer.rs`.

use super::failure::Failure;
use super::solve::{angular, load, Request};
use pkm_runtime::kinematics::Pose;
use pkm_runtime::mass_properties::{arm_side, Body, Carrier, Loading};
use pkm_runtime::model::{JointType, Place};
use pkm_runtime::nalgebra::{Matrix3, Vector3};
use serde_json::{json, Map, Value};

mod bodies;
mod holding;
mod reference;
mod tree;
mod writer;

use bodies::{as_exported, ends_without_mass, merge, nodes, parallelogram, Assembly, Bars, Part};
use holding::{holding, motion};
use reference::reference;
use tree::{cut_crosses, spanning_tree};
use writer::{escape, num, nums, round2, scaled, unit, Writer};

/// A link declared massless (or of zero mass) that keeps a body of its own
/// (its joints cannot move to the next body: it branches, or ends the
/// tree) gets this fraction of the mechanism's total mass, and its inertia
/// this fraction of the total mass times the size squared: MuJoCo needs a
/// positive mass and inertia on every body that moves. pkm's forces for
/// the keyframe include them; `stand_in.force_change` says by how much
/// they move the holding forces.
pub const STAND_IN: f64 = 1e-11;

/// What `pkm export --mjcf` is asked.
pub struct Options<'a> {
    /// The reference configuration's inputs; empty: the study's start, else zeros.
    pub q: &'a [f64],
    /// The reference configuration's outputs by name (solved by the inverse
    /// plan); empty: inputs, or the outputs' home where there is no forward solution.
    pub pose: &'a [(String, f64)],
    /// The assembly branch (its index in `pkm fk`'s list, or `pkm ik`'s
    /// with a pose; as `branch` in a study).
    pub branch: Option<usize>,
    /// With `fk_numeric`, which of the branch's assemblies (from 0, in `pkm fk`'s order).
    pub assembly: Option<usize>,
    /// The inputs' rates at the reference (input order); empty: at rest.
    pub rates: &'a [f64],
    /// The inputs' accelerations at the reference; empty: zero.
    pub accels: &'a [f64],
    /// The simulation timestep (s).
    pub timestep: f64,
}

/// The MJCF text and a description of how it maps to the mechanism.
pub struct Exported {
    /// The MJCF XML.
    pub xml: String,
    /// The joint map, the cut joints, the actuators, the stand-in masses.
    pub info: Map<String, Value>,
}

/// `pkm export --mjcf`: the MJCF text of the mechanism at its reference configuration.
pub fn mjcf(r: &Request, o: &Options) -> Result<Exported, Failure> {
    let l = load(r)?;
    let a = &l.compiled.analysis;
    let model = &l.model;
    let Some(units) = a.mass_and_loads.units else {
        return Err(Failure::input(
            "export needs the file's units and masses: `units { length = mm; mass = kg; }` and a `masses` block giving every moving link a mass or declaring it massless",
        ));
    };
    if !(o.timestep.is_finite() && o.timestep > 0.0) {
        return Err(Failure::input(format!(
            "--timestep = {} is not a positive time",
            o.timestep
        )));
    }
    let loading = pkm_dsl::numeric::loading(a, model, &l.values).map_err(|d| r.parse_failure(d))?;
    if let Some(j) = model.joints.iter().find(|j| j.actuated && j.kind == JointType::S) {
        return Err(Failure::input(format!(
            "export cannot drive the spherical joint {}: a motor acts on one joint variable",
            j.name
        )));
    }
    let total: f64 = loading.bodies.iter().map(|b| b.mass).sum();
    if total <= 0.0 {
        return Err(Failure::input(
            "export needs some mass: every moving link is massless, and MuJoCo cannot simulate that",
        ));
    }
    let m = units.length.metres();
    let reference = reference(r, &l, o)?;
    let (inputs, given, branch, signs, solution, at) = (
        &reference.inputs,
        &reference.given,
        reference.branch,
        &reference.signs,
        &reference.solution,
        &reference.at,
    );
    // The model's layout: three values per spherical joint.
    let values = solution.model_values(model);
    let motion = motion(r, model, inputs, &values, o)?;
    let assembly = Assembly {
        model,
        poses: solution.poses.iter().map(Pose::from).collect(),
        values,
        rates: motion.rates.clone(),
        accels: motion.accels.clone(),
        offsets: model.value_offsets().0,
        m,
    };

    let mut link_bodies: Vec<Option<Body>> = vec![None; model.links.len()];
    let mut bars = Bars { all: Vec::new() };
    for b in loading.bodies.iter().filter(|b| b.mass > 0.0) {
        match b.carrier {
            Carrier::Link(l) => link_bodies[l] = Some(b.clone()),
            Carrier::Bar { joint, .. } => {
                if arm_side(model, joint).is_none() {
                    return Err(Failure::input(format!(
                        "a bar of joint {}, which is not a parallelogram with an arm",
                        model.joints.get(joint).map_or("?", |j| j.name.as_str())
                    )));
                }
                bars.all.push(b.clone());
            }
        }
    }
    let light: Vec<bool> = (0..model.links.len())
        .map(|l| l > 0 && link_bodies[l].is_none())
        .collect();
    let mut loaded = vec![false; model.links.len()];
    for p in &loading.loads {
        loaded[p.link] = true;
    }
    let mut tree = spanning_tree(model, &light)?;
    cut_crosses(model, &mut tree, &light, &loaded);
    let nodes = nodes(&assembly, &tree, &link_bodies, &bars)?;
    let merged = merge(&nodes, model, &tree, &loaded);
    ends_without_mass(model, &tree, &nodes, &merged)?;

    // Mass properties as MuJoCo gets them (file units): declared, or the stand-ins.
    let size = pkm_runtime::kinematics::model_scale(model);
    let tiny = (STAND_IN * total, STAND_IN * total * size * size);
    let mut stand_ins = Vec::new();
    let bodies: Vec<Option<Body>> = nodes
        .nodes
        .iter()
        .enumerate()
        .map(|(k, node)| {
            if k == 0 || merged.merged[k] {
                return None;
            }
            if let Some(b) = &node.body {
                return Some(as_exported(b, model.planar, tiny.1));
            }
            let carrier = match node.part {
                Part::Link(l) => Carrier::Link(l),
                Part::TreeBar { joint, .. } => Carrier::Bar {
                    joint,
                    hinge: parallelogram(model, &assembly.poses, joint)
                        .map_or([0.0; 3], |p| p.arm_at)
                        .into(),
                },
                Part::Base | Part::Bar { .. } => return None,
            };
            stand_ins.push(k);
            Some(Body {
                carrier,
                mass: tiny.0,
                centroid: Vector3::zeros(),
                inertia: Matrix3::identity() * tiny.1,
            })
        })
        .collect();
    let exported_loading = Loading {
        bodies: bodies.iter().flatten().cloned().collect(),
        ..loading.clone()
    };
    let skcs = pkm_dsl::numeric::skc_parts(a);
    let held = holding(model, &exported_loading, &skcs, &assembly.values, inputs, &motion);
    let declared = holding(model, &loading, &skcs, &assembly.values, inputs, &motion);

    let mut w = Writer {
        model,
        m,
        assembly: &assembly,
        nodes: &nodes,
        merged: &merged,
        bodies,
        // Drawn 1% of the size thick, to two figures (only the look depends on it).
        radius: round2(0.01 * size * m),
        xml: String::new(),
        joints: Map::new(),
        qpos: Vec::new(),
        qvel: Vec::new(),
    };
    let g = loading.gravity * m;
    let solref = format!(
        r#"solref="{} 1" solimp="0.9999 0.9999 0.001 0.5 2""#,
        num(2.0 * o.timestep)
    );
    let title = a.mechanism.title.clone().unwrap_or_default().replace("--", "—");
    w.line(0, &format!(r#"<mujoco model="{}">"#, escape(&model.name)));
    w.line(
        1,
        &format!(
            "<!-- {title}: written by pkm export at the {at}, branch {branch} ({}).",
            signs.concat()
        ),
    );
    w.line(
        1,
        "     SI units: metres, kilograms, seconds, radians; docs/export.md gives the conventions.",
    );
    w.line(
        1,
        "     The keyframe `reference` holds it still: its ctrl is pkm's inverse dynamics at rest. -->",
    );
    w.line(
        1,
        r#"<compiler angle="radian" inertiafromgeom="false" autolimits="true"/>"#,
    );
    w.line(
        1,
        &format!(
            r#"<option timestep="{}" integrator="implicitfast" gravity="{}">"#,
            num(o.timestep),
            nums(&[g.x, g.y, g.z])
        ),
    );
    // The drawing is not a body's shape: nothing collides.
    w.line(2, r#"<flag contact="disable"/>"#);
    w.line(1, "</option>");
    w.line(1, "<default>");
    w.line(2, r#"<geom contype="0" conaffinity="0" rgba="0.3 0.5 0.8 1"/>"#);
    w.line(1, "</default>");
    w.line(1, "<worldbody>");
    w.line(2, r#"<light pos="0 0 3" dir="0 0 -1" directional="true"/>"#);
    // The base: its joints' points and its guide lines.
    w.link_geoms(2, 0);
    let mut lines = Vec::new();
    for j in &model.joints {
        for s in 0..2 {
            if let (0, Place::Line { through, along }) = (j.links[s], j.places[s]) {
                let d = unit(along);
                let ends: Vec<f64> = [-1.0, 1.0]
                    .iter()
                    .flat_map(|k| [0, 1, 2].map(|i| (through[i] + k * size * d[i]) * m))
                    .collect();
                let line = format!(
                    r#"<geom type="capsule" size="{}" fromto="{}" rgba="0.5 0.5 0.5 1"/>"#,
                    num(0.5 * w.radius),
                    nums(&ends)
                );
                // Two joints on one guide: one line.
                if !lines.contains(&line) {
                    lines.push(line);
                }
            }
        }
    }
    for text in lines {
        w.line(2, &text);
    }
    // The loads: constant forces through a site of their link, in the world's axes.
    let load_names: Vec<String> = a
        .mass_and_loads
        .loads
        .iter()
        .map(|p| format!("load.{}", p.name))
        .collect();
    let mut sites: Vec<(String, usize, [f64; 3])> = load_names
        .iter()
        .zip(&loading.loads)
        .map(|(n, p)| (n.clone(), p.link, p.at.into()))
        .collect();
    if !sites.is_empty() {
        w.line(2, r#"<site name="pkm.world" pos="0 0 0"/>"#);
    }
    // A cut U's two points, one on each axis a size from the centre, in
    // the frames of the links on either side (the tendon's ends).
    let mut tendons = Vec::new();
    for c in &tree.crosses {
        let cross = &assembly.poses[c.link];
        let name = &model.links[c.link];
        let mut ends = Vec::new();
        for (k, (&j, &end)) in c.joints.iter().zip(&c.ends).enumerate() {
            let joint = &model.joints[j];
            let axis = unit(cross.rotate(joint.places[usize::from(joint.links[1] == c.link)].axis()));
            let point = cross.transform_point(c.centre);
            let along = [0, 1, 2].map(|i| point[i] + size * axis[i]);
            let site = format!("{name}.{}", ["a", "b"][k]);
            sites.push((site.clone(), end, assembly.poses[end].inverse().transform_point(along)));
            ends.push(site);
        }
        tendons.push((format!("{name}.angle"), ends));
    }
    for c in nodes.nodes[0].children.clone() {
        w.body(2, w.down(c), &sites);
    }
    w.line(1, "</worldbody>");
    if !tendons.is_empty() {
        w.line(1, "<tendon>");
        for (name, ends) in &tendons {
            w.line(
                2,
                &format!(r#"<spatial name="{}" width="{}">"#, escape(name), num(0.5 * w.radius)),
            );
            for site in ends {
                w.line(3, &format!(r#"<site site="{}"/>"#, escape(site)));
            }
            w.line(2, "</spatial>");
        }
        w.line(1, "</tendon>");
    }

    let mut equalities = Vec::new();
    let mut cut = Vec::new();
    for &c in &tree.cut {
        let j = &model.joints[c];
        cut.push(j.name.clone());
        let body = |link: usize| w.name(w.body_of_link(link));
        let (name, body1, body2) = (escape(&j.name), body(j.links[0]), body(j.links[1]));
        let at = j.places[0].at();
        let connect = |name: &str, p: [f64; 3]| {
            format!(
                r#"<connect name="{name}" body1="{body1}" body2="{body2}" anchor="{}" {solref}/>"#,
                nums(&scaled(p, m))
            )
        };
        equalities.push(connect(&name, at));
        // A spatial hinge: a second point on its axis keeps the axes together.
        if j.kind == JointType::R && !model.planar {
            let d = unit(j.places[0].axis());
            equalities.push(connect(&format!("{name}.axis"), [0, 1, 2].map(|i| at[i] + size * d[i])));
        }
    }
    // A cut U: its neighbours share the centre, and the tendon between its
    // axes keeps its length at the reference (the angle between the axes).
    let mut crosses = Vec::new();
    for (c, (tendon, _)) in tree.crosses.iter().zip(&tendons) {
        let [u, v] = c.ends;
        let (body1, body2) = (w.name(w.body_of_link(u)), w.name(w.body_of_link(v)));
        let centre = assembly.poses[u]
            .inverse()
            .transform_point(assembly.poses[c.link].transform_point(c.centre));
        let name = escape(&model.links[c.link]);
        equalities.push(format!(
            r#"<connect name="{name}" body1="{body1}" body2="{body2}" anchor="{}" {solref}/>"#,
            nums(&scaled(centre, m))
        ));
        let tendon = escape(tendon);
        equalities.push(format!(
            r#"<tendon name="{tendon}" tendon1="{tendon}" polycoef="0 0 0 0 0" {solref}/>"#
        ));
        crosses.push(json!({
            "cross": model.links[c.link],
            "joints": c.joints.map(|j| model.joints[j].name.clone()),
            "bodies": [body1, body2],
            "connect": model.links[c.link],
            "tendon": tendon,
        }));
    }
    for node in &nodes.nodes {
        match node.part {
            Part::TreeBar { joint, .. } => {
                let name = escape(&model.joints[joint].name);
                equalities.push(format!(
                    r#"<joint name="{name}.tie" joint1="{name}.tip" joint2="{name}" polycoef="0 -1 0 0 0" {solref}/>"#
                ));
            }
            // Another bar turns with its parallelogram's value.
            Part::Bar { joint, number, .. } => {
                let name = escape(&model.joints[joint].name);
                equalities.push(format!(
                    r#"<joint name="{name}.bar{number}.tie" joint1="{name}.bar{number}" joint2="{name}" polycoef="0 1 0 0 0" {solref}/>"#
                ));
            }
            _ => {}
        }
    }
    if !equalities.is_empty() {
        w.line(1, "<equality>");
        for e in &equalities {
            w.line(2, e);
        }
        w.line(1, "</equality>");
    }

    let mut actuators = Map::new();
    let mut ctrl = Vec::new();
    w.line(1, "<actuator>");
    for (k, &j) in inputs.iter().enumerate() {
        let joint = &model.joints[j];
        let name = escape(&joint.name);
        w.line(2, &format!(r#"<motor name="{name}" joint="{name}" gear="1"/>"#));
        let (unit_name, to_pkm) = if angular(joint.kind) {
            ("N·m", 1.0 / m)
        } else {
            ("N", 1.0)
        };
        ctrl.push(held.as_ref().map_or(0.0, |h| h.forces[k] / to_pkm));
        actuators.insert(
            joint.name.clone(),
            json!({ "joint": joint.name, "unit": unit_name, "to_pkm": to_pkm }),
        );
    }
    // Each load a force and moment (N, N·m) at its site, in the world's axes, at a fixed ctrl of 1.
    let mut applied = Vec::new();
    for ((named, p), site) in a.mass_and_loads.loads.iter().zip(&loading.loads).zip(&load_names) {
        let (point, force, moment) = (p.at * m, p.force * m, p.moment * (m * m));
        let gear = [force.x, force.y, force.z, moment.x, moment.y, moment.z];
        let site = escape(site);
        w.line(
            2,
            &format!(
                r#"<general name="{site}" site="{site}" refsite="pkm.world" gear="{}" ctrlrange="1 1"/>"#,
                nums(&gear)
            ),
        );
        ctrl.push(1.0);
        applied.push(json!({
            "name": named.name,
            "actuator": format!("load.{}", named.name),
            "body": w.name(w.body_of_link(p.link)),
            "point": [point.x, point.y, point.z],
            "force": [force.x, force.y, force.z],
            "moment": [moment.x, moment.y, moment.z],
        }));
    }
    w.line(1, "</actuator>");
    w.line(1, "<keyframe>");
    let qvel = if motion.given {
        format!(r#" qvel="{}""#, nums(&w.qvel))
    } else {
        String::new()
    };
    let key = format!(
        r#"<key name="reference" qpos="{}"{qvel} ctrl="{}"/>"#,
        nums(&w.qpos),
        nums(&ctrl)
    );
    w.line(2, &key);
    w.line(1, "</keyframe>");
    w.line(0, "</mujoco>");

    let names: Vec<&str> = inputs.iter().map(|&j| model.joints[j].name.as_str()).collect();
    let by_name =
        |v: &[f64]| -> Map<String, Value> { names.iter().zip(v).map(|(n, x)| (n.to_string(), json!(x))).collect() };
    let mut info = Map::new();
    info.insert("name".into(), json!(model.name));
    info.insert("metres_per_unit".into(), json!(m));
    info.insert("size".into(), json!(size * m));
    info.insert("branch".into(), json!(branch));
    info.insert("signs".into(), json!(signs));
    info.insert("branch_from".into(), json!(reference.branch_from));
    info.insert("inputs".into(), Value::Object(by_name(given)));
    // The inputs in the order `--q`, `pkm dynamics` and the keyframe's ctrl take them.
    info.insert("input_order".into(), json!(names));
    info.insert("inputs_from".into(), json!(reference.inputs_from));
    // How the reference was solved: `solver`, the pose or the virtual variable.
    info.extend(reference.how.clone());
    // The inputs' rates and accelerations (the model's input order: by name).
    let by_input = |v: &[f64]| -> Map<String, Value> {
        model
            .inputs()
            .iter()
            .zip(v)
            .map(|(&j, x)| (model.joints[j].name.clone(), json!(x)))
            .collect()
    };
    info.insert(
        "motion".into(),
        json!({
            "at_rest": !motion.given,
            "rates": by_input(&motion.input_rates),
            "accelerations": by_input(&motion.input_accels),
        }),
    );
    info.insert("joints".into(), Value::Object(w.joints.clone()));
    info.insert("cut".into(), json!(cut));
    info.insert("cut_crosses".into(), json!(crosses));
    info.insert("actuators".into(), Value::Object(actuators));
    let merged_links: Map<String, Value> = (1..model.links.len())
        .filter(|&l| merged.merged[nodes.of_link[l]])
        .map(|l| (model.links[l].clone(), json!(w.name(w.body_of_link(l)))))
        .collect();
    info.insert("merged".into(), Value::Object(merged_links));
    let change = match (&held, &declared) {
        (Ok(h), Ok(d)) => {
            let peak = d.forces.iter().fold(0.0f64, |p, x| p.max(x.abs()));
            let most = h
                .forces
                .iter()
                .zip(&d.forces)
                .fold(0.0f64, |p, (x, y)| p.max((x - y).abs()));
            json!(if peak > 0.0 { most / peak } else { most })
        }
        _ => Value::Null,
    };
    info.insert(
        "stand_in".into(),
        json!({
            "mass": tiny.0,
            "inertia": tiny.1 * m * m,
            "bodies": stand_ins.iter().map(|&k| w.name(k)).collect::<Vec<_>>(),
            "force_change": change,
        }),
    );
    info.insert(
        "holding".into(),
        match (&held, &declared) {
            (Ok(h), Ok(d)) => json!({
                "ok": true,
                "actuators": by_name(&h.forces),
                "as_declared": by_name(&d.forces),
                "conditioning": d.conditioning,
            }),
            (Err(e), _) | (_, Err(e)) => json!({ "ok": false, "reason": e }),
        },
    );
    info.insert("loads".into(), json!(applied));
    info.insert("keyframe".into(), json!("reference"));
    Ok(Exported { xml: w.xml, info })
}
