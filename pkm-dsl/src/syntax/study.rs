//! The `study` block as written, built from its parse ([`build`]);
//! `crate::semantics::study` checks and evaluates it.

use super::ast::Name;
use super::expr::Expr;
use super::parser::{self, Rule};
use crate::diagnostics::Span;
use pest::iterators::Pair;

/// One `study { … }` block as written.
#[derive(Debug, Clone, PartialEq)]
pub struct Study {
    /// Its statements, in order.
    pub items: Vec<StudyItem>,
    /// The whole block.
    pub span: Span,
}

/// How the inputs move along the trajectory.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Motion {
    /// q_i(t) = start_i + amplitude_i·sin(πt).
    Sine,
    /// q_i(t) = start_i + speed_i·t.
    ConstantSpeed,
}

/// One statement of a study block, with its span.
#[derive(Debug, Clone, PartialEq)]
pub enum StudyItem {
    /// `ranges { P1 = -250 .. 0; … }`: an actuated joint's name and bounds.
    Ranges(Vec<(Name, Expr, Expr)>, Span),
    /// `start (…);`: the sample input, one value per actuator.
    Start(Vec<Expr>, Span),
    /// `pose (…);`: the sample pose of a file without a forward plan, one
    /// value per declared output.
    Pose(Vec<Expr>, Span),
    /// `trajectory sine amplitude (…) duration T;` or `trajectory constant speed (…) duration T;`.
    Trajectory {
        /// Sine or constant speed.
        motion: Motion,
        /// The amplitudes or speeds, one per actuator.
        values: Vec<Expr>,
        /// The duration in seconds, if given.
        duration: Option<Expr>,
        /// The statement.
        span: Span,
    },
    /// `point G;`: the point whose workspace and motion are shown.
    Point(Name),
    /// `branch 1;`: the assembly branch's index.
    Branch(Name),
    /// `sections { x = 60; … }`: workspace section planes.
    Sections(Vec<(Name, Expr)>, Span),
    /// `nodes 40;`: grid nodes per input.
    Nodes(Name),
}

/// The grammar's name for a study rule, for syntax errors.
pub(crate) fn rule_name(r: Rule) -> &'static str {
    match r {
        Rule::study_stmt | Rule::kw_study => "`study { … }`",
        Rule::study_ranges | Rule::kw_ranges => "`ranges { JOINT = LOW .. HIGH; }`",
        Rule::study_range => "a range `JOINT = LOW .. HIGH;`",
        Rule::study_start | Rule::kw_start => "`start (…);`",
        Rule::study_pose => "`pose (…);`",
        Rule::study_trajectory | Rule::kw_trajectory => {
            "`trajectory sine amplitude (…)` or `trajectory constant speed (…)`"
        }
        Rule::study_sine | Rule::kw_sine => "`sine amplitude (…)`",
        Rule::kw_amplitude => "`amplitude`",
        Rule::study_constant | Rule::kw_constant => "`constant speed (…)`",
        Rule::kw_speed => "`speed`",
        Rule::kw_duration => "`duration`",
        Rule::study_point => "`point NAME;`",
        Rule::study_branch => "`branch N;`",
        Rule::study_sections | Rule::kw_sections => "`sections { x = …; }`",
        Rule::study_section => "a section `x = …;`",
        Rule::study_nodes | Rule::kw_nodes => "`nodes N;`",
        _ => "a study statement",
    }
}

/// Builds a study block from its parse.
pub(crate) fn build(p: Pair<Rule>) -> Study {
    let span = parser::span_of(&p);
    let mut items = Vec::new();
    for q in p.into_inner() {
        let at = parser::span_of(&q);
        let rule = q.as_rule();
        let mut inner = q
            .into_inner()
            .filter(|r| !format!("{:?}", r.as_rule()).starts_with("kw_"));
        let item = match rule {
            Rule::study_ranges => StudyItem::Ranges(
                inner
                    .map(|r| {
                        let mut it = r.into_inner();
                        let n = parser::name(it.next().expect("range's joint"));
                        let lo = parser::expr(it.next().expect("range's low end"));
                        let hi = parser::expr(it.next().expect("range's high end"));
                        (n, lo, hi)
                    })
                    .collect(),
                at,
            ),
            Rule::study_start => StudyItem::Start(parser::tuple(inner.next().expect("start's tuple")).items, at),
            Rule::study_pose => StudyItem::Pose(parser::tuple(inner.next().expect("pose's tuple")).items, at),
            Rule::study_trajectory => {
                let m = inner.next().expect("trajectory's motion");
                let motion = if m.as_rule() == Rule::study_sine {
                    Motion::Sine
                } else {
                    Motion::ConstantSpeed
                };
                let t = m
                    .into_inner()
                    .find(|r| r.as_rule() == Rule::tuple)
                    .expect("trajectory's tuple");
                StudyItem::Trajectory {
                    motion,
                    values: parser::tuple(t).items,
                    duration: inner.next().map(parser::expr),
                    span: at,
                }
            }
            Rule::study_point => StudyItem::Point(parser::name(inner.next().expect("point's name"))),
            Rule::study_branch => StudyItem::Branch(parser::name(inner.next().expect("branch's index"))),
            Rule::study_nodes => StudyItem::Nodes(parser::name(inner.next().expect("node count"))),
            Rule::study_sections => StudyItem::Sections(
                inner
                    .map(|r| {
                        let mut it = r.into_inner();
                        let n = parser::name(it.next().expect("section's axis"));
                        (n, parser::expr(it.next().expect("section's value")))
                    })
                    .collect(),
                at,
            ),
            _ => continue,
        };
        items.push(item);
    }
    Study { items, span }
}
