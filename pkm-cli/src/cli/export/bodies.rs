//! The bodies along the tree: the MuJoCo joints ([`MjJoint`]), one node per
//! link and declared bar ([`Nodes`]) at the reference assembly
//! ([`Assembly`]), the parallelograms, the nodes without mass merged into
//! their child ([`Merged`]), and the mass properties MuJoCo reads.

use super::tree::Tree;
use super::writer::{scaled, unit};
use crate::cli::failure::Failure;
use pkm_runtime::kinematics::Pose;
use pkm_runtime::mass_properties::{arm_side, bar_pose, Body, Carrier};
use pkm_runtime::model::{JointType, Model, Place};
use pkm_runtime::nalgebra::{Isometry3, Matrix3, Vector3};

/// What kind of MuJoCo joint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum MjKind {
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
    pub(super) fn name(self) -> &'static str {
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
pub(super) struct MjJoint {
    pub(super) name: String,
    pub(super) kind: MjKind,
    /// The pkm joint it stands for.
    pub(super) pkm: usize,
    /// Its point (file units) and unit axis, world, at the reference.
    pub(super) anchor: [f64; 3],
    pub(super) axis: [f64; 3],
    /// `qpos` at the reference (rad or m; a ball's is the identity).
    pub(super) reference: f64,
    /// `qpos = scale · pkm's value` (hinges and slides).
    pub(super) scale: f64,
}

/// What a body of the tree stands for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Part {
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
pub(super) struct Node {
    pub(super) part: Part,
    /// Its frame in the world at the reference (file units).
    pub(super) pose: Pose<f64>,
    pub(super) parent: usize,
    /// The joints from its parent.
    own: Vec<MjJoint>,
    pub(super) children: Vec<usize>,
    /// Its mass properties (file units), if it has mass.
    pub(super) body: Option<Body>,
    /// A bar's two hinges (world, file units), to draw it.
    pub(super) ends: Option<[[f64; 3]; 2]>,
}

/// The declared bars with mass, per parallelogram.
pub(super) struct Bars {
    pub(super) all: Vec<Body>,
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
pub(super) struct Parallelogram {
    arm_link: usize,
    /// The hinge axis in the arm link's frame (unit).
    local_axis: Vector3<f64>,
    axis: [f64; 3],
    offset: [f64; 3],
    /// The arm link's hinge point (its frame).
    pub(super) arm_at: [f64; 3],
}

/// The mechanism assembled at the reference configuration.
pub(super) struct Assembly<'a> {
    pub(super) model: &'a Model,
    /// Every link's pose (file units).
    pub(super) poses: Vec<Pose<f64>>,
    /// Every joint's values, in the model's layout (three per spherical joint).
    pub(super) values: Vec<f64>,
    /// Their rates and accelerations (zeros at rest; a spherical joint's:
    /// the relative angular velocity and its rate, world axes).
    pub(super) rates: Vec<f64>,
    pub(super) accels: Vec<f64>,
    pub(super) offsets: Vec<usize>,
    /// Metres per file length unit.
    pub(super) m: f64,
}

impl Assembly<'_> {
    /// A joint's values (one, or a spherical joint's three).
    pub(super) fn of(&self, joint: usize) -> &[f64] {
        self.part(&self.values, joint)
    }

    /// A joint's part of `all` (values, rates or accelerations).
    pub(super) fn part<'v>(&self, all: &'v [f64], joint: usize) -> &'v [f64] {
        let at = self.offsets[joint];
        &all[at..at + self.model.joints[joint].kind.dof()]
    }
}

pub(super) fn parallelogram(model: &Model, poses: &[Pose<f64>], joint: usize) -> Option<Parallelogram> {
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
pub(super) struct Nodes {
    pub(super) nodes: Vec<Node>,
    /// Per link, its node.
    pub(super) of_link: Vec<usize>,
}

/// Builds the nodes along the tree from the base, then the declared bars
/// that do not carry a link.
pub(super) fn nodes(a: &Assembly, tree: &Tree, link_bodies: &[Option<Body>], bars: &Bars) -> Result<Nodes, Failure> {
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
pub(super) struct Merged {
    /// Per node: its joints go down to its one child, which carries them
    /// before its own (a serial chain in one MuJoCo body).
    pub(super) merged: Vec<bool>,
    /// Per node: the joints its body carries (its merged ancestors' first).
    pub(super) joints: Vec<Vec<MjJoint>>,
}

/// A node without mass goes into its child when it has one child, no
/// constraint or load acts on it, and MuJoCo takes the joints in one body:
/// the link is then exactly the joint chain it forms (a U joint's cross, a
/// parallelogram's bar, a massless link between two hinges), with no
/// stand-in mass.
pub(super) fn merge(n: &Nodes, model: &Model, tree: &Tree, loaded: &[bool]) -> Merged {
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
pub(super) fn ends_without_mass(model: &Model, tree: &Tree, n: &Nodes, merged: &Merged) -> Result<(), Failure> {
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
pub(super) fn as_exported(b: &Body, planar: bool, tiny: f64) -> Body {
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
