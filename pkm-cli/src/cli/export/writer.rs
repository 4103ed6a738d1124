//! The XML writer: numbers, names and poses as attribute text, and the
//! bodies, joints and geometry written out along the tree ([`Writer`]).

use super::bodies::{Assembly, Merged, MjJoint, MjKind, Nodes, Part};
use pkm_runtime::kinematics::Pose;
use pkm_runtime::mass_properties::Body;
use pkm_runtime::model::{Model, Place};
use serde_json::{json, Map, Value};
use std::fmt::Write;

/// A number for the XML: the shortest text that reads back to it.
pub(super) fn num(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else if (1e-4..1e7).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// `x` to two significant figures.
pub(super) fn round2(x: f64) -> f64 {
    if x > 0.0 && x.is_finite() {
        let k = 10f64.powi(1 - x.log10().floor() as i32);
        (x * k).round() / k
    } else {
        x
    }
}

pub(super) fn nums(v: &[f64]) -> String {
    v.iter().map(|&x| num(x)).collect::<Vec<_>>().join(" ")
}

pub(super) fn scaled(v: [f64; 3], k: f64) -> [f64; 3] {
    v.map(|x| x * k)
}

pub(super) fn unit(v: [f64; 3]) -> [f64; 3] {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    scaled(v, 1.0 / n)
}

/// A name or title as XML attribute text.
pub(super) fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A pose as `pos` and `quat` attributes, its translation from file units to metres.
fn placed(p: &Pose<f64>, m: f64) -> String {
    format!(
        r#"pos="{}" quat="{}""#,
        nums(&scaled(p.translation, m)),
        nums(&p.rotation)
    )
}

/// Everything the writer reads.
pub(super) struct Writer<'a> {
    pub(super) model: &'a Model,
    /// Metres per file length unit.
    pub(super) m: f64,
    pub(super) assembly: &'a Assembly<'a>,
    pub(super) nodes: &'a Nodes,
    pub(super) merged: &'a Merged,
    /// Per node with a body, its mass properties as exported (file units).
    pub(super) bodies: Vec<Option<Body>>,
    /// Geometry radius (m).
    pub(super) radius: f64,
    pub(super) xml: String,
    pub(super) joints: Map<String, Value>,
    /// The keyframe's `qpos` and `qvel`, in MuJoCo's order.
    pub(super) qpos: Vec<f64>,
    pub(super) qvel: Vec<f64>,
}

impl Writer<'_> {
    pub(super) fn line(&mut self, depth: usize, text: &str) {
        let _ = writeln!(self.xml, "{}{text}", "  ".repeat(depth));
    }

    /// A node's body name (`world` for the base).
    pub(super) fn name(&self, k: usize) -> String {
        let joint = |j: usize| escape(&self.model.joints[j].name);
        match self.nodes.nodes[k].part {
            Part::Base => "world".into(),
            Part::Link(l) => escape(&self.model.links[l]),
            Part::TreeBar { joint: j, .. } => format!("{}.bar", joint(j)),
            Part::Bar { joint: j, number, .. } => format!("{}.bar{number}", joint(j)),
        }
    }

    /// The node whose body carries node `k`'s joints: `k`, or the first
    /// below it that is not merged.
    pub(super) fn down(&self, mut k: usize) -> usize {
        while self.merged.merged[k] {
            k = self.nodes.nodes[k].children[0];
        }
        k
    }

    /// The body a link's joints end up in.
    pub(super) fn body_of_link(&self, link: usize) -> usize {
        self.down(self.nodes.of_link[link])
    }

    /// The node with a body that a node's children hang from.
    fn emitted_parent(&self, k: usize) -> usize {
        let mut p = self.nodes.nodes[k].parent;
        while self.merged.merged[p] {
            p = self.nodes.nodes[p].parent;
        }
        p
    }

    /// One joint of body `k`, in the body's frame, and its entry in the map.
    fn joint(&mut self, depth: usize, k: usize, j: &MjJoint) {
        let pose = self.nodes.nodes[k].pose;
        let inverse = pose.inverse();
        let (m, name) = (self.m, escape(&j.name));
        let at = nums(&scaled(inverse.transform_point(j.anchor), m));
        let pkm_joint = &self.model.joints[j.pkm];
        let a = self.assembly;
        let one_or_three = |v: &[f64]| if v.len() == 1 { json!(v[0]) } else { json!(v) };
        let rate = a.part(&a.rates, j.pkm);
        let mut entry = json!({
            "pkm": pkm_joint.name,
            "type": j.kind.name(),
            "body": self.name(k),
            "scale": j.scale,
            "reference": one_or_three(a.of(j.pkm)),
            "rate": one_or_three(rate),
            "acceleration": one_or_three(a.part(&a.accels, j.pkm)),
        });
        let text = match j.kind {
            MjKind::Ball { second, parent } => {
                // qpos = K⁻¹·D·K: K the body's frame in the parent link's
                // at the reference, D the change of the joint's rotation.
                let frame = parent.inverse().then(&pose).rotation;
                entry["second"] = json!(second);
                entry["frame"] = json!(frame);
                self.qpos.extend([1.0, 0.0, 0.0, 0.0]);
                // qvel: the body's angular velocity relative to the parent
                // link's, in the body's axes; pkm's is the second link's
                // relative to the first's, in the world's.
                let sign = if second { 1.0 } else { -1.0 };
                self.qvel
                    .extend(inverse.rotate([rate[0], rate[1], rate[2]].map(|x| sign * x)));
                format!(r#"<joint name="{name}" type="ball" pos="{at}"/>"#)
            }
            kind => {
                self.qpos.push(j.reference);
                self.qvel.push(j.scale * rate[0]);
                format!(
                    r#"<joint name="{name}" type="{}" pos="{at}" axis="{}" ref="{}"/>"#,
                    kind.name(),
                    nums(&unit(inverse.rotate(j.axis))),
                    num(j.reference)
                )
            }
        };
        self.joints.insert(j.name.clone(), entry);
        self.line(depth, &text);
    }

    /// The visible parts of a link: spheres at its joints' and named
    /// points, capsules between them (file units in, metres out).
    pub(super) fn link_geoms(&mut self, depth: usize, link: usize) {
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
        let (r, m) = (self.radius, self.m);
        for p in &kept {
            let text = format!(
                r#"<geom type="sphere" size="{}" pos="{}"/>"#,
                num(round2(1.5 * r)),
                nums(&scaled(*p, m))
            );
            self.line(depth, &text);
        }
        for w in kept.windows(2) {
            self.capsule(depth, w[0], w[1]);
        }
    }

    fn capsule(&mut self, depth: usize, a: [f64; 3], b: [f64; 3]) {
        let mut ends = scaled(a, self.m).to_vec();
        ends.extend(scaled(b, self.m));
        let text = format!(
            r#"<geom type="capsule" size="{}" fromto="{}"/>"#,
            num(self.radius),
            nums(&ends)
        );
        self.line(depth, &text);
    }

    /// Body `k` with its joints, inertial, geoms and load sites, and its subtree.
    pub(super) fn body(&mut self, depth: usize, k: usize, loads: &[(String, usize, [f64; 3])]) {
        let node = &self.nodes.nodes[k];
        let relative = self.nodes.nodes[self.emitted_parent(k)].pose.inverse().then(&node.pose);
        let text = format!(r#"<body name="{}" {}>"#, self.name(k), placed(&relative, self.m));
        self.line(depth, &text);
        for j in self.merged.joints[k].clone() {
            self.joint(depth + 1, k, &j);
        }
        if let Some(b) = &self.bodies[k] {
            let (m, i) = (self.m, b.inertia * (self.m * self.m));
            let text = format!(
                r#"<inertial pos="{}" mass="{}" fullinertia="{}"/>"#,
                nums(&scaled(b.centroid.into(), m)),
                num(b.mass),
                nums(&[i[(0, 0)], i[(1, 1)], i[(2, 2)], i[(0, 1)], i[(0, 2)], i[(1, 2)]])
            );
            self.line(depth + 1, &text);
        }
        match (node.part, node.ends) {
            (Part::Link(l), _) => self.link_geoms(depth + 1, l),
            (_, Some([a, b])) => {
                let inverse = node.pose.inverse();
                self.capsule(depth + 1, inverse.transform_point(a), inverse.transform_point(b));
            }
            _ => {}
        }
        for (name, link, at) in loads {
            if node.part == Part::Link(*link) {
                let text = format!(
                    r#"<site name="{}" pos="{}"/>"#,
                    escape(name),
                    nums(&scaled(*at, self.m))
                );
                self.line(depth + 1, &text);
            }
        }
        for c in self.nodes.nodes[k].children.clone() {
            self.body(depth + 1, self.down(c), loads);
        }
        self.line(depth, "</body>");
    }
}
