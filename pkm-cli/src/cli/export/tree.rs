//! The spanning tree of the link graph that MuJoCo's bodies follow
//! ([`Tree`]): its loops cut between links with mass, and the U joints whose
//! cross would hang at a cut cut whole ([`Cross`]).

use crate::cli::failure::Failure;
use pkm_runtime::model::{Joint, JointType, Model};
use pkm_runtime::nalgebra::Vector3;

/// A spanning tree of the link graph for MuJoCo's bodies.
pub(super) struct Tree {
    /// Per link, the joints to its children and the children.
    pub(super) children: Vec<Vec<(usize, usize)>>,
    /// The joints left out, each closed by equality constraints.
    pub(super) cut: Vec<usize>,
    /// The U joints cut whole: their crosses have no body.
    pub(super) crosses: Vec<Cross>,
}

impl Tree {
    /// Whether a cut joint or a cut U acts on `link`.
    pub(super) fn cut_at(&self, model: &Model, link: usize) -> bool {
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
pub(super) struct Cross {
    /// The cross.
    pub(super) link: usize,
    /// Its revolute joints, and the links on their far sides.
    pub(super) joints: [usize; 2],
    pub(super) ends: [usize; 2],
    /// The centre, in the cross's frame.
    pub(super) centre: [f64; 3],
}

/// The crosses of U joints ([`Cross`]) that hang from the tree at a cut:
/// each taken out of the tree (its joints leave, its cut joint with them).
pub(super) fn cut_crosses(model: &Model, tree: &mut Tree, light: &[bool], loaded: &[bool]) {
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
pub(super) fn spanning_tree(model: &Model, light: &[bool]) -> Result<Tree, Failure> {
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
