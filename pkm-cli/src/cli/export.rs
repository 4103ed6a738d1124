//! `pkm export --mjcf`: the mechanism as a MuJoCo model (MJCF XML) that
//! MuJoCo's viewer opens and simulates: one body per moving link with its
//! mass and inertia, the joints of a spanning tree, every loop closed by
//! equality constraints at a cut joint, a motor on every actuated joint,
//! the file's loads as constant forces, and a keyframe `reference` whose
//! motor inputs hold the mechanism still there (pkm's inverse dynamics at
//! rest).
//!
//! The model is built at a reference configuration (an assembled position
//! of the mechanism, on the study's branch) and each joint's `ref` is pkm's
//! value there, so that a hinge's `qpos` is pkm's angle and a slide's is
//! pkm's length in metres. A link without mass carries no body where its
//! joints can go to the next body down the tree (MuJoCo composes several
//! joints in one body as a serial chain): the spanning tree is chosen so
//! that the loops are cut between links with mass. docs/export.md gives
//! every convention and unit.

use super::failure::{Failure, Kind};
use super::solve::{angular, input_values, load, sign_text, Request};
use pkm_runtime::kinematics::Pose;
use pkm_runtime::mass_properties::{arm_side, bar_pose, Body, Carrier, Loading};
use pkm_runtime::model::{Joint, JointType, Model, Place};
use pkm_runtime::nalgebra::{Isometry3, Matrix3, Vector3};
use serde_json::{json, Map, Value};
use std::fmt::Write;

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
    /// The assembly branch (its index in `pkm fk`'s list, as `branch` in a study).
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

impl Tree {
    /// Whether a cut joint acts on `link`.
    fn cut_at(&self, model: &Model, link: usize) -> bool {
        self.cut.iter().any(|&c| model.joints[c].links.contains(&link))
    }
}

/// The tree keeps the actuated joints (a motor needs a joint of the tree),
/// then slides and parallelograms (no equality constraint closes them),
/// then the revolute and spherical joints of links without mass (`light`),
/// so that the loops are cut between links with mass: MuJoCo softens a
/// constraint by the inverse mass of the bodies it holds, and one on a
/// body without mass would carry no force. Among the rest a loop is cut at
/// a spherical joint (one `connect`) before a revolute one.
fn spanning_tree(model: &Model, light: &[bool]) -> Result<Tree, Failure> {
    let rank = |j: &Joint| {
        let light_ends = j.links.iter().filter(|&&l| light[l]).count();
        match (j.actuated, j.kind) {
            (true, _) => (0, 0, 0),
            (false, JointType::P) => (1, 0, 0),
            (false, JointType::Pa) => (2, 0, 0),
            (false, JointType::R) => (3, 2 - light_ends, 0),
            (false, JointType::S) => (3, 2 - light_ends, 1),
        }
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

/// A pose as `pos` and `quat` attributes, its translation from file units to metres.
fn placed(p: &Pose<f64>, m: f64) -> String {
    format!(
        r#"pos="{}" quat="{}""#,
        nums(&scaled(p.translation, m)),
        nums(&p.rotation)
    )
}

/// What kind of MuJoCo joint.
#[derive(Debug, Clone, Copy, PartialEq)]
enum MjKind {
    Hinge,
    Slide,
    /// A ball: whether the body is on the joint's second link's side, and
    /// the world pose of the link on the parent's side at the reference.
    Ball {
        second: bool,
        parent: Pose<f64>,
    },
}

impl MjKind {
    fn name(self) -> &'static str {
        match self {
            MjKind::Hinge => "hinge",
            MjKind::Slide => "slide",
            MjKind::Ball { .. } => "ball",
        }
    }
}

/// One MuJoCo joint, placed in the world at the reference configuration:
/// the body it ends up in writes its point and axis in its own frame.
#[derive(Debug, Clone)]
struct MjJoint {
    name: String,
    kind: MjKind,
    /// The pkm joint it stands for.
    pkm: usize,
    /// Its point (file units) and unit axis, world, at the reference.
    anchor: [f64; 3],
    axis: [f64; 3],
    /// `qpos` at the reference (rad or m; a ball's is the identity).
    reference: f64,
    /// `qpos = scale · pkm's value` (hinges and slides).
    scale: f64,
}

/// What a body of the tree stands for.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Part {
    /// The base (MuJoCo's world).
    Base,
    /// A link.
    Link(usize),
    /// The bar of a parallelogram of the tree that carries its child: the
    /// first bar the file declares for it, else one without mass.
    TreeBar { joint: usize },
    /// Another declared bar with mass, hinged on the arm-carrying link and
    /// tied to the parallelogram's value (its number among the joint's bars).
    Bar { joint: usize, number: usize },
}

/// A body of the tree before links without mass are merged away.
struct Node {
    part: Part,
    /// Its frame in the world at the reference (file units).
    pose: Pose<f64>,
    parent: usize,
    /// The joints from its parent.
    own: Vec<MjJoint>,
    children: Vec<usize>,
    /// Its mass properties (file units), if it has mass.
    body: Option<Body>,
    /// A bar's two hinges (world, file units), to draw it.
    ends: Option<[[f64; 3]; 2]>,
}

/// The declared bars with mass, per parallelogram.
struct Bars {
    all: Vec<Body>,
}

impl Bars {
    fn of(&self, joint: usize) -> Vec<usize> {
        (0..self.all.len())
            .filter(|&k| matches!(self.all[k].carrier, Carrier::Bar { joint: j, .. } if j == joint))
            .collect()
    }

    fn hinge(&self, k: usize) -> Vector3<f64> {
        match self.all[k].carrier {
            Carrier::Bar { hinge, .. } => hinge,
            Carrier::Link(_) => Vector3::zeros(),
        }
    }
}

/// A parallelogram at the reference: its arm-carrying link, the hinge axis
/// (world, unit, as the arm turns), and the offset from a bar's hinge on
/// the arm link to its far end on the other link (world, file units).
struct Parallelogram {
    arm_link: usize,
    /// The hinge axis in the arm link's frame (unit).
    local_axis: Vector3<f64>,
    axis: [f64; 3],
    offset: [f64; 3],
    /// The arm link's hinge point (its frame).
    arm_at: [f64; 3],
}

/// The mechanism assembled at the reference configuration.
struct Assembly<'a> {
    model: &'a Model,
    /// Every link's pose (file units).
    poses: Vec<Pose<f64>>,
    /// Every joint's values, in the model's layout (three per spherical joint).
    values: Vec<f64>,
    offsets: Vec<usize>,
    /// Metres per file length unit.
    m: f64,
}

impl Assembly<'_> {
    /// A joint's values (one, or a spherical joint's three).
    fn of(&self, joint: usize) -> &[f64] {
        let at = self.offsets[joint];
        &self.values[at..at + self.model.joints[joint].kind.dof()]
    }
}

fn parallelogram(model: &Model, poses: &[Pose<f64>], joint: usize) -> Option<Parallelogram> {
    let j = &model.joints[joint];
    let (arm_link, local_axis) = arm_side(model, joint)?;
    let side = usize::from(j.links[1] == arm_link);
    let other = j.links[1 - side];
    let at_arm = poses[arm_link].transform_point(j.places[side].at());
    let at_other = poses[other].transform_point(j.places[1 - side].at());
    Some(Parallelogram {
        arm_link,
        local_axis,
        axis: unit(poses[arm_link].rotate(local_axis.into())),
        offset: [0, 1, 2].map(|i| at_other[i] - at_arm[i]),
        arm_at: j.places[side].at(),
    })
}

/// The tree's bodies, each link and bar a node, and the joints between them.
struct Nodes {
    nodes: Vec<Node>,
    /// Per link, its node.
    of_link: Vec<usize>,
}

/// Builds the nodes along the tree from the base, then the declared bars
/// that do not carry a link.
fn nodes(a: &Assembly, tree: &Tree, link_bodies: &[Option<Body>], bars: &Bars) -> Result<Nodes, Failure> {
    let (model, poses, m) = (a.model, &a.poses, a.m);
    let mut nodes = vec![Node {
        part: Part::Base,
        pose: Pose::identity(),
        parent: 0,
        own: Vec::new(),
        children: Vec::new(),
        body: None,
        ends: None,
    }];
    let mut of_link = vec![0; model.links.len()];
    let push = |nodes: &mut Vec<Node>, node: Node| {
        let k = nodes.len();
        let parent = node.parent;
        nodes.push(node);
        nodes[parent].children.push(k);
        k
    };
    let mut queue = std::collections::VecDeque::from([0usize]);
    let mut tree_bars = Vec::new();
    while let Some(p) = queue.pop_front() {
        for &(joint, c) in &tree.children[p] {
            let j = &model.joints[joint];
            let value = a.of(joint)[0];
            let child_second = j.links[1] == c;
            let here = poses[c].transform_point(j.places[usize::from(child_second)].at());
            let mut parent = of_link[p];
            let own = match j.kind {
                JointType::R => {
                    let sign = if child_second { 1.0 } else { -1.0 };
                    let place = j.places[usize::from(child_second)];
                    vec![MjJoint {
                        name: j.name.clone(),
                        kind: MjKind::Hinge,
                        pkm: joint,
                        anchor: here,
                        axis: scaled(unit(poses[c].rotate(place.axis())), sign),
                        reference: value,
                        scale: 1.0,
                    }]
                }
                JointType::P => {
                    // The slider's point runs +d̂ along the guide: the
                    // second link moves +s·d̂ from the first when the first
                    // holds the guide, −s·d̂ when the second does.
                    let guide = usize::from(!matches!(j.places[0], Place::Line { .. }));
                    let d = match j.places[guide] {
                        Place::Point { .. } => [1.0, 0.0, 0.0],
                        place => unit(place.axis()),
                    };
                    let d = unit(poses[j.links[guide]].rotate(d));
                    let second_moves = if guide == 0 { 1.0 } else { -1.0 };
                    let sign = if child_second { second_moves } else { -second_moves };
                    let slider = 1 - guide;
                    vec![MjJoint {
                        name: j.name.clone(),
                        kind: MjKind::Slide,
                        pkm: joint,
                        anchor: poses[j.links[slider]].transform_point(j.places[slider].at()),
                        axis: scaled(d, sign),
                        reference: value * m,
                        scale: m,
                    }]
                }
                JointType::S => vec![MjJoint {
                    name: j.name.clone(),
                    kind: MjKind::Ball {
                        second: child_second,
                        parent: poses[p],
                    },
                    pkm: joint,
                    anchor: here,
                    axis: [0.0, 0.0, 1.0],
                    reference: 0.0,
                    scale: 1.0,
                }],
                JointType::Pa => {
                    // A bar hinged on the parent, turning with θ; the child
                    // hinged at its far end, turning back by θ (an equality
                    // ties the two), so that the child translates.
                    let Some(pa) = parallelogram(model, poses, joint) else {
                        return Err(Failure::input(format!("parallelogram {} has no arm", j.name)));
                    };
                    let declared = bars.of(joint).first().copied();
                    let hinge = declared.map_or(pa.arm_at, |k| bars.hinge(k).into());
                    let on_arm = poses[pa.arm_link].transform_point(hinge);
                    let on_other = [0, 1, 2].map(|i| on_arm[i] + pa.offset[i]);
                    let (root, tip) = if p == pa.arm_link {
                        (on_arm, on_other)
                    } else {
                        (on_other, on_arm)
                    };
                    let pose = bar_pose(
                        &Isometry3::from(poses[pa.arm_link]),
                        &pa.local_axis,
                        &Vector3::from(hinge),
                        value,
                    );
                    let hinge_joint = |name: String, anchor: [f64; 3], sign: f64| MjJoint {
                        name,
                        kind: MjKind::Hinge,
                        pkm: joint,
                        anchor,
                        axis: pa.axis,
                        reference: sign * value,
                        scale: sign,
                    };
                    let bar = push(
                        &mut nodes,
                        Node {
                            part: Part::TreeBar { joint },
                            pose: Pose::from(&pose),
                            parent,
                            own: vec![hinge_joint(j.name.clone(), root, 1.0)],
                            children: Vec::new(),
                            body: declared.map(|k| bars.all[k].clone()),
                            ends: Some([root, tip]),
                        },
                    );
                    tree_bars.extend(declared);
                    parent = bar;
                    vec![hinge_joint(format!("{}.tip", j.name), tip, -1.0)]
                }
            };
            of_link[c] = push(
                &mut nodes,
                Node {
                    part: Part::Link(c),
                    pose: poses[c],
                    parent,
                    own,
                    children: Vec::new(),
                    body: link_bodies[c].clone(),
                    ends: None,
                },
            );
            queue.push_back(c);
        }
    }
    // The other declared bars: hinged on the arm link, tied to the joint's value.
    for (joint, j) in model.joints.iter().enumerate() {
        let Some(pa) = (j.kind == JointType::Pa)
            .then(|| parallelogram(model, poses, joint))
            .flatten()
        else {
            continue;
        };
        let value = a.of(joint)[0];
        for (number, k) in bars.of(joint).into_iter().enumerate() {
            if tree_bars.contains(&k) {
                continue;
            }
            let hinge = bars.hinge(k);
            let pose = bar_pose(&Isometry3::from(poses[pa.arm_link]), &pa.local_axis, &hinge, value);
            let name = format!("{}.bar{}", j.name, number + 1);
            let anchor = poses[pa.arm_link].transform_point(hinge.into());
            let far = [0, 1, 2].map(|i| anchor[i] + pa.offset[i]);
            push(
                &mut nodes,
                Node {
                    part: Part::Bar {
                        joint,
                        number: number + 1,
                    },
                    pose: Pose::from(&pose),
                    parent: of_link[pa.arm_link],
                    own: vec![MjJoint {
                        name,
                        kind: MjKind::Hinge,
                        pkm: joint,
                        anchor,
                        axis: pa.axis,
                        reference: value,
                        scale: 1.0,
                    }],
                    children: Vec::new(),
                    body: Some(bars.all[k].clone()),
                    ends: Some([anchor, far]),
                },
            );
        }
    }
    Ok(Nodes { nodes, of_link })
}

/// Whether MuJoCo takes these joints, in this order, in one body: it
/// refuses a ball followed by a rotation.
fn one_body<'a>(joints: impl IntoIterator<Item = &'a MjJoint>) -> bool {
    let mut ball = false;
    for j in joints {
        if ball && j.kind != MjKind::Slide {
            return false;
        }
        ball |= matches!(j.kind, MjKind::Ball { .. });
    }
    true
}

/// Which nodes carry no body of their own, and every body's joints.
struct Merged {
    /// Per node: its joints go down to its one child, which carries them
    /// before its own (a serial chain in one MuJoCo body).
    merged: Vec<bool>,
    /// Per node: the joints its body carries (its merged ancestors' first).
    joints: Vec<Vec<MjJoint>>,
}

/// A node without mass goes into its child when it has one child, no
/// constraint or load acts on it, and MuJoCo takes the joints in one body:
/// the link is then exactly the joint chain it forms (a U joint's cross, a
/// parallelogram's bar, a massless link between two hinges), with no
/// stand-in mass.
fn merge(n: &Nodes, model: &Model, tree: &Tree, loaded: &[bool]) -> Merged {
    let count = n.nodes.len();
    let mut merged = vec![false; count];
    let mut joints: Vec<Vec<MjJoint>> = vec![Vec::new(); count];
    for k in 1..count {
        let node = &n.nodes[k];
        let mut list = if merged[node.parent] {
            joints[node.parent].clone()
        } else {
            Vec::new()
        };
        list.extend(node.own.iter().cloned());
        let free = match node.part {
            Part::Link(l) => !tree.cut_at(model, l) && !loaded[l],
            Part::TreeBar { .. } => true,
            Part::Base | Part::Bar { .. } => false,
        };
        if let ([child], None, true) = (node.children.as_slice(), &node.body, free) {
            merged[k] = one_body(list.iter().chain(&n.nodes[*child].own));
        }
        joints[k] = list;
    }
    Merged { merged, joints }
}

/// An error naming the links without mass that end the tree at a cut
/// joint: every spanning tree leaves them hanging from one side of their
/// loop, closed to the other by a constraint, and MuJoCo softens a
/// constraint by the inverse mass of its bodies (its regularisation is
/// `(1 − d)/d` times their inverse weight): on a body with a stand-in mass
/// it carries next to no force, and the loop opens under load.
fn ends_without_mass(model: &Model, tree: &Tree, n: &Nodes, merged: &Merged) -> Result<(), Failure> {
    let hanging: Vec<&str> = n
        .nodes
        .iter()
        .enumerate()
        .filter_map(|(k, node)| match node.part {
            Part::Link(l)
                if !merged.merged[k] && node.body.is_none() && node.children.is_empty() && tree.cut_at(model, l) =>
            {
                Some(model.links[l].as_str())
            }
            _ => None,
        })
        .collect();
    if hanging.is_empty() {
        return Ok(());
    }
    Err(Failure::input(format!(
        "export cannot close a loop through {}: without mass {} every spanning tree, and MuJoCo's constraint on a body without mass carries no force (it softens a constraint by its bodies' inverse mass); give {} a mass",
        hanging.join(", "),
        if hanging.len() == 1 { "it ends" } else { "they end" },
        if hanging.len() == 1 { "it" } else { "each" },
    )))
}

/// The mass properties MuJoCo reads for a body with mass (file units): a
/// planar link's moments about x and y, which planar motion never reads,
/// equal to its moment about z; a point mass, a thin rod or a flat plate
/// with `tiny` added to each principal moment (MuJoCo wants them positive
/// and the triangle inequality strict, and adding c to each moment adds c
/// to both margins).
fn as_exported(b: &Body, planar: bool, tiny: f64) -> Body {
    let mut inertia = b.inertia;
    if planar {
        inertia[(0, 0)] = inertia[(2, 2)];
        inertia[(1, 1)] = inertia[(2, 2)];
    }
    let principal = inertia.symmetric_eigenvalues();
    let trace = principal.sum();
    let margin = principal
        .iter()
        .fold(f64::INFINITY, |a, &p| a.min(p).min(trace - 2.0 * p));
    if margin.is_nan() || margin < tiny {
        inertia += Matrix3::identity() * tiny;
    }
    Body { inertia, ..b.clone() }
}

/// The actuators' forces (pkm's units, input order) that hold the
/// mechanism at rest at `values` under gravity and the loads of `loading`.
fn holding(
    model: &Model,
    loading: &Loading,
    skcs: &[pkm_runtime::newton_euler::SkcParts],
    values: &[f64],
    inputs: usize,
) -> Result<Vec<f64>, String> {
    let zeros = vec![0.0; inputs];
    pkm_runtime::newton_euler::inverse_dynamics(model, loading, skcs, values, &zeros, &zeros)
        .map(|r| r.actuators)
        .map_err(|e| e.to_string())
}

/// Everything the writer reads.
struct Writer<'a> {
    model: &'a Model,
    /// Metres per file length unit.
    m: f64,
    assembly: &'a Assembly<'a>,
    nodes: &'a Nodes,
    merged: &'a Merged,
    /// Per node with a body, its mass properties as exported (file units).
    bodies: Vec<Option<Body>>,
    /// Geometry radius (m).
    radius: f64,
    xml: String,
    joints: Map<String, Value>,
    /// The keyframe's `qpos`, in MuJoCo's order.
    qpos: Vec<f64>,
}

impl Writer<'_> {
    fn line(&mut self, depth: usize, text: &str) {
        let _ = writeln!(self.xml, "{}{text}", "  ".repeat(depth));
    }

    /// A node's body name (`world` for the base).
    fn name(&self, k: usize) -> String {
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
    fn down(&self, mut k: usize) -> usize {
        while self.merged.merged[k] {
            k = self.nodes.nodes[k].children[0];
        }
        k
    }

    /// The body a link's joints end up in.
    fn body_of_link(&self, link: usize) -> usize {
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
        let value = self.assembly.of(j.pkm);
        let mut entry = json!({
            "pkm": pkm_joint.name,
            "type": j.kind.name(),
            "body": self.name(k),
            "scale": j.scale,
            "reference": if value.len() == 1 { json!(value[0]) } else { json!(value) },
        });
        let text = match j.kind {
            MjKind::Ball { second, parent } => {
                // qpos = K⁻¹·D·K: K the body's frame in the parent link's
                // at the reference, D the change of the joint's rotation.
                let frame = parent.inverse().then(&pose).rotation;
                entry["second"] = json!(second);
                entry["frame"] = json!(frame);
                self.qpos.extend([1.0, 0.0, 0.0, 0.0]);
                format!(r#"<joint name="{name}" type="ball" pos="{at}"/>"#)
            }
            kind => {
                self.qpos.push(j.reference);
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
    fn link_geoms(&mut self, depth: usize, link: usize) {
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
    fn body(&mut self, depth: usize, k: usize, loads: &[(String, usize, [f64; 3])]) {
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

/// The reference configuration's inputs (given, else the study's start,
/// else zeros) and the branch (given, else the study's), each with where
/// it came from.
struct Reference {
    inputs: Vec<f64>,
    inputs_from: &'static str,
    branch: Option<(usize, &'static str)>,
}

fn reference(r: &Request, l: &super::solve::Loaded, inputs: &[usize], o: &Options) -> Result<Reference, Failure> {
    let model = &l.model;
    let ast = pkm_dsl::parse(r.source).map_err(|d| r.parse_failure(d.into()))?;
    let names: Vec<String> = model
        .joints
        .iter()
        .filter(|j| j.actuated)
        .map(|j| j.name.clone())
        .collect();
    let values = pkm_dsl::numeric::parameter_values(&l.analysis, &l.values).map_err(|d| r.parse_failure(d))?;
    let study = pkm_dsl::study::resolve(&ast.studies, &names, &values).map_err(|d| r.parse_failure(d))?;
    let branch = match (o.branch, study.branch) {
        (Some(b), _) => Some((b, "--branch")),
        (None, Some(b)) => Some((b, "the study's `branch`")),
        (None, None) => None,
    };
    let (inputs, inputs_from) = match (o.q.is_empty(), study.start) {
        (false, _) => (input_values(r, model, inputs, "--q", o.q)?, "--q"),
        // The study's start is in the declaration order of the actuated joints.
        (true, Some(start)) => (
            inputs
                .iter()
                .map(|&j| {
                    let k = names.iter().position(|n| *n == model.joints[j].name).unwrap_or(0);
                    start.get(k).copied().unwrap_or(0.0)
                })
                .collect(),
            "the study's start",
        ),
        (true, None) => (vec![0.0; inputs.len()], "zeros"),
    };
    Ok(Reference {
        inputs,
        inputs_from,
        branch,
    })
}

/// The branch to export and its solution: the one asked for (by `--branch`
/// or the study), else the first that assembles.
fn assembled(
    runs: Vec<(
        Vec<pkm_runtime::primitives::Sign>,
        Result<pkm_runtime::spatial::Solution, pkm_runtime::solution::SolveError>,
    )>,
    wanted: Option<(usize, &'static str)>,
    at: &str,
) -> Result<(usize, Vec<&'static str>, pkm_runtime::spatial::Solution), Failure> {
    let count = runs.len();
    if let Some((b, from)) = wanted {
        let Some((signs, run)) = runs.into_iter().nth(b) else {
            return Err(Failure::input(format!(
                "branch {b} ({from}): the mechanism has {count} branches, 0 to {}",
                count.saturating_sub(1)
            )));
        };
        return match run {
            Ok(s) => Ok((b, sign_text(&signs), s)),
            Err(e) => Err(Failure::new(
                Kind::Unreachable,
                format!("branch {b} ({from}) does not assemble at the {at}: {e}"),
            )),
        };
    }
    let mut reasons = Vec::new();
    for (k, (signs, run)) in runs.into_iter().enumerate() {
        match run {
            Ok(s) => return Ok((k, sign_text(&signs), s)),
            Err(e) => reasons.push(format!("branch {k}: {e}")),
        }
    }
    Err(Failure::new(
        Kind::Unreachable,
        format!("no branch assembles at the {at} (give --q): {}", reasons.join("; ")),
    ))
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
    let total: f64 = loading.bodies.iter().map(|b| b.mass).sum();
    if total <= 0.0 {
        return Err(Failure::input(
            "export needs some mass: every moving link is massless, and MuJoCo cannot simulate that",
        ));
    }
    let m = units.length.metres();
    let plan = pkm_dsl::planner::forward_plan(a).map_err(|d| r.parse_failure(d))?;
    let inputs = plan.input_joints(model);
    let reference = reference(r, &l, &inputs, o)?;
    let given = &reference.inputs;
    let runs = pkm_runtime::spatial::run_all(model, &plan, given);
    let shown: Vec<String> = given.iter().map(|v| num(*v)).collect();
    let at = format!("inputs ({}) from {}", shown.join(", "), reference.inputs_from);
    let (branch, signs, solution) = assembled(runs, reference.branch, &at)?;
    // The model's layout: three values per spherical joint.
    let assembly = Assembly {
        model,
        poses: solution.poses.iter().map(Pose::from).collect(),
        // The model's layout: three values per spherical joint.
        values: solution.model_values(model),
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
    let tree = spanning_tree(model, &light)?;
    let nodes = nodes(&assembly, &tree, &link_bodies, &bars)?;
    let mut loaded = vec![false; model.links.len()];
    for p in &loading.loads {
        loaded[p.link] = true;
    }
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
    let held = holding(model, &exported_loading, &skcs, &assembly.values, inputs.len());
    let declared = holding(model, &loading, &skcs, &assembly.values, inputs.len());

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
    let load_sites: Vec<(String, usize, [f64; 3])> = load_names
        .iter()
        .zip(&loading.loads)
        .map(|(n, p)| (n.clone(), p.link, p.at.into()))
        .collect();
    if !load_sites.is_empty() {
        w.line(2, r#"<site name="pkm.world" pos="0 0 0"/>"#);
    }
    for c in nodes.nodes[0].children.clone() {
        w.body(2, w.down(c), &load_sites);
    }
    w.line(1, "</worldbody>");

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
        ctrl.push(held.as_ref().map_or(0.0, |h| h[k] / to_pkm));
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
    let key = format!(
        r#"<key name="reference" qpos="{}" ctrl="{}"/>"#,
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
    info.insert(
        "branch_from".into(),
        json!(reference.branch.map_or("the first that assembles", |(_, from)| from)),
    );
    info.insert("inputs".into(), Value::Object(by_name(given)));
    // The inputs in the order `--q`, `pkm dynamics` and the keyframe's ctrl take them.
    info.insert("input_order".into(), json!(names));
    info.insert("inputs_from".into(), json!(reference.inputs_from));
    info.insert("joints".into(), Value::Object(w.joints.clone()));
    info.insert("cut".into(), json!(cut));
    info.insert("actuators".into(), Value::Object(actuators));
    let merged_links: Map<String, Value> = (1..model.links.len())
        .filter(|&l| merged.merged[nodes.of_link[l]])
        .map(|l| (model.links[l].clone(), json!(w.name(w.body_of_link(l)))))
        .collect();
    info.insert("merged".into(), Value::Object(merged_links));
    let change = match (&held, &declared) {
        (Ok(h), Ok(d)) => {
            let peak = d.iter().fold(0.0f64, |p, x| p.max(x.abs()));
            let most = h.iter().zip(d).fold(0.0f64, |p, (x, y)| p.max((x - y).abs()));
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
            (Ok(h), Ok(d)) => json!({ "ok": true, "actuators": by_name(h), "as_declared": by_name(d) }),
            (Err(e), _) | (_, Err(e)) => json!({ "ok": false, "reason": e }),
        },
    );
    info.insert("loads".into(), json!(applied));
    info.insert("keyframe".into(), json!("reference"));
    Ok(Exported { xml: w.xml, info })
}
