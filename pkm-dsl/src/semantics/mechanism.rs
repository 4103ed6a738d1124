//! The semantic model: the mechanism as a graph of links and joints with its
//! axis relations, built from the syntax tree with every check that needs no
//! geometry. All errors are collected, not just the first.

use crate::syntax::ast::{DirectionRef, MechanismAst, Name, RelationKind};
use crate::diagnostics::{Diagnostic, Diagnostics, Span};
use crate::limits::MAX_RELATIONS;
use std::collections::{HashMap, HashSet};

/// The joint types of the POC literature.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum JointKind {
    /// Revolute, f = 1.
    R,
    /// Prismatic, f = 1.
    P,
    /// Helical, f = 1.
    H,
    /// Cylindrical, f = 2.
    C,
    /// Universal (two perpendicular intersecting axes), f = 2.
    U,
    /// Spherical, f = 3.
    S,
    /// Parallelogram of four R joints, counted as one joint with one
    /// translational DOF; its internal loop is not counted in v or Σξ.
    Pa,
}

impl JointKind {
    /// The type named by the prefix of a joint's name (`R11` → R, `Pa` → Pa).
    pub fn from_name_prefix(name: &str) -> Option<JointKind> {
        if name.starts_with("Pa") {
            return Some(JointKind::Pa);
        }
        Self::from_symbol(name.get(..1)?)
    }

    /// The type written out in full (`R`, `P`, `H`, `C`, `U`, `S`, `Pa`).
    pub fn from_symbol(s: &str) -> Option<JointKind> {
        Some(match s {
            "R" => JointKind::R,
            "P" => JointKind::P,
            "H" => JointKind::H,
            "C" => JointKind::C,
            "U" => JointKind::U,
            "S" => JointKind::S,
            "Pa" => JointKind::Pa,
            _ => return None,
        })
    }

    /// The joint's degree of freedom f.
    pub fn dof(self) -> usize {
        match self {
            JointKind::R | JointKind::P | JointKind::H | JointKind::Pa => 1,
            JointKind::C | JointKind::U => 2,
            JointKind::S => 3,
        }
    }

    /// The type's symbol.
    pub fn symbol(self) -> &'static str {
        match self {
            JointKind::R => "R",
            JointKind::P => "P",
            JointKind::H => "H",
            JointKind::C => "C",
            JointKind::U => "U",
            JointKind::S => "S",
            JointKind::Pa => "Pa",
        }
    }

    /// Whether the joint has an axis direction that relations can refer to.
    pub fn has_direction(self) -> bool {
        self != JointKind::S
    }

    /// Whether the joint has a fixed axis line (so it can be coaxial with another).
    pub fn has_axis_line(self) -> bool {
        matches!(self, JointKind::R | JointKind::H | JointKind::C | JointKind::U)
    }

    /// Whether the joint rotates about its axis (its axis names a rotation).
    pub fn is_rotational(self) -> bool {
        matches!(self, JointKind::R | JointKind::H | JointKind::C | JointKind::U)
    }
}

/// What a user can ask the compiler to generate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Capability {
    /// Topology analysis only (always on).
    Analysis,
    /// Closed-form forward position solution.
    Fk,
    /// Closed-form inverse position solution.
    Ik,
    /// Forward position solution of a κ = 1 mechanism by one virtual
    /// variable and the roots of its compatibility residual.
    FkNumeric,
    /// Output and input Jacobians.
    Jacobian,
    /// Velocities of points and links.
    Velocity,
    /// Accelerations of points and links.
    Acceleration,
    /// Workspace sweeps.
    Workspace,
    /// Inverse dynamics.
    Dynamics,
    /// Static stiffness.
    Stiffness,
}

impl Capability {
    /// Every capability with its DSL name.
    pub const ALL: [(Capability, &'static str); 10] = [
        (Capability::Analysis, "analysis"),
        (Capability::Fk, "fk"),
        (Capability::Ik, "ik"),
        (Capability::Jacobian, "jacobian"),
        (Capability::Velocity, "velocity"),
        (Capability::Acceleration, "acceleration"),
        (Capability::Workspace, "workspace"),
        (Capability::Dynamics, "dynamics"),
        (Capability::FkNumeric, "fk_numeric"),
        (Capability::Stiffness, "stiffness"),
    ];

    /// The DSL name.
    pub fn name(self) -> &'static str {
        Self::ALL.iter().find(|(c, _)| *c == self).map_or("?", |(_, n)| n)
    }

    /// Every capability's name, listed with commas.
    pub fn names() -> String {
        let names: Vec<&str> = Self::ALL.iter().map(|(_, n)| *n).collect();
        names.join(", ")
    }
}

/// A rigid body of the mechanism. Link 0 is the base (frame).
#[derive(Debug, Clone, PartialEq)]
pub struct Link {
    /// Its name (`base`, `platform`, a label, or `J1/J2` for an anonymous link between two joints).
    pub name: String,
    /// Its description from a `link` statement.
    pub description: Option<String>,
    /// Where it is first named, if it is named.
    pub span: Option<Span>,
}

/// A kinematic joint between two links.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// Its name.
    pub name: String,
    /// Its type.
    pub kind: JointKind,
    /// The two links it connects; the joint's motion is that of `links[1]` relative
    /// to `links[0]`. A joint on the base has the base first.
    pub links: [usize; 2],
    /// Whether it is actuated.
    pub actuated: bool,
    /// Where it is declared.
    pub span: Span,
    /// The branch (limb) it belongs to.
    pub branch: Option<usize>,
}

impl Joint {
    /// The link at the other end from `link`.
    pub fn other(&self, link: usize) -> usize {
        if self.links[0] == link {
            self.links[1]
        } else {
            self.links[0]
        }
    }
}

/// A universal (U) joint as the semantic model holds it: two revolutes whose
/// axes meet at right angles at the U's centre, `NAME.a` from the U's first
/// link to an internal cross link `NAME.cross` and `NAME.b` from the cross
/// to the U's second link. The cross is massless and carries nothing else,
/// so topology (f = 1 + 1, one link and one joint more: the same loops),
/// plans, the Newton reference, velocities and generated code all treat the
/// U as the two revolutes it is, under the names the user writes for its
/// axes. The topology's generic instances put both axes through one point.
#[derive(Debug, Clone, PartialEq)]
pub struct Universal {
    /// Its name as written (`U1`).
    pub name: String,
    /// The revolutes `NAME.a` (on the first link) and `NAME.b` (on the second).
    pub halves: [usize; 2],
    /// The internal cross link.
    pub cross: usize,
    /// Where it is declared.
    pub span: Span,
}

/// A branch (limb) from the base to the platform; it may contain loops (a hybrid branch).
#[derive(Debug, Clone, PartialEq)]
pub struct Branch {
    /// Its name.
    pub name: String,
    /// Its joints.
    pub joints: Vec<usize>,
    /// Where its name is written.
    pub span: Span,
}

/// A direction that relations can refer to: a joint's axis, a frame axis, or
/// the second axis of a U joint.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DirectionItem {
    /// The axis (or sliding direction) of a joint.
    Joint(usize),
    /// Frame axis 0 = x, 1 = y, 2 = z.
    Frame(usize),
    /// The second axis of a U joint.
    USecond(usize),
    /// The normal of the k-th plane `◇(A,B)` written in a relation.
    PlaneNormal(usize),
}

/// One declared (or implied) relation between two directions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Relation {
    /// Which relation.
    pub kind: RelationKind,
    /// Left side.
    pub a: DirectionItem,
    /// Right side.
    pub b: DirectionItem,
    /// Where it is written, if it is written (implied relations have none).
    pub span: Option<Span>,
}

/// A mechanism ready for analysis.
#[derive(Debug, Clone, PartialEq)]
pub struct Mechanism {
    /// Its name.
    pub name: String,
    /// Its title.
    pub title: Option<String>,
    /// Declared `planar;`.
    pub planar: bool,
    /// Links; 0 is the base.
    pub links: Vec<Link>,
    /// Joints in declaration order, compound hinges expanded.
    pub joints: Vec<Joint>,
    /// Branches.
    pub branches: Vec<Branch>,
    /// The moving platform, if there is one.
    pub platform: Option<usize>,
    /// The joint on whose axis the platform's base point o lies, if chosen by the user.
    pub base_point: Option<usize>,
    /// Requested capabilities with where they are written.
    pub capabilities: Vec<(Capability, Span)>,
    /// Every relation, declared and implied.
    pub relations: Vec<Relation>,
    /// Whether frame axis x, y, z was tied to the mechanism by a relation.
    pub frame_declared: [bool; 3],
    /// How many planes `◇(A,B)` relations wrote (each has a normal direction item).
    pub planes: usize,
    /// The U joints, each two revolutes of `joints` and a cross link of `links`.
    pub universals: Vec<Universal>,
}

impl Mechanism {
    /// Where the mechanism's first joint is declared (a place for whole-mechanism errors).
    pub fn name_span(&self) -> Span {
        self.joints.first().map_or_else(Span::default, |j| j.span)
    }

    /// Σf over all joints.
    pub fn total_dof(&self) -> usize {
        self.joints.iter().map(|j| j.kind.dof()).sum()
    }

    /// Number of actuated joints.
    pub fn actuator_count(&self) -> usize {
        self.joints.iter().filter(|j| j.actuated).count()
    }

    /// Whether the capability was requested.
    pub fn wants(&self, c: Capability) -> bool {
        self.capabilities.iter().any(|(k, _)| *k == c)
    }

    /// The joint called `name`.
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// The U joint called `name`.
    pub fn universal(&self, name: &str) -> Option<&Universal> {
        self.universals.iter().find(|u| u.name == name)
    }

    /// The joint called `name` that touches `link`: the joint itself, or
    /// the half of a U joint of that name on that side.
    pub fn joint_on(&self, name: &str, link: usize) -> Option<usize> {
        self.joint_index(name)
            .or_else(|| {
                self.universal(name)?
                    .halves
                    .into_iter()
                    .find(|&h| self.joints[h].links.contains(&link))
            })
            .filter(|&j| self.joints[j].links.contains(&link))
    }

    /// The joints incident to each link.
    pub fn incidence(&self) -> Vec<Vec<usize>> {
        let mut inc = vec![Vec::new(); self.links.len()];
        for (j, joint) in self.joints.iter().enumerate() {
            inc[joint.links[0]].push(j);
            inc[joint.links[1]].push(j);
        }
        inc
    }
}

const BASE_ALIASES: [&str; 4] = ["base", "frame", "ground", "0"];
const FRAME_AXES: [&str; 3] = ["x", "y", "z"];
pub use crate::limits::MAX_JOINTS;

struct Builder {
    planes: usize,
    errors: Diagnostics,
    links: Vec<Link>,
    link_by_name: HashMap<String, usize>,
    joints: Vec<Joint>,
    joint_by_name: HashMap<String, usize>,
    relations: Vec<Relation>,
    universals: Vec<Universal>,
    /// Unknown joint names already reported (one error per name).
    unknown_reported: HashSet<String>,
}

impl Builder {
    fn link(&mut self, name: &Name) -> usize {
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

    fn anonymous_link(&mut self, after: &str, before: &str) -> usize {
        self.links.push(Link {
            name: format!("{after}/{before}"),
            description: None,
            span: None,
        });
        self.links.len() - 1
    }

    fn add_joint(&mut self, name: &Name, kind: JointKind, links: [usize; 2], actuated: bool, branch: Option<usize>) {
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
    fn add_universal(
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
    fn direction_ref(&mut self, d: &DirectionRef) -> Option<(DirectionItem, bool)> {
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

    fn direction(&mut self, name: &Name) -> Option<DirectionItem> {
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
        links,
        joints,
        branches,
        platform,
        base_point,
        capabilities,
        relations,
        frame_declared,
        planes,
        universals,
    })
}

/// The steps of [`build`], each one named part of the description.
impl Builder {
    /// The requested capabilities; an unknown one is an error. What each
    /// needs of the rest of the file is checked where code is generated
    /// ([`crate::check_capabilities`]).
    fn capabilities(&mut self, ast: &MechanismAst) -> Vec<(Capability, Span)> {
        let mut capabilities = Vec::new();
        for c in &ast.capabilities {
            match Capability::ALL.iter().find(|(_, n)| *n == c.text) {
                Some((k, _)) => capabilities.push((*k, c.span)),
                None => self.errors.push(
                    Diagnostic::new(c.span, format!("unknown capability `{}`", c.text))
                        .label("not a capability")
                        .note(format!("capabilities: {}", Capability::names())),
                ),
            }
        }
        capabilities
    }

    /// Explicit joints (planar link/joint lists); k links on one axis make k − 1 coaxial joints.
    fn declared_joints(&mut self, ast: &MechanismAst) {
        for decl in &ast.joints {
            let Some(kind) = JointKind::from_symbol(&decl.kind.text) else {
                self.errors.push(
                    Diagnostic::new(decl.kind.span, format!("unknown joint type `{}`", decl.kind.text))
                        .label("expected R, P, H, C, U, S or Pa"),
                );
                continue;
            };
            let links: Vec<usize> = decl.links.iter().map(|l| self.link(l)).collect();
            if kind == JointKind::U {
                if links.len() > 2 {
                    self.errors.push(
                        Diagnostic::new(decl.kind.span, "a U joint joins two links")
                            .label("compound joints must be R, H or C"),
                    );
                } else {
                    self.add_universal(&decl.name, [links[0], links[1]], decl.actuated, None);
                }
                continue;
            }
            if links.len() > 2 && !kind.has_axis_line() {
                self.errors.push(
                    Diagnostic::new(
                        decl.kind.span,
                        format!("a compound hinge needs an axis line; `{}` has none", decl.kind.text),
                    )
                    .label("compound joints must be R, H, C or U"),
                );
                continue;
            }
            let first = self.joints.len();
            for (k, &other) in links.iter().enumerate().skip(1) {
                let n = if k == 1 {
                    decl.name.clone()
                } else {
                    Name {
                        text: format!("{}.{}", decl.name.text, k),
                        span: decl.name.span,
                    }
                };
                self.add_joint(&n, kind, [links[0], other], decl.actuated && k == 1, None);
                if k > 1 && self.joints.len() > first + k - 1 {
                    let j = self.joints.len() - 1;
                    self.relations.push(Relation {
                        kind: RelationKind::Coaxial,
                        a: DirectionItem::Joint(first),
                        b: DirectionItem::Joint(j),
                        span: None,
                    });
                }
            }
        }
    }

    /// Chains: joints in order, anonymous links between them unless labelled.
    fn chains(&mut self, ast: &MechanismAst) {
        for chain in &ast.chains {
            // A chain is a single open chain: no inner link twice, none equal to an end.
            let mut seen: Vec<&str> = vec![chain.start.text.as_str(), chain.end.text.as_str()];
            for label in chain.connectors.iter().filter_map(|c| c.label.as_ref()) {
                if seen.contains(&label.text.as_str()) {
                    self.errors.push(
                        Diagnostic::new(label.span, format!("link `{}` appears twice in one chain", label.text))
                            .label("a chain visits each link once")
                            .note("close a loop with a second chain that starts or ends at this link"),
                    );
                }
                seen.push(label.text.as_str());
            }
            let start = self.link(&chain.start);
            let end = self.link(&chain.end);
            let mut prev_link = start;
            let mut prev_joint: Option<usize> = None;
            for (i, cj) in chain.joints.iter().enumerate() {
                let Some(kind) = JointKind::from_name_prefix(&cj.name.text) else {
                    self.errors.push(
                        Diagnostic::new(cj.name.span, format!("unknown joint type in `{}`", cj.name.text))
                            .label("a joint's name starts with its type")
                            .note("joint types: R, P, H, C, U, S and Pa (parallelogram)"),
                    );
                    continue;
                };
                let next_link = if i + 1 == chain.joints.len() {
                    end
                } else {
                    let conn = &chain.connectors[i];
                    match &conn.label {
                        Some(label) => self.link(label),
                        None => self.anonymous_link(&cj.name.text, &chain.joints[i + 1].name.text),
                    }
                };
                // A U joint is two revolutes: the relation before it is its
                // first axis's (`U1.a`), the one after it its second's.
                let (this, last) = if kind == JointKind::U {
                    match self.add_universal(&cj.name, [prev_link, next_link], cj.actuated, chain.branch) {
                        Some([a, b]) => (Some(a), Some(b)),
                        None => (None, None),
                    }
                } else {
                    let before = self.joints.len();
                    self.add_joint(&cj.name, kind, [prev_link, next_link], cj.actuated, chain.branch);
                    let this = if self.joints.len() > before { Some(before) } else { None };
                    (this, this)
                };
                if let (Some(p), Some(t), Some(conn)) =
                    (prev_joint, this, i.checked_sub(1).map(|k| &chain.connectors[k]))
                {
                    if let Some((kind, span)) = conn.relation {
                        if let Some(sj) = [p, t].into_iter().find(|&x| !self.joints[x].kind.has_direction()) {
                            self.errors.push(
                                Diagnostic::new(
                                    span,
                                    format!(
                                        "joint `{}` is spherical and has no axis to relate",
                                        self.joints[sj].name
                                    ),
                                )
                                .label("write `-` next to an S joint"),
                            );
                            prev_joint = last;
                            prev_link = next_link;
                            continue;
                        }
                        self.relations.push(Relation {
                            kind,
                            a: DirectionItem::Joint(p),
                            b: DirectionItem::Joint(t),
                            span: Some(span),
                        });
                    }
                }
                prev_joint = last;
                prev_link = next_link;
            }
        }
    }

    /// The links' descriptions, where the links list gives them.
    fn link_descriptions(&mut self, ast: &MechanismAst) {
        for decl in &ast.links {
            let i = self.link(&decl.name);
            if decl.description.is_some() {
                self.links[i].description.clone_from(&decl.description);
            }
        }
    }

    /// Relation statements. A plane stands for its normal: `X ∥ ◇P` says X is
    /// perpendicular to P's normal, `X ⊥ ◇P` that it is parallel to it.
    fn relation_statements(&mut self, ast: &MechanismAst) {
        for stmt in &ast.relations {
            let items: Vec<Option<(DirectionItem, bool)>> = stmt.items.iter().map(|d| self.direction_ref(d)).collect();
            for (k, (kind, span)) in stmt.ops.iter().enumerate() {
                if let (Some((a, a_plane)), Some((c, c_plane))) = (items[k], items[k + 1]) {
                    let kind = match *kind {
                        RelationKind::Coaxial if a_plane || c_plane => {
                            self.errors.push(
                                Diagnostic::new(*span, "a plane cannot be coaxial with anything").label("not a line"),
                            );
                            continue;
                        }
                        RelationKind::Concurrent if a_plane || c_plane => {
                            self.errors.push(
                                Diagnostic::new(*span, "a plane cannot meet other axes at one point")
                                    .label("not a line"),
                            );
                            continue;
                        }
                        RelationKind::Parallel if a_plane != c_plane => RelationKind::Perpendicular,
                        RelationKind::Perpendicular if a_plane != c_plane => RelationKind::Parallel,
                        k => k,
                    };
                    self.relations.push(Relation {
                        kind,
                        a,
                        b: c,
                        span: Some(*span),
                    });
                }
            }
        }
    }

    /// Which frame axes the written relations name.
    fn frame_axes_related(&self) -> [bool; 3] {
        let mut frame_declared = [false; 3];
        for r in &self.relations {
            for item in [r.a, r.b] {
                if let DirectionItem::Frame(i) = item {
                    frame_declared[i] = true;
                }
            }
        }
        frame_declared
    }

    /// Implied relations: the frame is orthonormal, U axes are perpendicular,
    /// and a planar mechanism's rotations are about z and its slides lie in xy.
    fn implied_relations(&mut self, planar: bool) {
        let implied = |kind, a, b| Relation { kind, a, b, span: None };
        self.relations.push(implied(
            RelationKind::Perpendicular,
            DirectionItem::Frame(0),
            DirectionItem::Frame(1),
        ));
        self.relations.push(implied(
            RelationKind::Perpendicular,
            DirectionItem::Frame(1),
            DirectionItem::Frame(2),
        ));
        self.relations.push(implied(
            RelationKind::Perpendicular,
            DirectionItem::Frame(0),
            DirectionItem::Frame(2),
        ));
        let halves: Vec<usize> = self.universals.iter().flat_map(|u| u.halves).collect();
        if planar {
            for u in &self.universals {
                self.errors.push(
                    Diagnostic::new(u.span, format!("joint `{}` (U) cannot move in a plane", u.name))
                        .label("planar mechanisms have R, P and Pa joints only"),
                );
            }
        }
        for (j, joint) in self.joints.clone().iter().enumerate() {
            if halves.contains(&j) {
                continue;
            }
            if joint.kind == JointKind::U {
                self.relations.push(implied(
                    RelationKind::Perpendicular,
                    DirectionItem::Joint(j),
                    DirectionItem::USecond(j),
                ));
            }
            if planar {
                match joint.kind {
                    JointKind::R | JointKind::Pa => self.relations.push(implied(
                        RelationKind::Parallel,
                        DirectionItem::Joint(j),
                        DirectionItem::Frame(2),
                    )),
                    JointKind::P => self.relations.push(implied(
                        RelationKind::Perpendicular,
                        DirectionItem::Joint(j),
                        DirectionItem::Frame(2),
                    )),
                    _ => self.errors.push(
                        Diagnostic::new(
                            joint.span,
                            format!(
                                "joint `{}` ({}) cannot move in a plane",
                                joint.name,
                                joint.kind.symbol()
                            ),
                        )
                        .label("planar mechanisms have R, P and Pa joints only"),
                    ),
                }
            }
        }
    }

    /// Only joints with an axis line can meet at a point, and two parallel
    /// axes that meet are one line: the relation for that is `≡`.
    fn check_concurrent(&mut self) {
        let classes = DirectionClasses::new(&self.joints, &self.relations);
        for r in &self.relations {
            if r.kind != RelationKind::Concurrent {
                continue;
            }
            let span = r.span.unwrap_or_default();
            let (DirectionItem::Joint(a), DirectionItem::Joint(b)) = (r.a, r.b) else {
                self.errors.push(
                    Diagnostic::new(span, "only joint axes can meet at one point")
                        .label("a frame axis has no position"),
                );
                continue;
            };
            let mut lines = true;
            for j in [a, b] {
                let joint = &self.joints[j];
                if !joint.kind.has_axis_line() {
                    lines = false;
                    self.errors.push(
                        Diagnostic::new(
                            span,
                            format!(
                                "joint `{}` ({}) has no axis line to meet others at a point",
                                joint.name,
                                joint.kind.symbol()
                            ),
                        )
                        .label("concurrent axes must be of R, H, C or U joints"),
                    );
                }
            }
            if lines && classes.class_of(r.a) == classes.class_of(r.b) && !self.coaxial(a, b) {
                self.errors.push(
                    Diagnostic::new(
                        span,
                        format!(
                            "`{} ∧ {}`: the other relations make these axes parallel, and parallel axes meet only as one line",
                            self.joints[a].name, self.joints[b].name
                        ),
                    )
                    .label("write `≡` for one axis line"),
                );
            }
        }
    }

    /// Whether a written or implied relation makes joints `a` and `b` coaxial.
    fn coaxial(&self, a: usize, b: usize) -> bool {
        self.relations.iter().any(|r| {
            r.kind == RelationKind::Coaxial
                && ((r.a, r.b) == (DirectionItem::Joint(a), DirectionItem::Joint(b))
                    || (r.a, r.b) == (DirectionItem::Joint(b), DirectionItem::Joint(a)))
        })
    }

    /// Only two joints can be coaxial, and only joints with an axis line.
    fn check_coaxial(&mut self) {
        for r in &self.relations {
            if r.kind == RelationKind::Coaxial {
                if !matches!((r.a, r.b), (DirectionItem::Joint(_), DirectionItem::Joint(_))) {
                    if let Some(span) = r.span {
                        self.errors.push(
                            Diagnostic::new(span, "only two joints can be coaxial")
                                .label("a frame axis or plane has no position"),
                        );
                    }
                    continue;
                }
                for item in [r.a, r.b] {
                    if let DirectionItem::Joint(j) = item {
                        let joint = &self.joints[j];
                        if !joint.kind.has_axis_line() {
                            self.errors.push(
                                Diagnostic::new(
                                    r.span.unwrap_or(joint.span),
                                    format!(
                                        "joint `{}` ({}) has no axis line to share",
                                        joint.name,
                                        joint.kind.symbol()
                                    ),
                                )
                                .label("coaxial joints must be R, H, C or U"),
                            );
                        }
                    }
                }
            }
        }
    }

    /// The limit on joints and links, checked before the connectivity
    /// pass, which is quadratic in the links.
    fn check_size(&mut self, ast: &MechanismAst) {
        if self.joints.len() > MAX_JOINTS || self.links.len() > MAX_JOINTS {
            self.errors.push(
                Diagnostic::new(
                    ast.name.span,
                    format!(
                        "the mechanism has {} joints and {} links; the limit is {MAX_JOINTS} of each",
                        self.joints.len(),
                        self.links.len()
                    ),
                )
                .label("too large"),
            );
        }
    }

    /// Every link must hang in the mechanism: reached from the base, held by two joints.
    fn check_links_hang(&mut self, ast: &MechanismAst) {
        if self.errors.is_empty() {
            let all: Vec<usize> = (0..self.joints.len()).collect();
            for (i, link) in self.links.iter().enumerate().skip(1) {
                let degree = self.joints.iter().filter(|j| j.links.contains(&i)).count();
                let span = link.span.unwrap_or_default();
                if !connected(&self.joints, &all, 0, i) {
                    self.errors.push(
                        Diagnostic::new(span, format!("link `{}` is not connected to the base", link.name))
                            .label("unreachable link"),
                    );
                } else if degree < 2 {
                    let mut d = Diagnostic::new(span, format!("link `{}` hangs on a single joint", link.name))
                        .label("dangling link")
                        .note("every link of a parallel mechanism lies on a loop");
                    if let Some(s) = suggest(
                        &link.name,
                        self.links.iter().map(|l| l.name.as_str()).filter(|n| *n != link.name),
                    ) {
                        d = d.note(format!("did you mean `{s}`?"));
                    }
                    self.errors.push(d);
                }
            }
            if self.joints.is_empty() {
                self.errors
                    .push(Diagnostic::new(ast.name.span, "the mechanism has no joints").label("empty mechanism"));
            }
        }
    }

    /// The branches and the joints each holds.
    fn branches(&self, ast: &MechanismAst) -> Vec<Branch> {
        ast.branches
            .iter()
            .enumerate()
            .map(|(i, n)| Branch {
                name: n.text.clone(),
                joints: (0..self.joints.len())
                    .filter(|&j| self.joints[j].branch == Some(i))
                    .collect(),
                span: n.span,
            })
            .collect()
    }

    /// The platform: the named link, or the link called `platform`.
    fn platform(&mut self, ast: &MechanismAst) -> Option<usize> {
        let platform = match &ast.platform {
            Some(n) => match self.link_by_name.get(&n.text) {
                Some(&i) => Some(i),
                None => {
                    self.errors.push(
                        Diagnostic::new(n.span, format!("unknown link `{}`", n.text)).label("no joint touches it"),
                    );
                    None
                }
            },
            None => self.link_by_name.get("platform").copied(),
        };
        if platform == Some(0) {
            if let Some(n) = &ast.platform {
                self.errors
                    .push(Diagnostic::new(n.span, "the platform cannot be the base").label("the base"));
            }
        }
        platform
    }

    /// Branches run from the base to the platform.
    fn check_branches(&mut self, branches: &[Branch], platform: Option<usize>) {
        if !branches.is_empty() && platform.is_none() {
            self.errors.push(
                Diagnostic::new(branches[0].span, "branches need a platform")
                    .label("branch without a platform")
                    .note("name a link `platform`, or write `platform = LINK;`"),
            );
        }
        if let Some(p) = platform {
            for br in branches {
                if !connected(&self.joints, &br.joints, 0, p) {
                    self.errors.push(
                        Diagnostic::new(
                            br.span,
                            format!(
                                "branch `{}` never reaches the platform `{}`",
                                br.name, self.links[p].name
                            ),
                        )
                        .label("a branch must connect the base to the platform"),
                    );
                }
            }
        }
    }

    /// The base point's joint: on the platform, with an axis line.
    fn base_point(&mut self, ast: &MechanismAst, platform: Option<usize>) -> Option<usize> {
        ast.point
            .as_ref()
            .map(|(_, jn)| {
                // A U joint's centre: its half on the platform.
                let half = |u: &Universal| {
                    (u.name == jn.text).then(|| {
                        let on = |&h: &usize| platform.is_some_and(|p| self.joints[h].links.contains(&p));
                        u.halves.into_iter().find(on).unwrap_or(u.halves[1])
                    })
                };
                let j = self.joint_by_name.get(&jn.text).copied();
                (jn, j.or_else(|| self.universals.iter().find_map(half)))
            })
            .and_then(|(jn, j)| match j {
                Some(j) => {
                    let joint = &self.joints[j];
                    if platform.is_some_and(|p| !joint.links.contains(&p)) {
                        self.errors.push(
                            Diagnostic::new(jn.span, format!("joint `{}` does not touch the platform", jn.text))
                                .label("the base point must lie on a platform joint"),
                        );
                    } else if matches!(joint.kind, JointKind::P | JointKind::Pa) {
                        self.errors.push(
                            Diagnostic::new(
                                jn.span,
                                format!(
                                    "joint `{}` ({}) has no axis line for the base point",
                                    jn.text,
                                    joint.kind.symbol()
                                ),
                            )
                            .label("needs R, H, C, U or S"),
                        );
                    }
                    Some(j)
                }
                None => {
                    self.errors
                        .push(Diagnostic::new(jn.span, format!("unknown joint `{}`", jn.text)).label("not declared"));
                    None
                }
            })
    }
}

fn connected(joints: &[Joint], subset: &[usize], from: usize, to: usize) -> bool {
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

fn check_relations(joints: &[Joint], relations: &[Relation], errors: &mut Diagnostics) {
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

#[cfg(test)]
mod tests {
    /// The messages of every error the text produces, in order.
    fn check(source: &str, expected: &[&str]) {
        let messages: Vec<String> = match crate::topology::analysis::analyze_source(source) {
            Ok(_) => Vec::new(),
            Err(d) => d.0.into_iter().map(|e| e.message).collect(),
        };
        assert_eq!(messages, expected, "{source}");
    }

    const FOUR_BAR: &str = "base R1* ∥ R2 ∥ R3 ∥ R4 base;";

    #[test]
    fn only_axis_lines_meet_at_a_point() {
        let chain = "base R1* - R2 - P1 - R4 base;";
        check(
            "mechanism m { base R1* - R2 - R3 - R4 base; R1 ∧ R2 /\\ R3 ∧ R4; }",
            &[],
        );
        check(
            &format!("mechanism m {{ {chain} R1 ∧ P1; }}"),
            &["joint `P1` (P) has no axis line to meet others at a point"],
        );
        check(
            &format!("mechanism m {{ {chain} R1 ∧ x; }}"),
            &["only joint axes can meet at one point"],
        );
        check(
            &format!("mechanism m {{ {chain} R1 ∧ ◇xoy; }}"),
            &["a plane cannot meet other axes at one point"],
        );
        check(
            &format!("mechanism m {{ {chain} R1 ∥ R2; R1 ∧ R2; }}"),
            &["`R1 ∧ R2`: the other relations make these axes parallel, and parallel axes meet only as one line"],
        );
    }

    #[test]
    fn planar_mechanisms_have_r_p_and_pa_only() {
        check(
            "mechanism m { planar; base R1* ∥ R2 - S1 - R4 base; }",
            &["joint `S1` (S) cannot move in a plane"],
        );
    }

    #[test]
    fn coaxial_needs_an_axis_line() {
        check(
            &format!("mechanism m {{ planar; {FOUR_BAR} base P1 - R5 [k] - R6 base; R5 ≡ P1; }}"),
            &["joint `P1` (P) has no axis line to share"],
        );
    }

    #[test]
    fn spherical_joints_have_no_axis() {
        check(
            "mechanism m { base S1* - P1 - S2 base; S1 ∥ P1; }",
            &["joint `S1` is spherical and has no axis to relate"],
        );
    }

    #[test]
    fn branches_need_a_platform() {
        check(
            "mechanism m { planar; branch A { base R1* ∥ R2 ∥ R3 ∥ R4 base; } }",
            &["branches need a platform"],
        );
    }

    #[test]
    fn platform_cannot_be_the_base() {
        check(
            &format!("mechanism m {{ planar; {FOUR_BAR} platform = base; }}"),
            &["the platform cannot be the base"],
        );
    }

    #[test]
    fn base_point_must_be_on_a_platform_joint() {
        check(
            "mechanism m { planar; base R1* ∥ R2 ∥ R3 platform; base R4 ∥ R5 ∥ R6 platform; point o on R1; }",
            &["joint `R1` does not touch the platform"],
        );
        check(
            "mechanism m { planar; base R1* ∥ R2 ∥ R3 platform; base R4 ∥ R5 ∥ R6 platform; point o on R9; }",
            &["unknown joint `R9`"],
        );
    }

    #[test]
    fn explicit_joint_declarations() {
        check("mechanism m { joint A = Q(base, 1); }", &["unknown joint type `Q`"]);
        check(
            "mechanism m { planar; joint A = R(1, 1)*; joint B = R(base, 1); joint C = R(1, base); }",
            &["joint `A` connects link `1` to itself"],
        );
        check(
            "mechanism m { joint G = P(1, 2, 3); }",
            &["a compound hinge needs an axis line; `P` has none"],
        );
    }

    #[test]
    fn frame_axis_names_are_reserved() {
        check(
            "mechanism m { planar; base R1* [x] ∥ R2 ∥ R3 ∥ R4 base; }",
            &["`x` names a frame axis and cannot name a link"],
        );
    }

    #[test]
    fn every_link_is_reached_from_the_base() {
        check(
            &format!("mechanism m {{ planar; {FOUR_BAR} joint A = R(7, 8); joint B = R(8, 7); }}"),
            &[
                "link `7` is not connected to the base",
                "link `8` is not connected to the base",
            ],
        );
    }

    #[test]
    fn over_constrained_perpendicularity() {
        check(
            &format!("mechanism m {{ {FOUR_BAR} R1 ⊥ x; R1 ⊥ y; R1 ⊥ z; }}"),
            &["a direction is required to be perpendicular to three independent directions"],
        );
    }

    #[test]
    fn actuators_must_match_the_dof() {
        check(
            "mechanism m { planar; base R1 ∥ R2 ∥ R3 ∥ R4 base; }",
            &["the mechanism has 1 DOF but 0 actuated joints"],
        );
        check(
            "mechanism m { planar; base R1* ∥ R2* ∥ R3 ∥ R4 base; }",
            &["the mechanism has 1 DOF but 2 actuated joints"],
        );
    }

    #[test]
    fn actuators_that_cannot_drive_the_mechanism() {
        // F = 2 = I, but both inputs sit in the four-bar loop R1-R4 of a Watt
        // six-bar: that loop is over-driven and the other loop moves freely.
        check(
            "mechanism m { planar; base R1* ∥ R2* [c] ∥ R3 ∥ R4 base; c R5 ∥ R6 ∥ R7 ∥ R8 base; }",
            &["with its actuated joints locked the mechanism still moves (1 DOF): the actuators cannot drive it"],
        );
    }

    #[test]
    fn planes_stand_for_their_normals() {
        // R1 ⊥ ◇xoz makes R1 ∥ y, which contradicts R1 ⊥ y.
        check(
            &format!("mechanism m {{ {FOUR_BAR} R1 ⊥ ◇xoz; R1 ⊥ y; }}"),
            &["`R1 ⊥ y` contradicts the other relations, which make them parallel"],
        );
        check(
            &format!("mechanism m {{ planar; {FOUR_BAR} P9 ∥ ◇xoy; }}"),
            &["unknown joint `P9`"],
        );
        check(
            &format!("mechanism m {{ planar; {FOUR_BAR} R3 ≡ ◇xoy; }}"),
            &["a plane cannot be coaxial with anything"],
        );
        check(
            &format!("mechanism m {{ planar; {FOUR_BAR} R3 ⊥ ◇xyz; }}"),
            &["unknown frame plane `◇xyz`"],
        );
        check(
            &format!("mechanism m {{ planar; {FOUR_BAR} R3 ∥ ◇(R1, R2); }}"),
            &["the plane ◇(R1,R2) is not defined: its axes are parallel"],
        );
        check("mechanism m { base R1* ∥ R2 ∥ R3 ∥ R4 base; x ∥ ◇(R1, y); }", &[]);
        check(
            &format!("mechanism m {{ planar; {FOUR_BAR} R1 ∥ R9; R2 ∥ R9; }}"),
            &["unknown joint `R9`"],
        );
    }

    #[test]
    fn a_chain_visits_each_link_once() {
        check(
            "mechanism m { planar; base R1* [a] ∥ R2 [b] ∥ R3 [a] ∥ R4 base; }",
            &["link `a` appears twice in one chain"],
        );
        // Both are true: the label repeats the start, so R1 would join the base to itself.
        check(
            "mechanism m { planar; base R1* [base] ∥ R2 ∥ R3 base; }",
            &[
                "link `base` appears twice in one chain",
                "joint `R1` connects link `base` to itself",
            ],
        );
    }

    #[test]
    fn capabilities_must_be_known() {
        check(
            &format!("mechanism m {{ capabilities fk, ik; planar; {FOUR_BAR} }}"),
            &[],
        );
        // What these need of the file is checked where code is generated
        // (codegen's `stiffness_needs_units_limbs_and_ik`).
        check(
            &format!("mechanism m {{ capabilities fk, dynamics, stiffness; planar; {FOUR_BAR} }}"),
            &[],
        );
        check(
            &format!("mechanism m {{ capabilities fk, workspace; planar; {FOUR_BAR} }}"),
            &[],
        );
        check(
            &format!("mechanism m {{ capabilities fkk; planar; {FOUR_BAR} }}"),
            &["unknown capability `fkk`"],
        );
    }

    #[test]
    fn valid_descriptions_pass() {
        check(&format!("mechanism m {{ planar; {FOUR_BAR} }}"), &[]);
        check("mechanism m { planar; base R1* || R2 _|_ P1 - R3 base; x || P1; }", &[]);
    }

    /// A 6-UPS leg set, with `extra` written after the first leg.
    fn ups(first_leg: &str, extra: &str) -> String {
        let legs: String = (2..=6)
            .map(|i| format!("branch L{i} {{ base U{i} - P{i}* - S{i} platform; }} "))
            .collect();
        format!("mechanism m {{ branch L1 {{ {first_leg} }} {legs} {extra} }}")
    }

    #[test]
    fn u_joints_name_their_two_axes() {
        check(&ups("base U1 - P1* - S1 platform;", "U1.a ⊥ x; U1.b ∥ P2;"), &[]);
        check(
            &ups("base U1 - P1* - S1 platform;", "U1 ∥ x;"),
            &["U joint `U1` has two axes"],
        );
        check(
            &ups("base U1 - P1* - S1 platform;", "U1.c ∥ x;"),
            &["unknown joint `U1.c`"],
        );
        // The implied U1.a ⊥ U1.b, contradicted.
        check(
            &ups("base U1 - P1* - S1 platform;", "U1.a ∥ y; U1.b ∥ y;"),
            &["this relation makes `U1.a` parallel to `U1.b`, which must be perpendicular (implied by the frame, a U joint or `planar`)"],
        );
    }

    #[test]
    fn u_joints_are_passive_and_spatial() {
        check(
            &ups("base U1* - P1* - S1 platform;", ""),
            &["U joint `U1` cannot be an input"],
        );
        check(
            "mechanism m { planar; base R1* ∥ R2 - U1 - R3 base; }",
            &["joint `U1` (U) cannot move in a plane"],
        );
        check(
            &ups("base U1 - P1* - S1 platform;", "joint U1 = U(base, platform);"),
            // Declared joints come first: the chain's U1 is the second, and left out.
            &[
                "joint `U1` is declared twice",
                "branch `L1` never reaches the platform `platform`",
            ],
        );
    }

    #[test]
    fn a_chain_relates_the_u_axis_on_the_shared_link() {
        // base R1 [k] ∥ U1 [l] ⊥ P1: R1 and U1.a sit on k, U1.b and P1 on l.
        let ast = crate::parse("mechanism m { base R1* [k] ∥ U1 [l] ⊥ P1 [n] - S1 base; }").unwrap();
        let m = super::build(&ast).unwrap();
        let j = |n: &str| super::DirectionItem::Joint(m.joint_index(n).unwrap());
        let has = |kind, a, b| m.relations.iter().any(|r| r.kind == kind && r.a == a && r.b == b);
        use crate::syntax::ast::RelationKind::{Parallel, Perpendicular};
        assert!(has(Parallel, j("R1"), j("U1.a")));
        assert!(has(Perpendicular, j("U1.b"), j("P1")));
        assert!(has(Perpendicular, j("U1.a"), j("U1.b")));
        let u = m.universal("U1").unwrap();
        let names = |l: usize| m.links[l].name.as_str();
        assert_eq!(
            u.halves.map(|h| m.joints[h].links.map(names)),
            [["k", "U1.cross"], ["U1.cross", "l"]]
        );
        assert_eq!(
            m.joint_on("U1", m.links.iter().position(|x| x.name == "l").unwrap()),
            m.joint_index("U1.b")
        );
    }

    #[test]
    fn parallel_sliders_in_series_leave_the_crank_locked() {
        // R1 ⊥ P1 ∥ P2 − R2: the links beside P1 ∥ P2 only translate along x
        // relative to each other, so both turn by the same angle about two
        // distinct axes, which closes the loop only at zero turn. The one
        // DOF (Σf 4 − ξ 3) is P1 and P2 sliding against each other; R1 never moves.
        check(
            "mechanism m { planar; base R1* _|_ P1 || P2 - R2 base; x || P1; }",
            &["with its actuated joints locked the mechanism still moves (1 DOF): the actuators cannot drive it"],
        );
    }
}
