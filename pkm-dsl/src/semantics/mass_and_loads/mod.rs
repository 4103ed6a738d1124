//! What inverse dynamics needs besides the geometry: the file's `units`,
//! each link's mass properties (`masses`), `gravity` and external `loads`,
//! as written (`crate::syntax::masses`) and checked against the mechanism ([`resolve`]).
//!
//! Units: lengths in the file's length unit (`length = m | cm | mm`),
//! masses in its mass unit (`mass = kg | g`), inertias in mass unit ·
//! length unit² about the centroid, in the link's frame; gravity in m/s²;
//! forces in N and moments in N·(length unit), as the seed papers print them.
//!
//! ```
//! let c = pkm_dsl::compile("mechanism m { planar; base R1* [a] ∥ R2 [b] ∥ R3 [c] ∥ R4 base;
//!     parameters { l = 100; }
//!     geometry { base { R1 = (0, 0); R4 = (3 * l, 0); } a { R1 = (0, 0); R2 = (l, 0); }
//!                b { R2 = (0, 0); R3 = (2.5 * l, 0); } c { R3 = (2 * l, 0); R4 = (0, 0); } }
//!     units { length = mm; mass = kg; }
//!     masses { a { mass = 0.1; centroid = (l / 2, 0); inertia = 83.3; } massless b, c; } }").unwrap();
//! let d = &c.analysis.mass_and_loads;
//! assert_eq!(d.masses[0].mass, 0.1);
//! assert_eq!(d.gravity, [0.0, -9.81, 0.0]);
//! ```

use crate::diagnostics::{Diagnostic, Diagnostics, Span};
use crate::semantics::geometry::Geometry;
use crate::semantics::mechanism::{suggest, Mechanism};
use crate::syntax::ast::Name;
use crate::syntax::expr::Expr;
pub use crate::syntax::masses::{LoadDecl, MassDecl, UnitsDecl, Value};
use pkm_runtime::solution::PointRef;
use std::collections::HashMap;

mod units;

use units::*;
pub use units::{LengthUnit, MassUnit, Units};

/// An inertia tensor about the centroid, in the link's frame.
#[derive(Debug, Clone, PartialEq)]
pub enum Inertia {
    /// None declared: a point mass.
    Point,
    /// Planar: the moment about z.
    Planar(Expr),
    /// Principal moments along the link's axes `(Ixx, Iyy, Izz)`.
    Principal([Expr; 3]),
    /// The whole symmetric tensor `(Ixx, Iyy, Izz, Ixy, Ixz, Iyz)`, its
    /// off-diagonal entries as they stand in the tensor (`Ixy = −∫xy dm`).
    Full([Expr; 6]),
}

/// One link's mass properties, as expressions of the parameters and at
/// their nominal values.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkMass {
    /// The link.
    pub link: usize,
    /// Its mass (mass unit).
    pub mass_expr: Expr,
    /// Its mass at the nominal parameters.
    pub mass: f64,
    /// Its centroid in the link's frame (z = 0 in planar mechanisms).
    pub centroid: [Expr; 3],
    /// Its inertia about the centroid.
    pub inertia: Inertia,
}

/// A parallelogram bar's mass properties. The bar is not a link: it is
/// hinged at `hinge`, a point of the link that holds the joint's arm (in
/// that link's frame), and turns with the joint's value about the hinge
/// axis. Its frame has its origin at the hinge and the arm-carrying link's
/// axes turned by the joint's value about the hinge axis (at value 0,
/// that link's axes); its centroid and inertia are in that frame.
#[derive(Debug, Clone, PartialEq)]
pub struct BarMass {
    /// The parallelogram joint.
    pub joint: usize,
    /// The hinge in the arm-carrying link's frame (z = 0 in planar mechanisms).
    pub hinge: [Expr; 3],
    /// Its mass (mass unit).
    pub mass_expr: Expr,
    /// Its mass at the nominal parameters.
    pub mass: f64,
    /// Its centroid in the bar's frame.
    pub centroid: [Expr; 3],
    /// Its inertia about the centroid, the bar's axes.
    pub inertia: Inertia,
}

/// An external load on a link: a force at one of its points and a moment,
/// in base coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct Load {
    /// Its name.
    pub name: String,
    /// The link.
    pub link: usize,
    /// Where the force acts.
    pub at: Option<PointRef>,
    /// The force (N), zeros where none is given.
    pub force: [Expr; 3],
    /// The moment (N·length unit), zeros where none is given.
    pub moment: [Expr; 3],
}

/// A mechanism's mass properties and loads, checked.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MassAndLoads {
    /// The file's units, if declared.
    pub units: Option<Units>,
    /// The links with mass.
    pub masses: Vec<LinkMass>,
    /// The links declared `massless`.
    pub massless: Vec<usize>,
    /// Parallelograms' bars with mass (bars not declared have none).
    pub bars: Vec<BarMass>,
    /// Gravity in base coordinates (m/s²) at the nominal parameters: the
    /// declared vector, or 9.81 along −z (spatial) or −y (planar).
    pub gravity: [f64; 3],
    /// The declared gravity's expressions, for other parameter values.
    pub gravity_declared: Option<[Expr; 3]>,
    /// External loads.
    pub loads: Vec<Load>,
}

/// Everything [`resolve`] reads from the syntax tree.
#[derive(Debug, Clone, Copy)]
pub struct Declared<'a> {
    /// `units` blocks.
    pub units: &'a [UnitsDecl],
    /// `masses` blocks, each a list of entries, with the block's span.
    pub masses: &'a [(Vec<MassDecl>, Span)],
    /// `gravity` statements.
    pub gravity: &'a [Value],
    /// `loads` entries.
    pub loads: &'a [LoadDecl],
}

/// Checks the declared units, masses, gravity and loads against the
/// mechanism and its geometry, the values at the nominal parameters.
///
/// Errors point at the span: a unit that is not one of the listed, a key
/// given twice, masses or loads without units, an unknown link (or the
/// base), a link given twice, an unknown key, a missing `mass` or
/// `centroid`, a tuple of the wrong length, a negative mass, an inertia
/// that is not positive semi-definite or whose principal moments break the
/// triangle inequality, a load without a force or a moment, a force
/// without its point, a point not on the load's link.
pub fn resolve(d: Declared, mech: &Mechanism, geometry: &Geometry) -> Result<MassAndLoads, Diagnostics> {
    let mut errors = Diagnostics::default();
    let values = geometry.nominal();
    let known = |n: &str| values.contains_key(n);
    let units = units(d.units, &mut errors);
    let planar = mech.planar;
    // A block with a wrong unit is reported there, not as missing.
    if d.units.is_empty() {
        let first = d.masses.first().map(|(_, s)| *s).or(d.loads.first().map(|l| l.span));
        if let Some(span) = first {
            errors.push(
                Diagnostic::new(span, "masses and loads need the file's units")
                    .label("in which units?")
                    .note("declare them once: `units { length = mm; mass = kg; }`"),
            );
        }
    }
    let mut out = MassAndLoads {
        units,
        gravity: if planar { [0.0, -9.81, 0.0] } else { [0.0, 0.0, -9.81] },
        ..Default::default()
    };
    let mut given: HashMap<usize, Span> = HashMap::new();
    let mut bars_given: Vec<((usize, [u64; 3]), Span)> = Vec::new();
    for entry in d.masses.iter().flat_map(|(e, _)| e) {
        match entry {
            MassDecl::Massless(links) => {
                for l in links {
                    if let Some(i) = moving_link(mech, l, &mut given, &mut errors) {
                        out.massless.push(i);
                    }
                }
            }
            MassDecl::Link { link, items } => {
                let Some(i) = moving_link(mech, link, &mut given, &mut errors) else {
                    continue;
                };
                let who = Owner { name: link, link: true };
                if let Some((mass_expr, mass, centroid, inertia)) =
                    mass_properties(&who, items, planar, &values, &known, &mut errors)
                {
                    out.masses.push(LinkMass {
                        link: i,
                        mass_expr,
                        mass,
                        centroid,
                        inertia,
                    });
                }
            }
            MassDecl::Bar { joint, hinge, items } => {
                let Some(j) = parallelogram(mech, joint, &mut errors) else {
                    continue;
                };
                let Some(at) = vector(
                    &Value::Tuple(hinge.clone()),
                    planar,
                    "a bar's hinge",
                    &known,
                    &mut errors,
                ) else {
                    continue;
                };
                let nominal = at.clone().map(|e| e.eval(&values));
                if nominal.iter().any(|x| !x.is_finite()) {
                    errors.push(Diagnostic::new(hinge.span, "the bar's hinge is not finite").label("here"));
                    continue;
                }
                if let Some((_, first)) = bars_given.iter().find(|(k, _)| *k == (j, nominal.map(f64::to_bits))) {
                    errors.push(
                        Diagnostic::new(
                            hinge.span,
                            format!("the bar of `{}` at this hinge is given twice", joint.text),
                        )
                        .label("again")
                        .also(*first, "first here"),
                    );
                    continue;
                }
                bars_given.push(((j, nominal.map(f64::to_bits)), hinge.span));
                let who = Owner {
                    name: joint,
                    link: false,
                };
                if let Some((mass_expr, mass, centroid, inertia)) =
                    mass_properties(&who, items, planar, &values, &known, &mut errors)
                {
                    out.bars.push(BarMass {
                        joint: j,
                        hinge: at,
                        mass_expr,
                        mass,
                        centroid,
                        inertia,
                    });
                }
            }
        }
    }
    if let Some(second) = d.gravity.get(1) {
        errors.push(Diagnostic::new(second.span(), "gravity is given twice").label("again"));
    }
    if let Some(g) = d.gravity.first() {
        if let Some(v) = vector(g, planar, "gravity", &known, &mut errors) {
            let g = v.clone().map(|e| e.eval(&values));
            if g.iter().all(|x| x.is_finite()) {
                out.gravity = g;
                out.gravity_declared = Some(v);
            } else {
                errors.push(Diagnostic::new(d.gravity[0].span(), "gravity is not finite").label("here"));
            }
        }
    }
    out.loads = loads(d.loads, mech, geometry, &values, &known, &mut errors);
    errors.into_result(out)
}

/// The moving link `l` names, recorded as given (the base, an unknown link
/// and a second entry for one link are errors).
fn moving_link(
    mech: &Mechanism,
    l: &Name,
    given: &mut HashMap<usize, Span>,
    errors: &mut Diagnostics,
) -> Option<usize> {
    let Some(i) = mech.links.iter().position(|x| x.name == l.text) else {
        let mut e = Diagnostic::new(l.span, format!("unknown link `{}`", l.text)).label("no such link");
        if let Some(s) = suggest(&l.text, mech.links.iter().map(|x| x.name.as_str())) {
            e = e.note(format!("did you mean `{s}`?"));
        }
        errors.push(e);
        return None;
    };
    if i == 0 {
        errors.push(
            Diagnostic::new(l.span, "the base has no mass properties")
                .label("fixed")
                .note("its mass does not enter the dynamics; the reactions on it are computed"),
        );
        return None;
    }
    errors
        .given_once(given, i, l.span, || format!("link `{}`", l.text))
        .then_some(i)
}

/// Whose mass properties: a link's, or a parallelogram bar's (`name` its joint).
struct Owner<'a> {
    name: &'a Name,
    link: bool,
}

impl Owner<'_> {
    /// `link `a`` or `the bar of `Pa``, as messages name it.
    fn who(&self) -> String {
        if self.link {
            format!("link `{}`", self.name.text)
        } else {
            format!("the bar of `{}`", self.name.text)
        }
    }

    /// `` `a` `` or `the bar of `Pa``.
    fn short(&self) -> String {
        if self.link {
            format!("`{}`", self.name.text)
        } else {
            self.who()
        }
    }
}

/// The parallelogram joint `j` names (an unknown joint, or one that is not
/// a `Pa`, is an error).
fn parallelogram(mech: &Mechanism, j: &Name, errors: &mut Diagnostics) -> Option<usize> {
    let Some(i) = mech.joints.iter().position(|x| x.name == j.text) else {
        let mut e = Diagnostic::new(j.span, format!("unknown joint `{}`", j.text)).label("no such joint");
        if let Some(s) = suggest(&j.text, mech.joints.iter().map(|x| x.name.as_str())) {
            e = e.note(format!("did you mean `{s}`?"));
        }
        errors.push(e);
        return None;
    };
    if mech.joints[i].kind != crate::semantics::mechanism::JointKind::Pa {
        errors.push(
            Diagnostic::new(j.span, format!("`{}` is not a parallelogram", j.text))
                .label(format!("its type is {}", mech.joints[i].kind.symbol()))
                .note("only a parallelogram's (`Pa`) swinging bars are bodies without a link of their own"),
        );
        return None;
    }
    Some(i)
}

/// A link's or a bar's `{ mass = …; centroid = (…); inertia = …; }`,
/// checked: the mass (expression and nominal value), centroid and inertia.
fn mass_properties(
    owner: &Owner,
    items: &[(Name, Value)],
    planar: bool,
    values: &HashMap<String, f64>,
    known: &dyn Fn(&str) -> bool,
    errors: &mut Diagnostics,
) -> Option<(Expr, f64, [Expr; 3], Inertia)> {
    let name = owner.name;
    let mut seen: HashMap<&str, Span> = HashMap::new();
    let (mut mass, mut centroid, mut inertia) = (None, None, Inertia::Point);
    for (key, v) in items {
        if !errors.given_once(&mut seen, key.text.as_str(), key.span, || format!("`{}`", key.text)) {
            continue;
        }
        match key.text.as_str() {
            "mass" => mass = scalar(v, "a mass", known, errors).map(|e| (e, v.span())),
            "centroid" => centroid = vector(v, planar, "the centroid", known, errors),
            "inertia" => {
                if let Some(i) = inertia_of(v, planar, values, known, errors) {
                    inertia = i;
                }
            }
            _ => errors.push(
                Diagnostic::new(key.span, format!("unknown mass property `{}`", key.text))
                    .label("not a property")
                    .note("a body takes `mass`, `centroid` and `inertia` (about the centroid)"),
            ),
        }
    }
    for (key, missing) in [("mass", mass.is_none()), ("centroid", centroid.is_none())] {
        if missing && !seen.contains_key(key) {
            let e =
                Diagnostic::new(name.span, format!("{} needs its `{key}`", owner.who())).label(format!("no `{key}`"));
            errors.push(if owner.link {
                e.note("or declare it `massless`")
            } else {
                e.note("or leave the bar out: a bar not declared has no mass")
            });
        }
    }
    let ((mass_expr, span), centroid) = (mass?, centroid?);
    if centroid.iter().any(|e| !e.eval(values).is_finite()) {
        errors
            .push(Diagnostic::new(name.span, format!("the centroid of {} is not finite", owner.short())).label("here"));
        return None;
    }
    let m = mass_expr.eval(values);
    if !m.is_finite() || m < 0.0 {
        errors.push(
            Diagnostic::new(span, format!("the mass of {} is {m}", owner.short()))
                .label("a mass is finite and not negative"),
        );
        return None;
    }
    Some((mass_expr, m, centroid, inertia))
}

/// Expressions whose names are all parameters (the unknown ones are errors).
fn known_names(v: &Value, known: &dyn Fn(&str) -> bool, errors: &mut Diagnostics) -> bool {
    let mut found = Vec::new();
    for e in v.items() {
        e.check(known, &mut found);
    }
    let ok = found.is_empty();
    errors.0.extend(found);
    ok
}

fn scalar(v: &Value, what: &str, known: &dyn Fn(&str) -> bool, errors: &mut Diagnostics) -> Option<Expr> {
    let items = v.items();
    if items.len() != 1 {
        errors.push(Diagnostic::new(v.span(), format!("{what} is one value")).label(format!("{} given", items.len())));
        return None;
    }
    known_names(v, known, errors).then(|| items[0].clone())
}

/// A point or vector: two values in a planar mechanism (z = 0), three in a
/// spatial one.
fn vector(
    v: &Value,
    planar: bool,
    what: &str,
    known: &dyn Fn(&str) -> bool,
    errors: &mut Diagnostics,
) -> Option<[Expr; 3]> {
    let items = v.items();
    let (wanted, how) = if planar { (2, "(x, y)") } else { (3, "(x, y, z)") };
    if items.len() != wanted || matches!(v, Value::Scalar(..)) {
        errors.push(
            Diagnostic::new(
                v.span(),
                format!(
                    "{what} has {wanted} values {how} in a {} mechanism",
                    if planar { "planar" } else { "spatial" }
                ),
            )
            .label(format!("{} given", items.len())),
        );
        return None;
    }
    if !known_names(v, known, errors) {
        return None;
    }
    let z = Expr::Num(0.0);
    Some([
        items[0].clone(),
        items[1].clone(),
        items.get(2).map_or(z, |e| (*e).clone()),
    ])
}

/// `inertia = I;` (planar: about z), `(Ixx, Iyy, Izz)` or
/// `(Ixx, Iyy, Izz, Ixy, Ixz, Iyz)`, checked at the nominal parameters.
fn inertia_of(
    v: &Value,
    planar: bool,
    values: &HashMap<String, f64>,
    known: &dyn Fn(&str) -> bool,
    errors: &mut Diagnostics,
) -> Option<Inertia> {
    let items = v.items();
    let form = match (planar, items.len()) {
        (true, 1) => Inertia::Planar(items[0].clone()),
        (false, 3) if matches!(v, Value::Tuple(_)) => Inertia::Principal(std::array::from_fn(|i| items[i].clone())),
        (false, 6) => Inertia::Full(std::array::from_fn(|i| items[i].clone())),
        _ => {
            let how = if planar {
                "a planar link's inertia is one value, its moment about z"
            } else {
                "a spatial link's inertia is (Ixx, Iyy, Izz) or (Ixx, Iyy, Izz, Ixy, Ixz, Iyz)"
            };
            errors.push(Diagnostic::new(v.span(), how).label(format!("{} values given", items.len())));
            return None;
        }
    };
    if !known_names(v, known, errors) {
        return None;
    }
    let n: Vec<f64> = items.iter().map(|e| e.eval(values)).collect();
    if let Some(problem) = inertia_problem(&n) {
        errors.push(Diagnostic::new(v.span(), problem).label("not an inertia"));
        return None;
    }
    Some(form)
}

pub use pkm_runtime::mass_properties::{inertia_problem, inertia_tensor};

/// The loads, checked.
fn loads(
    decls: &[LoadDecl],
    mech: &Mechanism,
    geometry: &Geometry,
    values: &HashMap<String, f64>,
    known: &dyn Fn(&str) -> bool,
    errors: &mut Diagnostics,
) -> Vec<Load> {
    let planar = mech.planar;
    let mut out: Vec<Load> = Vec::new();
    let mut names: HashMap<&str, Span> = HashMap::new();
    for d in decls {
        if !errors.given_once(&mut names, d.name.text.as_str(), d.name.span, || {
            format!("load `{}`", d.name.text)
        }) {
            continue;
        }
        let zero = || [Expr::Num(0.0), Expr::Num(0.0), Expr::Num(0.0)];
        let (mut force, mut moment) = (None, None);
        for (key, v) in &d.parts {
            let (slot, parsed) = if key.text == "force" {
                (&mut force, vector(v, planar, "a force", known, errors))
            } else if planar {
                let m = scalar(v, "a planar moment (about z)", known, errors);
                (&mut moment, m.map(|e| [Expr::Num(0.0), Expr::Num(0.0), e]))
            } else {
                (&mut moment, vector(v, false, "a moment", known, errors))
            };
            if slot.is_some() {
                errors.push(
                    Diagnostic::new(key.span, format!("the load's `{}` is given twice", key.text)).label("again"),
                );
            }
            *slot = parsed.or(slot.take());
        }
        let at = match &d.at {
            Some(p) => {
                let mut found = Vec::new();
                let point = crate::semantics::geometry::link_point(
                    mech,
                    &geometry.places,
                    &geometry.points,
                    &d.link,
                    p,
                    &mut found,
                );
                errors.0.extend(found);
                match point {
                    Some((_, point)) => Some(point),
                    None => continue,
                }
            }
            None => {
                if d.parts.iter().any(|(k, _)| k.text == "force") {
                    errors.push(
                        Diagnostic::new(d.span, format!("load `{}` has a force but no point", d.name.text))
                            .label("where does it act?")
                            .note("name the point: `… on LINK at POINT;`"),
                    );
                    continue;
                }
                None
            }
        };
        let Some(link) = mech.links.iter().position(|x| x.name == d.link.text) else {
            errors.push(Diagnostic::new(d.link.span, format!("unknown link `{}`", d.link.text)).label("no such link"));
            continue;
        };
        if link == 0 {
            errors.push(
                Diagnostic::new(d.link.span, "a load on the base does nothing")
                    .label("fixed")
                    .note("loads act on moving links"),
            );
            continue;
        }
        let finite = |v: &Option<[Expr; 3]>| v.iter().flatten().all(|e| e.eval(values).is_finite());
        if !finite(&force) || !finite(&moment) {
            errors.push(Diagnostic::new(d.span, format!("load `{}` is not finite", d.name.text)).label("here"));
            continue;
        }
        out.push(Load {
            name: d.name.text.clone(),
            link,
            at,
            force: force.unwrap_or_else(zero),
            moment: moment.unwrap_or_else(zero),
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A planar four-bar with named links, placed; `extra` adds statements.
    fn four_bar(extra: &str) -> String {
        format!(
            "mechanism m {{ planar; base R1* [a] ∥ R2 [b] ∥ R3 [c] ∥ R4 base;
             parameters {{ l = 100; }}
             geometry {{ base {{ R1 = (0, 0); R4 = (3 * l, 0); }} a {{ R1 = (0, 0); R2 = (l, 0); point M = (l / 2, 0); }}
                         b {{ R2 = (0, 0); R3 = (2.5 * l, 0); }} c {{ R3 = (2 * l, 0); R4 = (0, 0); }} }}
             {extra} }}"
        )
    }

    /// The four-bar declared spatially (axes along z): three-value forms.
    fn spatial(extra: &str) -> String {
        format!(
            "mechanism m {{ base R1* [a] ∥ R2 [b] ∥ R3 [c] ∥ R4 base;
             parameters {{ l = 100; }}
             geometry {{ base {{ R1 = (0, 0, 0) along z; R4 = (3 * l, 0, 0) along z; }}
                         a {{ R1 = (0, 0, 0) along z; R2 = (l, 0, 0) along z; }}
                         b {{ R2 = (0, 0, 0) along z; R3 = (2.5 * l, 0, 0) along z; }}
                         c {{ R3 = (2 * l, 0, 0) along z; R4 = (0, 0, 0) along z; }} }}
             {extra} }}"
        )
    }

    /// The messages of every error the text produces, in order.
    fn check(source: &str, expected: &[&str]) {
        let messages: Vec<String> = match crate::topology::analysis::analyze_source(source) {
            Ok(_) => Vec::new(),
            Err(d) => d.0.into_iter().map(|e| e.message).collect(),
        };
        assert_eq!(messages, expected, "{source}");
    }

    fn resolved(source: &str) -> MassAndLoads {
        crate::topology::analysis::analyze_source(source)
            .expect("no error")
            .mass_and_loads
    }

    const UNITS: &str = "units { length = mm; mass = kg; }";

    #[test]
    fn masses_gravity_and_loads_are_read_in_the_files_units() {
        let d = resolved(&four_bar(&format!(
            "{UNITS} masses {{ a {{ mass = 0.1 * 2; centroid = (l / 2, 0); inertia = 83.3; }} massless b; c {{ mass = 1; centroid = (l, 0); }} }}
             gravity (0, -9.8);
             loads {{ push = force (10, 0) on a at M; brake = moment 5 on c; }}"
        )));
        assert_eq!(
            d.units,
            Some(Units {
                length: LengthUnit::Mm,
                mass: MassUnit::Kg
            })
        );
        assert_eq!(d.units.map(|u| u.length.metres()), Some(1e-3));
        assert_eq!((d.masses[0].link, d.masses[0].mass), (1, 0.2));
        assert_eq!(d.masses[0].inertia, Inertia::Planar(Expr::Num(83.3)));
        assert_eq!((d.masses[1].link, d.masses[1].inertia.clone()), (3, Inertia::Point));
        assert_eq!(d.massless, vec![2]);
        assert_eq!(d.gravity, [0.0, -9.8, 0.0]);
        assert_eq!(d.loads.len(), 2);
        assert_eq!((d.loads[0].link, d.loads[0].at), (1, Some(PointRef::Named(0))));
        assert_eq!(d.loads[1].moment[2], Expr::Num(5.0));
        assert_eq!(d.loads[1].at, None);
    }

    #[test]
    fn gravity_defaults_to_minus_y_planar_and_minus_z_spatial() {
        assert_eq!(resolved(&four_bar("")).gravity, [0.0, -9.81, 0.0]);
        assert_eq!(resolved(&spatial("")).gravity, [0.0, 0.0, -9.81]);
        assert_eq!(resolved(&four_bar("")).units, None);
    }

    #[test]
    fn units_are_one_block_with_a_length_and_a_mass() {
        check(
            &four_bar("units { length = inch; mass = kg; time = s; }"),
            &["`inch` is not a unit of length", "unknown unit `time`"],
        );
        check(&four_bar("units { length = mm; }"), &["`units` needs `mass`"]);
        check(
            &four_bar("units { length = mm; mass = kg; length = m; }"),
            &["`length` is given twice"],
        );
        check(
            &four_bar(&format!("{UNITS} {UNITS}")),
            &["a mechanism has one `units` block"],
        );
        check(
            &four_bar("masses { massless a, b, c; }"),
            &["masses and loads need the file's units"],
        );
    }

    #[test]
    fn each_moving_link_once_with_mass_and_centroid() {
        check(
            &four_bar(&format!(
                "{UNITS} masses {{ base {{ mass = 1; centroid = (0, 0); }} d {{ mass = 1; centroid = (0, 0); }}
                 a {{ mass = 1; }} massless a; b {{ centroid = (0, 0); colour = 3; }} }}"
            )),
            &[
                "the base has no mass properties",
                "unknown link `d`",
                "link `a` needs its `centroid`",
                "link `a` is given twice",
                "unknown mass property `colour`",
                "link `b` needs its `mass`",
            ],
        );
        check(
            &four_bar(&format!(
                "{UNITS} masses {{ a {{ mass = 1; mass = 2; centroid = (0, 0, 0); }} }}"
            )),
            &[
                "`mass` is given twice",
                "the centroid has 2 values (x, y) in a planar mechanism",
            ],
        );
        check(
            &four_bar(&format!("{UNITS} masses {{ a {{ mass = q; centroid = (0, 0); }} }}")),
            &["unknown parameter `q`"],
        );
    }

    #[test]
    fn a_mass_is_not_negative() {
        check(
            &four_bar(&format!(
                "{UNITS} masses {{ a {{ mass = 1 - l; centroid = (0, 0); }} }}"
            )),
            &["the mass of `a` is -99"],
        );
        check(
            &four_bar(&format!("{UNITS} masses {{ a {{ mass = 0; centroid = (0, 0); }} }}")),
            &[],
        );
    }

    #[test]
    fn an_inertia_is_a_rigid_bodys() {
        let with = |inertia: &str| {
            spatial(&format!(
                "{UNITS} masses {{ a {{ mass = 1; centroid = (0, 0, 0); inertia = {inertia}; }} }}"
            ))
        };
        // A rod along x: (0, I, I) meets the triangle inequality with equality.
        check(&with("(0, 5, 5)"), &[]);
        check(&with("(1, 5, 5, 0.5, 0, 0)"), &[]);
        check(
            &with("(1, 2)"),
            &["a spatial link's inertia is (Ixx, Iyy, Izz) or (Ixx, Iyy, Izz, Ixy, Ixz, Iyz)"],
        );
        check(
            &with("(1, 1, 3)"),
            &["the principal moments [1.0, 1.0, 3.0] break the triangle inequality: 3 exceeds the sum of the other two (2)"],
        );
        check(
            &with("(-1, 2, 2)"),
            &["a principal moment of inertia is -1, negative: the tensor is not positive semi-definite"],
        );
        // Eigenvalues of [[1, 2, 0], [2, 1, 0], [0, 0, 1]] are 3, −1 and 1.
        check(
            &with("(1, 1, 1, 2, 0, 0)"),
            &["a principal moment of inertia is -1, negative: the tensor is not positive semi-definite"],
        );
        let planar = |inertia: &str| {
            four_bar(&format!(
                "{UNITS} masses {{ a {{ mass = 1; centroid = (0, 0); inertia = {inertia}; }} }}"
            ))
        };
        check(&planar("-2"), &["the moment of inertia is -2, negative"]);
        check(
            &planar("(1, 2, 3)"),
            &["a planar link's inertia is one value, its moment about z"],
        );
    }

    #[test]
    fn a_load_acts_on_a_point_of_its_link() {
        check(
            &four_bar(&format!(
                "{UNITS} loads {{ p = force (1, 0) on a; q = force (1, 0) on b at M; r = moment (1, 2) on a; s = force (1, 0) on a at M; s = moment 1 on a; t = force (1, 0) force (0, 1) on a at M; }}"
            )),
            &[
                "load `p` has a force but no point",
                "`M` is not a point of link `b`",
                "a planar moment (about z) is one value",
                "load `s` is given twice",
                "the load's `force` is given twice",
            ],
        );
        check(
            &four_bar(&format!("{UNITS} loads {{ p = force (1, 0) on e at M; }}")),
            &["unknown link `e`"],
        );
        check(
            &four_bar(&format!(
                "{UNITS} loads {{ p = moment 1 on base; q = force (sqrt(-1), 0) on a at M; }}"
            )),
            &["a load on the base does nothing", "load `q` is not finite"],
        );
    }

    #[test]
    fn gravity_has_the_mechanisms_dimension() {
        check(
            &four_bar("gravity (0, 0, -9.81);"),
            &["gravity has 2 values (x, y) in a planar mechanism"],
        );
        check(
            &four_bar("gravity (0, -9.81); gravity (0, -1);"),
            &["gravity is given twice"],
        );
        assert_eq!(resolved(&spatial("gravity (0, -9.81, 0);")).gravity, [0.0, -9.81, 0.0]);
    }

    /// A five-bar with a parallelogram branch (`examples/mechanisms/five_bar_pa.pkm`'s).
    fn with_pa(extra: &str) -> String {
        format!(
            "mechanism m {{
                branch I {{ base R1* [a1] ∥ R2 [b1] ∥ R3 [b2] ∥ R4 [a2] ∥ R5* base; b1 R6 [cross] ⊥ R7 platform; }}
                branch II {{ base P3* [s3] ∥ R8 [r8] - Pa [pc] - R9 platform; }}
                R6 ≡ R3; y ∥ R1; x ∥ P3; R7 ∥ R8 ∥ R9; Pa ⊥ R8;
                parameters {{ a = 250; d = 80; r = 150; l = 260; h = 80; p = 380; m = 300; }}
                geometry {{
                    base  {{ R1 = (-d, -a, 0) along y; R5 = (d, -a, 0) along y; P3 = through (0, a, 0) along x; }}
                    a1    {{ R1 = (0, 0, 0) along y; R2 = (r, 0, 0) along y; }}
                    b1    {{ R2 = (0, 0, 0) along y; R3 = (l, 0, 0) along y; R6 = (l, 0, 0) along y; }}
                    b2    {{ R3 = (l, 0, 0) along y; R4 = (0, 0, 0) along y; }}
                    a2    {{ R4 = (r, 0, 0) along y; R5 = (0, 0, 0) along y; }}
                    cross {{ R6 = (0, 0, 0) along y; R7 = (0, 0, 0) along x; }}
                    platform {{ R7 = (0, 0, 0) along x; R9 = (0, p, 0) along x; }}
                    pc    {{ R9 = (0, 0, 0) along x; Pa = (0, 0, 0) along y; }}
                    r8    {{ R8 = (0, 0, 0) along x; Pa = (0, 0, 0) along y arm (0, 0, m); }}
                    s3    {{ P3 = (0, 0, 0); R8 = (0, 0, h) along x; }}
                }}
                {UNITS} {extra} }}"
        )
    }

    #[test]
    fn a_parallelograms_bars_carry_mass() {
        let a = crate::topology::analysis::analyze_source(&with_pa(
            "masses { Pa bar at (-20, 0, 0) { mass = 0.1 * 2; centroid = (0, 0, m / 2); inertia = (1500, 1500, 10); }
                      Pa bar at (20, 0, 0) { mass = 0.2; centroid = (0, 0, m / 2); } }",
        ))
        .expect("no error");
        let d = &a.mass_and_loads;
        assert_eq!(d.bars.len(), 2);
        let b = &d.bars[0];
        assert_eq!((a.mechanism.joints[b.joint].name.as_str(), b.mass), ("Pa", 0.2));
        let at = |v: &[Expr; 3]| v.clone().map(|e| e.eval(&HashMap::from([("m".to_string(), 300.0)])));
        assert_eq!(at(&b.hinge), [-20.0, 0.0, 0.0]);
        assert_eq!(at(&b.centroid), [0.0, 0.0, 150.0]);
        assert!(matches!(b.inertia, Inertia::Principal(_)));
        assert_eq!(d.bars[1].inertia, Inertia::Point);
        assert!(d.masses.is_empty(), "bars are not links");
    }

    #[test]
    fn a_bar_belongs_to_a_parallelogram_and_is_a_rigid_body() {
        check(
            &with_pa(
                "masses { Pq bar at (0, 0, 0) { mass = 1; centroid = (0, 0, 0); }
                          R8 bar at (0, 0, 0) { mass = 1; centroid = (0, 0, 0); }
                          Pa bar at (0, 0) { mass = 1; centroid = (0, 0, 0); }
                          Pa bar at (0, 0, 0) { centroid = (0, 0, 0); }
                          Pa bar at (1, 0, 0) { mass = 1 - m; centroid = (0, 0, 0); }
                          Pa bar at (2, 0, 0) { mass = 1; centroid = (0, 0, 0); inertia = (1, 1, 3); }
                          Pa bar at (3, 0, 0) { mass = 1; centroid = (0, 0, 0); }
                          Pa bar at (3, 0, 0) { mass = 1; centroid = (0, 0, 0); } }",
            ),
            &[
                "unknown joint `Pq`",
                "`R8` is not a parallelogram",
                "a bar's hinge has 3 values (x, y, z) in a spatial mechanism",
                "the bar of `Pa` needs its `mass`",
                "the mass of the bar of `Pa` is -299",
                "the principal moments [1.0, 1.0, 3.0] break the triangle inequality: 3 exceeds the sum of the other two (2)",
                "the bar of `Pa` at this hinge is given twice",
            ],
        );
    }

    #[test]
    fn a_parenthesised_expression_is_not_a_tuple() {
        let d = resolved(&four_bar(&format!(
            "{UNITS} masses {{ a {{ mass = (1 + 1) * 2; centroid = (0, 0); }} }}"
        )));
        assert_eq!(d.masses[0].mass, 4.0);
    }
}
