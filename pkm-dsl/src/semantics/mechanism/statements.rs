//! The steps of [`build`](super::build), each one named part of the
//! description: capabilities, declared joints, chains, relations written and
//! implied, and the checks that every link hangs in the mechanism and every
//! branch reaches the platform.

use super::builder::*;
use super::relations::*;
use super::*;
use crate::diagnostics::{Diagnostic, Span};
use crate::syntax::ast::{MechanismAst, Name, RelationKind};

/// The steps of [`build`], each one named part of the description.
impl Builder {
    /// The requested capabilities; an unknown one is an error. What each
    /// needs of the rest of the file is checked where code is generated
    /// ([`crate::check_capabilities`]).
    pub(super) fn capabilities(&mut self, ast: &MechanismAst) -> Vec<(Capability, Span)> {
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
    pub(super) fn declared_joints(&mut self, ast: &MechanismAst) {
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
    pub(super) fn chains(&mut self, ast: &MechanismAst) {
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
    pub(super) fn link_descriptions(&mut self, ast: &MechanismAst) {
        for decl in &ast.links {
            let i = self.link(&decl.name);
            if decl.description.is_some() {
                self.links[i].description.clone_from(&decl.description);
            }
        }
    }

    /// Relation statements. A plane stands for its normal: `X ∥ ◇P` says X is
    /// perpendicular to P's normal, `X ⊥ ◇P` that it is parallel to it.
    pub(super) fn relation_statements(&mut self, ast: &MechanismAst) {
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
    pub(super) fn frame_axes_related(&self) -> [bool; 3] {
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
    pub(super) fn implied_relations(&mut self, planar: bool) {
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
    pub(super) fn check_concurrent(&mut self) {
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
    pub(super) fn coaxial(&self, a: usize, b: usize) -> bool {
        self.relations.iter().any(|r| {
            r.kind == RelationKind::Coaxial
                && ((r.a, r.b) == (DirectionItem::Joint(a), DirectionItem::Joint(b))
                    || (r.a, r.b) == (DirectionItem::Joint(b), DirectionItem::Joint(a)))
        })
    }

    /// Only two joints can be coaxial, and only joints with an axis line.
    pub(super) fn check_coaxial(&mut self) {
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
    pub(super) fn check_size(&mut self, ast: &MechanismAst) {
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
    pub(super) fn check_links_hang(&mut self, ast: &MechanismAst) {
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
    pub(super) fn branches(&self, ast: &MechanismAst) -> Vec<Branch> {
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
    pub(super) fn platform(&mut self, ast: &MechanismAst) -> Option<usize> {
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
    pub(super) fn check_branches(&mut self, branches: &[Branch], platform: Option<usize>) {
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
    pub(super) fn base_point(&mut self, ast: &MechanismAst, platform: Option<usize>) -> Option<usize> {
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
