//! Dimensions and geometry: parameters with nominal values, and every joint
//! placed in the frames of its two links (see `docs/language.md`).
//! Checked here: names, tuple sizes, that each joint is placed on both its
//! links in the form its type needs, and that the declared ∥ / ⊥ / ≡
//! relations hold between axes placed on a common link.

use crate::diagnostics::{Diagnostic, Diagnostics, Span};
use crate::semantics::mechanism::{suggest, Mechanism};
use crate::syntax::ast::{AxisRef, LinkGeometry, MechanismAst, Place, Placement, Tuple};
use crate::syntax::expr::{Definition, Expr};
use nalgebra::Vector3;
use std::collections::HashMap;

mod checks;
mod outputs;

use checks::*;
pub(crate) use outputs::link_point;
use outputs::*;

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
