//! The `units`, `masses`, `gravity` and `loads` blocks as written, built
//! from their parse ([`build_units`], [`build_masses`], [`build_gravity`],
//! [`build_loads`]); `crate::semantics::mass_and_loads` checks them against the
//! mechanism.

use super::ast::{Name, Tuple};
use super::expr::Expr;
use super::parser::{self, Rule};
use crate::diagnostics::Span;
use pest::iterators::Pair;

/// A value as written: a tuple, or one expression (with its span).
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// `(e1, e2, …)`.
    Tuple(Tuple),
    /// One expression.
    Scalar(Expr, Span),
}

impl Value {
    pub(crate) fn span(&self) -> Span {
        match self {
            Value::Tuple(t) => t.span,
            Value::Scalar(_, s) => *s,
        }
    }

    /// The expressions: a tuple's items, or the one expression.
    pub(crate) fn items(&self) -> Vec<&Expr> {
        match self {
            Value::Tuple(t) => t.items.iter().collect(),
            Value::Scalar(e, _) => vec![e],
        }
    }
}

/// `units { length = mm; mass = kg; }` as written.
#[derive(Debug, Clone, PartialEq)]
pub struct UnitsDecl {
    /// Each `key = unit;`.
    pub items: Vec<(Name, Name)>,
    /// The whole block.
    pub span: Span,
}

/// One entry of a `masses { … }` block.
#[derive(Debug, Clone, PartialEq)]
pub enum MassDecl {
    /// `LINK { mass = …; centroid = (…); inertia = …; }`.
    Link {
        /// The link.
        link: Name,
        /// Each `key = value;`.
        items: Vec<(Name, Value)>,
    },
    /// `massless LINK, LINK;`: links declared without mass or inertia.
    Massless(Vec<Name>),
    /// `JOINT bar at (…) { mass = …; centroid = (…); inertia = …; }`: a
    /// swinging bar of parallelogram `JOINT`, hinged at that point of the
    /// link that holds the joint's arm.
    Bar {
        /// The parallelogram joint.
        joint: Name,
        /// The hinge point, in the arm-carrying link's frame.
        hinge: Tuple,
        /// Each `key = value;`.
        items: Vec<(Name, Value)>,
    },
}

/// `NAME = force (…) moment (…) on LINK at POINT;` as written.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadDecl {
    /// The load's name.
    pub name: Name,
    /// `force` and `moment` parts, in order, each with its keyword.
    pub parts: Vec<(Name, Value)>,
    /// The link it acts on.
    pub link: Name,
    /// The point a force acts at.
    pub at: Option<Name>,
    /// The whole declaration.
    pub span: Span,
}

/// The grammar's name for a rule of these blocks, for syntax errors.
pub(crate) fn rule_name(r: Rule) -> &'static str {
    match r {
        Rule::units_stmt | Rule::kw_units => "`units { length = mm; mass = kg; }`",
        Rule::unit_item => "a unit `length = mm;`",
        Rule::masses_stmt | Rule::kw_masses => "`masses { LINK { … } }`",
        Rule::massless_item | Rule::kw_massless => "`massless LINK, …;`",
        Rule::link_mass => "a link's mass properties `LINK { mass = …; centroid = (…); inertia = …; }`",
        Rule::bar_mass | Rule::kw_bar => "a parallelogram bar's mass properties `JOINT bar at (…) { mass = …; … }`",
        Rule::mass_item => "`mass = …;`, `centroid = (…);` or `inertia = …;`",
        Rule::gravity_stmt | Rule::kw_gravity => "`gravity (…);`",
        Rule::loads_stmt | Rule::kw_loads => "`loads { NAME = force (…) on LINK at POINT; }`",
        Rule::load => "a load `NAME = force (…) on LINK at POINT;`",
        Rule::load_part | Rule::kw_force | Rule::kw_moment => "`force (…)` or `moment (…)`",
        _ => "a value",
    }
}

fn value(p: Pair<Rule>) -> Value {
    match p.as_rule() {
        Rule::tuple => Value::Tuple(parser::tuple(p)),
        _ => {
            let span = parser::span_of(&p);
            Value::Scalar(parser::expr(p), span)
        }
    }
}

/// Builds a `units` block from its parse.
pub(crate) fn build_units(p: Pair<Rule>) -> UnitsDecl {
    let span = parser::span_of(&p);
    let items = p
        .into_inner()
        .filter(|q| q.as_rule() == Rule::unit_item)
        .map(|q| {
            let mut it = q.into_inner();
            let key = parser::name(it.next().expect("unit's key"));
            (key, parser::name(it.next().expect("unit's name")))
        })
        .collect();
    UnitsDecl { items, span }
}

/// Builds the entries of a `masses` block from its parse.
pub(crate) fn build_masses(p: Pair<Rule>) -> Vec<MassDecl> {
    p.into_inner()
        .filter_map(|q| match q.as_rule() {
            Rule::massless_item => Some(MassDecl::Massless(
                q.into_inner()
                    .filter(|r| r.as_rule() == Rule::name)
                    .map(parser::name)
                    .collect(),
            )),
            Rule::link_mass => {
                let mut it = q.into_inner();
                let link = parser::name(it.next().expect("the link"));
                Some(MassDecl::Link {
                    link,
                    items: mass_items(it),
                })
            }
            Rule::bar_mass => {
                let mut it = q
                    .into_inner()
                    .filter(|r| !matches!(r.as_rule(), Rule::kw_bar | Rule::kw_at));
                let joint = parser::name(it.next().expect("the joint"));
                let hinge = parser::tuple(it.next().expect("the hinge"));
                Some(MassDecl::Bar {
                    joint,
                    hinge,
                    items: mass_items(it),
                })
            }
            _ => None,
        })
        .collect()
}

/// The `key = value;` items of a link's or a bar's mass properties.
fn mass_items<'a>(items: impl Iterator<Item = Pair<'a, Rule>>) -> Vec<(Name, Value)> {
    items
        .map(|item| {
            let mut kv = item.into_inner();
            let key = parser::name(kv.next().expect("the key"));
            (key, value(kv.next().expect("the value")))
        })
        .collect()
}

/// Builds a `gravity` statement from its parse.
pub(crate) fn build_gravity(p: Pair<Rule>) -> Value {
    value(p.into_inner().nth(1).expect("gravity's value"))
}

/// Builds the loads of a `loads` block from its parse.
pub(crate) fn build_loads(p: Pair<Rule>) -> Vec<LoadDecl> {
    p.into_inner()
        .filter(|q| q.as_rule() == Rule::load)
        .map(|q| {
            let span = parser::span_of(&q);
            let mut it = q.into_inner();
            let name = parser::name(it.next().expect("the load's name"));
            let mut parts = Vec::new();
            let mut names = Vec::new();
            for r in it {
                match r.as_rule() {
                    Rule::load_part => {
                        let mut kv = r.into_inner();
                        let key = parser::name(kv.next().expect("force or moment"));
                        parts.push((key, value(kv.next().expect("its value"))));
                    }
                    Rule::name | Rule::ident => names.push(parser::name(r)),
                    _ => {}
                }
            }
            let mut names = names.into_iter();
            LoadDecl {
                name,
                parts,
                link: names.next().expect("the load's link"),
                at: names.next(),
                span,
            }
        })
        .collect()
}
