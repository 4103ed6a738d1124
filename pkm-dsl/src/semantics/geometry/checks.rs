//! The checks of a geometry against the model: each joint's form on its
//! links, the declared relations (parallel, perpendicular, coaxial) and
//! the concurrent axes, at the parameters' values.

use super::*;
use crate::diagnostics::{Diagnostic, Span};
use crate::semantics::mechanism::{DirectionItem, JointKind, Mechanism};
use crate::syntax::ast::RelationKind;
use crate::syntax::expr::Expr;
use nalgebra::Vector3;
use std::collections::HashMap;

/// Each joint type needs its own form of placement on each side.
pub(super) fn check_forms(
    mech: &Mechanism,
    places: &mut [[Option<JointPlace>; 2]],
    spans: &[[Option<Span>; 2]],
    values: &HashMap<String, f64>,
    errors: &mut Vec<Diagnostic>,
) {
    for (j, joint) in mech.joints.iter().enumerate() {
        let missing: Vec<&str> = (0..2)
            .filter(|&s| places[j][s].is_none())
            .map(|s| mech.links[joint.links[s]].name.as_str())
            .collect();
        if !missing.is_empty() {
            let mut d = Diagnostic::new(
                joint.span,
                format!(
                    "joint `{}` has no place on link{} `{}`",
                    joint.name,
                    if missing.len() > 1 { "s" } else { "" },
                    missing.join("` and `")
                ),
            )
            .label("needs a place in the geometry");
            if missing.iter().any(|n| n.contains('/')) {
                d = d.note("an anonymous link takes geometry once it is named with a `[label]` in its chain");
            }
            errors.push(d);
            continue;
        }
        let span = |s: usize| spans[j][s].unwrap_or(joint.span);
        // A U joint's halves are revolutes; its errors name it a U.
        let symbol = if mech.universals.iter().any(|u| u.halves.contains(&j)) {
            "U"
        } else {
            joint.kind.symbol()
        };
        for (s, slot) in places[j].iter_mut().enumerate() {
            let place = slot.as_mut().expect("checked above");
            let problem = match (joint.kind, &mut *place) {
                (JointKind::Pa, JointPlace::Point(_, Some(_)) | JointPlace::Arm(..)) => None,
                (JointKind::Pa, _) => {
                    Some("a parallelogram takes a hinge `(…) along AXIS`, with `arm (…)` on one link".into())
                }
                (_, JointPlace::Arm(..)) => Some("only a parallelogram `Pa` takes an arm".into()),
                (JointKind::P, JointPlace::Point(_, Some(_))) => {
                    Some("a prismatic joint takes a guide line or a point, not an axis".into())
                }
                (JointKind::P, _) => None,
                (JointKind::S, JointPlace::Point(_, None)) => None,
                (JointKind::S, _) => Some("a spherical joint takes a centre `(…)` only".into()),
                (_, JointPlace::Line(..)) => Some(format!("a {symbol} joint takes a point and an axis, not a line")),
                (_, JointPlace::Point(_, axis @ None)) if mech.planar => {
                    // Planar rotations are about z.
                    *axis = Some([Expr::Num(0.0), Expr::Num(0.0), Expr::Num(1.0)]);
                    None
                }
                (_, JointPlace::Point(_, None)) => Some(format!("a {symbol} joint needs its axis: `(…) along x`")),
                (_, JointPlace::Point(_, Some(_))) => None,
            };
            if let Some(p) = problem {
                errors.push(Diagnostic::new(span(s), p).label(format!(
                    "joint `{}` on link `{}`",
                    joint.name, mech.links[joint.links[s]].name
                )));
            }
            let axis = match &*slot {
                Some(JointPlace::Point(_, Some(a))) | Some(JointPlace::Line(_, a)) | Some(JointPlace::Arm(_, a, _)) => {
                    Some(eval3(a, values))
                }
                _ => None,
            };
            if axis.is_some_and(|a| !a.iter().all(|x| x.is_finite()) || a.norm() == 0.0) {
                errors.push(Diagnostic::new(span(s), "the axis is zero or not finite").label("needs a direction"));
            }
        }
        // A P joint's guide line, and a parallelogram's arm, sit on exactly one side.
        type IsForm = fn(&JointPlace) -> bool;
        let one_side: Option<(IsForm, String, &str)> = match joint.kind {
            JointKind::P => Some((
                |p| matches!(p, JointPlace::Line(..)),
                format!(
                    "prismatic joint `{}` needs a guide line on one link and a point on the other",
                    joint.name
                ),
                "guide lines",
            )),
            JointKind::Pa => Some((
                |p| matches!(p, JointPlace::Arm(..)),
                format!(
                    "parallelogram `{}` needs its arm `arm (…)` on exactly one of its links",
                    joint.name
                ),
                "arms",
            )),
            _ => None,
        };
        if let Some((is_form, message, what)) = one_side {
            let n = places[j].iter().flatten().filter(|p| is_form(p)).count();
            if n != 1 {
                errors.push(Diagnostic::new(span(1), message).label(format!("{n} {what}")));
            }
        }
    }
}
/// The direction of a joint's axis on one side, if placed with one.
pub(super) fn axis_on(
    places: &[[Option<JointPlace>; 2]],
    mech: &Mechanism,
    j: usize,
    link: usize,
    values: &HashMap<String, f64>,
) -> Option<(Vector3<f64>, Option<Vector3<f64>>)> {
    let side = mech.joints[j].links.iter().position(|&l| l == link)?;
    match places[j][side].as_ref()? {
        JointPlace::Point(p, Some(a)) | JointPlace::Arm(p, a, _) => {
            Some((eval3(a, values).normalize(), Some(eval3(p, values))))
        }
        JointPlace::Line(p, a) => Some((
            eval3(a, values).normalize(),
            if mech.joints[j].kind == JointKind::P {
                None
            } else {
                Some(eval3(p, values))
            },
        )),
        _ => None,
    }
}
/// Relations between axes placed on one link (or a joint on the base and a
/// frame axis) are checked in that link's frame at the nominal dimensions.
pub(super) fn check_relations(
    mech: &Mechanism,
    places: &[[Option<JointPlace>; 2]],
    values: &HashMap<String, f64>,
    errors: &mut Vec<Diagnostic>,
) {
    const TOL: f64 = 1e-9;
    for r in &mech.relations {
        let Some(span) = r.span else { continue };
        if r.kind == RelationKind::Concurrent {
            continue; // check_concurrent: a point, not a pair of directions
        }
        let frame_axis = |k: usize| {
            let mut v = Vector3::zeros();
            v[k] = 1.0;
            v
        };
        let pair = match (r.a, r.b) {
            (DirectionItem::Joint(a), DirectionItem::Joint(b)) => {
                let shared = mech.joints[a]
                    .links
                    .iter()
                    .copied()
                    .find(|l| mech.joints[b].links.contains(l));
                shared.and_then(|l| {
                    Some((
                        axis_on(places, mech, a, l, values)?,
                        axis_on(places, mech, b, l, values)?,
                        l,
                    ))
                })
            }
            (DirectionItem::Joint(a), DirectionItem::Frame(k)) | (DirectionItem::Frame(k), DirectionItem::Joint(a)) => {
                axis_on(places, mech, a, 0, values).map(|x| (x, (frame_axis(k), None), 0))
            }
            _ => None,
        };
        let Some(((da, pa), (db, pb), link)) = pair else {
            continue;
        };
        let angle = da.cross(&db).norm().atan2(da.dot(&db)).to_degrees();
        let holds = match r.kind {
            RelationKind::Parallel => da.cross(&db).norm() < TOL,
            RelationKind::Perpendicular => da.dot(&db).abs() < TOL,
            RelationKind::Concurrent => true,
            RelationKind::Coaxial => {
                da.cross(&db).norm() < TOL
                    && matches!((pa, pb), (Some(p), Some(q)) if (p - q).cross(&da).norm() < TOL * (1.0 + p.norm() + q.norm()))
            }
        };
        if !holds {
            let what = match r.kind {
                RelationKind::Coaxial if da.cross(&db).norm() < TOL => {
                    "the axes are parallel but not on one line".to_string()
                }
                _ => format!("the axes are {angle:.3}° apart"),
            };
            errors.push(
                Diagnostic::new(
                    span,
                    format!(
                        "relation `{}` does not hold in the geometry of link `{}`",
                        r.kind.symbol(),
                        mech.links[link].name
                    ),
                )
                .label(what),
            );
        }
    }
}
/// Concurrent axes (`∧`) are checked link by link at the nominal
/// dimensions: on each link, the axes of one group's joints placed there
/// meet at one point, the group's centre in that link's frame (the first
/// two that are not parallel fix it); across each joint of the group, the
/// centres on its two links are the same point of its axis, the same
/// distance along it from the joint's place on either side (the places
/// coincide and the axes agree when the joint is closed).
pub(super) fn check_concurrent(
    mech: &Mechanism,
    places: &[[Option<JointPlace>; 2]],
    values: &HashMap<String, f64>,
    errors: &mut Vec<Diagnostic>,
) {
    let groups = crate::semantics::mechanism::concurrent_groups(&mech.joints, &mech.relations);
    let n_groups = groups.iter().flatten().max().map_or(0, |g| g + 1);
    let name = |j: usize| mech.joints[j].name.as_str();
    for g in 0..n_groups {
        let members: Vec<usize> = (0..mech.joints.len()).filter(|&j| groups[j] == Some(g)).collect();
        // Where the group is written: the first `∧` naming the joint, or any.
        let span_of = |j: usize| {
            let of = |pick: &dyn Fn(&crate::semantics::mechanism::Relation) -> bool| {
                mech.relations
                    .iter()
                    .filter(|r| r.kind == RelationKind::Concurrent)
                    .find(|r| pick(r))
                    .and_then(|r| r.span)
            };
            of(&|r| r.a == DirectionItem::Joint(j) || r.b == DirectionItem::Joint(j))
                .or_else(|| {
                    of(&|r| {
                        [r.a, r.b]
                            .iter()
                            .any(|i| matches!(i, DirectionItem::Joint(k) if members.contains(k)))
                    })
                })
                .unwrap_or_default()
        };
        // Where two of them are written together, if they are, else the second's.
        let span_pair = |a: usize, b: usize| {
            mech.relations
                .iter()
                .find(|r| {
                    r.kind == RelationKind::Concurrent
                        && [r.a, r.b].contains(&DirectionItem::Joint(a))
                        && [r.a, r.b].contains(&DirectionItem::Joint(b))
                })
                .and_then(|r| r.span)
                .unwrap_or_else(|| span_of(b))
        };
        let mut centres: HashMap<usize, Vector3<f64>> = HashMap::new();
        for link in 0..mech.links.len() {
            let lines: Vec<(usize, Vector3<f64>, Vector3<f64>)> = members
                .iter()
                .filter_map(|&j| match axis_on(places, mech, j, link, values)? {
                    (d, Some(p)) => Some((j, d, p)),
                    _ => None,
                })
                .collect();
            let Some((i, k)) = (0..lines.len())
                .flat_map(|i| (i + 1..lines.len()).map(move |k| (i, k)))
                .find(|&(i, k)| lines[i].1.cross(&lines[k].1).norm() > 1e-6)
            else {
                continue;
            };
            let scale = 1.0 + lines.iter().map(|l| l.2.norm()).fold(0.0, f64::max);
            let tol = 1e-9 * scale;
            let ((a, da, pa), (b, db, pb)) = (lines[i], lines[k]);
            // The closest points of the two lines.
            let w = pa - pb;
            let (e, f, c) = (da.dot(&db), da.dot(&w), db.dot(&w));
            let den = 1.0 - e * e;
            let (sa, sb) = ((e * c - f) / den, (c - e * f) / den);
            let (qa, qb) = (pa + da * sa, pb + db * sb);
            let lname = &mech.links[link].name;
            if (qa - qb).norm() > tol {
                errors.push(
                    Diagnostic::new(
                        span_pair(a, b),
                        format!("relation `∧` does not hold in the geometry of link `{lname}`"),
                    )
                    .label(format!(
                        "the axes of `{}` and `{}` pass {} apart",
                        name(a),
                        name(b),
                        length((qa - qb).norm())
                    )),
                );
                continue;
            }
            let centre = (qa + qb) / 2.0;
            let mut holds = true;
            for &(j, d, p) in &lines {
                let off = (centre - p) - d * d.dot(&(centre - p));
                if off.norm() > tol {
                    holds = false;
                    errors.push(
                        Diagnostic::new(
                            span_of(j),
                            format!("relation `∧` does not hold in the geometry of link `{lname}`"),
                        )
                        .label(format!(
                            "the axis of `{}` passes {} from where `{}` and `{}` meet",
                            name(j),
                            length(off.norm()),
                            name(a),
                            name(b)
                        )),
                    );
                }
            }
            if holds {
                centres.insert(link, centre);
            }
        }
        // Across each joint: the same point of its axis on both sides.
        for &j in &members {
            let [l0, l1] = [mech.joints[j].links[0], mech.joints[j].links[1]];
            let (Some(c0), Some(c1)) = (centres.get(&l0), centres.get(&l1)) else {
                continue;
            };
            let along = |l: usize, c: &Vector3<f64>| {
                axis_on(places, mech, j, l, values).and_then(|(d, p)| Some((c - p?).dot(&d)))
            };
            let (Some(s0), Some(s1)) = (along(l0, c0), along(l1, c1)) else {
                continue;
            };
            let tol = 1e-9 * (1.0 + c0.norm().max(c1.norm()) + s0.abs().max(s1.abs()));
            if (s0 - s1).abs() > tol {
                errors.push(
                    Diagnostic::new(
                        span_of(j),
                        format!(
                            "relation `∧` does not hold across joint `{}`: links `{}` and `{}` put the centre at different points of its axis",
                            name(j),
                            mech.links[l0].name,
                            mech.links[l1].name
                        ),
                    )
                    .label(format!("{} apart along `{}`", length((s0 - s1).abs()), name(j))),
                );
            }
        }
    }
}
/// A length for a message: three decimals, or three digits where smaller.
pub(super) fn length(x: f64) -> String {
    if x >= 1e-3 {
        format!("{x:.3}")
    } else {
        format!("{x:.3e}")
    }
}
