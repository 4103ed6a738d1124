//! What the planner knows while it searches a plan: the known links, the
//! given joints, the reaches along which a point stays put. Each step
//! kind's `find` (in its own file) looks at a [`Search`] for a joint it can
//! solve and adds its step; [`Search::step`] tries them in the order of
//! `steps::FIND_ORDER`. The structural conditions (a point on an axis, parallel
//! axes, a plane that is not parallel to the motion) are checked on the
//! geometry at its nominal dimensions.

use super::Geometry;
use crate::model::{JointType, Model, Place};
use crate::plan::{self, Anchor, Hop, Plan, Step};
use crate::solution::PointRef;
use nalgebra::{Isometry3, UnitQuaternion, Vector3};

use crate::plan::v3;

/// What the planner knows about the nominal model while it searches a plan.
pub struct Search<'a> {
    pub(crate) model: &'a Model,
    /// The model's geometry as the steps take it.
    pub(crate) geometry: Geometry<f64>,
    pub(crate) tol: f64,
    pub(crate) known: Vec<bool>,
    /// Joints whose value an input gives, with its index.
    pub(crate) given: Vec<Option<usize>>,
    pub(crate) used: Vec<bool>,
    /// Links pinned by a point output: the point, in the link's frame. A
    /// pinned link is not known (its turn is not), but that point of it is.
    pub(crate) pins: Vec<Option<Vector3<f64>>>,
    pub(crate) steps: Vec<Step>,
    pub(crate) branches: usize,
    /// Whether each link was known at the start (the base, a placed output
    /// link), not solved by a step: a link aimed from there composes no
    /// rotation.
    pub(crate) at_start: Vec<bool>,
    /// Links that keep the base's orientation (their POC set has no
    /// rotation): [`super::trilaterate`] may place them.
    pub(crate) translating: Vec<bool>,
}

/// Where a stalled search stands ([`Search::stall`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Stall {
    /// The link the last step placed (`None`: only the start placed links).
    pub last: Option<usize>,
    /// The joints between a known and a new link no step solved: `(joint,
    /// known link, new link, whether an input gives its value)`.
    pub open: Vec<(usize, usize, usize, bool)>,
    /// The unknown links a point output pins, with the pin (in the link's frame).
    pub pinned: Vec<(usize, [f64; 3])>,
    /// Per open joint, the nearest group of unknown links it opens, up to
    /// a known link again: what a step would have to close.
    pub groups: Vec<Group>,
}

/// The unknown links between an open joint and the nearest known link
/// beyond them ([`Stall::groups`]): a dyad (two links, three joints) is
/// what the circle, sphere, cone and line steps close; a longer chain (a
/// group of class III or higher) is closed by no single step.
#[derive(Debug, Clone, PartialEq)]
pub struct Group {
    /// The joints in order, from the open one (known link → first unknown
    /// link) to the one that reaches a known link again.
    pub joints: Vec<usize>,
    /// The unknown links in order.
    pub links: Vec<usize>,
    /// The known links at its two ends.
    pub ends: [usize; 2],
    /// How a dyad's three joints stand, at the nominal geometry.
    pub shape: Shape,
}

/// How a group's joints stand ([`Group::shape`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    /// A dyad of revolutes and slides whose axes are all parallel (a planar dyad).
    Planar,
    /// A dyad of three revolutes whose axes meet at one point (spherical).
    Concurrent,
    /// A dyad with a spherical joint or a U at this joint.
    Spherical(usize),
    /// A dyad whose joints are none of the above (a spatial dyad).
    Spatial,
    /// More than two unknown links in a row.
    Chain,
}

/// One way out of a link along which a point stays put: the hops taken,
/// the link reached and the point in its frame.
#[derive(Clone)]
pub(crate) struct Reach {
    pub(crate) hops: Vec<Hop>,
    pub(crate) link: usize,
    pub(crate) x: Vector3<f64>,
}

pub(crate) fn reversed(hops: &[Hop]) -> plan::Hops {
    hops.iter()
        .rev()
        .map(|h| Hop {
            joint: h.joint,
            forward: !h.forward,
        })
        .collect()
}

impl<'a> Search<'a> {
    /// The search of a plan for `model` that starts from the steps `start`
    /// (pose outputs placing links): `known` links (the base and those
    /// placed), links `pinned` at a point (in the link's frame) by a point
    /// output, and the joints whose value an input gives (`given`, with the
    /// input's index).
    pub fn new(
        model: &'a Model,
        given: Vec<Option<usize>>,
        known: Vec<bool>,
        pinned: Vec<Option<[f64; 3]>>,
        start: Vec<Step>,
    ) -> Self {
        Search {
            model,
            geometry: Geometry::of(model),
            tol: 1e-9 * crate::kinematics::model_scale(model).max(1.0),
            known,
            given,
            used: vec![false; model.joints.len()],
            pins: pinned.into_iter().map(|p| p.map(v3)).collect(),
            steps: start,
            branches: 0,
            at_start: vec![true; model.links.len()],
            translating: vec![false; model.links.len()],
        }
    }

    /// Marks the links that keep the base's orientation (a platform whose
    /// POC set has no rotation), which three spheres may place.
    pub fn set_translating(&mut self, links: Vec<bool>) {
        self.translating = links;
    }

    /// Which links are known so far.
    pub fn known(&self) -> &[bool] {
        &self.known
    }

    /// Where a search that stalled stands: the link its last step placed
    /// (`None`: no step placed one, only the start did), the joints left
    /// open between a known and a new link (`(joint, known link, new
    /// link, whether an input gives its value)`, in joint order), and the
    /// links a point output pins, each with its pin's place (in its frame).
    pub fn stall(&self) -> Stall {
        let last = self.steps.iter().rev().find_map(|s| match s.solves() {
            (Some(_), to) => Some(to),
            (None, _) => None,
        });
        let open = self
            .frontier()
            .map(|(j, from, to)| (j, from, to, self.given[j].is_some()))
            .collect();
        let pinned = (0..self.pins.len())
            .filter(|&l| !self.known[l])
            .filter_map(|l| self.pins[l].map(|p| (l, [p.x, p.y, p.z])))
            .collect();
        let groups = self
            .frontier()
            .filter_map(|(j, from, to)| self.group(j, from, to))
            .collect();
        Stall {
            last,
            open,
            pinned,
            groups,
        }
    }

    /// The shortest chain of unknown links from `to` (entered from the
    /// known `from` through open joint `j`) to a known link, through joints
    /// no step used, and how its joints stand (for a dyad).
    fn group(&self, j: usize, from: usize, to: usize) -> Option<Group> {
        let n = self.model.links.len();
        // Breadth first over unknown links: (joint in, previous link).
        let mut came: Vec<Option<(usize, usize)>> = vec![None; n];
        let mut queue = std::collections::VecDeque::from([to]);
        came[to] = Some((j, from));
        let mut end = None;
        'search: while let Some(l) = queue.pop_front() {
            for (q, joint) in self.model.joints.iter().enumerate() {
                if q == j || self.used[q] || !joint.links.contains(&l) || came[l].is_some_and(|(i, _)| i == q) {
                    continue;
                }
                let next = joint.other(l);
                if self.known[next] {
                    end = Some((q, l, next));
                    break 'search;
                }
                if came[next].is_none() {
                    came[next] = Some((q, l));
                    queue.push_back(next);
                }
            }
        }
        let (last, mut l, known) = end?;
        let (mut joints, mut links) = (vec![last], Vec::new());
        while let Some((q, prev)) = came[l] {
            links.push(l);
            joints.push(q);
            if q == j {
                break;
            }
            l = prev;
        }
        joints.reverse();
        links.reverse();
        let shape = if links.len() == 2 {
            self.dyad_shape([joints[0], joints[1], joints[2]], [links[0], links[1]])
        } else {
            Shape::Chain
        };
        Some(Group {
            joints,
            links,
            ends: [from, known],
            shape,
        })
    }

    /// How the joints `[j, q, h]` of a dyad (links `[b, c]`: j and q on b,
    /// q and h on c) stand at the nominal geometry.
    fn dyad_shape(&self, [j, q, h]: [usize; 3], [b, c]: [usize; 2]) -> Shape {
        if let Some(&s) = [j, q, h].iter().find(|&&k| self.kind(k) == JointType::S) {
            return Shape::Spherical(s);
        }
        if Self::parallel(self.axis(j, b), self.axis(q, b)) && Self::parallel(self.axis(q, c), self.axis(h, c)) {
            return Shape::Planar;
        }
        let revolutes = [j, q, h].iter().all(|&k| self.kind(k) == JointType::R);
        // Where j's and q's axes meet on b, if they do, carried to c.
        let meet = |a: (Vector3<f64>, Vector3<f64>), b: (Vector3<f64>, Vector3<f64>)| {
            let (d1, d2) = (a.1.normalize(), b.1.normalize());
            let w = a.0 - b.0;
            let (c, e) = (d1.dot(&d2), 1.0 - d1.dot(&d2).powi(2));
            (e > 1e-12).then(|| {
                let t1 = (c * d2.dot(&w) - d1.dot(&w)) / e;
                let p1 = a.0 + d1 * t1;
                let t2 = d2.dot(&(p1 - b.0));
                (p1, (p1 - (b.0 + d2 * t2)).norm())
            })
        };
        let line = |k: usize, l: usize| (v3(self.place(k, l).at()), self.axis(k, l));
        let concurrent = revolutes
            && meet(line(j, b), line(q, b)).is_some_and(|(p, gap)| {
                gap <= self.tol && {
                    let on_c = self.zero(q, b).inverse_transform_point(&p.into()).coords;
                    self.on_axis(h, c, on_c)
                }
            });
        if concurrent {
            Shape::Concurrent
        } else {
            Shape::Spatial
        }
    }

    /// Adds the next step: the first step kind of `steps::FIND_ORDER` that
    /// finds one. False when none does.
    pub fn step(&mut self) -> bool {
        super::FIND_ORDER.iter().any(|find| find(self))
    }

    /// The plan found, for `n_inputs` given values (`inputs`: the input
    /// joints of a forward plan). The parallelograms' planes take their
    /// choices last (`pa_plane::number_choices`).
    pub fn into_plan(mut self, n_inputs: usize, inputs: Vec<usize>) -> Plan {
        let branches = super::pa_plane::number_choices(&mut self.steps, self.branches);
        Plan {
            steps: self.steps,
            branches,
            n_inputs,
            inputs,
            by_miss: Vec::new(),
        }
    }

    pub(crate) fn other(&self, j: usize, l: usize) -> usize {
        self.model.joints[j].other(l)
    }

    pub(crate) fn side(&self, j: usize, l: usize) -> usize {
        usize::from(self.model.joints[j].links[0] != l)
    }

    pub(crate) fn place(&self, j: usize, l: usize) -> Place {
        self.model.joints[j].places[self.side(j, l)]
    }

    pub(crate) fn zero(&self, j: usize, from: usize) -> Isometry3<f64> {
        let forward = self.model.joints[j].links[0] == from;
        plan::pose_of(&self.geometry.joints[j].zero[usize::from(!forward)])
    }

    pub(crate) fn hop(&self, j: usize, from: usize) -> Hop {
        Hop {
            joint: j,
            forward: self.model.joints[j].links[0] == from,
        }
    }

    pub(crate) fn kind(&self, j: usize) -> JointType {
        self.model.joints[j].kind
    }

    /// Whether `x` (in `l`'s frame) is on the axis of revolute `j`.
    pub(crate) fn on_axis(&self, j: usize, l: usize, x: Vector3<f64>) -> bool {
        if self.kind(j) != JointType::R {
            return false;
        }
        let p = self.place(j, l);
        let a = v3(p.axis()).normalize();
        (x - v3(p.at())).cross(&a).norm() <= self.tol
    }

    /// Whether another revolute of `l` shares the axis of revolute `j`
    /// (a compound hinge): both its point and its direction lie on it.
    pub(crate) fn carries_coaxial(&self, j: usize, l: usize) -> bool {
        self.model.joints.iter().enumerate().any(|(k, joint)| {
            k != j
                && joint.kind == JointType::R
                && joint.links.contains(&l)
                && self.on_axis(j, l, v3(self.place(k, l).at()))
                && Self::parallel(self.axis(k, l), self.axis(j, l))
        })
    }

    pub(crate) fn parallel(a: Vector3<f64>, b: Vector3<f64>) -> bool {
        a.normalize().cross(&b.normalize()).norm() <= 1e-9
    }

    /// Whether every hop of `hops` out of `start` turns about an axis
    /// parallel to `k` (in `start`'s frame), so that `k` stays put across them.
    pub(crate) fn hops_about(&self, start: usize, hops: &[Hop], k: Vector3<f64>) -> bool {
        hops.iter().enumerate().all(|(i, h)| {
            // A spherical joint carries its centre whatever it turns by: as
            // the last hop it keeps the point; before another, it leaves
            // that one's axis unknown.
            if self.kind(h.joint) == JointType::S {
                return i + 1 == hops.len();
            }
            let pre = &hops[..i];
            Self::parallel(self.rotation(pre) * self.axis(h.joint, self.link_after(start, pre)), k)
        })
    }

    /// Whether `a` and `b` are normal to each other (to the same 1e-9 as [`Search::parallel`]).
    pub(crate) fn normal(a: Vector3<f64>, b: Vector3<f64>) -> bool {
        a.normalize().dot(&b.normalize()).abs() <= 1e-9
    }

    /// Whether `x` (in `l`'s frame) is the centre of spherical joint `j`.
    pub(crate) fn at_centre(&self, j: usize, l: usize, x: Vector3<f64>) -> bool {
        self.kind(j) == JointType::S && (x - v3(self.place(j, l).at())).norm() <= self.tol
    }

    /// The links reached from `start` through revolutes whose axes carry
    /// the point `x` and spherical joints centred on it (so it does not
    /// move), stopping at known links.
    pub(crate) fn fixed_reach(&self, start: usize, x: Vector3<f64>, exclude: &[usize]) -> Vec<Reach> {
        self.reach(start, x, exclude, |_, _| false)
    }

    /// Where `point` (at `x` in `beyond`'s frame) is known: the first reach
    /// out of `beyond` that keeps it put ([`Search::fixed_reach`], joints
    /// in `exclude` not crossed) through joints turning about `k` (in
    /// `beyond`'s frame) to a known link, as the anchor a step aims at.
    pub(crate) fn known_about(
        &self,
        beyond: usize,
        point: PointRef,
        x: Vector3<f64>,
        exclude: &[usize],
        k: Vector3<f64>,
    ) -> Option<Anchor> {
        let r = self
            .fixed_reach(beyond, x, exclude)
            .into_iter()
            .find(|r| !r.hops.is_empty() && self.known[r.link] && self.hops_about(beyond, &r.hops, k))?;
        Some(Anchor {
            link: r.link,
            hops: reversed(&r.hops),
            point,
        })
    }

    /// The ways out of `start` along which point `x` keeps its distance
    /// from every axis parallel to `k` (in `start`'s frame), through at
    /// least one slide: [`Search::fixed_reach`]'s hops, and slides along
    /// `k` (which move the point along such an axis). Seen along `k` the
    /// links they join are one body. Joints in `exclude` are not crossed.
    pub(crate) fn axial_reach(&self, start: usize, x: Vector3<f64>, exclude: &[usize], k: Vector3<f64>) -> Vec<Reach> {
        let mut out = self.reach(start, x, exclude, |q, r| {
            self.kind(q) == JointType::P && Self::parallel(self.rotation(&r.hops) * self.axis(q, r.link), k)
        });
        out.retain(|r| r.hops.iter().any(|h| self.kind(h.joint) == JointType::P));
        out
    }

    /// The links reached from `start`, breadth first, through joints that
    /// keep the point `x` put (a revolute's axis through it, a spherical
    /// joint's centre on it) or that `also` lets it cross (joint, the reach
    /// so far), each link once, stopping at known links; joints in
    /// `exclude` are not crossed. The point is carried at joint value 0.
    fn reach(
        &self,
        start: usize,
        x: Vector3<f64>,
        exclude: &[usize],
        also: impl Fn(usize, &Reach) -> bool,
    ) -> Vec<Reach> {
        let mut out = vec![Reach {
            hops: vec![],
            link: start,
            x,
        }];
        let mut i = 0;
        while i < out.len() {
            let r = out[i].clone();
            i += 1;
            if self.known[r.link] && !r.hops.is_empty() {
                continue;
            }
            for (q, joint) in self.model.joints.iter().enumerate() {
                if exclude.contains(&q) || !joint.links.contains(&r.link) || r.hops.iter().any(|h| h.joint == q) {
                    continue;
                }
                let next = self.other(q, r.link);
                if out.iter().any(|o| o.link == next)
                    || !(self.on_axis(q, r.link, r.x) || self.at_centre(q, r.link, r.x) || also(q, &r))
                {
                    continue;
                }
                let x = self.zero(q, r.link).inverse_transform_point(&r.x.into()).coords;
                let mut hops = r.hops.clone();
                hops.push(self.hop(q, r.link));
                out.push(Reach { hops, link: next, x });
            }
        }
        out
    }

    /// The rotation from the frame of `start` to that of the link at the end of `hops` (value 0).
    pub(crate) fn rotation(&self, hops: &[Hop]) -> UnitQuaternion<f64> {
        let (frame, _) = self.geometry.across(crate::frame::Frame::identity(), 0, hops);
        plan::pose_of(&frame).rotation
    }

    /// The joints no step has used between a known link and a new one, in
    /// joint order: `(joint, known link, new link)`.
    fn frontier(&self) -> impl Iterator<Item = (usize, usize, usize)> + '_ {
        self.model.joints.iter().enumerate().filter_map(|(j, joint)| {
            let [u, v] = joint.links;
            let open = !self.used[j] && self.known[u] != self.known[v];
            open.then(|| if self.known[u] { (j, u, v) } else { (j, v, u) })
        })
    }

    /// Candidate joints: one known link, a new link, value not given.
    pub(crate) fn candidates(&self) -> Vec<(usize, usize, usize)> {
        self.frontier()
            .filter(|&(j, ..)| self.given[j].is_none() && self.model.joints[j].kind != JointType::S)
            .collect()
    }

    /// Points of `to` to consider: its joints' places.
    pub(crate) fn points_of(&self, to: usize, j: usize) -> Vec<(PointRef, Vector3<f64>)> {
        let mut out = Vec::new();
        for (k, joint) in self.model.joints.iter().enumerate() {
            if k != j && joint.links.contains(&to) {
                let x = v3(self.place(k, to).at());
                // A point on the joint's own axis does not move with it.
                if !self.on_axis(j, to, x) {
                    out.push((PointRef::Joint(k), x));
                }
            }
        }
        out
    }

    /// For a step that turns `to` by joint `j` about `k` (in `to`'s frame)
    /// and carries a point across joint `q` to the link beyond it: `k` in
    /// that link's frame, and the places there of its joints but `q` and
    /// `j`, the points such a step may carry.
    pub(crate) fn across(
        &self,
        q: usize,
        to: usize,
        j: usize,
        k: Vector3<f64>,
    ) -> (Vector3<f64>, Vec<(PointRef, Vector3<f64>)>) {
        let beyond = self.other(q, to);
        let k_beyond = self.rotation(&[self.hop(q, to)]).inverse() * k;
        let places = self
            .model
            .joints
            .iter()
            .enumerate()
            .filter(|(h, jh)| *h != q && *h != j && jh.links.contains(&beyond))
            .map(|(h, _)| (PointRef::Joint(h), v3(self.place(h, beyond).at())))
            .collect();
        (k_beyond, places)
    }

    pub(crate) fn push(&mut self, step: Step, to: usize, j: usize) {
        self.at_start[to] = false;
        self.steps.push(step);
        self.known[to] = true;
        self.pins[to] = None;
        self.used[j] = true;
    }

    /// Whether `x` (in `l`'s frame) is the point `l` is pinned by.
    pub(crate) fn pinned_at(&self, l: usize, x: Vector3<f64>) -> bool {
        self.pins[l].is_some_and(|p| (p - x).norm() <= self.tol)
    }

    /// The direction of joint `j` in `l`'s frame: a revolute's axis or a
    /// slide's guide. A slide placed on `l` by a point alone takes its guide
    /// from the other link, turned into `l`'s frame at value 0.
    pub(crate) fn axis(&self, j: usize, l: usize) -> Vector3<f64> {
        match self.place(j, l) {
            Place::Point { .. } => {
                let other = self.model.joints[j].places[1 - self.side(j, l)];
                self.zero(j, self.other(j, l)).rotation * v3(other.axis())
            }
            p => v3(p.axis()),
        }
    }

    /// The link at the end of `hops` from `start`.
    pub(crate) fn link_after(&self, start: usize, hops: &[Hop]) -> usize {
        hops.iter().fold(start, |l, h| self.other(h.joint, l))
    }
}
