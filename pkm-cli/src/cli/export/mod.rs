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

use super::failure::{Failure, Kind};
use super::solve::{angular, input_values, load, ordered_pose, output_names, sign_text, Loaded, Request};
use super::table::{number_of, signs_of};
use pkm_dsl::mechanism::Capability;
use pkm_runtime::fk_numeric::{RootKind, VirtualPlan};
use pkm_runtime::kinematics::Pose;
use pkm_runtime::mass_properties::{arm_side, bar_pose, Body, Carrier, Loading};
use pkm_runtime::model::{Joint, JointType, Model, Place};
use pkm_runtime::nalgebra::{Isometry3, Matrix3, Vector3};
use pkm_runtime::newton::Output;
use pkm_runtime::plan::{Plan, Solution};
use pkm_runtime::primitives::Sign;
use pkm_runtime::solution::SolveError;
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

/// A spanning tree of the link graph for MuJoCo's bodies.
struct Tree {
    /// Per link, the joints to its children and the children.
    children: Vec<Vec<(usize, usize)>>,
    /// The joints left out, each closed by equality constraints.
    cut: Vec<usize>,
    /// The U joints cut whole: their crosses have no body.
    crosses: Vec<Cross>,
}

impl Tree {
    /// Whether a cut joint or a cut U acts on `link`.
    fn cut_at(&self, model: &Model, link: usize) -> bool {
        self.cut.iter().any(|&c| model.joints[c].links.contains(&link))
            || self.crosses.iter().any(|c| c.ends.contains(&link))
    }
}

/// A U joint cut whole: a link without mass between two revolute joints
/// whose axes meet (a U joint's cross), which the tree would leave hanging
/// from one of them with the other cut. MuJoCo's constraint on a body
/// without mass carries no force, so the cross has no body: its two
/// neighbours share the centre (a `connect`) and keep the angle between
/// the two axes (a spatial tendon between a point on each axis, one size
/// from the centre, of fixed length), which is the U's constraint.
struct Cross {
    /// The cross.
    link: usize,
    /// Its revolute joints, and the links on their far sides.
    joints: [usize; 2],
    ends: [usize; 2],
    /// The centre, in the cross's frame.
    centre: [f64; 3],
}

/// The crosses of U joints ([`Cross`]) that hang from the tree at a cut:
/// each taken out of the tree (its joints leave, its cut joint with them).
fn cut_crosses(model: &Model, tree: &mut Tree, light: &[bool], loaded: &[bool]) {
    let size = pkm_runtime::kinematics::model_scale(model);
    for link in 1..model.links.len() {
        let joints: Vec<usize> = (0..model.joints.len())
            .filter(|&j| model.joints[j].links.contains(&link))
            .collect();
        let [a, b] = joints[..] else { continue };
        let revolute = |j: usize| model.joints[j].kind == JointType::R && !model.joints[j].actuated;
        let hanging = tree.cut.contains(&a) != tree.cut.contains(&b) && tree.children[link].is_empty();
        if !(light[link] && !loaded[link] && revolute(a) && revolute(b) && hanging) {
            continue;
        }
        let place = |j: usize| {
            let joint = &model.joints[j];
            joint.places[usize::from(joint.links[1] == link)]
        };
        let (p, u, q, v) = (
            Vector3::from(place(a).at()),
            Vector3::from(place(a).axis()).normalize(),
            Vector3::from(place(b).at()),
            Vector3::from(place(b).axis()).normalize(),
        );
        let n = u.cross(&v);
        // The axes meet: not parallel, and no gap between them.
        if n.norm() < 1e-9 || (q - p).dot(&n).abs() / n.norm() > 1e-9 * size {
            continue;
        }
        // The point of a's axis nearest b's: p + t·u with (p + t·u − q)·(v × n) = 0.
        let t = (q - p).dot(&v.cross(&n)) / u.dot(&v.cross(&n));
        let centre = p + u * t;
        let far = |j: usize| {
            let l = model.joints[j].links;
            if l[0] == link {
                l[1]
            } else {
                l[0]
            }
        };
        let (tree_joint, cut_joint) = if tree.cut.contains(&a) { (b, a) } else { (a, b) };
        tree.cut.retain(|&c| c != cut_joint);
        for children in &mut tree.children {
            children.retain(|&(j, _)| j != tree_joint);
        }
        tree.crosses.push(Cross {
            link,
            joints: [a, b],
            ends: [far(a), far(b)],
            centre: centre.into(),
        });
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
    Ok(Tree {
        children,
        cut,
        crosses: Vec::new(),
    })
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
    /// Their rates and accelerations (zeros at rest; a spherical joint's:
    /// the relative angular velocity and its rate, world axes).
    rates: Vec<f64>,
    accels: Vec<f64>,
    offsets: Vec<usize>,
    /// Metres per file length unit.
    m: f64,
}

impl Assembly<'_> {
    /// A joint's values (one, or a spherical joint's three).
    fn of(&self, joint: usize) -> &[f64] {
        self.part(&self.values, joint)
    }

    /// A joint's part of `all` (values, rates or accelerations).
    fn part<'v>(&self, all: &'v [f64], joint: usize) -> &'v [f64] {
        let at = self.offsets[joint];
        &all[at..at + self.model.joints[joint].kind.dof()]
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

/// The reference's motion: every joint's rate and acceleration from the
/// inputs' (`--rates`, `--accels`; zeros, at rest, where not given), and
/// the inputs' in the model's input order, as Newton–Euler takes them.
struct Motion {
    given: bool,
    input_rates: Vec<f64>,
    input_accels: Vec<f64>,
    rates: Vec<f64>,
    accels: Vec<f64>,
}

fn motion(r: &Request, model: &Model, inputs: &[usize], values: &[f64], o: &Options) -> Result<Motion, Failure> {
    let order = model.inputs();
    let zeros = vec![0.0; inputs.len()];
    let mut given = Vec::new();
    for (flag, list) in [("--rates", o.rates), ("--accels", o.accels)] {
        let list = if list.is_empty() { &zeros } else { list };
        let v = input_values(r, model, inputs, flag, list)?;
        // In the model's input order.
        given.push(
            order
                .iter()
                .map(|j| inputs.iter().position(|k| k == j).map_or(0.0, |k| v[k]))
                .collect::<Vec<f64>>(),
        );
    }
    let input_accels = given.pop().unwrap_or_default();
    let input_rates = given.pop().unwrap_or_default();
    if o.rates.is_empty() && o.accels.is_empty() {
        return Ok(Motion {
            given: false,
            input_rates,
            input_accels,
            rates: vec![0.0; values.len()],
            accels: vec![0.0; values.len()],
        });
    }
    let a = pkm_runtime::velocity::accelerations(model, values, &input_rates, &input_accels).map_err(|e| {
        Failure::new(
            Kind::Unreachable,
            format!("the inputs' rates and accelerations give no motion at the reference: {e}"),
        )
    })?;
    Ok(Motion {
        given: true,
        input_rates,
        input_accels,
        rates: a.velocities.rates,
        accels: a.rates,
    })
}

/// The actuators' forces (pkm's units, in the order of `inputs`) at
/// `values` in the reference's motion (at rest: the forces that hold it)
/// under gravity and the loads of `loading` (Newton–Euler takes and gives
/// them in the model's input order).
fn holding(
    model: &Model,
    loading: &Loading,
    skcs: &[pkm_runtime::newton_euler::SkcParts],
    values: &[f64],
    inputs: &[usize],
    motion: &Motion,
) -> Result<Held, String> {
    let order = model.inputs();
    let r = pkm_runtime::newton_euler::inverse_dynamics(
        model,
        loading,
        skcs,
        values,
        &motion.input_rates,
        &motion.input_accels,
    )
    .map_err(|e| e.to_string())?;
    Ok(Held {
        forces: inputs
            .iter()
            .map(|j| order.iter().position(|k| k == j).map_or(f64::NAN, |k| r.actuators[k]))
            .collect(),
        conditioning: r.conditioning.iter().copied().fold(1.0, f64::min),
    })
}

/// The actuators' forces of [`holding`] and the least conditioning of an
/// SKC's force equations there (1 regular, 0 at a change point).
struct Held {
    forces: Vec<f64>,
    conditioning: f64,
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
    /// The keyframe's `qpos` and `qvel`, in MuJoCo's order.
    qpos: Vec<f64>,
    qvel: Vec<f64>,
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

/// The reference configuration: the actuated joints (in the order `--q`,
/// `pkm dynamics` and the motors take them) and their values, the branch,
/// the solution, and how each was chosen (for the JSON and the XML's
/// comment).
struct Reference {
    /// The actuated joints, in input order.
    inputs: Vec<usize>,
    /// Their values at the reference.
    given: Vec<f64>,
    inputs_from: &'static str,
    branch: usize,
    signs: Vec<&'static str>,
    branch_from: &'static str,
    solution: Solution,
    /// `solver`, and the pose (ik) or the virtual variable and the
    /// assembly (`fk_numeric`).
    how: Map<String, Value>,
    /// Where it was solved, for the XML's comment.
    at: String,
}

/// One branch's signs and its solution or why it has none.
type Run = (Vec<Sign>, Result<Solution, SolveError>);

/// The branch asked for (`--branch`, else the study's), with where it came from.
type Wanted = Option<(usize, &'static str)>;

/// How a reference configuration is solved: by the closed-form forward
/// plan (κ = 0), by the virtual variable (`fk_numeric`, a κ = 1 file that
/// asks for it), or by the inverse plan at a pose.
enum Way {
    Forward(Plan),
    Numeric(Box<VirtualPlan>),
    Inverse(Plan),
}

/// The reference configuration. With `--pose`, the inverse plan there;
/// else, with a forward solution (κ = 0, or κ = 1 and `fk_numeric`), the
/// inputs `--q`, else the study's start, else zeros; else (κ ≠ 0) the
/// inverse plan at the outputs' home ([`inverse_reference`]). The branch is
/// `--branch`, else the study's, else the first that assembles (at the
/// home pose: the best conditioned).
fn reference(r: &Request, l: &Loaded, o: &Options) -> Result<Reference, Failure> {
    let (a, model) = (&l.compiled.analysis, &l.model);
    let ast = pkm_dsl::parse(r.source).map_err(|d| r.parse_failure(d.into()))?;
    let names: Vec<String> = model
        .joints
        .iter()
        .filter(|j| j.actuated)
        .map(|j| j.name.clone())
        .collect();
    let values = pkm_dsl::numeric::parameter_values(a, &l.values).map_err(|d| r.parse_failure(d))?;
    let study = pkm_dsl::study::resolve(&ast.studies, &names, &values).map_err(|d| r.parse_failure(d))?;
    let wanted = match (o.branch, study.branch) {
        (Some(b), _) => Some((b, "--branch")),
        (None, Some(b)) => Some((b, "the study's `branch`")),
        (None, None) => None,
    };
    let numeric = a.topology.kappa == 1 && a.mechanism.wants(Capability::FkNumeric);
    let way = if !o.pose.is_empty() {
        Way::Inverse(l.compiled.inverse().cloned().map_err(|d| r.parse_failure(d))?)
    } else if a.topology.kappa == 0 {
        Way::Forward(l.compiled.forward().cloned().map_err(|d| r.parse_failure(d))?)
    } else if numeric && (!o.q.is_empty() || study.start.is_some() || l.compiled.inverse().is_err()) {
        Way::Numeric(Box::new(
            pkm_dsl::planner_numeric::forward_numeric_plan(a).map_err(|d| r.parse_failure(d))?,
        ))
    } else if !o.q.is_empty() {
        return Err(Failure::input(format!(
            "--q: {} has no forward solution to take inputs (κ = {}{}): give its outputs with --pose",
            model.name,
            a.topology.kappa,
            if a.topology.kappa == 1 {
                ", and it does not ask for `fk_numeric`"
            } else {
                ""
            }
        )));
    } else {
        match l.compiled.inverse().cloned() {
            Ok(plan) => Way::Inverse(plan),
            Err(d) => {
                let why = d.0.first().map(|x| x.message.clone()).unwrap_or_default();
                return Err(Failure::input(format!(
                    "export needs an assembled configuration, and nothing solves {}'s position: it has no \
                     closed-form forward plan (κ = {}), {}, and no inverse plan ({why})",
                    model.name,
                    a.topology.kappa,
                    if a.topology.kappa == 1 {
                        "does not ask for `fk_numeric` (the virtual variable's forward solution)"
                    } else {
                        "and κ > 1 has no numeric forward solution"
                    }
                )));
            }
        }
    };
    if o.assembly.is_some() && !matches!(way, Way::Numeric(_)) {
        return Err(Failure::input(
            "--assembly picks one of a branch's assemblies of `fk_numeric` (κ = 1); this reference is solved in closed form, one assembly per branch",
        ));
    }
    match way {
        Way::Forward(plan) => {
            let inputs = plan.input_joints(model);
            let (given, inputs_from) = given_inputs(r, model, &inputs, &names, &study, o)?;
            let runs = pkm_runtime::plan::run_all(model, &plan, &given);
            let at = format!("inputs ({}) from {inputs_from}", nums_comma(&given));
            let (branch, signs, solution, branch_from) = assembled(runs, wanted, &at, "--q")?;
            let mut how = Map::new();
            how.insert("solver".into(), json!("fk"));
            Ok(Reference {
                inputs,
                given,
                inputs_from,
                branch,
                signs,
                branch_from,
                solution,
                how,
                at,
            })
        }
        Way::Numeric(vp) => numeric_reference(r, l, &vp, &names, &study, o, wanted),
        Way::Inverse(plan) => inverse_reference(r, l, &plan, o, wanted),
    }
}

/// The inputs' values: `--q`, else the study's start, else zeros.
fn given_inputs(
    r: &Request,
    model: &Model,
    inputs: &[usize],
    names: &[String],
    study: &pkm_dsl::study::Resolved,
    o: &Options,
) -> Result<(Vec<f64>, &'static str), Failure> {
    Ok(match (o.q.is_empty(), &study.start) {
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
    })
}

fn nums_comma(v: &[f64]) -> String {
    v.iter().map(|&x| num(x)).collect::<Vec<_>>().join(", ")
}

/// A κ = 1 file that asks for `fk_numeric`: the assemblies the virtual
/// variable finds at the inputs, numbered as `pkm fk` lists them (the plan
/// branch they are found on; `--assembly` counts those of one branch, in
/// `pkm fk`'s order).
fn numeric_reference(
    r: &Request,
    l: &Loaded,
    vp: &VirtualPlan,
    names: &[String],
    study: &pkm_dsl::study::Resolved,
    o: &Options,
    wanted: Wanted,
) -> Result<Reference, Failure> {
    let model = &l.model;
    let inputs = vp.plan.inputs[..vp.plan.inputs.len() - 1].to_vec();
    let (given, inputs_from) = given_inputs(r, model, &inputs, names, study, o)?;
    let at = format!("inputs ({}) from {inputs_from}", nums_comma(&given));
    let virtual_name = model.joints[vp.joint].name.clone();
    let found = pkm_runtime::fk_numeric::solve(model, vp, &given).map_err(|e| Failure::input(e.to_string()))?;
    let count = 1usize << vp.plan.branches;
    let listed: Vec<Value> = found
        .iter()
        .map(|f| json!({ "branch": number_of(&f.signs), "signs": sign_text(&f.signs), "virtual": f.virtual_value }))
        .collect();
    let (branch, branch_from) = match (wanted, found.first()) {
        (Some((b, from)), _) if b >= count => {
            return Err(Failure::input(format!(
                "branch {b} ({from}): the plan has {count} branches, 0 to {}",
                count - 1
            )))
        }
        (Some((b, from)), _) => (b, from),
        (None, Some(first)) => (number_of(&first.signs), "the first that assembles"),
        (None, None) => {
            return Err(Failure::new(
                Kind::Unreachable,
                format!(
                    "no assembly at the {at}: the virtual variable {virtual_name}'s compatibility residual has no root on any branch (give --q)"
                ),
            ))
        }
    };
    // The branch's assemblies in `pkm fk`'s order; `--assembly` picks one.
    let on_branch: Vec<&pkm_runtime::fk_numeric::Assembly> =
        found.iter().filter(|f| number_of(&f.signs) == branch).collect();
    let within = o.assembly.unwrap_or(0);
    let Some(&assembly) = on_branch.get(within) else {
        return Err(Failure::new(
            Kind::Unreachable,
            format!(
                "branch {branch} ({branch_from}) has {} assembl{} at the {at}{}; the virtual variable {virtual_name} finds {} in all",
                on_branch.len(),
                if on_branch.len() == 1 { "y" } else { "ies" },
                o.assembly.map_or(String::new(), |k| format!(", no assembly {k} (--assembly)")),
                found.len()
            ),
        ));
    };
    let mut how = Map::new();
    how.insert("solver".into(), json!("fk_numeric"));
    how.insert("virtual".into(), json!({ virtual_name: assembly.virtual_value }));
    how.insert("assembly".into(), json!(within));
    how.insert("tangent".into(), json!(assembly.kind == RootKind::Tangency));
    how.insert("assemblies".into(), json!(listed));
    Ok(Reference {
        inputs,
        given,
        inputs_from,
        branch,
        signs: sign_text(&assembly.signs),
        branch_from,
        solution: assembly.solution.clone(),
        how,
        at: format!("{at}, assembly {within} of its branch"),
    })
}

/// Values tried for one output when the outputs' home is singular.
const SCAN: usize = 200;

/// The inverse plan at `--pose`, else at the outputs' home: every output
/// 0, unless no branch is regular there (the actuators cannot hold it).
/// Then one output moves from home to where the forward velocity map of
/// the first branch that assembles (or the one asked for) is best
/// conditioned (σ_min/σ_max of the loop equations' passive columns, 0 at an
/// output singularity): a platform's height z over (0, the mechanism's
/// reach], as `pkm report`'s stiffness map holds its platform level at its
/// best-conditioned height; without a height, the best of each output over
/// (−reach, reach] (an angle over (−π, π]). There the branch is the best
/// conditioned (the first of equals).
fn inverse_reference(r: &Request, l: &Loaded, plan: &Plan, o: &Options, wanted: Wanted) -> Result<Reference, Failure> {
    let model = &l.model;
    let inputs = model.inputs();
    let outputs = output_names(l);
    let count = 1usize << plan.branches;
    if let Some((b, from)) = wanted.filter(|(b, _)| *b >= count) {
        return Err(Failure::input(format!(
            "branch {b} ({from}): the inverse plan has {count} branches, 0 to {}",
            count - 1
        )));
    }
    let scale = pkm_runtime::kinematics::model_scale(model);
    let sigma = |pose: &[f64], b: usize| -> Option<f64> {
        let s = pkm_runtime::plan::run(model, plan, pose, &signs_of(b, plan.branches)).ok()?;
        let loops = pkm_runtime::velocity::loops(model, &s.model_values(model)).ok()?;
        Some(loops.passive_sigma(scale))
    };
    // Equal conditionings (branches that differ by a leg's sense) within
    // rounding: the first.
    let better = |s: f64, than: f64| s > than * (1.0 + 1e-9);
    // The best-conditioned (branch, σ) at a pose, on the wanted branch or any.
    let best = |pose: &[f64]| -> Option<(usize, f64)> {
        let branches: Vec<usize> = match wanted {
            Some((b, _)) => vec![b],
            None => (0..count).collect(),
        };
        branches
            .into_iter()
            .filter_map(|b| sigma(pose, b).map(|s| (b, s)))
            .fold(None, |acc: Option<(usize, f64)>, x| match acc {
                Some(a) if !better(x.1, a.1) => Some(a),
                _ => Some(x),
            })
    };
    let (pose, pose_from, preferred) = if o.pose.is_empty() {
        let home = vec![0.0; outputs.len()];
        match best(&home).filter(|(_, s)| *s > pkm_runtime::velocity::SINGULAR) {
            Some((b, _)) => (home, "the outputs' home (every output 0)".to_string(), Some(b)),
            None => {
                // One output moved at a time: the platform's height over
                // (0, R] if an output is one, else each output over (−R, R]
                // (an angle over (−π, π]); R the mechanism's reach.
                let reach = reach(model);
                let moved: Vec<(usize, f64, f64)> = match height_output(l) {
                    Some(z) => vec![(z, 0.0, reach)],
                    None => outputs
                        .iter()
                        .enumerate()
                        .map(|(i, (_, angle))| {
                            let r = if *angle { std::f64::consts::PI } else { reach };
                            (i, -r, r)
                        })
                        .collect(),
                };
                let mut found: Option<(usize, f64, f64)> = None;
                for &(i, low, high) in &moved {
                    for k in 1..=SCAN {
                        let mut pose = home.clone();
                        pose[i] = low + (high - low) * k as f64 / SCAN as f64;
                        // The wanted branch, or the first that assembles.
                        let first = match wanted {
                            Some((b, _)) => sigma(&pose, b),
                            None => (0..count).find_map(|b| sigma(&pose, b)),
                        };
                        if let Some(s) = first.filter(|&s| found.is_none_or(|f| better(s, f.2))) {
                            found = Some((i, pose[i], s));
                        }
                    }
                }
                let mut pose = home;
                // There, the best-conditioned branch.
                match found.and_then(|(i, v, _)| {
                    pose[i] = v;
                    best(&pose).map(|(b, _)| (i, b))
                }) {
                    Some((i, b)) => {
                        let why = format!(
                            "the outputs' home, where no branch is regular, with {} where the forward velocity map of the first branch that assembles is best conditioned{}",
                            outputs[i].0,
                            if moved.len() == 1 { " (the platform's height)" } else { " (each output tried)" }
                        );
                        (pose, why, Some(b))
                    }
                    None => (pose, "the outputs' home (every output 0)".to_string(), None),
                }
            }
        }
    } else {
        (ordered_pose(r, l, o.pose)?, "--pose".to_string(), None)
    };
    let pose_text = outputs
        .iter()
        .zip(&pose)
        .map(|((n, _), v)| format!("{n} = {}", num(*v)))
        .collect::<Vec<_>>()
        .join(", ");
    let at = format!("pose ({pose_text}) from {pose_from}");
    let pose_from = pose_from.as_str();
    let runs = pkm_runtime::plan::run_all(model, plan, &pose);
    // At the home pose without a branch asked for: the best-conditioned one.
    let wanted = wanted.or(preferred.map(|b| (b, "the best conditioned at the pose")));
    let (branch, signs, solution, branch_from) = assembled(runs, wanted, &at, "--pose")?;
    let given = inputs.iter().map(|&j| solution.values[j]).collect();
    let mut how = Map::new();
    how.insert("solver".into(), json!("ik"));
    let by_name: Map<String, Value> = outputs
        .iter()
        .zip(&pose)
        .map(|((n, angle), v)| (n.clone(), json!(r.shown_value(*v, *angle))))
        .collect();
    how.insert("pose".into(), Value::Object(by_name));
    let length = l
        .compiled
        .analysis
        .mass_and_loads
        .units
        .map_or("file unit", |u| u.length.symbol());
    let angle = if r.degrees { "deg" } else { "rad" };
    let units: Map<String, Value> = outputs
        .iter()
        .map(|(n, is_angle)| (n.clone(), json!(if *is_angle { angle } else { length })))
        .collect();
    how.insert("pose_units".into(), Value::Object(units));
    how.insert("pose_from".into(), json!(pose_from));
    Ok(Reference {
        inputs,
        given,
        inputs_from: "the inverse solution at the pose",
        branch,
        signs,
        branch_from,
        solution,
        how,
        at,
    })
}

/// Which declared output value is a platform's height (z of a spatial
/// pose or point output, or a pose part z), if one is.
fn height_output(l: &Loaded) -> Option<usize> {
    let mut at = 0;
    for (declared, o) in l.compiled.analysis.geometry.outputs.iter().zip(&l.outputs) {
        let z = match *o {
            Output::Pose { .. } | Output::Point { .. } if !l.model.planar => Some(2),
            Output::Parts { parts, .. } => parts.given().position(|p| p == 2),
            _ => None,
        };
        if let Some(z) = z.filter(|&z| z < declared.names.len()) {
            return Some(at + z);
        }
        at += declared.names.len();
    }
    None
}

/// The mechanism's reach: each link's largest distance between two of its
/// joint places, summed over the moving links.
fn reach(model: &Model) -> f64 {
    let mut per_link = vec![0.0f64; model.links.len()];
    for a in &model.joints {
        for b in &model.joints {
            for (sa, &la) in a.links.iter().enumerate() {
                for (sb, &lb) in b.links.iter().enumerate() {
                    if la == lb {
                        let (p, q) = (a.places[sa].at(), b.places[sb].at());
                        let d = (0..3).map(|i| (p[i] - q[i]).powi(2)).sum::<f64>().sqrt();
                        per_link[la] = per_link[la].max(d);
                    }
                }
            }
        }
    }
    per_link.iter().skip(1).sum::<f64>().max(1.0)
}

/// The branch to export and its solution: the one asked for (by `--branch`,
/// the study or the best conditioned), else the first that assembles.
fn assembled(
    runs: Vec<Run>,
    wanted: Wanted,
    at: &str,
    flag: &str,
) -> Result<(usize, Vec<&'static str>, Solution, &'static str), Failure> {
    let count = runs.len();
    if let Some((b, from)) = wanted {
        let Some((signs, run)) = runs.into_iter().nth(b) else {
            return Err(Failure::input(format!(
                "branch {b} ({from}): the mechanism has {count} branches, 0 to {}",
                count.saturating_sub(1)
            )));
        };
        return match run {
            Ok(s) => Ok((b, sign_text(&signs), s, from)),
            Err(e) => Err(Failure::new(
                Kind::Unreachable,
                format!("branch {b} ({from}) does not assemble at the {at}: {e}"),
            )),
        };
    }
    let mut reasons = Vec::new();
    for (k, (signs, run)) in runs.into_iter().enumerate() {
        match run {
            Ok(s) => return Ok((k, sign_text(&signs), s, "the first that assembles")),
            Err(e) => reasons.push(format!("branch {k}: {e}")),
        }
    }
    Err(Failure::new(
        Kind::Unreachable,
        format!("no branch assembles at the {at} (give {flag}): {}", reasons.join("; ")),
    ))
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
