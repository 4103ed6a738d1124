//! The builder of the semantic model: the links and joints as the
//! description names them, the U joints' parts, direction references, the
//! size checks and [`build`], which runs the steps in `statements.rs`.

use super::relations::check_relations;
use super::*;
use crate::diagnostics::{Diagnostic, Diagnostics, Span};
use crate::limits::MAX_RELATIONS;
use crate::syntax::ast::{DirectionRef, MechanismAst, Name, RelationKind};
use std::collections::{HashMap, HashSet};

pub(super) const BASE_ALIASES: [&str; 4] = ["base", "frame", "ground", "0"];
pub(super) const FRAME_AXES: [&str; 3] = ["x", "y", "z"];

pub(super) struct Builder {
    pub(super) planes: usize,
    pub(super) errors: Diagnostics,
    pub(super) links: Vec<Link>,
    pub(super) link_by_name: HashMap<String, usize>,
    pub(super) joints: Vec<Joint>,
    pub(super) joint_by_name: HashMap<String, usize>,
    pub(super) relations: Vec<Relation>,
    pub(super) universals: Vec<Universal>,
    /// Unknown joint names already reported (one error per name).
    pub(super) unknown_reported: HashSet<String>,
}

impl Builder {
    pub(super) fn link(&mut self, name: &Name) -> usize {
        let key = if BASE_ALIASES.contains(&name.text.as_str()) {
            "base".to_string()
        } else {
            name.text.clone()
        };
        if let Some(&i) = self.link_by_name.get(&key) {
            return i;
        }
        if FRAME_AXES.contains(&key.as_str()) {
            self.errors.push(
                Diagnostic::new(
                    name.span,
                    format!("`{}` names a frame axis and cannot name a link", name.text),
                )
                .label("reserved name"),
            );
        }
        self.links.push(Link {
            name: key.clone(),
            description: None,
            span: Some(name.span),
        });
        self.link_by_name.insert(key, self.links.len() - 1);
        self.links.len() - 1
    }

    pub(super) fn anonymous_link(&mut self, after: &str, before: &str) -> usize {
        self.links.push(Link {
            name: format!("{after}/{before}"),
            description: None,
            span: None,
        });
        self.links.len() - 1
    }

    pub(super) fn add_joint(
        &mut self,
        name: &Name,
        kind: JointKind,
        links: [usize; 2],
        actuated: bool,
        branch: Option<usize>,
    ) {
        if FRAME_AXES.contains(&name.text.as_str()) {
            self.errors.push(
                Diagnostic::new(
                    name.span,
                    format!("`{}` names a frame axis and cannot name a joint", name.text),
                )
                .label("reserved name"),
            );
        }
        if let Some(&first) = self.joint_by_name.get(&name.text) {
            let first_span = self.joints[first].span;
            self.errors.push(
                Diagnostic::new(name.span, format!("joint `{}` is declared twice", name.text))
                    .label("second declaration")
                    .also(first_span, "first declared"),
            );
            return;
        }
        if links[0] == links[1] {
            self.errors.push(
                Diagnostic::new(
                    name.span,
                    format!(
                        "joint `{}` connects link `{}` to itself",
                        name.text, self.links[links[0]].name
                    ),
                )
                .label("a joint needs two different links"),
            );
        }
        self.joint_by_name.insert(name.text.clone(), self.joints.len());
        self.joints.push(Joint {
            name: name.text.clone(),
            kind,
            links,
            actuated,
            span: name.span,
            branch,
        });
    }

    /// A U joint: the revolutes `NAME.a` (first link to a new cross link)
    /// and `NAME.b` (cross to the second link), perpendicular, meeting at
    /// the U's centre (see [`Universal`]). Returns the two halves.
    pub(super) fn add_universal(
        &mut self,
        name: &Name,
        links: [usize; 2],
        actuated: bool,
        branch: Option<usize>,
    ) -> Option<[usize; 2]> {
        if actuated {
            self.errors.push(
                Diagnostic::new(name.span, format!("U joint `{}` cannot be an input", name.text))
                    .label("a U joint has two values")
                    .note("drive a revolute or prismatic joint instead"),
            );
        }
        if let Some(first) = self.universals.iter().find(|u| u.name == name.text).map(|u| u.span) {
            self.errors.push(
                Diagnostic::new(name.span, format!("joint `{}` is declared twice", name.text))
                    .label("second declaration")
                    .also(first, "first declared"),
            );
            return None;
        }
        if links[0] == links[1] {
            self.errors.push(
                Diagnostic::new(
                    name.span,
                    format!(
                        "joint `{}` connects link `{}` to itself",
                        name.text, self.links[links[0]].name
                    ),
                )
                .label("a joint needs two different links"),
            );
            return None;
        }
        self.links.push(Link {
            name: format!("{}.cross", name.text),
            description: Some(format!("the cross of U joint {}", name.text)),
            span: None,
        });
        let cross = self.links.len() - 1;
        let half = |axis: &str| Name {
            text: format!("{}.{axis}", name.text),
            span: name.span,
        };
        let first = self.joints.len();
        self.add_joint(&half("a"), JointKind::R, [links[0], cross], false, branch);
        self.add_joint(&half("b"), JointKind::R, [cross, links[1]], false, branch);
        if self.joints.len() != first + 2 {
            return None;
        }
        let halves = [first, first + 1];
        self.relations.push(Relation {
            kind: RelationKind::Perpendicular,
            a: DirectionItem::Joint(halves[0]),
            b: DirectionItem::Joint(halves[1]),
            span: None,
        });
        self.universals.push(Universal {
            name: name.text.clone(),
            halves,
            cross,
            span: name.span,
        });
        Some(halves)
    }

    /// The direction a relation names, and whether it is a plane's normal.
    pub(super) fn direction_ref(&mut self, d: &DirectionRef) -> Option<(DirectionItem, bool)> {
        match d {
            DirectionRef::Axis(n) => self.direction(n).map(|i| (i, false)),
            DirectionRef::FramePlane(n) => {
                let normal = match n.text.as_str() {
                    "yoz" | "zoy" => 0,
                    "xoz" | "zox" => 1,
                    "xoy" | "yox" => 2,
                    _ => {
                        self.errors.push(
                            Diagnostic::new(n.span, format!("unknown frame plane `◇{}`", n.text))
                                .label("expected ◇xoy, ◇yoz or ◇xoz"),
                        );
                        return None;
                    }
                };
                Some((DirectionItem::Frame(normal), true))
            }
            DirectionRef::PlaneOf(p, q, span) => {
                let (a, c) = (self.direction(p), self.direction(q));
                let (a, c) = (a?, c?);
                let normal = DirectionItem::PlaneNormal(self.planes);
                self.planes += 1;
                for side in [a, c] {
                    self.relations.push(Relation {
                        kind: RelationKind::Perpendicular,
                        a: normal,
                        b: side,
                        span: Some(*span),
                    });
                }
                Some((normal, true))
            }
        }
    }

    pub(super) fn direction(&mut self, name: &Name) -> Option<DirectionItem> {
        if let Some(i) = FRAME_AXES.iter().position(|a| *a == name.text) {
            return Some(DirectionItem::Frame(i));
        }
        match self.joint_by_name.get(&name.text) {
            Some(&j) => {
                if !self.joints[j].kind.has_direction() {
                    self.errors.push(
                        Diagnostic::new(
                            name.span,
                            format!("joint `{}` is spherical and has no axis to relate", name.text),
                        )
                        .label("S joint"),
                    );
                    return None;
                }
                Some(DirectionItem::Joint(j))
            }
            None if self.universals.iter().any(|u| u.name == name.text) => {
                self.errors.push(
                    Diagnostic::new(name.span, format!("U joint `{}` has two axes", name.text))
                        .label("which one?")
                        .note(format!(
                            "write `{0}.a` (the axis fixed in its first link) or `{0}.b` (in its second)",
                            name.text
                        )),
                );
                None
            }
            None => {
                let message = format!("unknown joint `{}`", name.text);
                // One error per unknown name, at its first use.
                if self.unknown_reported.insert(name.text.clone()) {
                    let mut d = Diagnostic::new(name.span, message).label("not declared");
                    if let Some(s) = suggest(&name.text, self.joint_by_name.keys().map(String::as_str)) {
                        d = d.note(format!("did you mean `{s}`?"));
                    }
                    self.errors.push(d);
                }
                None
            }
        }
    }
}

/// The closest known name within edit distance 2, for "did you mean".
pub fn suggest<'a>(name: &str, known: impl Iterator<Item = &'a str>) -> Option<&'a str> {
    known
        .map(|k| (edit_distance(name, k), k))
        // Short names are easily close to each other: allow one edit below four characters.
        .filter(|(d, _)| *d <= if name.chars().count() < 4 { 1 } else { 2 })
        .min()
        .map(|(_, k)| k)
}

fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1];
        for (j, cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != *cb);
            cur.push(sub.min(prev[j + 1] + 1).min(cur[j] + 1));
        }
        prev = cur;
    }
    prev[b.len()]
}

/// Checks the sizes of the syntax tree against [`crate::limits`] before any
/// pass over it: joints, links named in `link` statements, and relations.
fn check_sizes(ast: &MechanismAst) -> Result<(), Diagnostic> {
    // Every joint name in the text (a compound hinge on k links is k − 1 joints).
    let mut joints: Vec<Span> = ast
        .chains
        .iter()
        .flat_map(|c| c.joints.iter().map(|j| j.name.span))
        .collect();
    for decl in &ast.joints {
        joints.extend(std::iter::repeat_n(
            decl.name.span,
            decl.links.len().saturating_sub(1).max(1),
        ));
    }
    if joints.len() > MAX_JOINTS {
        joints.sort_unstable_by_key(|s| s.start);
        return Err(Diagnostic::new(
            joints[MAX_JOINTS],
            format!("the mechanism has {} joints; the limit is {MAX_JOINTS}", joints.len()),
        )
        .label(format!("joint number {} in the text", MAX_JOINTS + 1)));
    }
    let mut names = HashSet::new();
    for decl in &ast.links {
        names.insert(decl.name.text.as_str());
        if names.len() > MAX_JOINTS {
            return Err(Diagnostic::new(
                decl.name.span,
                format!("more than {MAX_JOINTS} links are named; the limit is {MAX_JOINTS}"),
            )
            .label(format!("link number {} here", MAX_JOINTS + 1)));
        }
    }
    let written = ast.chains.iter().map(|c| c.connectors.len()).sum::<usize>()
        + ast.relations.iter().map(|r| r.ops.len()).sum::<usize>();
    if written > MAX_RELATIONS {
        let first = ast.relations.iter().find_map(|r| r.ops.first()).map(|o| o.1);
        return Err(Diagnostic::new(
            first.unwrap_or(ast.name.span),
            format!("the mechanism writes {written} relations; the limit is {MAX_RELATIONS}"),
        )
        .label("relations start here"));
    }
    Ok(())
}

/// Builds the semantic model from the syntax tree, collecting every error:
/// the capabilities, the joints and links (declared, then along the
/// chains), the relations (written, then implied), the checks that every
/// link hangs in the mechanism and every branch reaches the platform, and
/// the base point.
pub fn build(ast: &MechanismAst) -> Result<Mechanism, Diagnostics> {
    check_sizes(ast)?;
    let mut b = Builder {
        unknown_reported: HashSet::new(),
        planes: 0,
        errors: Diagnostics::default(),
        links: Vec::new(),
        link_by_name: HashMap::new(),
        joints: Vec::new(),
        joint_by_name: HashMap::new(),
        relations: Vec::new(),
        universals: Vec::new(),
    };
    b.link(&Name {
        text: "base".into(),
        span: Span::default(),
    });
    b.links[0].span = None;
    let capabilities = b.capabilities(ast);
    b.declared_joints(ast);
    b.chains(ast);
    b.link_descriptions(ast);
    b.relation_statements(ast);
    let planar = ast.planar.is_some();
    let mut frame_declared = b.frame_axes_related();
    b.implied_relations(planar);
    if planar {
        frame_declared[2] = true;
    }
    b.check_coaxial();
    b.check_concurrent();
    check_relations(&b.joints, &b.relations, &mut b.errors);
    b.check_size(ast);
    b.check_links_hang(ast);
    let branches = b.branches(ast);
    let platform = b.platform(ast);
    b.check_branches(&branches, platform);
    let base_point = b.base_point(ast, platform);
    let platform_outputs = platform_outputs(ast, platform.map(|p| b.links[p].name.as_str()));
    let output_link = if platform.is_some() { None } else { output_link(&b, ast) };

    let Builder {
        errors,
        links,
        mut joints,
        relations,
        planes,
        universals,
        ..
    } = b;
    // A joint on the base measures its other link from the base: its value is
    // that link's angle (or slide) relative to the base, however it was written.
    for joint in &mut joints {
        if joint.links[1] == 0 {
            joint.links.swap(0, 1);
        }
    }
    errors.into_result(Mechanism {
        name: ast.name.text.clone(),
        title: ast.title.clone(),
        planar,
        mobility_by_geometry: ast.mobility_by_geometry,
        links,
        joints,
        branches,
        platform,
        base_point,
        platform_outputs,
        output_link,
        capabilities,
        relations,
        frame_declared,
        planes,
        universals,
    })
}

/// The parts of the platform's pose declared as outputs (`pose (z, rx, ry)
/// of platform at o`), in the order written.
fn platform_outputs(ast: &MechanismAst, platform: Option<&str>) -> Vec<String> {
    ast.outputs
        .iter()
        .filter_map(|o| match &o.what {
            crate::syntax::ast::OutputWhat::Pose {
                link,
                parts: Some(parts),
                ..
            } if Some(link.text.as_str()) == platform => Some(parts.iter().map(|p| p.text.clone())),
            _ => None,
        })
        .flatten()
        .collect()
}

/// The link of the first pose or point output, and the joint it is taken
/// at where that names one of the link's joints with a point (not a P).
fn output_link(b: &Builder, ast: &MechanismAst) -> Option<(usize, Option<usize>)> {
    use crate::syntax::ast::OutputWhat;
    ast.outputs.iter().find_map(|o| {
        let (OutputWhat::Pose { link, at, .. } | OutputWhat::Point { link, at }) = &o.what else {
            return None;
        };
        let l = *b.link_by_name.get(&link.text).filter(|&&l| l != 0)?;
        let joint =
            b.joint_by_name.get(&at.text).copied().filter(|&j| {
                b.joints[j].links.contains(&l) && !matches!(b.joints[j].kind, JointKind::P | JointKind::Pa)
            });
        Some((l, joint))
    })
}
