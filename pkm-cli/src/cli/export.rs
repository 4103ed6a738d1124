//! `pkm export --mjcf`: the mechanism as a MuJoCo model (MJCF XML) that
//! MuJoCo's viewer opens and simulates: one body per moving link with its
//! mass and inertia, the joints of a spanning tree, every loop closed by
//! equality constraints at a cut joint, and a motor on every actuated joint.
//!
//! The model is built at a reference configuration (an assembled position
//! of the mechanism) and each joint's `ref` is pkm's value there, so that a
//! hinge's `qpos` is pkm's angle and a slide's is pkm's length in metres.
//! docs/export.md gives every convention and unit.

use super::failure::{Failure, Kind};
use super::solve::{angular, input_values, load, Request};
use pkm_runtime::kinematics::Pose;
use pkm_runtime::mass_properties::{arm_side, Carrier, Loading};
use pkm_runtime::model::{Joint, JointType, Model, Place};
use pkm_runtime::nalgebra::Matrix3;
use serde_json::{json, Map, Value};
use std::fmt::Write;

/// A link declared massless (or of zero mass) gets this fraction of the
/// mechanism's total mass, and its inertia this fraction of the total mass
/// times the size squared: MuJoCo needs a positive mass and inertia on every
/// body that moves, and these change the actuators' forces by about this
/// fraction (docs/export.md shows it stays below 1e-9).
pub const STAND_IN: f64 = 1e-11;

/// What `pkm export --mjcf` is asked.
pub struct Options<'a> {
    /// The reference configuration's inputs; empty: the study's start, else zeros.
    pub q: &'a [f64],
    /// The assembly branch (its index, as `branch` in a study).
    pub branch: Option<usize>,
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

/// A spanning tree of the link graph for MuJoCo's bodies.
struct Tree {
    /// Per link, the joints to its children and the children.
    children: Vec<Vec<(usize, usize)>>,
    /// The joints left out, each closed by equality constraints.
    cut: Vec<usize>,
}

/// The tree keeps the actuated joints (a motor needs a joint of the tree),
/// then slides and parallelograms (no equality constraint closes them),
/// then revolutes, then spherical joints: loops are cut at a spherical
/// joint (one `connect`) or a revolute one (one or two `connect`s).
fn spanning_tree(model: &Model) -> Result<Tree, Failure> {
    let rank = |j: &Joint| match (j.actuated, j.kind) {
        (true, _) => 0,
        (false, JointType::P) => 1,
        (false, JointType::Pa) => 2,
        (false, JointType::R) => 3,
        (false, JointType::S) => 4,
    };
    let mut order: Vec<usize> = (0..model.joints.len()).collect();
    order.sort_by_key(|&j| rank(&model.joints[j]));
    let mut root: Vec<usize> = (0..model.links.len()).collect();
    fn find(root: &mut [usize], mut x: usize) -> usize {
        while root[x] != x {
            root[x] = root[root[x]];
            x = root[x];
        }
        x
    }
    let mut in_tree = vec![false; model.joints.len()];
    for &j in &order {
        let [u, v] = model.joints[j].links;
        let (a, b) = (find(&mut root, u), find(&mut root, v));
        if a != b {
            root[a] = b;
            in_tree[j] = true;
        }
    }
    let cut: Vec<usize> = (0..model.joints.len()).filter(|&j| !in_tree[j]).collect();
    for &j in &cut {
        let joint = &model.joints[j];
        let why = match (joint.actuated, joint.kind) {
            (true, _) => "it is actuated, and its loop has no passive joint to cut instead",
            (false, JointType::P) => "it is a slide, and its loop has no revolute or spherical joint to cut instead",
            (false, JointType::Pa) => {
                "it is a parallelogram, and its loop has no revolute or spherical joint to cut instead"
            }
            _ => continue,
        };
        return Err(Failure::input(format!(
            "export cannot close the loop at joint {}: {why}",
            joint.name
        )));
    }
    // Children by a walk from the base along the tree's joints.
    let mut children = vec![Vec::new(); model.links.len()];
    let mut reached = vec![false; model.links.len()];
    reached[0] = true;
    let mut queue = std::collections::VecDeque::from([0]);
    while let Some(l) = queue.pop_front() {
        for (j, joint) in model.joints.iter().enumerate().filter(|(j, _)| in_tree[*j]) {
            let other = match joint.links {
                [u, v] if u == l => v,
                [u, v] if v == l => u,
                _ => continue,
            };
            if !reached[other] {
                reached[other] = true;
                children[l].push((j, other));
                queue.push_back(other);
            }
        }
    }
    if let Some(l) = reached.iter().position(|r| !r) {
        return Err(Failure::input(format!(
            "link {} is not connected to the base",
            model.links[l]
        )));
    }
    Ok(Tree { children, cut })
}

/// A number for the XML: the shortest text that reads back to it.
fn num(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else if (1e-4..1e7).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// `x` to two significant figures.
fn round2(x: f64) -> f64 {
    if x > 0.0 && x.is_finite() {
        let k = 10f64.powi(1 - x.log10().floor() as i32);
        (x * k).round() / k
    } else {
        x
    }
}

fn nums(v: &[f64]) -> String {
    v.iter().map(|&x| num(x)).collect::<Vec<_>>().join(" ")
}

fn scaled(v: [f64; 3], k: f64) -> [f64; 3] {
    v.map(|x| x * k)
}

fn unit(v: [f64; 3]) -> [f64; 3] {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    scaled(v, 1.0 / n)
}

/// A name or title as XML attribute text.
fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A pose as `pos` and `quat` attributes (translation already in metres).
fn placed(p: &Pose<f64>) -> String {
    format!(r#"pos="{}" quat="{}""#, nums(&p.translation), nums(&p.rotation))
}

/// The mass properties MuJoCo reads: mass, centroid and inertia tensor in
/// SI, with the stand-ins where a link has none.
struct Inertial {
    mass: f64,
    centroid: [f64; 3],
    inertia: Matrix3<f64>,
    stand_in: bool,
}

impl Inertial {
    fn xml(&self) -> String {
        let i = &self.inertia;
        format!(
            r#"<inertial pos="{}" mass="{}" fullinertia="{}"/>"#,
            nums(&self.centroid),
            num(self.mass),
            nums(&[i[(0, 0)], i[(1, 1)], i[(2, 2)], i[(0, 1)], i[(0, 2)], i[(1, 2)]])
        )
    }
}

/// Everything the writer reads.
struct Writer<'a> {
    model: &'a Model,
    /// Metres per file length unit.
    m: f64,
    /// Link poses at the reference configuration (file units).
    poses: Vec<Pose<f64>>,
    values: Vec<f64>,
    offsets: Vec<usize>,
    inertials: Vec<Inertial>,
    bars: Vec<Bar>,
    /// Stand-in mass and inertia (kg, kg·m²).
    tiny: (f64, f64),
    /// Geometry radius (m).
    radius: f64,
    tree: Tree,
    xml: String,
    joints: Map<String, Value>,
    stand_ins: Vec<String>,
}

impl Writer<'_> {
    fn line(&mut self, depth: usize, text: &str) {
        let _ = writeln!(self.xml, "{}{text}", "  ".repeat(depth));
    }

    fn name(&self, link: usize) -> String {
        if link == 0 {
            "world".into()
        } else {
            escape(&self.model.links[link])
        }
    }

    /// A joint's MuJoCo names and pkm's: `qpos = scale · value`.
    fn map(&mut self, mj: &str, joint: usize, kind: &str, scale: f64) {
        let j = &self.model.joints[joint];
        let value = self.values[self.offsets[joint]];
        self.joints.insert(
            mj.to_string(),
            json!({ "pkm": j.name, "type": kind, "scale": scale, "reference": value }),
        );
    }

    /// The bars with mass that `link` carries: each a body hinged at its
    /// hinge about the parallelogram's axis, at its turn at the reference
    /// configuration (`ref`, so that `qpos` is the joint's value; an
    /// equality ties it to the joint's hinge).
    fn bars(&mut self, depth: usize, link: usize) {
        let m = self.m;
        for k in 0..self.bars.len() {
            let b = &self.bars[k];
            if b.carrier != link {
                continue;
            }
            let (joint, hinge, axis) = (b.joint, b.hinge, b.axis);
            let value = self.values[self.offsets[joint]];
            let (c, s) = ((0.5 * value).cos(), (0.5 * value).sin());
            let turn = Pose {
                rotation: [c, s * axis[0], s * axis[1], s * axis[2]],
                translation: scaled(hinge, m),
            };
            let inertial = b.inertial.xml();
            let name = format!("{}.bar{}", self.model.joints[joint].name, k + 1);
            self.map(&name, joint, "hinge", 1.0);
            let name = escape(&name);
            self.line(depth, &format!(r#"<body name="{name}" {}>"#, placed(&turn)));
            self.line(
                depth + 1,
                &format!(
                    r#"<joint name="{name}" type="hinge" pos="0 0 0" axis="{}" ref="{}"/>"#,
                    nums(&axis),
                    num(value)
                ),
            );
            self.line(depth + 1, &inertial);
            self.line(depth, "</body>");
        }
    }

    /// The visible parts of a link: spheres at its joints' and named
    /// points, capsules between them (file units in, metres out).
    fn geoms(&mut self, depth: usize, link: usize) {
        let mut points: Vec<[f64; 3]> = Vec::new();
        for j in &self.model.joints {
            for s in 0..2 {
                if j.links[s] == link && !matches!(j.places[s], Place::Line { .. }) {
                    points.push(j.places[s].at());
                }
            }
        }
        points.extend(self.model.points.iter().filter(|p| p.link == link).map(|p| p.at));
        let size = pkm_runtime::kinematics::model_scale(self.model);
        let mut kept: Vec<[f64; 3]> = Vec::new();
        for p in points {
            let far = |q: &[f64; 3]| (0..3).map(|i| (p[i] - q[i]).powi(2)).sum::<f64>().sqrt() > 1e-9 * size;
            if kept.iter().all(far) {
                kept.push(p);
            }
        }
        let at = |p: [f64; 3], m: f64| scaled(p, m);
        let (r, m) = (self.radius, self.m);
        for p in &kept {
            let text = format!(
                r#"<geom type="sphere" size="{}" pos="{}"/>"#,
                num(round2(1.5 * r)),
                nums(&at(*p, m))
            );
            self.line(depth, &text);
        }
        for w in kept.windows(2) {
            let mut ends = at(w[0], m).to_vec();
            ends.extend(at(w[1], m));
            let text = format!(r#"<geom type="capsule" size="{}" fromto="{}"/>"#, num(r), nums(&ends));
            self.line(depth, &text);
        }
    }

    /// Link `link`'s body, reached from `parent` through joint `joint`, and its subtree.
    fn body(&mut self, depth: usize, parent: usize, joint: usize, link: usize) {
        let j = self.model.joints[joint].clone();
        let (m, value) = (self.m, self.values[self.offsets[joint]]);
        let child_side = usize::from(j.links[1] == link);
        let relative = self.poses[parent].inverse().then(&self.poses[link]);
        let in_metres = |p: Pose<f64>| Pose {
            translation: scaled(p.translation, m),
            ..p
        };
        let name = escape(&j.name);
        let mut depth = depth;
        let mut closing = 1;
        let place = j.places[child_side];
        let joint_xml = match j.kind {
            JointType::R => {
                // v turns by +θ about its axis relative to u; u by −θ relative to v.
                let sign = if child_side == 1 { 1.0 } else { -1.0 };
                self.map(&j.name, joint, "hinge", 1.0);
                format!(
                    r#"<joint name="{name}" type="hinge" pos="{}" axis="{}" ref="{}"/>"#,
                    nums(&scaled(place.at(), m)),
                    nums(&scaled(unit(place.axis()), sign)),
                    num(value)
                )
            }
            JointType::P => {
                // The slider's point runs +d̂ along the guide; the two links keep one orientation.
                let guide = if matches!(j.places[0], Place::Line { .. }) {
                    0
                } else {
                    1
                };
                let d = match j.places[guide] {
                    Place::Point { .. } => [1.0, 0.0, 0.0],
                    p => unit(p.axis()),
                };
                let sign = if child_side == guide { -1.0 } else { 1.0 };
                self.map(&j.name, joint, "slide", m);
                format!(
                    r#"<joint name="{name}" type="slide" pos="{}" axis="{}" ref="{}"/>"#,
                    nums(&scaled(place.at(), m)),
                    nums(&scaled(d, sign)),
                    num(value * m)
                )
            }
            JointType::S => {
                self.map(&j.name, joint, "ball", 1.0);
                format!(
                    r#"<joint name="{name}" type="ball" pos="{}"/>"#,
                    nums(&scaled(place.at(), m))
                )
            }
            JointType::Pa => {
                // A bar hinged on the parent at its place, turning with θ;
                // the child hinged at the bar's tip, turning back by θ (a
                // joint equality ties the two), so that it translates.
                let root = j.places[1 - child_side];
                let bar = Pose::translation(scaled(root.at(), m));
                self.map(&j.name, joint, "hinge", 1.0);
                let mut tip = format!("{}.tip", j.name);
                self.map(&tip, joint, "hinge", -1.0);
                tip = escape(&tip);
                self.line(
                    depth,
                    &format!(r#"<body name="{}.bar" {}>"#, escape(&j.name), placed(&bar)),
                );
                self.line(
                    depth + 1,
                    &format!(
                        r#"<joint name="{name}" type="hinge" pos="0 0 0" axis="{}" ref="{}"/>"#,
                        nums(&unit(root.axis())),
                        num(value)
                    ),
                );
                let (mass, inertia) = self.tiny;
                self.line(
                    depth + 1,
                    &format!(
                        r#"<inertial pos="0 0 0" mass="{}" diaginertia="{i} {i} {i}"/>"#,
                        num(mass),
                        i = num(inertia)
                    ),
                );
                self.stand_ins.push(format!("{}.bar", j.name));
                // The tip: the child's hinge point seen from the bar.
                let tip_at = relative.transform_point(place.at());
                let ends = [
                    0.0,
                    0.0,
                    0.0,
                    tip_at[0] - root.at()[0],
                    tip_at[1] - root.at()[1],
                    tip_at[2] - root.at()[2],
                ]
                .map(|x| x * m);
                self.line(
                    depth + 1,
                    &format!(
                        r#"<geom type="capsule" size="{}" fromto="{}"/>"#,
                        num(self.radius),
                        nums(&ends)
                    ),
                );
                depth += 1;
                closing += 1;
                format!(
                    r#"<joint name="{tip}" type="hinge" pos="{}" axis="{}" ref="{}"/>"#,
                    nums(&scaled(place.at(), m)),
                    nums(&unit(place.axis())),
                    num(-value)
                )
            }
        };
        let mut pose = in_metres(relative);
        if j.kind == JointType::Pa {
            pose.translation = [0, 1, 2].map(|i| pose.translation[i] - j.places[1 - child_side].at()[i] * m);
        }
        self.line(
            depth,
            &format!(r#"<body name="{}" {}>"#, self.name(link), placed(&pose)),
        );
        self.line(depth + 1, &joint_xml);
        let inertial = self.inertials[link].xml();
        self.line(depth + 1, &inertial);
        if self.inertials[link].stand_in {
            self.stand_ins.push(self.model.links[link].clone());
        }
        self.geoms(depth + 1, link);
        self.bars(depth + 1, link);
        for (k, child) in self.tree.children[link].clone() {
            self.body(depth + 1, link, k, child);
        }
        for d in (depth + 1 - closing..=depth).rev() {
            self.line(d, "</body>");
        }
    }
}

/// A parallelogram's bar with mass: a body of its own, hinged on the
/// link that holds the joint's arm and tied to the joint's value.
struct Bar {
    joint: usize,
    /// The arm-carrying link.
    carrier: usize,
    /// The hinge (file units) and its unit axis, in the carrier's frame.
    hinge: [f64; 3],
    axis: [f64; 3],
    inertial: Inertial,
}

/// The mass properties of every link in SI, stand-ins where none, and the
/// parallelograms' bars that have mass.
/// Every link's mass properties, the bars with mass, and the stand-in
/// mass and inertia.
type Inertials = (Vec<Inertial>, Vec<Bar>, (f64, f64));

fn inertials(model: &Model, loading: &Loading, m: f64) -> Result<Inertials, Failure> {
    let total: f64 = loading.bodies.iter().map(|b| b.mass).sum();
    if total <= 0.0 {
        return Err(Failure::input(
            "export needs some mass: every moving link is massless, and MuJoCo cannot simulate that",
        ));
    }
    let size = pkm_runtime::kinematics::model_scale(model) * m;
    let tiny = (STAND_IN * total, STAND_IN * total * size * size);
    let mut out: Vec<Inertial> = (0..model.links.len())
        .map(|_| Inertial {
            mass: tiny.0,
            centroid: [0.0; 3],
            inertia: Matrix3::identity() * tiny.1,
            stand_in: true,
        })
        .collect();
    let mut bars = Vec::new();
    for b in &loading.bodies {
        if b.mass <= 0.0 {
            continue;
        }
        let mut inertia = b.inertia * (m * m);
        if model.planar {
            // A planar link turns about z only: its moments about x and y
            // play no part; equal to the one about z they make a valid body.
            inertia[(0, 0)] = inertia[(2, 2)];
            inertia[(1, 1)] = inertia[(2, 2)];
        }
        // A point mass, a thin rod or a flat plate gets the stand-in
        // inertia added: MuJoCo wants every principal moment positive and
        // the triangle inequality strict (a plate's I₁ + I₂ = I₃ may round
        // below), and adding c to each moment adds c to both margins.
        let principal = inertia.symmetric_eigenvalues();
        let trace = principal.sum();
        let margin = principal
            .iter()
            .fold(f64::INFINITY, |a, &p| a.min(p).min(trace - 2.0 * p));
        if margin.is_nan() || margin < tiny.1 {
            inertia += Matrix3::identity() * tiny.1;
        }
        let inertial = Inertial {
            mass: b.mass,
            centroid: [0, 1, 2].map(|i| b.centroid[i] * m),
            inertia,
            stand_in: false,
        };
        match b.carrier {
            Carrier::Link(l) => out[l] = inertial,
            Carrier::Bar { joint, hinge } => {
                let Some((carrier, axis)) = arm_side(model, joint) else {
                    return Err(Failure::input(format!(
                        "a bar of joint {}, which is not a parallelogram with an arm",
                        model.joints.get(joint).map_or("?", |j| j.name.as_str())
                    )));
                };
                bars.push(Bar {
                    joint,
                    carrier,
                    hinge: hinge.into(),
                    axis: axis.into(),
                    inertial,
                });
            }
        }
    }
    Ok((out, bars, tiny))
}

/// The reference configuration's inputs: given, else the study's start, else zeros.
fn reference_inputs(
    r: &Request,
    l: &super::solve::Loaded,
    inputs: &[usize],
    q: &[f64],
) -> Result<(Vec<f64>, &'static str), Failure> {
    let model = &l.model;
    if !q.is_empty() {
        return Ok((input_values(r, model, inputs, "--q", q)?, "--q"));
    }
    let ast = pkm_dsl::parse(r.source).map_err(|d| r.parse_failure(d.into()))?;
    let names: Vec<String> = model
        .joints
        .iter()
        .filter(|j| j.actuated)
        .map(|j| j.name.clone())
        .collect();
    let values = pkm_dsl::numeric::parameter_values(&l.analysis, &l.values).map_err(|d| r.parse_failure(d))?;
    let study = pkm_dsl::study::resolve(&ast.studies, &names, &values).map_err(|d| r.parse_failure(d))?;
    match study.start {
        // The study's start is in the declaration order of the actuated joints.
        Some(start) => Ok((
            inputs
                .iter()
                .map(|&j| {
                    let k = names.iter().position(|n| *n == model.joints[j].name).unwrap_or(0);
                    start.get(k).copied().unwrap_or(0.0)
                })
                .collect(),
            "the study's start",
        )),
        None => Ok((vec![0.0; inputs.len()], "zeros")),
    }
}

/// `pkm export --mjcf`: the MJCF text of the mechanism at its reference configuration.
pub fn mjcf(r: &Request, o: &Options) -> Result<Exported, Failure> {
    let l = load(r)?;
    let a = &l.analysis;
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
    let m = units.length.metres();
    let plan = pkm_dsl::planner::forward_plan(a).map_err(|d| r.parse_failure(d))?;
    let inputs = plan.input_joints(model);
    let (given, source) = reference_inputs(r, &l, &inputs, o.q)?;
    let runs = pkm_runtime::spatial::run_all(model, &plan, &given);
    let shown: Vec<String> = given.iter().map(|v| num(*v)).collect();
    let at = format!("inputs ({}) from {source}", shown.join(", "));
    let (branch, solution) = match o.branch {
        Some(b) => match runs.into_iter().nth(b) {
            Some((_, Ok(s))) => (b, s),
            Some((_, Err(e))) => {
                return Err(Failure::new(
                    Kind::Unreachable,
                    format!("branch {b} does not assemble at the {at}: {e}"),
                ))
            }
            None => {
                return Err(Failure::input(format!(
                    "--branch {b}: the mechanism has fewer branches"
                )))
            }
        },
        None => {
            let mut reasons = Vec::new();
            let mut found = None;
            for (k, (_, run)) in runs.into_iter().enumerate() {
                match run {
                    Ok(s) => {
                        found = Some((k, s));
                        break;
                    }
                    Err(e) => reasons.push(format!("branch {k}: {e}")),
                }
            }
            found.ok_or_else(|| {
                Failure::new(
                    Kind::Unreachable,
                    format!("no branch assembles at the {at} (give --q): {}", reasons.join("; ")),
                )
            })?
        }
    };
    let tree = spanning_tree(model)?;
    let (inertials, bars, tiny) = inertials(model, &loading, m)?;
    let (offsets, _) = model.value_offsets();
    let size = pkm_runtime::kinematics::model_scale(model);
    let mut w = Writer {
        model,
        m,
        poses: solution.poses.iter().map(Pose::from).collect(),
        values: solution.values.clone(),
        offsets,
        inertials,
        bars,
        tiny,
        // Drawn 1% of the size thick, to two figures (only the look depends on it).
        radius: round2(0.01 * size * m),
        tree,
        xml: String::new(),
        joints: Map::new(),
        stand_ins: Vec::new(),
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
        &format!("<!-- {title}: written by pkm export at the {at}, branch {branch}."),
    );
    w.line(
        1,
        "     SI units: metres, kilograms, seconds, radians; docs/export.md gives the conventions. -->",
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
    let base_geoms = {
        w.geoms(2, 0);
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
        lines
    };
    for text in base_geoms {
        w.line(2, &text);
    }
    w.bars(2, 0);
    for (k, child) in w.tree.children[0].clone() {
        w.body(2, 0, k, child);
    }
    w.line(1, "</worldbody>");
    let mut equalities = Vec::new();
    let mut cut = Vec::new();
    for &c in &w.tree.cut {
        let j = &model.joints[c];
        cut.push(j.name.clone());
        let (name, body1, body2) = (escape(&j.name), w.name(j.links[0]), w.name(j.links[1]));
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
    for j in model.joints.iter().filter(|j| j.kind == JointType::Pa) {
        let name = escape(&j.name);
        equalities.push(format!(
            r#"<joint name="{name}.tie" joint1="{name}.tip" joint2="{name}" polycoef="0 -1 0 0 0" {solref}/>"#
        ));
    }
    // A bar with mass turns with its parallelogram's value.
    for (k, b) in w.bars.iter().enumerate() {
        let (joint, bar) = (escape(&model.joints[b.joint].name), k + 1);
        equalities.push(format!(
            r#"<joint name="{joint}.bar{bar}.tie" joint1="{joint}.bar{bar}" joint2="{joint}" polycoef="0 1 0 0 0" {solref}/>"#
        ));
    }
    if !equalities.is_empty() {
        w.line(1, "<equality>");
        for e in &equalities {
            w.line(2, e);
        }
        w.line(1, "</equality>");
    }
    let mut actuators = Map::new();
    w.line(1, "<actuator>");
    for &j in &inputs {
        let joint = &model.joints[j];
        let name = escape(&joint.name);
        w.line(2, &format!(r#"<motor name="{name}" joint="{name}" gear="1"/>"#));
        let (unit_name, to_pkm) = if angular(joint.kind) {
            ("N·m", 1.0 / m)
        } else {
            ("N", 1.0)
        };
        actuators.insert(
            joint.name.clone(),
            json!({ "joint": joint.name, "unit": unit_name, "to_pkm": to_pkm }),
        );
    }
    w.line(1, "</actuator>");
    w.line(0, "</mujoco>");
    let loads: Vec<String> = a.mass_and_loads.loads.iter().map(|p| p.name.clone()).collect();
    let mut info = Map::new();
    info.insert("name".into(), json!(model.name));
    info.insert("metres_per_unit".into(), json!(m));
    info.insert("branch".into(), json!(branch));
    let names: Vec<&str> = inputs.iter().map(|&j| model.joints[j].name.as_str()).collect();
    info.insert(
        "inputs".into(),
        json!(names
            .iter()
            .zip(&given)
            .map(|(n, v)| (n.to_string(), json!(v)))
            .collect::<Map<_, _>>()),
    );
    info.insert("joints".into(), Value::Object(w.joints));
    info.insert("cut".into(), json!(cut));
    info.insert("actuators".into(), Value::Object(actuators));
    info.insert(
        "stand_in".into(),
        json!({ "mass": tiny.0, "inertia": tiny.1, "bodies": w.stand_ins }),
    );
    info.insert("loads_left_out".into(), json!(loads));
    // What MJCF cannot hold, for a simulation to apply (`mj_applyFT`): each
    // load's body, its point in the body's frame (m), its force (N) and
    // moment (N·m), world axes.
    let applied: Vec<Value> = a
        .mass_and_loads
        .loads
        .iter()
        .zip(&loading.loads)
        .map(|(named, p)| {
            let (point, force, moment) = (p.at * m, p.force * m, p.moment * (m * m));
            json!({
                "name": named.name,
                "body": model.links[p.link],
                "point": [point.x, point.y, point.z],
                "force": [force.x, force.y, force.z],
                "moment": [moment.x, moment.y, moment.z],
            })
        })
        .collect();
    info.insert("loads".into(), json!(applied));
    Ok(Exported { xml: w.xml, info })
}
