//! Solution plans of every mechanism, planar and spatial (see
//! `pkm_runtime::spatial`): links are solved one joint at a time, each
//! joint value from what the rest of the mechanism fixes about one point or
//! direction of the new link. The structural
//! conditions (a point on an axis, parallel axes, a plane that is not
//! parallel to the motion) are checked on the geometry at its nominal
//! dimensions; no mechanism is named here.

use crate::analysis::Analysis;
use crate::diagnostics::{Diagnostic, Diagnostics};
use pkm_runtime::model::{JointType, Model, Place};
use pkm_runtime::newton::model_scale;
use pkm_runtime::solution::PointRef;
use pkm_runtime::spatial::{self, Anchor, Constraint, Direction, Hop, Plan, Step, Turn};
use pkm_runtime::steps::Geometry;
use std::collections::HashMap;

use nalgebra::{Isometry3, Vector3};

fn v3(a: [f64; 3]) -> Vector3<f64> {
    Vector3::new(a[0], a[1], a[2])
}

/// What the planner knows about the nominal model.
struct Planner<'a> {
    model: &'a Model,
    /// The model's geometry as the steps take it.
    geometry: Geometry<f64>,
    tol: f64,
    known: Vec<bool>,
    /// Joints whose value an input gives, with its index.
    given: Vec<Option<usize>>,
    used: Vec<bool>,
    /// Links pinned by a point output: the point, in the link's frame. A
    /// pinned link is not known (its turn is not), but that point of it is.
    pins: Vec<Option<Vector3<f64>>>,
    steps: Vec<Step>,
    branches: usize,
}

/// One way out of a link along which a point stays put: the hops taken,
/// the link reached and the point in its frame.
#[derive(Clone)]
struct Reach {
    hops: Vec<Hop>,
    link: usize,
    x: Vector3<f64>,
}

fn reversed(hops: &[Hop]) -> spatial::Hops {
    hops.iter()
        .rev()
        .map(|h| Hop {
            joint: h.joint,
            forward: !h.forward,
        })
        .collect()
}

impl Planner<'_> {
    fn other(&self, j: usize, l: usize) -> usize {
        let ls = self.model.joints[j].links;
        if ls[0] == l {
            ls[1]
        } else {
            ls[0]
        }
    }

    fn side(&self, j: usize, l: usize) -> usize {
        usize::from(self.model.joints[j].links[0] != l)
    }

    fn place(&self, j: usize, l: usize) -> Place {
        self.model.joints[j].places[self.side(j, l)]
    }

    fn zero(&self, j: usize, from: usize) -> Isometry3<f64> {
        let forward = self.model.joints[j].links[0] == from;
        spatial::pose_of(&self.geometry.joints[j].zero[usize::from(!forward)])
    }

    fn hop(&self, j: usize, from: usize) -> Hop {
        Hop {
            joint: j,
            forward: self.model.joints[j].links[0] == from,
        }
    }

    fn kind(&self, j: usize) -> JointType {
        self.model.joints[j].kind
    }

    /// Whether `x` (in `l`'s frame) is on the axis of revolute `j`.
    fn on_axis(&self, j: usize, l: usize, x: Vector3<f64>) -> bool {
        if self.kind(j) != JointType::R {
            return false;
        }
        let p = self.place(j, l);
        let a = v3(p.axis()).normalize();
        (x - v3(p.at())).cross(&a).norm() <= self.tol
    }

    fn parallel(a: Vector3<f64>, b: Vector3<f64>) -> bool {
        a.normalize().cross(&b.normalize()).norm() <= 1e-9
    }

    /// The links reached from `start` through revolutes whose axes carry
    /// the point `x` (so it does not move), stopping at known links.
    fn fixed_reach(&self, start: usize, x: Vector3<f64>, exclude: &[usize]) -> Vec<Reach> {
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
            for (k, joint) in self.model.joints.iter().enumerate() {
                if exclude.contains(&k) || !joint.links.contains(&r.link) || r.hops.iter().any(|h| h.joint == k) {
                    continue;
                }
                let next = self.other(k, r.link);
                if out.iter().any(|o| o.link == next) || !self.on_axis(k, r.link, r.x) {
                    continue;
                }
                let x = self.zero(k, r.link).inverse_transform_point(&r.x.into()).coords;
                let mut hops = r.hops.clone();
                hops.push(self.hop(k, r.link));
                out.push(Reach { hops, link: next, x });
            }
        }
        out
    }

    /// The rotation from the frame of `start` to that of the link at the end of `hops` (value 0).
    fn rotation(&self, hops: &[Hop]) -> nalgebra::UnitQuaternion<f64> {
        let (frame, _) = self.geometry.across(pkm_runtime::frame::Frame::identity(), 0, hops);
        spatial::pose_of(&frame).rotation
    }

    /// Candidate joints: one known link, a new link, value not given.
    fn candidates(&self) -> Vec<(usize, usize, usize)> {
        let mut out = Vec::new();
        for (j, joint) in self.model.joints.iter().enumerate() {
            if self.used[j] || self.given[j].is_some() || joint.kind == JointType::S {
                continue;
            }
            let [u, v] = joint.links;
            if self.known[u] != self.known[v] {
                let (from, to) = if self.known[u] { (u, v) } else { (v, u) };
                out.push((j, from, to));
            }
        }
        out
    }

    /// Points of `to` to consider: its joints' places.
    fn points_of(&self, to: usize, j: usize) -> Vec<(PointRef, Vector3<f64>)> {
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

    fn push(&mut self, step: Step, to: usize, j: usize) {
        self.steps.push(step);
        self.known[to] = true;
        self.pins[to] = None;
        self.used[j] = true;
    }

    /// Whether `x` (in `l`'s frame) is the point `l` is pinned by.
    fn pinned_at(&self, l: usize, x: Vector3<f64>) -> bool {
        self.pins[l].is_some_and(|p| (p - x).norm() <= self.tol)
    }

    fn transfers(&mut self) -> bool {
        for (j, joint) in self.model.joints.iter().enumerate() {
            let (Some(input), false) = (self.given[j], self.used[j]) else {
                continue;
            };
            let [u, v] = joint.links;
            if self.known[u] != self.known[v] {
                let (from, to) = if self.known[u] { (u, v) } else { (v, u) };
                self.push(
                    Step::Transfer {
                        joint: j,
                        from,
                        to,
                        input,
                    },
                    to,
                    j,
                );
                return true;
            }
        }
        false
    }

    fn try_aim(&mut self) -> bool {
        for (j, from, to) in self.candidates() {
            for (point, x) in self.points_of(to, j) {
                // A known link, or a pinned one at its pin (the new link's own pin too).
                let found = self
                    .fixed_reach(to, x, &[j])
                    .into_iter()
                    .find(|r| (self.known[r.link] && !r.hops.is_empty()) || self.pinned_at(r.link, r.x));
                if let Some(r) = found {
                    let target = Anchor {
                        link: r.link,
                        hops: reversed(&r.hops),
                        point,
                    };
                    let step = Step::Aim {
                        joint: j,
                        from,
                        to,
                        point,
                        target,
                    };
                    self.push(step, to, j);
                    return true;
                }
            }
        }
        false
    }

    /// The direction of joint `j` in `l`'s frame: a revolute's axis or a
    /// slide's guide. A slide placed on `l` by a point alone takes its guide
    /// from the other link, turned into `l`'s frame at value 0.
    fn axis(&self, j: usize, l: usize) -> Vector3<f64> {
        match self.place(j, l) {
            Place::Point { .. } => {
                let other = self.model.joints[j].places[1 - self.side(j, l)];
                self.zero(j, self.other(j, l)).rotation * v3(other.axis())
            }
            p => v3(p.axis()),
        }
    }

    fn try_align(&mut self) -> bool {
        for (j, from, to) in self.candidates() {
            if self.kind(j) != JointType::R {
                continue;
            }
            let k = self.axis(j, to);
            // Breadth-first through revolutes parallel to the first one met
            // (the group: that joint, the hops to it, its direction in `to`'s
            // frame) and translations; `last` is the last revolute crossed.
            #[derive(Clone)]
            struct Node {
                hops: Vec<Hop>,
                link: usize,
                group: Option<(usize, Vec<Hop>, Vector3<f64>)>,
                last: Option<usize>,
            }
            let mut queue = vec![Node {
                hops: vec![],
                link: to,
                group: None,
                last: None,
            }];
            let mut seen = vec![to];
            let mut i = 0;
            while i < queue.len() {
                let Node {
                    hops,
                    link,
                    group,
                    last,
                } = queue[i].clone();
                i += 1;
                if self.known[link] && !hops.is_empty() {
                    let (Some((g, ghops, a)), Some(last)) = (group, last) else {
                        continue;
                    };
                    // The group's direction must not be the joint's own axis.
                    if Self::parallel(a, k) {
                        continue;
                    }
                    // The target: the last revolute's axis on the link beyond it.
                    let Some(pos) = hops.iter().position(|h| h.joint == last) else {
                        continue;
                    };
                    let step = Step::Align {
                        joint: j,
                        from,
                        to,
                        group: Direction {
                            link: to,
                            hops: ghops.into(),
                            joint: g,
                        },
                        target: Direction {
                            link,
                            hops: reversed(&hops[pos + 1..]),
                            joint: last,
                        },
                    };
                    self.push(step, to, j);
                    return true;
                }
                if self.known[link] {
                    continue;
                }
                for (q, joint) in self.model.joints.iter().enumerate() {
                    if q == j || !joint.links.contains(&link) || hops.iter().any(|h| h.joint == q) {
                        continue;
                    }
                    let next = self.other(q, link);
                    if seen.contains(&next) {
                        continue;
                    }
                    let (group, last) = match joint.kind {
                        JointType::P | JointType::Pa => (group.clone(), last),
                        JointType::R => {
                            let dir = self.rotation(&hops) * self.axis(q, link);
                            match &group {
                                None => (Some((q, hops.clone(), dir)), Some(q)),
                                Some((_, _, a)) if Self::parallel(*a, dir) => (group.clone(), Some(q)),
                                Some(_) => continue,
                            }
                        }
                        JointType::S => continue,
                    };
                    seen.push(next);
                    let mut h = hops.clone();
                    h.push(self.hop(q, link));
                    queue.push(Node {
                        hops: h,
                        link: next,
                        group,
                        last,
                    });
                }
            }
        }
        false
    }

    /// The link at the end of `hops` from `start`.
    fn link_after(&self, start: usize, hops: &[Hop]) -> usize {
        hops.iter().fold(start, |l, h| self.other(h.joint, l))
    }

    fn try_pa_plane(&mut self) -> bool {
        for (j, from, to) in self.candidates() {
            if self.kind(j) != JointType::R {
                continue;
            }
            for (p, joint) in self.model.joints.iter().enumerate() {
                if p == j || joint.kind != JointType::Pa || !joint.links.contains(&to) {
                    continue;
                }
                let hinge = v3(self.place(p, to).at());
                if !self.on_axis(j, to, hinge) || Self::parallel(self.axis(p, to), self.axis(j, to)) {
                    continue;
                }
                let b = self.other(p, to);
                let x = v3(self.place(p, b).at());
                let found = self.fixed_reach(b, x, &[j, p]).into_iter().find(|r| self.known[r.link]);
                if let Some(r) = found {
                    let step = Step::PaPlane {
                        joint: j,
                        from,
                        to,
                        pa: p,
                        target: Anchor {
                            link: r.link,
                            hops: reversed(&r.hops),
                            point: PointRef::Joint(p),
                        },
                    };
                    self.push(step, to, j);
                    return true;
                }
            }
        }
        false
    }

    /// Constraints on point `x` of `to` from the rest of the mechanism.
    fn constraints(&self, j: usize, to: usize, point: PointRef, x: Vector3<f64>) -> Vec<(Constraint, bool)> {
        let mut out = Vec::new();
        let circle = self.kind(j) != JointType::P;
        // The motion's axis (circle) or direction (line) in `to`'s frame.
        let k = self.axis(j, to);
        for r in self.fixed_reach(to, x, &[j]) {
            if self.known[r.link] {
                continue;
            }
            let rot = self.rotation(&r.hops);
            // The hops that carry the point must turn about the motion's axis too.
            let hops_parallel = r.hops.iter().enumerate().all(|(i, h)| {
                let pre = &r.hops[..i];
                Self::parallel(self.rotation(pre) * self.axis(h.joint, self.link_after(to, pre)), k)
            });
            for (q, joint) in self.model.joints.iter().enumerate() {
                if q == j || !joint.links.contains(&r.link) || r.hops.iter().any(|h| h.joint == q) {
                    continue;
                }
                let next = self.other(q, r.link);
                match joint.kind {
                    // Sphere: the point is a parallelogram's hinge.
                    JointType::Pa if (r.x - v3(self.place(q, r.link).at())).norm() <= self.tol => {
                        let b = v3(self.place(q, next).at());
                        let mut excl = vec![j, q];
                        excl.extend(r.hops.iter().map(|h| h.joint));
                        if let Some(c) = self
                            .fixed_reach(next, b, &excl)
                            .into_iter()
                            .find(|c| self.known[c.link])
                        {
                            out.push((
                                Constraint::Sphere {
                                    centre: Anchor {
                                        link: c.link,
                                        hops: reversed(&c.hops),
                                        point: PointRef::Joint(q),
                                    },
                                    pa: q,
                                },
                                true,
                            ));
                        }
                    }
                    // A planar mechanism's link pinned at the revolute turns about it as if known.
                    JointType::R
                        if circle
                            && hops_parallel
                            && (self.known[next]
                                || (self.model.planar && self.pinned_at(next, v3(self.place(q, next).at())))) =>
                    {
                        let dir = rot * self.axis(q, r.link);
                        if Self::parallel(dir, k) {
                            out.push((
                                Constraint::Cylinder {
                                    hops: r.hops.clone().into(),
                                    joint: q,
                                    link: next,
                                },
                                true,
                            ));
                        }
                    }
                    JointType::P if circle && self.known[next] && hops_parallel => {
                        let dir = rot * self.axis(q, r.link);
                        if dir.normalize().dot(&k.normalize()).abs() <= 1e-9 {
                            out.push((
                                Constraint::Slider {
                                    hops: r.hops.clone().into(),
                                    joint: q,
                                    link: next,
                                },
                                true,
                            ));
                        }
                    }
                    _ => {}
                }
            }
            // Plane: a path of revolutes (and parallelograms) parallel to
            // one direction, and translations normal to it, to a known link.
            if let Some(c) = self.plane(j, point, &r, k, circle) {
                out.push(c);
            }
        }
        out
    }

    fn plane(&self, j: usize, point: PointRef, r: &Reach, k: Vector3<f64>, circle: bool) -> Option<(Constraint, bool)> {
        type Node = (Vec<Hop>, usize, Option<(usize, Vector3<f64>)>);
        let rot0 = self.rotation(&r.hops);
        let mut queue: Vec<Node> = vec![(vec![], r.link, None)];
        let mut seen = vec![r.link];
        let mut i = 0;
        while i < queue.len() {
            let (hops, link, w) = queue[i].clone();
            i += 1;
            if self.known[link] && !hops.is_empty() {
                let Some((g, wdir)) = w else { continue };
                // The plane must cut the motion: not parallel to a circle's plane or a line.
                let wk = wdir.normalize().dot(&k.normalize()).abs();
                if (circle && wk >= 1.0 - 1e-9) || (!circle && wk <= 1e-9) {
                    continue;
                }
                let Some(g_pos) = hops.iter().position(|h| h.joint == g) else {
                    continue;
                };
                let mut all = r.hops.clone();
                all.extend(hops.iter().copied());
                // The normal: g's axis on the link before it, seen from the known link.
                let normal = Direction {
                    link,
                    hops: reversed(&hops[g_pos..]),
                    joint: g,
                };
                return Some((
                    Constraint::Plane {
                        normal,
                        anchor: Anchor {
                            link,
                            hops: reversed(&all),
                            point,
                        },
                    },
                    circle,
                ));
            }
            if self.known[link] {
                continue;
            }
            let rot = rot0 * self.rotation(&hops);
            for (q, joint) in self.model.joints.iter().enumerate() {
                if q == j
                    || !joint.links.contains(&link)
                    || hops.iter().any(|h| h.joint == q)
                    || r.hops.iter().any(|h| h.joint == q)
                {
                    continue;
                }
                let next = self.other(q, link);
                if seen.contains(&next) {
                    continue;
                }
                let dir = rot * self.axis(q, link);
                let w_next = match (joint.kind, w) {
                    (JointType::R | JointType::Pa, None) => Some((q, dir)),
                    (JointType::R | JointType::Pa, Some((_, wd))) if Self::parallel(dir, wd) => w,
                    (JointType::P, Some((_, wd))) if dir.normalize().dot(&wd.normalize()).abs() <= 1e-9 => w,
                    _ => continue,
                };
                seen.push(next);
                let mut h = hops.clone();
                h.push(self.hop(q, link));
                queue.push((h, next, w_next));
            }
        }
        None
    }

    fn try_locus(&mut self, want_branch: bool) -> bool {
        for (j, from, to) in self.candidates() {
            for (point, x) in self.points_of(to, j) {
                let found = self
                    .constraints(j, to, point, x)
                    .into_iter()
                    .find(|(_, two)| *two == want_branch);
                if let Some((constraint, two)) = found {
                    let branch = if two {
                        self.branches += 1;
                        Some(self.branches - 1)
                    } else {
                        None
                    };
                    let step = Step::Locus {
                        joint: j,
                        from,
                        to,
                        point,
                        constraint,
                        branch,
                    };
                    self.push(step, to, j);
                    return true;
                }
            }
        }
        false
    }
}

fn solve(
    a: &Analysis,
    model: &Model,
    given: Vec<Option<usize>>,
    start: Vec<Step>,
    n_inputs: usize,
    inputs: Vec<usize>,
    what: &str,
) -> Result<Plan, Diagnostics> {
    let m = &a.mechanism;
    let mut known = vec![false; model.links.len()];
    known[0] = true;
    let mut pins = vec![None; model.links.len()];
    for s in &start {
        if let Step::Place { link, point, turn, .. } = s {
            match turn {
                Turn::Free => {
                    let at = spatial::local_point(model, *point, *link)
                        .map_err(|e| Diagnostics::from(Diagnostic::new(a.mechanism.name_span(), e.to_string())))?;
                    pins[*link] = Some(v3(at));
                }
                Turn::Fixed | Turn::About(_) => known[*link] = true,
            }
        }
    }
    let mut p = Planner {
        model,
        geometry: Geometry::of(model),
        tol: 1e-9 * model_scale(model).max(1.0),
        known,
        given,
        used: vec![false; model.joints.len()],
        pins,
        steps: start,
        branches: 0,
    };
    while !p.known.iter().all(|k| *k) {
        let progress = p.transfers()
            || p.try_aim()
            || p.try_align()
            || p.try_pa_plane()
            || p.try_locus(false)
            || p.try_locus(true);
        if !progress {
            let left: Vec<&str> = (0..m.links.len())
                .filter(|&l| !p.known[l])
                .map(|l| m.links[l].name.as_str())
                .collect();
            return Err(Diagnostic::new(
                m.name_span(),
                format!(
                    "no closed-form {what} plan: links {} are not reached by the step catalogue \
                     (aim, align, parallelogram plane, circle or line against sphere, plane or cylinder)",
                    left.join(", ")
                ),
            )
            .label("in this mechanism")
            .into());
        }
    }
    Ok(Plan {
        steps: p.steps,
        branches: p.branches,
        n_inputs,
        inputs,
    })
}

/// The spatial forward-position plan.
pub fn forward_plan(a: &Analysis) -> Result<Plan, Diagnostics> {
    let m = &a.mechanism;
    if a.topology.kappa != 0 {
        return Err(Diagnostic::new(
            m.name_span(),
            format!("a closed-form forward plan needs κ = 0 (κ = {})", a.topology.kappa),
        )
        .label("in this mechanism")
        .into());
    }
    let model = crate::numeric::model(a, &HashMap::new())?;
    let inputs = model.inputs();
    let mut given = vec![None; model.joints.len()];
    for (i, &j) in inputs.iter().enumerate() {
        given[j] = Some(i);
    }
    solve(a, &model, given, vec![], inputs.len(), inputs, "forward")
}

/// The spatial inverse-position plan from the declared outputs.
pub fn inverse_plan(a: &Analysis) -> Result<Plan, Diagnostics> {
    use crate::geometry::OutputKind;
    let m = &a.mechanism;
    if a.geometry.outputs.is_empty() {
        return Err(
            Diagnostic::new(m.name_span(), "an inverse solution needs `outputs { … }`")
                .label("in this mechanism")
                .into(),
        );
    }
    let model = crate::numeric::model(a, &HashMap::new())?;
    let nominal = a.geometry.nominal();
    let mut given = vec![None; model.joints.len()];
    let mut start = Vec::new();
    let mut next = 0;
    let planar = m.planar;
    for o in &a.geometry.outputs {
        match &o.kind {
            OutputKind::Pose { link, point, about } => {
                let turn = match about {
                    Some(k) => Turn::About(crate::geometry::eval_vec3(k, &nominal)),
                    None if planar => Turn::About([0.0, 0.0, 1.0]),
                    None => Turn::Fixed,
                };
                start.push(Step::Place {
                    link: *link,
                    point: *point,
                    input: next,
                    planar,
                    turn,
                });
            }
            OutputKind::Point { link, point } if planar => start.push(Step::Place {
                link: *link,
                point: *point,
                input: next,
                planar,
                turn: Turn::Free,
            }),
            OutputKind::Point { .. } => {
                return Err(Diagnostic::new(
                    m.name_span(),
                    "a spatial inverse plan needs each output link's pose (`pose of L at P`), not a point alone",
                )
                .label("in this mechanism")
                .into())
            }
            OutputKind::Joint(j) => given[*j] = Some(next),
        }
        next += o.names.len();
    }
    solve(a, &model, given, start, next, vec![], "inverse")
}
