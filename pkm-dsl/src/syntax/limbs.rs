//! The `limbs` block as written, built from its parse ([`build_limbs`]);
//! `crate::semantics::limb_properties` checks it against the mechanism.

use super::ast::Name;
use super::expr::Expr;
use super::parser::{self, Rule};
use crate::diagnostics::Span;
use pest::iterators::Pair;

/// One entry of a `limbs { … }` block as written:
/// `A, B { E = …; A = …; I = …; }`.
#[derive(Debug, Clone, PartialEq)]
pub struct LimbDecl {
    /// The branches it gives properties to.
    pub branches: Vec<Name>,
    /// Each `key = value;`, the value with its span.
    pub items: Vec<(Name, LimbValue)>,
    /// The whole entry.
    pub span: Span,
}

/// A value of a limb property: its expression and where it is written.
#[derive(Debug, Clone, PartialEq)]
pub struct LimbValue {
    /// The expression (of the parameters).
    pub expr: Expr,
    /// Where it is written.
    pub span: Span,
}

/// The grammar's name for a rule of the block, for syntax errors.
pub(crate) fn rule_name(r: Rule) -> &'static str {
    match r {
        Rule::limbs_stmt | Rule::kw_limbs => "`limbs { BRANCH { … } }`",
        Rule::limb_entry => "a limb's properties `BRANCH, … { E = …; A = …; I = …; }`",
        _ => "`E = …;`, `A = …;`, `I = …;`, `axial = …;`, `bending = …;` or `actuator = …;`",
    }
}

/// Builds the entries of a `limbs` block from its parse.
pub(crate) fn build_limbs(p: Pair<Rule>) -> Vec<LimbDecl> {
    p.into_inner()
        .filter(|q| q.as_rule() == Rule::limb_entry)
        .map(|q| {
            let span = parser::span_of(&q);
            let mut branches = Vec::new();
            let mut items = Vec::new();
            for r in q.into_inner() {
                match r.as_rule() {
                    Rule::name => branches.push(parser::name(r)),
                    Rule::limb_item => {
                        let mut kv = r.into_inner();
                        let key = parser::name(kv.next().expect("the key"));
                        let v = kv.next().expect("the value");
                        let span = parser::span_of(&v);
                        items.push((
                            key,
                            LimbValue {
                                expr: parser::expr(v),
                                span,
                            },
                        ));
                    }
                    _ => {}
                }
            }
            LimbDecl { branches, items, span }
        })
        .collect()
}
