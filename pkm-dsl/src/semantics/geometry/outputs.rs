//! The declared outputs (a point's coordinates, an angle of the platform's
//! pose) resolved against the model, and the points on links they name.

use super::*;
use crate::diagnostics::Diagnostic;
use crate::semantics::mechanism::Mechanism;
use crate::syntax::ast::MechanismAst;

pub(super) fn resolve_outputs(
    ast: &MechanismAst,
    mech: &Mechanism,
    places: &[[Option<JointPlace>; 2]],
    points: &[NamedPoint],
    abouts: &[Option<Vec3>],
    complete: bool,
    errors: &mut Vec<Diagnostic>,
) -> Vec<Output> {
    let mut out = Vec::new();
    let mut seen: Vec<String> = Vec::new();
    for (decl, about) in ast.outputs.iter().zip(abouts) {
        if !complete {
            errors.push(Diagnostic::new(decl.span, "outputs need a `geometry` block").label("no geometry"));
            return out;
        }
        for n in &decl.names {
            if seen.contains(&n.text) {
                errors.push(Diagnostic::new(n.span, format!("output `{}` is named twice", n.text)).label("second use"));
            }
            seen.push(n.text.clone());
        }
        let kind = match &decl.what {
            crate::syntax::ast::OutputWhat::Joint(j) => {
                let Some(index) = mech.joint_index(&j.text) else {
                    let d = match mech.universal(&j.text) {
                        Some(_) => Diagnostic::new(j.span, format!("U joint `{}` has two values", j.text))
                            .label("which one?")
                            .note(format!("write `joint {0}.a` or `joint {0}.b`", j.text)),
                        None => Diagnostic::new(j.span, format!("unknown joint `{}`", j.text)).label("not declared"),
                    };
                    errors.push(d);
                    continue;
                };
                if decl.names.len() != 1 {
                    errors.push(Diagnostic::new(decl.span, "a joint output has one value").label("give it one name"));
                    continue;
                }
                OutputKind::Joint(index)
            }
            crate::syntax::ast::OutputWhat::Pose {
                link,
                at,
                about: about_ast,
                parts: Some(parts),
            } => {
                let Some(given) = pose_parts(mech, decl, parts, about_ast.is_some(), errors) else {
                    continue;
                };
                let Some((l, point)) = link_point(mech, places, points, link, at, errors) else {
                    continue;
                };
                OutputKind::Parts {
                    link: l,
                    point,
                    parts: given,
                }
            }
            crate::syntax::ast::OutputWhat::Pose {
                link,
                at,
                about: about_ast,
                parts: None,
            } => {
                if mech.planar && about_ast.is_some() {
                    errors.push(
                        Diagnostic::new(decl.span, "a planar pose turns about z: drop `about`")
                            .label("planar mechanism"),
                    );
                    continue;
                }
                let (wanted, what) = match (mech.planar, about_ast.is_some()) {
                    (true, _) => (3, "a planar pose has three values: x, y and the angle"),
                    (false, false) => (3, "a spatial pose without `about` has three values: x, y and z"),
                    (false, true) => (
                        4,
                        "a spatial pose `about` an axis has four values: x, y, z and the angle",
                    ),
                };
                if decl.names.len() != wanted {
                    errors.push(Diagnostic::new(decl.span, what).label(format!("{} names given", decl.names.len())));
                    continue;
                }
                let Some((l, point)) = link_point(mech, places, points, link, at, errors) else {
                    continue;
                };
                OutputKind::Pose {
                    link: l,
                    point,
                    about: about.clone().map(Box::new),
                }
            }
            crate::syntax::ast::OutputWhat::Point { link, at } => {
                let (wanted, what) = if mech.planar {
                    (2, "a planar point has two values: x and y")
                } else {
                    (3, "a spatial point has three values: x, y and z")
                };
                if decl.names.len() != wanted {
                    errors.push(Diagnostic::new(decl.span, what).label(format!("{} names given", decl.names.len())));
                    continue;
                }
                let Some((l, point)) = link_point(mech, places, points, link, at, errors) else {
                    continue;
                };
                OutputKind::Point { link: l, point }
            }
        };
        out.push(Output {
            names: decl.names.iter().map(|n| n.text.clone()).collect(),
            kind,
        });
    }
    out
}
/// The parts a `pose (…) of` output gives: of x, y, z, rx, ry, rz, each
/// once and in that order, one name each, in a spatial mechanism, without
/// `about`.
pub(super) fn pose_parts(
    mech: &Mechanism,
    decl: &crate::syntax::ast::OutputDecl,
    parts: &[crate::syntax::ast::Name],
    about: bool,
    errors: &mut Vec<Diagnostic>,
) -> Option<pkm_runtime::steps::place::PoseParts> {
    use pkm_runtime::steps::place::PoseParts;
    if mech.planar {
        errors.push(
            Diagnostic::new(decl.span, "a planar pose is x, y and the angle: drop the parts").label("planar mechanism"),
        );
        return None;
    }
    if about {
        errors.push(
            Diagnostic::new(decl.span, "a pose given by parts turns by rx, ry, rz: drop `about`").label("both given"),
        );
        return None;
    }
    let mut given = [false; 6];
    let mut last = None;
    for p in parts {
        let Some(i) = PoseParts::NAMES.iter().position(|n| *n == p.text) else {
            errors.push(
                Diagnostic::new(p.span, format!("unknown part `{}`", p.text)).label("one of x, y, z, rx, ry, rz"),
            );
            return None;
        };
        if last.is_some_and(|l| l >= i) {
            errors.push(
                Diagnostic::new(p.span, "the parts go in the order x, y, z, rx, ry, rz, each once")
                    .label("out of order"),
            );
            return None;
        }
        last = Some(i);
        given[i] = true;
    }
    if decl.names.len() != parts.len() {
        errors.push(
            Diagnostic::new(
                decl.span,
                format!("a pose given by {} parts has {} values", parts.len(), parts.len()),
            )
            .label(format!("{} names given", decl.names.len())),
        );
        return None;
    }
    Some(PoseParts(given))
}
/// An output's (or a load's) link and its point (a named point of the
/// link, or a joint placed on it by a point).
pub(crate) fn link_point(
    mech: &Mechanism,
    places: &[[Option<JointPlace>; 2]],
    points: &[NamedPoint],
    link: &crate::syntax::ast::Name,
    at: &crate::syntax::ast::Name,
    errors: &mut Vec<Diagnostic>,
) -> Option<(usize, pkm_runtime::solution::PointRef)> {
    use pkm_runtime::solution::PointRef;
    let Some(l) = mech.links.iter().position(|x| x.name == link.text) else {
        errors.push(Diagnostic::new(link.span, format!("unknown link `{}`", link.text)).label("no joint touches it"));
        return None;
    };
    let named = points
        .iter()
        .position(|p| p.link == l && p.name == at.text)
        .map(PointRef::Named);
    let joint = mech.joint_on(&at.text, l).filter(|&j| {
        let side = mech.joints[j].links.iter().position(|&x| x == l);
        matches!(side.and_then(|s| places[j][s].as_ref()), Some(JointPlace::Point(..)))
    });
    let point = named.or(joint.map(PointRef::Joint));
    if point.is_none() {
        errors.push(
            Diagnostic::new(at.span, format!("`{}` is not a point of link `{}`", at.text, link.text))
                .label("a named point or a joint placed on that link"),
        );
    }
    point.map(|p| (l, p))
}
