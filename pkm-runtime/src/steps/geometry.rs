//! The geometry the steps compute with, prepared once from the parameters:
//! each joint's ([`JointGeometry`]: its places, their canonical frames, its
//! transform at a value ([`JointValue`]), the value between two poses, its
//! closure residual, and how it moves a point of the new link, [`Motion`])
//! and the mechanism's ([`Geometry`]: every joint's and every named point,
//! the hops and anchors the steps read).

use crate::frame::Frame;
use crate::model::{JointType, Place};
use crate::plan::{Anchor, Direction, Hop};
use crate::scalar::{constant, cross, dot, norm, reject, scale, sub, unit, Scalar};
use crate::solution::PointRef;

/// A joint's geometry: its places on its two links, their canonical frames
/// and its transform at value 0 (and the inverse), computed once.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointGeometry<T> {
    /// R, P, S or Pa.
    pub kind: JointType,
    /// The two links it joins.
    pub links: [usize; 2],
    /// Its places on `links[0]` and `links[1]`.
    pub places: [Place<T>; 2],
    /// The places' canonical frames.
    pub frames: [Frame<T>; 2],
    /// The transform from `links[0]` to `links[1]` at value 0, and its inverse.
    pub zero: [Frame<T>; 2],
}

/// A place's direction: an axis, a guide, or z for a bare point.
pub fn place_axis<T: Scalar>(p: &Place<T>) -> [T; 3] {
    match *p {
        Place::Axis { axis, .. } | Place::Arm { axis, .. } | Place::Line { along: axis, .. } => axis,
        Place::Point { .. } => constant([0.0, 0.0, 1.0]),
    }
}

/// The frame with origin `at` and z along `axis`; x is the world x axis
/// made perpendicular to z (the world y axis when z is within about 25° of
/// x): the model's canonical frame ([`crate::model::canonical_frame`]).
pub fn canonical_frame<T: Scalar>(at: [T; 3], axis: [T; 3]) -> Frame<T> {
    let z = unit(axis);
    let (o, n) = (T::c(1.0), T::c(0.0));
    let near_x = |a: T, b: T| T::if_less(z[0].abs(), T::c(0.9), a, b);
    let e = [near_x(o, n), near_x(n, o), n];
    let x = unit(reject(e, z));
    let y = cross(z, x);
    Frame {
        r: [[x[0], y[0], z[0]], [x[1], y[1], z[1]], [x[2], y[2], z[2]]],
        t: at,
    }
}

/// How a joint's value is held: the turn of an R or Pa joint (cosine and
/// sine, and the angle itself where it was given or a kernel forms it from
/// its terms before normalising them), the slide of a P joint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum JointValue<T> {
    /// `cos θ`, `sin θ`, and `θ` where it was given or formed.
    Turn(T, T, Option<T>),
    /// The slide.
    Slide(T),
}

impl<T: Scalar> JointValue<T> {
    /// The value: the angle or the slide.
    pub fn value(self) -> T {
        match self {
            JointValue::Turn(c, s, angle) => angle.unwrap_or_else(|| s.atan2(c)),
            JointValue::Slide(t) => t,
        }
    }

    /// A given value of a joint of type `kind`.
    pub fn given(kind: JointType, v: T) -> Self {
        match kind {
            JointType::R | JointType::Pa => JointValue::Turn(v.cos(), v.sin(), Some(v)),
            _ => JointValue::Slide(v),
        }
    }
}

impl<T: Scalar> JointGeometry<T> {
    /// The link at the other end from `link`.
    pub fn other(&self, link: usize) -> usize {
        if self.links[0] == link {
            self.links[1]
        } else {
            self.links[0]
        }
    }

    /// A joint from its type, links and places.
    pub fn new(kind: JointType, links: [usize; 2], places: [Place<T>; 2]) -> Self {
        let frames = places.map(|p| canonical_frame(p.at(), place_axis(&p)));
        let mut j = JointGeometry {
            kind,
            links,
            places,
            frames,
            zero: [Frame::identity(); 2],
        };
        let zero = j.transform(match kind {
            JointType::P => JointValue::Slide(T::c(0.0)),
            _ => JointValue::Turn(T::c(1.0), T::c(0.0), None),
        });
        j.zero = [zero, zero.inverse()];
        j
    }

    /// The pose of `links[1]` relative to `links[0]` at `value`.
    pub fn transform(&self, value: JointValue<T>) -> Frame<T> {
        let [fu, fv] = &self.frames;
        match (self.kind, value) {
            (JointType::R, JointValue::Turn(c, s, _)) => fu.then(&Frame::about_z(c, s)).then(&fv.inverse()),
            (JointType::Pa, JointValue::Turn(c, s, _)) => {
                // The link with the arm: its hinge frame, the arm turned
                // about the hinge axis, then the other hinge's frame.
                let swing = |f: &Frame<T>, arm: [T; 3]| {
                    let local = f.rotate_back(arm);
                    Frame::translation([c * local[0] - s * local[1], s * local[0] + c * local[1], local[2]])
                };
                match (self.places[0], self.places[1]) {
                    (_, Place::Arm { arm, .. }) => fv.then(&swing(fv, arm)).then(&fu.inverse()).inverse(),
                    (Place::Arm { arm, .. }, _) => fu.then(&swing(fu, arm)).then(&fv.inverse()),
                    _ => fu.then(&fv.inverse()),
                }
            }
            (JointType::P, JointValue::Slide(t)) => {
                let slide = |guide: &Place<T>, slider: &Place<T>| {
                    let (q, d) = match *guide {
                        Place::Line { through, along } => (through, unit(along)),
                        Place::Axis { at, axis } | Place::Arm { at, axis, .. } => (at, unit(axis)),
                        Place::Point { at } => (at, constant([1.0, 0.0, 0.0])),
                    };
                    let p = slider.at();
                    Frame::translation([q[0] + t * d[0] - p[0], q[1] + t * d[1] - p[1], q[2] + t * d[2] - p[2]])
                };
                if matches!(self.places[0], Place::Line { .. }) {
                    slide(&self.places[0], &self.places[1])
                } else {
                    slide(&self.places[1], &self.places[0]).inverse()
                }
            }
            // S joints are never solved by a step, only checked at their centres.
            _ => {
                let (cu, cv) = (self.places[0].at(), self.places[1].at());
                Frame::translation(sub(cu, cv))
            }
        }
    }

    /// The pose of the link across the joint from the known pose `from` at
    /// `value`; `forward` when `from` is the joint's first link.
    pub fn transfer(&self, from: &Frame<T>, forward: bool, value: JointValue<T>) -> Frame<T> {
        let t = self.transform(value);
        from.then(&if forward { t } else { t.inverse() })
    }

    /// The joint's value from the poses of its two links.
    pub fn value_between(&self, u: &Frame<T>, v: &Frame<T>) -> T {
        let rel = u.inverse().then(v);
        match self.kind {
            JointType::R => {
                let m = self.frames[0].inverse().then(&rel).then(&self.frames[1]);
                m.r[1][0].atan2(m.r[0][0])
            }
            JointType::P => {
                let (guide, slider, rel) = if matches!(self.places[0], Place::Line { .. }) {
                    (self.places[0], self.places[1], rel)
                } else {
                    (self.places[1], self.places[0], rel.inverse())
                };
                let p = rel.apply(slider.at());
                dot(sub(p, guide.at()), unit(place_axis(&guide)))
            }
            JointType::Pa => {
                let (arm_side, rel) = if matches!(self.places[0], Place::Arm { .. }) {
                    (0, rel)
                } else {
                    (1, rel.inverse())
                };
                let (fa, fo) = (self.frames[arm_side], self.frames[1 - arm_side]);
                let t = fa.inverse().then(&rel).then(&fo).t;
                let Place::Arm { arm, .. } = self.places[arm_side] else {
                    return T::c(f64::NAN);
                };
                let a = fa.rotate_back(arm);
                (a[0] * t[1] - a[1] * t[0]).atan2(a[0] * t[0] + a[1] * t[1])
            }
            JointType::S => T::c(f64::NAN),
        }
    }

    /// The joint's closure residual between the poses `u` and `v` of its
    /// links (zero, to rounding, for a closed joint): where its place on `v`
    /// is minus where its place on `u` is, or, for P and Pa joints, where
    /// `u` and the joint's own value put it (3 lengths); then, times
    /// `extent`, for an R joint the difference of the two places' axes
    /// (the closure of a revolute, with no angle taken), for P and Pa joints
    /// the first two columns of the rotation between the predicted and the
    /// actual pose. A half turn shows as 2·extent. S joints: the centres only.
    pub fn closure_residual(&self, u: &Frame<T>, v: &Frame<T>, extent: T) -> [T; RESIDUAL_ROWS] {
        let pv = v.apply(self.places[1].at());
        let zero = T::c(0.0);
        match self.kind {
            JointType::S => {
                let d = sub(u.apply(self.places[0].at()), pv);
                [d[0], d[1], d[2], zero, zero, zero, zero, zero, zero]
            }
            JointType::R => {
                let d = sub(u.apply(self.places[0].at()), pv);
                let axis = |pose: &Frame<T>, side: usize| pose.then(&self.frames[side]).column(2);
                let w = scale(extent, sub(axis(u, 0), axis(v, 1)));
                [d[0], d[1], d[2], w[0], w[1], w[2], zero, zero, zero]
            }
            _ => {
                let value = self.value_between(u, v);
                let value = match self.kind {
                    JointType::P => JointValue::Slide(value),
                    _ => JointValue::Turn(value.cos(), value.sin(), Some(value)),
                };
                let predicted = self.transfer(u, true, value);
                let d = sub(predicted.apply(self.places[1].at()), pv);
                let (x, y) = (
                    scale(extent, sub(predicted.column(0), v.column(0))),
                    scale(extent, sub(predicted.column(1), v.column(1))),
                );
                [d[0], d[1], d[2], x[0], x[1], x[2], y[0], y[1], y[2]]
            }
        }
    }
}

/// Rows of [`JointGeometry::closure_residual`] per joint.
pub const RESIDUAL_ROWS: usize = 9;

/// A mechanism's geometry at its parameters: every joint's, and every
/// named point in its link's frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Geometry<T> {
    /// Joints in declaration order.
    pub joints: Vec<JointGeometry<T>>,
    /// Named points.
    pub named: Vec<[T; 3]>,
}

impl<T: Scalar> Geometry<T> {
    /// The mechanism's size: the largest distance of a joint's place or a
    /// named point from its link's origin, or 1 where there is none
    /// ([`crate::kinematics::model_scale`], for every [`Scalar`]: generated
    /// code prepares it from the parameters).
    pub fn scale(&self) -> T {
        let places = self.joints.iter().flat_map(|j| j.places.iter().map(|p| p.at()));
        let zero = T::c(0.0);
        let l = places
            .chain(self.named.iter().copied())
            .map(norm)
            .fold(zero, crate::scalar::max);
        T::if_less(zero, l, l, T::c(1.0))
    }

    /// A point of a link in that link's frame: a joint's place on it or a named point.
    pub fn local(&self, point: PointRef, link: usize) -> [T; 3] {
        match point {
            PointRef::Joint(j) => {
                let joint = &self.joints[j];
                joint.places[usize::from(joint.links[0] != link)].at()
            }
            PointRef::Named(n) => self.named[n],
        }
    }

    /// The pose of the last link of a hop chain (joints crossed at value 0)
    /// from `link` at `pose`, and that link.
    pub fn across(&self, mut pose: Frame<T>, mut link: usize, hops: &[Hop]) -> (Frame<T>, usize) {
        for h in hops {
            let j = &self.joints[h.joint];
            pose = pose.then(&j.zero[usize::from(!h.forward)]);
            link = if h.forward { j.links[1] } else { j.links[0] };
        }
        (pose, link)
    }

    /// An anchored point's world position: [`Geometry::anchor_local`]
    /// with the known link's pose applied to it once.
    pub fn anchor(&self, poses: &[Frame<T>], a: &Anchor) -> [T; 3] {
        poses[a.link].apply(self.anchor_local(a))
    }

    /// An anchored point in its known link's frame. The hops are crossed at
    /// value 0 from the identity, so it depends on the dimensions alone
    /// (solved code prepares it once; the planner reads it at plan time).
    pub fn anchor_local(&self, a: &Anchor) -> [T; 3] {
        let (hops, l) = self.across(Frame::identity(), a.link, &a.hops);
        hops.apply(self.local(a.point, l))
    }

    /// A direction known through hops: the axis of a joint's place on the
    /// last link, turned into the known link's frame as [`Geometry::anchor`] does.
    pub fn direction(&self, pose: Frame<T>, link: usize, d: &Direction) -> [T; 3] {
        let (hops, l) = self.across(Frame::identity(), link, &d.hops);
        let j = &self.joints[d.joint];
        pose.rotate(hops.rotate(place_axis(&j.places[usize::from(j.links[0] != l)])))
    }

    /// A point of a link in the frame of the last link of `hops` (at value 0).
    pub fn carry(&self, x: [T; 3], hops: &[Hop]) -> [T; 3] {
        let (pose, _) = self.across(Frame::identity(), usize::MAX, hops);
        pose.apply_back(x)
    }
}

/// How a point of the new link moves with the joint value: on a circle
/// `centre + R(axis, θ)·radius` (R and Pa joints) or a line `start + s·along`
/// (P joints, `along` unit).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Motion<T> {
    /// `centre + R(axis, θ)·radius`, `axis` unit.
    Circle {
        /// Centre (for a parallelogram, the point the arm swings about).
        centre: [T; 3],
        /// Unit axis.
        axis: [T; 3],
        /// The point at θ = 0 minus the centre.
        radius: [T; 3],
        /// The circle's radius from the links' own geometry: exact where
        /// `|radius|` carries the rounding of the world transform, which
        /// keeps nearly concentric circles accurate.
        length: T,
    },
    /// `start + s·along`, `along` unit.
    Line {
        /// The point at s = 0.
        start: [T; 3],
        /// Unit direction.
        along: [T; 3],
    },
}

impl<T: Scalar> JointGeometry<T> {
    /// The motion of the new link's point `local` as the joint turns or
    /// slides from the known pose `from`.
    pub fn motion(&self, from: &Frame<T>, forward: bool, local: [T; 3]) -> Motion<T> {
        let zero = from.then(&self.zero[usize::from(!forward)]);
        let (side_from, side_new) = if forward { (0, 1) } else { (1, 0) };
        match self.kind {
            JointType::P => {
                let x0 = zero.apply(local);
                let (guide_side, sign) = if matches!(self.places[side_from], Place::Line { .. }) {
                    (side_from, 1.0)
                } else {
                    (side_new, -1.0)
                };
                let guide_pose = if guide_side == side_from { from } else { &zero };
                let d = guide_pose.rotate(unit(place_axis(&self.places[guide_side])));
                Motion::Line {
                    start: x0,
                    along: scale(T::c(sign), d),
                }
            }
            JointType::Pa => {
                let x0 = zero.apply(local);
                let frame = from.then(&self.frames[side_from]);
                let k = frame.column(2);
                let (arm_side, sign) = if matches!(self.places[side_from], Place::Arm { .. }) {
                    (side_from, 1.0)
                } else {
                    (side_new, -1.0)
                };
                let Place::Arm { arm, axis, .. } = self.places[arm_side] else {
                    return Motion::Line {
                        start: x0,
                        along: constant([0.0; 3]),
                    };
                };
                let arm_pose = if arm_side == side_from { from } else { &zero };
                let a = scale(T::c(sign), arm_pose.rotate(arm));
                Motion::Circle {
                    centre: sub(x0, a),
                    axis: k,
                    radius: a,
                    length: norm(reject(arm, unit(axis))),
                }
            }
            _ => {
                let frame = from.then(&self.frames[side_from]);
                let sign = if forward { 1.0 } else { -1.0 };
                let k = scale(T::c(sign), frame.column(2));
                let place = self.places[side_new];
                // The offset from the joint's own place, turned: the value-0
                // pose carries that place onto the centre, and the difference
                // of two world points would round twice.
                let offset = sub(local, place.at());
                Motion::Circle {
                    centre: frame.t,
                    axis: k,
                    radius: zero.rotate(offset),
                    length: norm(reject(offset, unit(place_axis(&place)))),
                }
            }
        }
    }

    /// The axis the joint turns the new link about (R joints).
    pub fn turning_axis(&self, from: &Frame<T>, forward: bool) -> Option<[T; 3]> {
        match (self.kind, self.motion(from, forward, constant([0.0; 3]))) {
            (JointType::R, Motion::Circle { axis, .. }) => Some(axis),
            _ => None,
        }
    }
}

impl<T: Scalar> Geometry<T> {
    /// The geometry of a model at its dimensions, its numbers as constants
    /// of the scalar (f64 itself for the interpreter; hyper-duals for the
    /// Lagrange path's derivatives).
    pub fn of(model: &crate::model::Model) -> Self {
        Geometry {
            joints: model
                .joints
                .iter()
                .map(|j| JointGeometry::new(j.kind, j.links, j.places.map(|p| p.map(T::c))))
                .collect(),
            named: model.points.iter().map(|p| p.at.map(T::c)).collect(),
        }
    }
}
