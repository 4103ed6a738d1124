//! Dimensions and geometry: parameters with nominal values, and every joint
//! placed in the frames of its two links (see `docs/solver-design.md`).
//! Checked here: names, tuple sizes, that each joint is placed on both its
//! links in the form its type needs, and that the declared ∥ / ⊥ / ≡
//! relations hold between axes placed on a common link.

use crate::syntax::ast::{AxisRef, LinkGeometry, MechanismAst, Place, Placement, RelationKind, Tuple};
use crate::diagnostics::{Diagnostic, Diagnostics, Span};
use crate::syntax::expr::{Definition, Expr};
use crate::semantics::mechanism::{suggest, DirectionItem, JointKind, Mechanism};
use nalgebra::Vector3;
use std::collections::HashMap;

/// A dimension parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    /// Its name (a field of the generated parameter struct).
    pub name: String,
    /// Where its name is written.
    pub span: Span,
    /// Its defining expression.
    pub expr: Expr,
    /// Its nominal value.
    pub value: f64,
}

/// A point or direction as three expressions (z = 0 in planar mechanisms).
pub type Vec3 = [Expr; 3];

/// Where a joint sits on one of its links, in that link's frame.
#[derive(Debug, Clone, PartialEq)]
pub enum JointPlace {
    /// A point, with the joint's axis through it (rotational joints), if any.
    Point(Vec3, Option<Vec3>),
    /// A line: the guide of a prismatic joint.
    Line(Vec3, Vec3),
    /// A parallelogram's hinge point and axis, and its arm (see
    /// `pkm_runtime::model::Place::Arm`).
    Arm(Vec3, Vec3, Vec3),
}

impl JointPlace {
    /// The runtime's place, each coordinate triple evaluated by `eval` (to
    /// numbers for the model, to symbols for the code generator).
    pub fn place<T>(&self, eval: impl Fn(&Vec3) -> [T; 3]) -> pkm_runtime::model::Place<T> {
        use pkm_runtime::model::Place as P;
        match self {
            JointPlace::Point(at, Some(axis)) => P::Axis {
                at: eval(at),
                axis: eval(axis),
            },
            JointPlace::Point(at, None) => P::Point { at: eval(at) },
            JointPlace::Line(at, along) => P::Line {
                through: eval(at),
                along: eval(along),
            },
            JointPlace::Arm(at, axis, arm) => P::Arm {
                at: eval(at),
                axis: eval(axis),
                arm: eval(arm),
            },
        }
    }

    /// The place's point.
    pub fn at(&self) -> &Vec3 {
        match self {
            JointPlace::Point(at, _) | JointPlace::Line(at, _) | JointPlace::Arm(at, _, _) => at,
        }
    }
}

/// A named point fixed on a link.
#[derive(Debug, Clone, PartialEq)]
pub struct NamedPoint {
    /// Its name.
    pub name: String,
    /// The link it belongs to.
    pub link: usize,
    /// Its coordinates in the link's frame.
    pub at: Vec3,
}

/// The geometry of a mechanism.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Geometry {
    /// Parameters in declaration order.
    pub parameters: Vec<Parameter>,
    /// `places[j][s]`: joint j on its link `links[s]`; all present when `complete`.
    pub places: Vec<[Option<JointPlace>; 2]>,
    /// Named points.
    pub points: Vec<NamedPoint>,
    /// Whether a `geometry` block was written (then every joint is placed).
    pub complete: bool,
    /// What the inverse solution is given, in order.
    pub outputs: Vec<Output>,
}

/// One output declaration, resolved.
#[derive(Debug, Clone, PartialEq)]
pub struct Output {
    /// The names of its values.
    pub names: Vec<String>,
    /// What it measures.
    pub kind: OutputKind,
}

/// What an output measures.
#[derive(Debug, Clone, PartialEq)]
pub enum OutputKind {
    /// The pose of link `link` at one of its points: planar (x, y, angle),
    /// or spatial (x, y, z) with the angle about `about` if given (the link's
    /// orientation is that rotation of the base's frame).
    Pose {
        /// The link.
        link: usize,
        /// The point: a named point of the link, or a joint placed on it.
        point: pkm_runtime::solution::PointRef,
        /// Spatial: the world axis the link turns about, if it turns.
        about: Option<Box<Vec3>>,
    },
    /// A point of link `link` alone (x, y, and z if spatial); the link's
    /// orientation is not given.
    Point {
        /// The link.
        link: usize,
        /// A named point of the link, or a joint placed on it.
        point: pkm_runtime::solution::PointRef,
    },
    /// A spatial pose of link `link` at one of its points, in part: the
    /// `parts` of x, y, z, rx, ry, rz (`R = R_z(rz)·R_y(ry)·R_x(rx)`) given,
    /// in that order; the others are the mechanism's (parasitic motion).
    Parts {
        /// The link.
        link: usize,
        /// The point: a named point of the link, or a joint placed on it.
        point: pkm_runtime::solution::PointRef,
        /// Which values are given.
        parts: pkm_runtime::steps::place::PoseParts,
    },
    /// The value of joint `joint`.
    Joint(usize),
}

impl Geometry {
    /// The link and point of the first output that places a point (a
    /// pose, a point or pose parts): the platform and the reference point
    /// the stiffness is given about.
    pub fn first_point_output(&self) -> Option<(usize, pkm_runtime::solution::PointRef)> {
        self.outputs.iter().find_map(|o| match &o.kind {
            OutputKind::Pose { link, point, .. }
            | OutputKind::Point { link, point }
            | OutputKind::Parts { link, point, .. } => Some((*link, *point)),
            OutputKind::Joint(_) => None,
        })
    }

    /// Nominal parameter values by name.
    pub fn nominal(&self) -> HashMap<String, f64> {
        self.parameters.iter().map(|p| (p.name.clone(), p.value)).collect()
    }
}

const RUST_KEYWORDS: [&str; 38] = [
    "as", "async", "await", "break", "const", "continue", "crate", "dyn", "else", "enum", "extern", "false", "fn",
    "for", "if", "impl", "in", "let", "loop", "match", "mod", "move", "mut", "pub", "ref", "return", "self", "Self",
    "static", "struct", "super", "trait", "true", "type", "unsafe", "use", "where", "while",
];

/// A point or direction at the given parameter values.
pub fn eval_vec3(v: &Vec3, values: &HashMap<String, f64>) -> [f64; 3] {
    [v[0].eval(values), v[1].eval(values), v[2].eval(values)]
}

fn eval3(v: &Vec3, values: &HashMap<String, f64>) -> Vector3<f64> {
    Vector3::from(eval_vec3(v, values))
}

/// Builds and checks the geometry of `mech` from its syntax tree: the
/// parameters' values, every link's placements (joints and named points),
/// the checks of the joints' forms and of the relations against the
/// numbers, and the outputs.
pub fn build(ast: &MechanismAst, mech: &Mechanism) -> Result<Geometry, Diagnostics> {
    let mut errors: Vec<Diagnostic> = Vec::new();
    let (parameters, values) = parameters(ast, &mut errors);
    let coordinates = Coordinates { mech, values: &values };
    let mut placed = Placements {
        places: vec![[None, None]; mech.joints.len()],
        spans: vec![[None, None]; mech.joints.len()],
        points: Vec::new(),
    };
    for lg in &ast.geometry {
        placed.link_geometry(lg, mech, &coordinates, &mut errors);
    }
    let Placements {
        mut places,
        spans: place_span,
        points,
    } = placed;

    let complete = !ast.geometry.is_empty();
    if complete {
        place_crosses(mech, &mut places);
    }
    if complete && errors.is_empty() {
        check_forms(mech, &mut places, &place_span, &values, &mut errors);
        if errors.is_empty() {
            check_relations(mech, &places, &values, &mut errors);
            check_concurrent(mech, &places, &values, &mut errors);
        }
    }
    let abouts: Vec<Option<Vec3>> = ast
        .outputs
        .iter()
        .map(|o| match &o.what {
            crate::syntax::ast::OutputWhat::Pose { about: Some(a), .. } => coordinates.axis(a, &mut errors),
            _ => None,
        })
        .collect();
    let outputs = resolve_outputs(ast, mech, &places, &points, &abouts, complete, &mut errors);
    if errors.is_empty() {
        Ok(Geometry {
            parameters,
            places,
            points,
            complete,
            outputs,
        })
    } else {
        Err(Diagnostics(errors))
    }
}

/// Each U joint's cross link holds its two axes through its origin, the
/// first (`NAME.a`) along z and the second (`NAME.b`) along x: the cross's
/// frame is the first axis's joint frame when `NAME.a` = 0. With the
/// model's conventions (`pkm_runtime::model`), `NAME.b`'s frame on the
/// cross then has its x axis along the cross's y and its y axis along the
/// first axis, so at `NAME.b` = 0 the second link's frame of `NAME.b` has
/// its y axis along the first axis.
fn place_crosses(mech: &Mechanism, places: &mut [[Option<JointPlace>; 2]]) {
    let c = |v: [f64; 3]| v.map(Expr::Num);
    for u in &mech.universals {
        for (h, axis) in u.halves.into_iter().zip([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]) {
            let side = usize::from(mech.joints[h].links[1] == u.cross);
            places[h][side] = Some(JointPlace::Point(c([0.0; 3]), Some(c(axis))));
        }
    }
}

/// The parameters, each defined once and not a reserved word, with their
/// values in dependency order, whatever the order of definition.
fn parameters(ast: &MechanismAst, errors: &mut Vec<Diagnostic>) -> (Vec<Parameter>, HashMap<String, f64>) {
    let mut first_span: HashMap<String, Span> = HashMap::new();
    for (name, _) in &ast.parameters {
        first_span.entry(name.text.clone()).or_insert(name.span);
    }
    for (name, e) in &ast.parameters {
        e.check(&|n: &str| first_span.contains_key(n), errors);
        if RUST_KEYWORDS.contains(&name.text.as_str()) || name.text == "pi" {
            errors.push(
                Diagnostic::new(name.span, format!("`{}` cannot name a parameter", name.text)).label("reserved word"),
            );
        } else if first_span[&name.text] != name.span {
            errors.push(
                Diagnostic::new(name.span, format!("parameter `{}` is defined twice", name.text))
                    .label("second definition")
                    .also(first_span[&name.text], "first defined"),
            );
        }
    }
    // Values in dependency order, whatever the order of definition.
    let definitions: Vec<Definition> = ast
        .parameters
        .iter()
        .map(|(name, expr)| Definition {
            name: &name.text,
            span: name.span,
            expr,
        })
        .collect();
    let (values, value_errors) = crate::syntax::expr::resolve(&definitions, &HashMap::new());
    errors.extend(value_errors);
    let parameters: Vec<Parameter> = ast
        .parameters
        .iter()
        .map(|(name, e)| Parameter {
            name: name.text.clone(),
            span: name.span,
            expr: e.clone(),
            value: values.get(&name.text).copied().unwrap_or(f64::NAN),
        })
        .collect();
    (parameters, values)
}

/// Coordinates written in a geometry block, as expressions of the parameters.
struct Coordinates<'a> {
    mech: &'a Mechanism,
    values: &'a HashMap<String, f64>,
}

impl Coordinates<'_> {
    /// A point `(x, y)` or `(x, y, z)`: as many coordinates as the
    /// mechanism has dimensions, each an expression of known parameters.
    fn point(&self, t: &Tuple, errors: &mut Vec<Diagnostic>) -> Option<Vec3> {
        let (mech, values) = (self.mech, self.values);
        let dims = if mech.planar { 2 } else { 3 };
        let zero = Expr::Num(0.0);
        if t.items.len() != dims {
            errors.push(
                Diagnostic::new(t.span, format!("expected {dims} coordinates, found {}", t.items.len())).label(
                    if mech.planar {
                        "a planar mechanism takes (x, y)"
                    } else {
                        "takes (x, y, z)"
                    },
                ),
            );
            return None;
        }
        let known = |n: &str| values.contains_key(n);
        for e in &t.items {
            e.check(&known, errors);
        }
        let mut it = t.items.iter().cloned();
        Some([it.next()?, it.next()?, it.next().unwrap_or_else(|| zero.clone())])
    }

    /// A direction: a vector `(…)` or a frame axis (`z` alone in a planar mechanism).
    fn axis(&self, a: &AxisRef, errors: &mut Vec<Diagnostic>) -> Option<Vec3> {
        let mech = self.mech;
        let zero = Expr::Num(0.0);
        match a {
            AxisRef::Vector(t) => self.point(t, errors),
            AxisRef::Frame(n) => {
                let k = ["x", "y", "z"].iter().position(|x| *x == n.text);
                match k {
                    Some(2) if mech.planar => Some([zero.clone(), zero.clone(), Expr::Num(1.0)]),
                    Some(k) if !mech.planar || k < 2 => {
                        let mut v = [zero.clone(), zero.clone(), zero.clone()];
                        v[k] = Expr::Num(1.0);
                        Some(v)
                    }
                    _ => {
                        errors.push(
                            Diagnostic::new(n.span, format!("unknown axis `{}`", n.text))
                                .label("expected x, y, z or (…)"),
                        );
                        None
                    }
                }
            }
        }
    }
}

/// The joints' places on their two links (with where each was written)
/// and the named points, as the geometry blocks give them.
struct Placements {
    places: Vec<[Option<JointPlace>; 2]>,
    spans: Vec<[Option<Span>; 2]>,
    points: Vec<NamedPoint>,
}

impl Placements {
    /// One link's block: its named points and its joints' places.
    fn link_geometry(
        &mut self,
        lg: &LinkGeometry,
        mech: &Mechanism,
        coordinates: &Coordinates,
        errors: &mut Vec<Diagnostic>,
    ) {
        let Some(link) = mech
            .links
            .iter()
            .position(|l| l.name == lg.link.text || (lg.link.text == "frame" && l.name == "base"))
        else {
            let mut d =
                Diagnostic::new(lg.link.span, format!("unknown link `{}`", lg.link.text)).label("no joint touches it");
            if let Some(s) = suggest(&lg.link.text, mech.links.iter().map(|l| l.name.as_str())) {
                d = d.note(format!("did you mean `{s}`?"));
            }
            errors.push(d);
            return;
        };
        for p in &lg.placements {
            if p.extra_point {
                self.named_point(p, link, mech, coordinates, errors);
            } else {
                self.joint_placement(p, lg, link, mech, coordinates, errors);
            }
        }
    }

    /// `point NAME = (…);`: a named point of the link.
    fn named_point(
        &mut self,
        p: &Placement,
        link: usize,
        mech: &Mechanism,
        coordinates: &Coordinates,
        errors: &mut Vec<Diagnostic>,
    ) {
        if mech.joint_index(&p.name.text).is_some() || self.points.iter().any(|q| q.name == p.name.text) {
            errors.push(
                Diagnostic::new(p.name.span, format!("`{}` is already a joint or a point", p.name.text))
                    .label("name taken"),
            );
            return;
        }
        match &p.place {
            Place::Point(t, None) => {
                if let Some(at) = coordinates.point(t, errors) {
                    self.points.push(NamedPoint {
                        name: p.name.text.clone(),
                        link,
                        at,
                    });
                }
            }
            _ => errors.push(Diagnostic::new(p.span, "a named point is a plain point `(…)`").label("no axis or line")),
        }
    }

    /// A joint's place on the link. A compound hinge `G` is the joints G,
    /// G.2, …: the name places every one of them that touches this link.
    fn joint_placement(
        &mut self,
        p: &Placement,
        lg: &LinkGeometry,
        link: usize,
        mech: &Mechanism,
        coordinates: &Coordinates,
        errors: &mut Vec<Diagnostic>,
    ) {
        let group: Vec<usize> = (0..mech.joints.len())
            .filter(|&j| {
                let n = &mech.joints[j].name;
                n == &p.name.text || n.strip_prefix(p.name.text.as_str()).is_some_and(|r| r.starts_with('.'))
            })
            .collect();
        if group.is_empty() {
            let mut d = Diagnostic::new(p.name.span, format!("unknown joint `{}`", p.name.text))
                .label("not declared")
                .note("write `point NAME = (…);` for a named point of the link");
            if let Some(s) = suggest(&p.name.text, mech.joints.iter().map(|j| j.name.as_str())) {
                d = d.note(format!("did you mean `{s}`?"));
            }
            errors.push(d);
            return;
        }
        let touching: Vec<usize> = group
            .iter()
            .copied()
            .filter(|&j| mech.joints[j].links.contains(&link))
            .collect();
        if touching.is_empty() {
            let joint = &mech.joints[group[0]];
            errors.push(
                Diagnostic::new(
                    p.name.span,
                    format!("joint `{}` does not touch link `{}`", p.name.text, lg.link.text),
                )
                .label("placed on the wrong link")
                .note(format!(
                    "it connects `{}` and `{}`",
                    mech.links[joint.links[0]].name, mech.links[joint.links[1]].name
                )),
            );
            return;
        }
        for j in touching {
            let joint = &mech.joints[j];
            let side = joint.links.iter().position(|&l| l == link).expect("touching");
            if let Some(first) = self.spans[j][side] {
                errors.push(
                    Diagnostic::new(
                        p.name.span,
                        format!("joint `{}` is placed twice on link `{}`", joint.name, lg.link.text),
                    )
                    .label("second placement")
                    .also(first, "first placed"),
                );
                continue;
            }
            let resolved = match &p.place {
                Place::Point(t, a) => {
                    let at = coordinates.point(t, errors);
                    let axis = match a {
                        Some(a) => coordinates.axis(a, errors),
                        None => None,
                    };
                    at.map(|at| JointPlace::Point(at, axis))
                }
                Place::Line(t, a) => match (coordinates.point(t, errors), coordinates.axis(a, errors)) {
                    (Some(at), Some(d)) => Some(JointPlace::Line(at, d)),
                    _ => None,
                },
                Place::Arm(t, a, arm) => {
                    match (
                        coordinates.point(t, errors),
                        coordinates.axis(a, errors),
                        coordinates.point(arm, errors),
                    ) {
                        (Some(at), Some(d), Some(arm)) => Some(JointPlace::Arm(at, d, arm)),
                        _ => None,
                    }
                }
            };
            self.spans[j][side] = Some(p.span);
            self.places[j][side] = resolved;
        }
    }
}

fn resolve_outputs(
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
fn pose_parts(
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

/// Each joint type needs its own form of placement on each side.
fn check_forms(
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
fn axis_on(
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
fn check_relations(
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
fn check_concurrent(
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
fn length(x: f64) -> String {
    if x >= 1e-3 {
        format!("{x:.3}")
    } else {
        format!("{x:.3e}")
    }
}

#[cfg(test)]
mod tests {
    fn check(source: &str, expected: &[&str]) {
        let result = crate::parse(source).map_err(crate::Diagnostics::from).and_then(|ast| {
            let m = crate::semantics::mechanism::build(&ast)?;
            super::build(&ast, &m)
        });
        let messages: Vec<String> = match result {
            Ok(_) => Vec::new(),
            Err(d) => d.0.into_iter().map(|e| e.message).collect(),
        };
        assert_eq!(messages, expected, "{source}");
    }

    const FOUR_BAR: &str = "planar; base R1* [crank] ∥ R2 [coupler] ∥ R3 [rocker] ∥ R4 base;";
    const PLACED: &str = "base { R1 = (0, 0); R4 = (l4, 0); } crank { R1 = (0, 0); R2 = (l1, 0); }
        coupler { R2 = (0, 0); R3 = (l2, 0); } rocker { R3 = (0, 0); R4 = (l3, 0); }";

    /// A U joint between the base and a link held by a second chain.
    fn universal(outputs: &str) -> String {
        format!(
            "mechanism m {{ base U1 [k] - S1 base; base R1* [j] - S2 k; parameters {{ l = 1; }}
             geometry {{ base {{ U1 = (0, 0, 0) along z; S1 = (0, 0, l); R1 = (l, 0, 0) along z; }}
                         k {{ U1 = (0, 0, 0) along x; S1 = (l, 0, 0); S2 = (0, l, 0); }}
                         j {{ R1 = (0, 0, 0) along z; S2 = (l, 0, 0); }} }}
             outputs {{ {outputs} }} }}"
        )
    }

    #[test]
    fn u_joints_are_placed_and_read_like_revolutes() {
        check(&universal("t = joint U1.b;"), &[]);
        check(&universal("x, y, z = point U1 of k;"), &[]);
        check(&universal("t = joint U1;"), &["U joint `U1` has two values"]);
        check(
            &universal("t = joint U1.b;").replace("U1 = (0, 0, 0) along x;", "U1 = (0, 0, 0);"),
            &["a U joint needs its axis: `(…) along x`"],
        );
    }

    #[test]
    fn a_placed_four_bar() {
        check(
            &format!("mechanism m {{ {FOUR_BAR} parameters {{ l1 = 1; l2 = 3; l3 = 2; l4 = 2.5; }} geometry {{ {PLACED} }} }}"),
            &[],
        );
    }

    #[test]
    fn parameter_errors() {
        check(
            &format!("mechanism m {{ {FOUR_BAR} parameters {{ a = b + 1; }} }}"),
            &["unknown parameter `b`"],
        );
        check(
            &format!("mechanism m {{ {FOUR_BAR} parameters {{ a = 1; a = 2; }} }}"),
            &["parameter `a` is defined twice"],
        );
        check(
            &format!("mechanism m {{ {FOUR_BAR} parameters {{ type = 1; }} }}"),
            &["`type` cannot name a parameter"],
        );
        check(
            &format!("mechanism m {{ {FOUR_BAR} parameters {{ a = 1 / 0; }} }}"),
            &["parameter `a` = 1 / 0 is infinite: division by zero"],
        );
        check(
            &format!("mechanism m {{ {FOUR_BAR} parameters {{ a = sqrt(1, 2); b = foo(1); }} }}"),
            &["`sqrt` takes 1 argument", "unknown function `foo`"],
        );
    }

    /// `pose (…) of`: the parts' names, order and count, spatial only, without `about`.
    #[test]
    fn pose_parts_errors() {
        let spatial = "base R1* [crank] ∥ R2 [coupler] ∥ R3 [rocker] ∥ R4 base; parameters { l = 1; }
            geometry { base { R1 = (0, 0, 0) along z; R4 = (l, 0, 0) along z; } crank { R1 = (0, 0, 0) along z; R2 = (l, 0, 0) along z; }
            coupler { R2 = (0, 0, 0) along z; R3 = (l, 0, 0) along z; } rocker { R3 = (0, 0, 0) along z; R4 = (l, 0, 0) along z; } }";
        let with = |outputs: &str| format!("mechanism m {{ {spatial} outputs {{ {outputs} }} }}");
        check(&with("z, a = pose (z, rz) of coupler at R2;"), &[]);
        check(&with("a = pose (w) of coupler at R2;"), &["unknown part `w`"]);
        check(
            &with("a, b = pose (rz, z) of coupler at R2;"),
            &["the parts go in the order x, y, z, rx, ry, rz, each once"],
        );
        check(
            &with("a, b = pose (z, z) of coupler at R2;"),
            &["the parts go in the order x, y, z, rx, ry, rz, each once"],
        );
        check(
            &with("a = pose (z, rz) of coupler at R2;"),
            &["a pose given by 2 parts has 2 values"],
        );
        check(
            &with("a, b = pose (z, rz) of coupler at R2 about z;"),
            &["a pose given by parts turns by rx, ry, rz: drop `about`"],
        );
        check(
            &format!("mechanism m {{ {FOUR_BAR} parameters {{ l1 = 1; l2 = 3; l3 = 2; l4 = 2.5; }} geometry {{ {PLACED} }} outputs {{ x, y = pose (x, y) of coupler at R2; }} }}"),
            &["a planar pose is x, y and the angle: drop the parts"],
        );
    }

    #[test]
    fn placement_errors() {
        let p = "parameters { l1 = 1; l2 = 3; l3 = 2; l4 = 2.5; }";
        check(
            &format!("mechanism m {{ {FOUR_BAR} {p} geometry {{ base {{ R1 = (0, 0); R4 = (l4, 0); }} crank {{ R1 = (0, 0); R2 = (l1, 0); }} }} }}"),
            &[
                "joint `R2` has no place on link `coupler`",
                "joint `R3` has no place on links `coupler` and `rocker`",
                "joint `R4` has no place on link `rocker`",
            ],
        );
        check(
            &format!("mechanism m {{ {FOUR_BAR} {p} geometry {{ crank {{ R3 = (0, 0); }} cranc {{ }} }} }}"),
            &["joint `R3` does not touch link `crank`", "unknown link `cranc`"],
        );
        check(
            &format!("mechanism m {{ {FOUR_BAR} {p} geometry {{ crank {{ R1 = (0, 0, 0); R9 = (1, 0); }} }} }}"),
            &["expected 2 coordinates, found 3", "unknown joint `R9`"],
        );
    }

    #[test]
    fn guides_and_arms_sit_on_one_side() {
        let chain = "base P1* [s] ∥ R1 [r] - Pa [c] - R2 base; parameters { l = 1; }";
        let geometry = |base_p: &str, r_pa: &str, c_pa: &str| {
            format!(
                "geometry {{ base {{ P1 = {base_p}; R2 = (0, 0, 0) along x; }} s {{ P1 = (0, 0, 0); R1 = (0, 0, 0) along x; }}
                 r {{ R1 = (0, 0, 0) along x; Pa = (0, 0, 0) along z{r_pa}; }} c {{ Pa = (0, 0, 0) along z{c_pa}; R2 = (0, 0, 0) along x; }} }}"
            )
        };
        let line = "through (0, 0, 0) along x";
        check(
            &format!("mechanism m {{ {chain} {} }}", geometry(line, " arm (0, l, 0)", "")),
            &[],
        );
        check(
            &format!("mechanism m {{ {chain} {} }}", geometry("(0, 0, 0)", "", "")),
            &[
                "prismatic joint `P1` needs a guide line on one link and a point on the other",
                "parallelogram `Pa` needs its arm `arm (…)` on exactly one of its links",
            ],
        );
        check(
            &format!(
                "mechanism m {{ {chain} {} }}",
                geometry(line, " arm (0, l, 0)", " arm (0, l, 0)")
            ),
            &["parallelogram `Pa` needs its arm `arm (…)` on exactly one of its links"],
        );
    }

    /// A spherical four-bar with right-angled links: each link's two axes
    /// meet at its origin, the joints placed 1 along their axes.
    #[test]
    fn concurrent_axes_meet_on_every_link_and_across_every_joint() {
        let chain = "base R1* [a] - R2 [b] - R3 [c] - R4 base; R1 ∧ R2 ∧ R3 /\\ R4; parameters { l = 1; }";
        let geometry = |b_r3: &str, c_r3: &str| {
            format!(
                "geometry {{ base {{ R1 = (0, 0, l) along z; R4 = (l, 0, 0) along x; }} a {{ R1 = (0, 0, l) along z; R2 = (0, l, 0) along y; }}
                 b {{ R2 = (0, 0, l) along z; R3 = {b_r3}; }} c {{ R3 = {c_r3}; R4 = (0, 0, l) along z; }} }}"
            )
        };
        check(
            &format!(
                "mechanism m {{ {chain} {} }}",
                geometry("(l, 0, 0) along x", "(l, 0, 0) along x")
            ),
            &[],
        );
        // R3's axis on b moved 0.5 off the origin: it misses R2's there.
        check(
            &format!(
                "mechanism m {{ {chain} {} }}",
                geometry("(l, 0.5, 0) along x", "(l, 0, 0) along x")
            ),
            &["relation `∧` does not hold in the geometry of link `b`"],
        );
        // R3 placed 2 from the centre on c but 1 on b: the centres are 1 apart along R3.
        check(
            &format!("mechanism m {{ {chain} {} }}", geometry("(l, 0, 0) along x", "(2 * l, 0, 0) along x")),
            &["relation `∧` does not hold across joint `R3`: links `b` and `c` put the centre at different points of its axis"],
        );
    }

    #[test]
    fn relations_are_checked_against_the_geometry() {
        let spatial = "base R1* [a] ⊥ R2 [b] ∥ R3 [c] - R4 base; parameters { l = 1; }";
        let geometry = |r2: &str| {
            format!(
                "geometry {{ base {{ R1 = (0, 0, 0) along z; R4 = (l, 0, 0) along z; }} a {{ R1 = (0, 0, 0) along z; R2 = (l, 0, 0) along {r2}; }}
                 b {{ R2 = (0, 0, 0) along x; R3 = (l, 0, 0) along x; }} c {{ R3 = (0, 0, 0) along x; R4 = (0, l, 0) along z; }} }}"
            )
        };
        check(&format!("mechanism m {{ {spatial} {} }}", geometry("x")), &[]);
        check(
            &format!("mechanism m {{ {spatial} {} }}", geometry("(1, 0, 1)")),
            &["relation `⊥` does not hold in the geometry of link `a`"],
        );
    }
}
