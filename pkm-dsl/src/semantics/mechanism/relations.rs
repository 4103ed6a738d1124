//! The axis relations as classes: connectivity through a subset of
//! joints, direction classes (union-find over parallel relations), groups of
//! concurrent axes, and the relations' consistency check.

use super::builder::FRAME_AXES;
use super::*;
use crate::diagnostics::{Diagnostic, Diagnostics, Span};
use crate::syntax::ast::RelationKind;
use std::collections::HashMap;

pub(super) fn connected(joints: &[Joint], subset: &[usize], from: usize, to: usize) -> bool {
    let mut seen = vec![from];
    let mut stack = vec![from];
    while let Some(l) = stack.pop() {
        if l == to {
            return true;
        }
        for &j in subset {
            let joint = &joints[j];
            if joint.links.contains(&l) {
                let o = joint.other(l);
                if !seen.contains(&o) {
                    seen.push(o);
                    stack.push(o);
                }
            }
        }
    }
    false
}

/// Union-find over direction items: parallel (and coaxial) relations merge classes.
#[derive(Debug, Clone)]
pub struct DirectionClasses {
    items: Vec<DirectionItem>,
    parent: Vec<usize>,
}

impl DirectionClasses {
    /// The classes of every joint axis, U second axis and frame axis under `relations`.
    pub fn new(joints: &[Joint], relations: &[Relation]) -> Self {
        let mut items: Vec<DirectionItem> = (0..3).map(DirectionItem::Frame).collect();
        for (j, joint) in joints.iter().enumerate() {
            if joint.kind.has_direction() {
                items.push(DirectionItem::Joint(j));
            }
            if joint.kind == JointKind::U {
                items.push(DirectionItem::USecond(j));
            }
        }
        for r in relations {
            for item in [r.a, r.b] {
                if matches!(item, DirectionItem::PlaneNormal(_)) && !items.contains(&item) {
                    items.push(item);
                }
            }
        }
        let mut c = DirectionClasses {
            parent: (0..items.len()).collect(),
            items,
        };
        let axis_line = |i: DirectionItem| match i {
            DirectionItem::Joint(j) => joints[j].kind.has_axis_line(),
            _ => false,
        };
        for r in relations {
            // A coaxial relation on a joint without an axis line is reported
            // elsewhere; it must not also merge directions.
            if r.kind == RelationKind::Coaxial && !(axis_line(r.a) && axis_line(r.b)) {
                continue;
            }
            if matches!(r.kind, RelationKind::Parallel | RelationKind::Coaxial) {
                if let (Some(a), Some(b)) = (c.index(r.a), c.index(r.b)) {
                    let (ra, rb) = (c.find(a), c.find(b));
                    c.parent[ra.max(rb)] = ra.min(rb);
                }
            }
        }
        c
    }

    /// The position of an item, if it has a direction.
    pub fn index(&self, item: DirectionItem) -> Option<usize> {
        self.items.iter().position(|i| *i == item)
    }

    /// The class (root index) of item number `i`.
    pub fn find(&self, mut i: usize) -> usize {
        while self.parent[i] != i {
            i = self.parent[i];
        }
        i
    }

    /// The class of an item.
    pub fn class_of(&self, item: DirectionItem) -> Option<usize> {
        self.index(item).map(|i| self.find(i))
    }

    /// Every item.
    pub fn items(&self) -> &[DirectionItem] {
        &self.items
    }
}

/// The point each joint's axis meets others at, if a `∧` relation says so:
/// a group number per joint. Axes related by `∧` (and those coaxial with
/// them, on the same line) meet at one point; statements that share an axis
/// name the same point.
pub fn concurrent_groups(joints: &[Joint], relations: &[Relation]) -> Vec<Option<usize>> {
    let n = joints.len();
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(p: &[usize], mut i: usize) -> usize {
        while p[i] != i {
            i = p[i];
        }
        i
    }
    let mut meets = vec![false; n];
    for r in relations {
        if let (RelationKind::Concurrent | RelationKind::Coaxial, DirectionItem::Joint(a), DirectionItem::Joint(b)) =
            (r.kind, r.a, r.b)
        {
            let (ra, rb) = (root(&parent, a), root(&parent, b));
            parent[ra.max(rb)] = ra.min(rb);
            if r.kind == RelationKind::Concurrent {
                meets[a] = true;
                meets[b] = true;
            }
        }
    }
    let mut with_point = vec![false; n];
    for j in 0..n {
        if meets[j] {
            with_point[root(&parent, j)] = true;
        }
    }
    let mut numbers: HashMap<usize, usize> = HashMap::new();
    (0..n)
        .map(|j| {
            let r = root(&parent, j);
            with_point[r].then(|| {
                let next = numbers.len();
                *numbers.entry(r).or_insert(next)
            })
        })
        .collect()
}

pub(super) fn check_relations(joints: &[Joint], relations: &[Relation], errors: &mut Diagnostics) {
    let classes = DirectionClasses::new(joints, relations);
    let item_name = |i: DirectionItem| match i {
        DirectionItem::Joint(j) => joints[j].name.clone(),
        DirectionItem::Frame(k) => FRAME_AXES[k].to_string(),
        DirectionItem::USecond(j) => format!("{}'", joints[j].name),
        DirectionItem::PlaneNormal(k) => format!("the normal of plane {}", k + 1),
    };
    // A plane ◇(A,B) needs two axes that are not parallel.
    let mut sides: HashMap<usize, (DirectionItem, Option<Span>)> = HashMap::new();
    for r in relations {
        if let (DirectionItem::PlaneNormal(k), side) = (r.a, r.b) {
            match sides.get(&k) {
                Some(&(first, span)) if classes.class_of(first) == classes.class_of(side) => errors.push(
                    Diagnostic::new(
                        span.unwrap_or_default(),
                        format!(
                            "the plane ◇({},{}) is not defined: its axes are parallel",
                            item_name(first),
                            item_name(side)
                        ),
                    )
                    .label("needs two axes that are not parallel"),
                ),
                Some(_) => {}
                None => {
                    sides.insert(k, (side, r.span));
                }
            }
        }
    }
    for r in relations {
        if r.kind != RelationKind::Perpendicular {
            continue;
        }
        if classes.class_of(r.a).is_some() && classes.class_of(r.a) == classes.class_of(r.b) {
            let msg = format!(
                "`{} ⊥ {}` contradicts the other relations, which make them parallel",
                item_name(r.a),
                item_name(r.b)
            );
            let d = match r.span {
                Some(s) => Diagnostic::new(s, msg).label("contradictory relation"),
                None => {
                    // An implied relation (planar, frame) was contradicted by a written one: point at that.
                    // An implied relation (frame, `planar`) was contradicted by a
                    // written one: point at the written relation that ties one of
                    // its two sides into the class, preferring one naming that side.
                    let in_class = |q: &&Relation| {
                        q.span.is_some()
                            && matches!(q.kind, RelationKind::Parallel | RelationKind::Coaxial)
                            && [q.a, q.b].iter().any(|i| classes.class_of(*i) == classes.class_of(r.a))
                    };
                    let names_side = |q: &&Relation| [q.a, q.b].iter().any(|i| *i == r.a || *i == r.b);
                    let written = relations
                        .iter()
                        .filter(in_class)
                        .find(names_side)
                        .or_else(|| relations.iter().find(in_class));
                    let msg = format!(
                        "this relation makes `{}` parallel to `{}`, which must be perpendicular (implied by the frame, a U joint or `planar`)",
                        item_name(r.a),
                        item_name(r.b)
                    );
                    match written.and_then(|q| q.span) {
                        Some(s) => Diagnostic::new(s, msg).label("contradictory relation"),
                        None => Diagnostic::global(msg),
                    }
                }
            };
            if !errors.0.iter().any(|e| e.span == d.span) {
                errors.push(d);
            }
        }
    }
}
