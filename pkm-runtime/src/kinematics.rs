//! The model's kinematics: link poses from joint values along a spanning
//! tree of the link graph, the loop-closure residual of the joints left out
//! of the tree, the model's size scale, and points of links.
//!
//! # Method
//! - Link poses are propagated from the base (link 0, at the identity) along a
//!   spanning tree of the link graph ([`spanning_tree`]): breadth first from
//!   link 0, scanning joints in declaration order. A joint traversed from its
//!   `links[1]` to its `links[0]` contributes the inverse of
//!   [`joint_pose`] (the conventions of [`crate::model`]).
//! - Every joint not in the tree is *cut*. Closing its loop means that the
//!   pose of its `v = links[1]` reached through the tree equals
//!   `T_u · joint_pose(joint)`; [`loop_residual`] returns the mismatch,
//!   6 rows per cut joint.
//!
//! Poses, joint transforms and the residual are generic over the scalar
//! ([`Real`], a [`Scalar`](crate::scalar::Scalar) with values) through [`Kinematics`], so that the same code evaluates them in
//! `f64` (for [`crate::newton`]) and in a higher precision (for a reference
//! solution). A pose is a unit quaternion and a translation, composed as
//! nalgebra composes an `Isometry3`, so the `f64` functions here return
//! nalgebra's types at no cost.

use std::collections::VecDeque;
use std::fmt;

use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};

use crate::model::{JointType, Model, Place};
use crate::scalar::{add, constant as lift, cross, dot, norm, scale, sub, unit as normalize, Real};

/// Why a model and a joint-value vector do not give link poses.
#[derive(Debug, Clone, PartialEq)]
pub enum ModelError {
    /// The model has no links, so no base.
    NoBase,
    /// A joint names a link that does not exist.
    BadLink {
        /// The joint's index.
        joint: usize,
        /// The link index it names.
        link: usize,
    },
    /// A link is not connected to the base by any chain of joints.
    Disconnected {
        /// The link's index.
        link: usize,
    },
    /// The joint-value vector does not have one value per joint variable.
    BadLength {
        /// `Model::value_offsets().1`.
        expected: usize,
        /// The vector's length.
        got: usize,
    },
    /// A joint value, or a pose computed from the values (e.g. through a
    /// zero-length axis), is not finite.
    NonFinite {
        /// What is not finite.
        what: String,
    },
}

impl fmt::Display for ModelError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ModelError::NoBase => write!(f, "the model has no links"),
            ModelError::BadLink { joint, link } => write!(f, "joint {joint} names link {link}, which does not exist"),
            ModelError::Disconnected { link } => write!(f, "link {link} is not connected to the base"),
            ModelError::BadLength { expected, got } => {
                write!(f, "expected {expected} joint values, got {got}")
            }
            ModelError::NonFinite { what } => write!(f, "{what} is not finite"),
        }
    }
}

impl std::error::Error for ModelError {}

/// A spanning tree of a model's link graph, rooted at the base.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Tree {
    /// For each link, the joint through which the tree reaches it; `None` for the base.
    pub parent: Vec<Option<usize>>,
    /// The links in breadth-first order, base first: every link comes after its parent.
    pub order: Vec<usize>,
    /// The joints not in the tree, in declaration order: one closure loop each.
    pub cut: Vec<usize>,
}

/// The spanning tree used by [`link_poses`]: breadth first from link 0; the
/// joints of each dequeued link are scanned in declaration order and a joint
/// whose other link is not reached yet enters the tree.
///
/// A joint connecting a link to itself is always cut.
pub fn spanning_tree(model: &Model) -> Result<Tree, ModelError> {
    let n = model.links.len();
    if n == 0 {
        return Err(ModelError::NoBase);
    }
    for (j, joint) in model.joints.iter().enumerate() {
        if let Some(&link) = joint.links.iter().find(|&&l| l >= n) {
            return Err(ModelError::BadLink { joint: j, link });
        }
    }
    let mut parent = vec![None; n];
    let mut reached = vec![false; n];
    let mut in_tree = vec![false; model.joints.len()];
    let mut order = Vec::with_capacity(n);
    let mut queue = VecDeque::from([0]);
    reached[0] = true;
    while let Some(link) = queue.pop_front() {
        order.push(link);
        for (j, joint) in model.joints.iter().enumerate() {
            let [u, v] = joint.links;
            let other = if u == link {
                v
            } else if v == link {
                u
            } else {
                continue;
            };
            if !reached[other] {
                reached[other] = true;
                parent[other] = Some(j);
                in_tree[j] = true;
                queue.push_back(other);
            }
        }
    }
    if let Some(link) = reached.iter().position(|&r| !r) {
        return Err(ModelError::Disconnected { link });
    }
    let cut = (0..model.joints.len()).filter(|&j| !in_tree[j]).collect();
    Ok(Tree { parent, order, cut })
}

/// A rigid transform in scalar `T`: `x ↦ R x + translation`, with `R` the
/// unit quaternion `rotation` = `[w, x, y, z]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose<T> {
    /// The rotation as a unit quaternion `[w, x, y, z]`.
    pub rotation: [T; 4],
    /// The translation.
    pub translation: [T; 3],
}

impl<T: Real> Pose<T> {
    /// The identity.
    pub fn identity() -> Self {
        Pose {
            rotation: [T::c(1.0), T::c(0.0), T::c(0.0), T::c(0.0)],
            translation: [T::c(0.0); 3],
        }
    }

    /// A pure translation.
    pub fn translation(t: [T; 3]) -> Self {
        Pose {
            translation: t,
            ..Pose::identity()
        }
    }

    /// `R v` (the vector turned, not shifted).
    pub fn rotate(&self, v: [T; 3]) -> [T; 3] {
        let [w, x, y, z] = self.rotation;
        let q = [x, y, z];
        // v + w t + q × t with t = 2 q × v, as nalgebra turns a vector.
        let t = scale(T::c(2.0), cross(q, v));
        add(add(scale(w, t), cross(q, t)), v)
    }

    /// `R p + translation`.
    pub fn transform_point(&self, p: [T; 3]) -> [T; 3] {
        add(self.rotate(p), self.translation)
    }

    /// The inverse transform.
    pub fn inverse(&self) -> Self {
        let [w, x, y, z] = self.rotation;
        let conj = Pose {
            rotation: [w, -x, -y, -z],
            translation: [T::c(0.0); 3],
        };
        let t = conj.rotate(self.translation);
        Pose {
            rotation: conj.rotation,
            translation: [-t[0], -t[1], -t[2]],
        }
    }

    /// `self · other`: first `other`, then `self`.
    pub fn then(&self, other: &Self) -> Self {
        let [aw, ax, ay, az] = self.rotation;
        let [bw, bx, by, bz] = other.rotation;
        Pose {
            rotation: [
                aw * bw - ax * bx - ay * by - az * bz,
                aw * bx + ax * bw + ay * bz - az * by,
                aw * by - ax * bz + ay * bw + az * bx,
                aw * bz + ax * by - ay * bx + az * bw,
            ],
            translation: add(self.translation, self.rotate(other.translation)),
        }
    }

    /// The rotation by the rotation vector `r` (angle `|r|` about `r`).
    pub fn rotation_vector(r: [T; 3]) -> Self {
        let half = scale(T::c(0.5), r);
        let n2 = dot(half, half);
        if n2 == T::c(0.0) {
            return Pose::identity();
        }
        let n = n2.sqrt();
        let k = n.sin() / n;
        Pose {
            rotation: [n.cos(), half[0] * k, half[1] * k, half[2] * k],
            translation: [T::c(0.0); 3],
        }
    }

    /// The rotation vector of the rotation (angle in `[0, π]`, zero for the identity).
    pub fn scaled_axis(&self) -> [T; 3] {
        let [w, x, y, z] = self.rotation;
        // q and −q are the same rotation: take the one with w ≥ 0.
        let v = if w >= T::c(0.0) { [x, y, z] } else { [-x, -y, -z] };
        let n = norm(v);
        if n <= T::c(0.0) {
            return [T::c(0.0); 3];
        }
        scale(n.atan2(w.abs()) * T::c(2.0) / n, v)
    }

    /// The unit quaternion of the rotation matrix with columns `x`, `y`, `z`.
    fn from_basis(x: [T; 3], y: [T; 3], z: [T; 3], at: [T; 3]) -> Self {
        let m = |i: usize, j: usize| [x, y, z][j][i];
        let (one, two, quarter) = (T::c(1.0), T::c(2.0), T::c(0.25));
        let trace = m(0, 0) + m(1, 1) + m(2, 2);
        // The largest of w, x, y, z first (as nalgebra does), for accuracy.
        let rotation = if trace > T::c(0.0) {
            let d = (trace + one).sqrt() * two;
            [
                d * quarter,
                (m(2, 1) - m(1, 2)) / d,
                (m(0, 2) - m(2, 0)) / d,
                (m(1, 0) - m(0, 1)) / d,
            ]
        } else if m(0, 0) > m(1, 1) && m(0, 0) > m(2, 2) {
            let d = (one + m(0, 0) - m(1, 1) - m(2, 2)).sqrt() * two;
            [
                (m(2, 1) - m(1, 2)) / d,
                d * quarter,
                (m(0, 1) + m(1, 0)) / d,
                (m(0, 2) + m(2, 0)) / d,
            ]
        } else if m(1, 1) > m(2, 2) {
            let d = (one + m(1, 1) - m(0, 0) - m(2, 2)).sqrt() * two;
            [
                (m(0, 2) - m(2, 0)) / d,
                (m(0, 1) + m(1, 0)) / d,
                d * quarter,
                (m(1, 2) + m(2, 1)) / d,
            ]
        } else {
            let d = (one + m(2, 2) - m(0, 0) - m(1, 1)).sqrt() * two;
            [
                (m(1, 0) - m(0, 1)) / d,
                (m(0, 2) + m(2, 0)) / d,
                (m(1, 2) + m(2, 1)) / d,
                d * quarter,
            ]
        };
        Pose {
            rotation,
            translation: at,
        }
    }

    /// Whether every component is finite.
    pub fn is_finite(&self) -> bool {
        self.rotation.iter().chain(&self.translation).all(|x| x.is_finite())
    }
}

impl From<Pose<f64>> for Isometry3<f64> {
    fn from(p: Pose<f64>) -> Self {
        let [w, x, y, z] = p.rotation;
        Isometry3::from_parts(
            Translation3::from(p.translation),
            UnitQuaternion::new_unchecked(Quaternion::new(w, x, y, z)),
        )
    }
}

impl From<&Isometry3<f64>> for Pose<f64> {
    fn from(t: &Isometry3<f64>) -> Self {
        let q = t.rotation.quaternion();
        Pose {
            rotation: [q.w, q.i, q.j, q.k],
            translation: t.translation.vector.into(),
        }
    }
}

/// The joint frame with origin `at` and z along `axis`; x is the unit
/// vector of the world x axis made perpendicular to z (the world y axis when
/// z is within about 25° of x). See [`crate::model::canonical_frame`].
pub fn frame<T: Real>(at: [f64; 3], axis: [f64; 3]) -> Pose<T> {
    if axis[0] == 0.0 && axis[1] == 0.0 && axis[2] > 0.0 {
        // Along +z (every axis of a planar model): the identity rotation,
        // exactly what the general construction below gives, without its
        // three square roots.
        return Pose::translation(lift(at));
    }
    let z = normalize(lift::<T>(axis));
    let (o, i) = (T::c(0.0), T::c(1.0));
    let e = if z[0].abs() < T::c(0.9) { [i, o, o] } else { [o, i, o] };
    let x = normalize(sub(e, scale(dot(z, e), z)));
    let y = cross(z, x);
    Pose::from_basis(x, y, z, lift(at))
}

/// The canonical frames of a joint's two places ([`frame`]).
pub fn frames<T: Real>(places: &[Place; 2]) -> [Pose<T>; 2] {
    places.map(|p| frame(p.at(), p.axis()))
}

/// The pose of a joint's `links[1]` relative to its `links[0]` (`T_u⁻¹ ·
/// T_v`) for the joint's values, by the conventions of [`crate::model`],
/// with the places' frames ([`frames`]) computed beforehand.
pub fn joint_pose<T: Real>(kind: JointType, places: &[Place; 2], frames: &[Pose<T>; 2], values: &[T]) -> Pose<T> {
    let [fu, fv] = frames;
    match kind {
        JointType::R => {
            let half = values[0] * T::c(0.5);
            let o = T::c(0.0);
            let rz = Pose {
                rotation: [half.cos(), o, o, half.sin()],
                translation: [o; 3],
            };
            fu.then(&rz).then(&fv.inverse())
        }
        JointType::Pa => {
            // The link with the arm: its hinge frame, then the arm turned by
            // the value about the hinge axis, then the other hinge's frame.
            let swing = |f: &Pose<T>, arm: [f64; 3]| {
                let [x, y, z] = f.inverse().rotate(lift(arm));
                let (s, c) = (values[0].sin(), values[0].cos());
                Pose::translation([c * x - s * y, s * x + c * y, z])
            };
            match (places[0], places[1]) {
                (_, Place::Arm { arm, .. }) => fv.then(&swing(fv, arm)).then(&fu.inverse()).inverse(),
                (Place::Arm { arm, .. }, _) => fu.then(&swing(fu, arm)).then(&fv.inverse()),
                _ => fu.then(&fv.inverse()),
            }
        }
        JointType::P => {
            let slide = |guide: &Place, slider: &Place| {
                let x = lift::<T>([1.0, 0.0, 0.0]);
                let (q, d) = match *guide {
                    Place::Line { through, along } => (lift(through), normalize(lift(along))),
                    Place::Axis { at, axis } | Place::Arm { at, axis, .. } => (lift(at), normalize(lift(axis))),
                    Place::Point { at } => (lift(at), x),
                };
                Pose::translation(sub(add(q, scale(values[0], d)), lift(slider.at())))
            };
            if matches!(places[0], Place::Line { .. }) {
                slide(&places[0], &places[1])
            } else {
                slide(&places[1], &places[0]).inverse()
            }
        }
        JointType::S => {
            let (cu, cv) = (lift::<T>(places[0].at()), lift::<T>(places[1].at()));
            let turn = Pose {
                translation: cu,
                ..Pose::rotation_vector([values[0], values[1], values[2]])
            };
            turn.then(&Pose::translation([-cv[0], -cv[1], -cv[2]]))
        }
    }
}

/// A model ready to evaluate in scalar `T`: its spanning tree, the offsets
/// of the joints' values, and every joint's place frames.
#[derive(Debug, Clone)]
pub struct Kinematics<'a, T> {
    /// The model.
    pub model: &'a Model,
    /// Its spanning tree ([`spanning_tree`]).
    pub tree: Tree,
    /// Each joint's first value's index (see [`Model::value_offsets`]).
    pub offsets: Vec<usize>,
    /// The length of a joint-value vector.
    pub len: usize,
    /// Each joint's place frames ([`frames`]).
    frames: Vec<[Pose<T>; 2]>,
}

impl<'a, T: Real> Kinematics<'a, T> {
    /// The tree, offsets and frames of `model`.
    ///
    /// # Errors
    /// As [`spanning_tree`].
    pub fn new(model: &'a Model) -> Result<Self, ModelError> {
        let tree = spanning_tree(model)?;
        let (offsets, len) = model.value_offsets();
        let frames = model.joints.iter().map(|j| frames(&j.places)).collect();
        Ok(Kinematics {
            model,
            tree,
            offsets,
            len,
            frames,
        })
    }

    /// Checks the length and finiteness of a joint-value vector.
    ///
    /// # Errors
    /// [`ModelError::BadLength`], [`ModelError::NonFinite`].
    pub fn check(&self, values: &[T]) -> Result<(), ModelError> {
        if values.len() != self.len {
            return Err(ModelError::BadLength {
                expected: self.len,
                got: values.len(),
            });
        }
        match values.iter().position(|x| !x.is_finite()) {
            Some(i) => Err(ModelError::NonFinite {
                what: format!("joint value {i}"),
            }),
            None => Ok(()),
        }
    }

    /// Joint `j`'s pose of `links[1]` relative to `links[0]` at `values`.
    fn joint(&self, j: usize, values: &[T]) -> Pose<T> {
        let joint = &self.model.joints[j];
        let o = self.offsets[j];
        joint_pose(
            joint.kind,
            &joint.places,
            &self.frames[j],
            &values[o..o + joint.kind.dof()],
        )
    }

    /// The world pose of every link for joint values already [`checked`](Self::check),
    /// propagated along the tree. Cut joints' values are not used.
    ///
    /// # Errors
    /// [`ModelError::NonFinite`] if a pose is not finite (e.g. through a zero-length axis).
    pub fn poses(&self, values: &[T]) -> Result<Vec<Pose<T>>, ModelError> {
        let mut poses = vec![Pose::identity(); self.model.links.len()];
        for &link in &self.tree.order {
            let Some(j) = self.tree.parent[link] else { continue };
            let joint = &self.model.joints[j];
            let t = self.joint(j, values);
            poses[link] = if joint.links[1] == link {
                poses[joint.links[0]].then(&t)
            } else {
                poses[joint.links[1]].then(&t.inverse())
            };
            if !poses[link].is_finite() {
                return Err(ModelError::NonFinite {
                    what: format!("the pose of link {link} (through joint {})", joint.name),
                });
            }
        }
        Ok(poses)
    }

    /// The loop-closure residual (see [`loop_residual`]) for joint values
    /// already [`checked`](Self::check) and their link [`poses`](Self::poses).
    ///
    /// # Errors
    /// [`ModelError::NonFinite`] if a cut joint's transform is not finite.
    pub fn residual(&self, values: &[T], poses: &[Pose<T>]) -> Result<Vec<T>, ModelError> {
        let mut r = Vec::with_capacity(6 * self.tree.cut.len());
        for &j in &self.tree.cut {
            let joint = &self.model.joints[j];
            let [u, v] = joint.links;
            let predicted = poses[u].then(&self.joint(j, values));
            if !predicted.is_finite() {
                return Err(ModelError::NonFinite {
                    what: format!("the transform of joint {}", joint.name),
                });
            }
            let dp = sub(poses[v].translation, predicted.translation);
            let [w, x, y, z] = predicted.rotation;
            let inverse = Pose {
                rotation: [w, -x, -y, -z],
                translation: [T::c(0.0); 3],
            };
            let dr = poses[v].then(&inverse).scaled_axis();
            r.extend(dp.into_iter().chain(dr));
        }
        Ok(r)
    }

    /// The loop residual at joint values already [`checked`](Self::check),
    /// with its position rows divided by `scale` (dimensionless, as Newton
    /// measures it).
    ///
    /// # Errors
    /// As [`poses`](Self::poses) and [`residual`](Self::residual), and
    /// [`ModelError::NonFinite`] for a row that is not finite.
    pub fn scaled_residual(&self, values: &[T], scale: T) -> Result<Vec<T>, ModelError> {
        let poses = self.poses(values)?;
        let mut r = self.residual(values, &poses)?;
        for (i, x) in r.iter_mut().enumerate() {
            if i % 6 < 3 {
                *x = *x / scale;
            }
        }
        match r.iter().position(|x| !x.is_finite()) {
            Some(i) => Err(ModelError::NonFinite {
                what: format!("residual row {i}"),
            }),
            None => Ok(r),
        }
    }

    /// World coordinates of the named point `name` for link poses from
    /// [`poses`](Self::poses); `None` if there is no such point or no pose for its link.
    pub fn point(&self, poses: &[Pose<T>], name: &str) -> Option<[T; 3]> {
        let p = self.model.points.iter().find(|p| p.name == name)?;
        Some(poses.get(p.link)?.transform_point(lift(p.at)))
    }

    /// World position of joint `joint`'s point (see [`joint_point`]).
    ///
    /// # Panics
    /// If `joint` is not a joint of the model or `poses` has no pose for its link.
    pub fn joint_point(&self, poses: &[Pose<T>], joint: usize) -> [T; 3] {
        let j = &self.model.joints[joint];
        let side = j.point_side();
        poses[j.links[side]].transform_point(lift(j.places[side].at()))
    }
}

fn checked<'a>(model: &'a Model, values: &[f64]) -> Result<Kinematics<'a, f64>, ModelError> {
    let k = Kinematics::new(model)?;
    k.check(values)?;
    Ok(k)
}

/// The world pose of every link (index = link index) for the joint values
/// `values` (laid out as by [`Model::value_offsets`]), propagated from the base
/// along [`spanning_tree`]. Cut joints' values are not used.
pub fn link_poses(model: &Model, values: &[f64]) -> Result<Vec<Isometry3<f64>>, ModelError> {
    let poses = checked(model, values)?.poses(values)?;
    Ok(poses.into_iter().map(Isometry3::from).collect())
}

/// The loop-closure residual at `values`: for each cut joint of
/// [`spanning_tree`] (in declaration order) with `u, v = links`, the
/// mismatch between `T_v` from [`link_poses`] and `T_u · joint_pose`:
/// rows `6k..6k+3` the difference of the origins' world positions (length
/// units), rows `6k+3..6k+6` the rotation vector (radians, angle in [0, π]) of
/// `R_v · R_predicted⁻¹`, in world axes.
pub fn loop_residual(model: &Model, values: &[f64]) -> Result<Vec<f64>, ModelError> {
    let k = checked(model, values)?;
    let poses = k.poses(values)?;
    k.residual(values, &poses)
}

/// The model's size scale `L`: the largest distance of any placed point (joint
/// places, guide lines' points, named points) from its link's origin, or 1 if
/// that is 0 or not finite. [`crate::newton::solve_fk`] measures position
/// mismatches in units of `L`.
pub fn model_scale(model: &Model) -> f64 {
    let joints = model.joints.iter().flat_map(|j| j.places.iter().map(Place::at));
    let named = model.points.iter().map(|p| p.at);
    let l = joints.chain(named).map(norm).fold(0.0, f64::max);
    if l > 0.0 && l.is_finite() {
        l
    } else {
        1.0
    }
}

/// The mechanism's reach: each moving link's largest distance between two
/// of its joint places, summed, and each parallelogram's arm (the bar it
/// swings, a link the model does not hold): an upper bound of how far a
/// point of it can be from the base's joints, without the driven slides'
/// travel; at least 1.
pub fn model_reach(model: &Model) -> f64 {
    let mut per_link = vec![0.0f64; model.links.len()];
    for a in &model.joints {
        for b in &model.joints {
            for (sa, &la) in a.links.iter().enumerate() {
                for (sb, &lb) in b.links.iter().enumerate() {
                    if la == lb {
                        let (p, q) = (a.places[sa].at(), b.places[sb].at());
                        per_link[la] = per_link[la].max(norm([p[0] - q[0], p[1] - q[1], p[2] - q[2]]));
                    }
                }
            }
        }
    }
    let arms: f64 = model
        .joints
        .iter()
        .flat_map(|j| j.places.iter())
        .map(|p| match *p {
            Place::Arm { arm, .. } => norm(arm),
            _ => 0.0,
        })
        .sum();
    (per_link.iter().skip(1).sum::<f64>() + arms).max(1.0)
}

/// World coordinates of the named point `name`, for link poses from
/// [`link_poses`]; `None` if there is no such point or no pose for its link.
pub fn point(model: &Model, poses: &[Isometry3<f64>], name: &str) -> Option<[f64; 3]> {
    let p = model.points.iter().find(|p| p.name == name)?;
    Some(Pose::from(poses.get(p.link)?).transform_point(p.at))
}

/// World position of joint `joint`'s point: its place on `links[0]`
/// transformed by that link's pose, except for a P joint, whose point is its
/// slider point (the non-guide place, on whichever link it sits; the guide is
/// `places[0]` if that is a line, as in [`joint_pose`]). Once the loops
/// are closed this is also the point's position seen from `links[1]` (for R
/// and S joints).
///
/// # Panics
/// If `joint` is not a joint of `model` or `poses` has no pose for its link.
pub fn joint_point(model: &Model, poses: &[Isometry3<f64>], joint: usize) -> [f64; 3] {
    let j = &model.joints[joint];
    let side = j.point_side();
    Pose::from(&poses[j.links[side]]).transform_point(j.places[side].at())
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::model::{Joint, NamedPoint};
    use nalgebra::{Point3, Vector3};
    use std::f64::consts::PI;

    pub(crate) fn z_axis(x: f64, y: f64) -> Place {
        Place::Axis {
            at: [x, y, 0.0],
            axis: [0.0, 0.0, 1.0],
        }
    }

    pub(crate) fn joint(name: &str, kind: JointType, links: [usize; 2], places: [Place; 2], actuated: bool) -> Joint {
        Joint {
            name: name.into(),
            kind,
            links,
            places,
            actuated,
        }
    }

    pub(crate) fn model(
        name: &str,
        planar: bool,
        links: &[&str],
        joints: Vec<Joint>,
        points: Vec<NamedPoint>,
    ) -> Model {
        Model {
            name: name.into(),
            planar,
            links: links.iter().map(|s| s.to_string()).collect(),
            joints,
            points,
        }
    }

    /// The four-bar of the brief: joints R1 (base–crank, actuated), R2
    /// (crank–coupler), R3 (coupler–rocker), R4 (base–rocker).
    pub(crate) fn four_bar(l1: f64, l2: f64, l3: f64, l4: f64) -> Model {
        use JointType::R;
        let joints = vec![
            joint("R1", R, [0, 1], [z_axis(0.0, 0.0), z_axis(0.0, 0.0)], true),
            joint("R2", R, [1, 2], [z_axis(l1, 0.0), z_axis(0.0, 0.0)], false),
            joint("R3", R, [2, 3], [z_axis(l2, 0.0), z_axis(l3, 0.0)], false),
            joint("R4", R, [0, 3], [z_axis(l4, 0.0), z_axis(0.0, 0.0)], false),
        ];
        model(
            "four_bar",
            true,
            &["base", "crank", "coupler", "rocker"],
            joints,
            vec![],
        )
    }

    #[test]
    fn spanning_tree_and_residual_rows_of_the_four_bar() {
        let m = four_bar(100.0, 250.0, 200.0, 300.0);
        let tree = spanning_tree(&m).unwrap();
        assert_eq!(tree.parent, vec![None, Some(0), Some(1), Some(3)]);
        assert_eq!(tree.order, vec![0, 1, 3, 2]);
        assert_eq!(tree.cut, vec![2]);
        // Hand values: θ = 90°, B = (0, 100); coupler along +x would put R3 at
        // (250, 100); rocker at 90° puts its R3 at (300, 200).
        // Mismatch of the rocker's origin: T_v = R4 frame at (300, 0) rotated 90°;
        // predicted: R3 on the coupler (250, 100), rocker rotated by 90° there, its
        // origin 200 below: (250, -100). Difference (50, 100, 0); orientations agree.
        let values = [PI / 2.0, -PI / 2.0, PI / 2.0, PI / 2.0];
        let r = loop_residual(&m, &values).unwrap();
        let want = [50.0, 100.0, 0.0, 0.0, 0.0, 0.0];
        for (x, w) in r.iter().zip(want) {
            assert!((x - w).abs() < 1e-12, "{r:?}");
        }
        // An orientation mismatch of 0.3 rad about z when R3 is off by 0.3.
        let r = loop_residual(&m, &[PI / 2.0, -PI / 2.0, PI / 2.0 + 0.3, PI / 2.0]).unwrap();
        assert!((r[5] + 0.3).abs() < 1e-12 && r[3] == 0.0 && r[4] == 0.0, "{r:?}");
    }

    /// Two poses with every component non-zero, built by nalgebra.
    fn samples() -> [Isometry3<f64>; 2] {
        [
            Isometry3::new(Vector3::new(1.0, -2.0, 0.5), Vector3::new(0.3, -1.1, 2.0)),
            Isometry3::new(Vector3::new(-0.7, 0.2, 3.0), Vector3::new(-2.5, 0.4, 0.9)),
        ]
    }

    fn close(a: &Isometry3<f64>, b: &Isometry3<f64>) -> bool {
        (a.translation.vector - b.translation.vector).norm() < 1e-12 && a.rotation.angle_to(&b.rotation) < 1e-12
    }

    #[test]
    fn pose_algebra_matches_nalgebra() {
        let [a, b] = samples();
        let (pa, pb) = (Pose::from(&a), Pose::from(&b));
        assert!(close(&Isometry3::from(pa.then(&pb)), &(a * b)));
        assert!(close(&Isometry3::from(pa.inverse()), &a.inverse()));
        let p = [0.25, -4.0, 1.5];
        let want = a.transform_point(&Point3::from(p));
        let got = pa.transform_point(p);
        assert!((Vector3::from(got) - want.coords).norm() < 1e-12);
        let axis = (a.rotation * b.rotation.inverse()).scaled_axis();
        let got = pa.then(&pb.inverse()).scaled_axis();
        assert!((Vector3::from(got) - axis).norm() < 1e-12);
        let r = [0.4, -1.2, 2.2];
        let want = Isometry3::rotation(Vector3::from(r));
        assert!(close(&Isometry3::from(Pose::rotation_vector(r)), &want));
    }

    #[test]
    fn frame_z_is_the_axis_and_x_follows_the_world_x() {
        // Hand values: axis z gives the identity; axis x gives x' = y, z' = x.
        let planar = frame::<f64>([1.0, 2.0, 0.0], [0.0, 0.0, 5.0]);
        assert_eq!(planar.rotation, [1.0, 0.0, 0.0, 0.0]);
        assert_eq!(planar.translation, [1.0, 2.0, 0.0]);
        let along_x = frame::<f64>([0.0; 3], [2.0, 0.0, 0.0]);
        let turned = |v| along_x.rotate(v).map(|x: f64| (x * 1e12).round() / 1e12);
        assert_eq!(turned([1.0, 0.0, 0.0]), [0.0, 1.0, 0.0]);
        assert_eq!(turned([0.0, 0.0, 1.0]), [1.0, 0.0, 0.0]);
    }
}
