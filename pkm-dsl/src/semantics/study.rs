//! The `study { … }` block: what `pkm report` samples — each actuator's
//! range, the sample input, the trajectory, the point followed, the branch,
//! the workspace's section planes and the sweep's grid nodes. Every key is
//! optional; the command line overrides each.
//!
//! ```
//! let ast = pkm_dsl::parse("mechanism m { planar; base R1* ∥ R2 ∥ R3 ∥ R4 base;
//!     study { ranges { R1 = -pi .. pi; } trajectory constant speed (1) duration 2 * pi; nodes 90; } }").unwrap();
//! let s = pkm_dsl::study::resolve(&ast.studies, &["R1".to_string()], &[], &Default::default()).unwrap();
//! assert_eq!(s.ranges, vec![Some((-std::f64::consts::PI, std::f64::consts::PI))]);
//! assert_eq!(s.nodes, Some(90));
//! ```

use crate::diagnostics::{Diagnostic, Diagnostics, Span};
use crate::syntax::expr::Expr;
pub use crate::syntax::study::{Motion, Study, StudyItem};
use std::collections::HashMap;

/// The most grid nodes per input the study may ask for (the report also
/// bounds the whole grid).
pub const MAX_NODES: usize = 1000;

/// A study with its expressions evaluated and its names checked.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Resolved {
    /// Each actuator's range (in the model's input order), where given.
    pub ranges: Vec<Option<(f64, f64)>>,
    /// The sample input.
    pub start: Option<Vec<f64>>,
    /// The sample pose (a file without a forward plan), one value per
    /// declared output.
    pub pose: Option<Vec<f64>>,
    /// The trajectory's motion and amplitudes or speeds.
    pub trajectory: Option<(Motion, Vec<f64>)>,
    /// The trajectory's duration (s).
    pub duration: Option<f64>,
    /// The point followed.
    pub point: Option<String>,
    /// The branch index.
    pub branch: Option<usize>,
    /// Section planes: axis (0 = x, 1 = y, 2 = z) and value.
    pub sections: Vec<(usize, f64)>,
    /// Grid nodes per input.
    pub nodes: Option<usize>,
}

fn item_span(item: &StudyItem) -> Span {
    match item {
        StudyItem::Ranges(_, s) | StudyItem::Start(_, s) | StudyItem::Pose(_, s) | StudyItem::Sections(_, s) => *s,
        StudyItem::Trajectory { span, .. } => *span,
        StudyItem::Point(n) | StudyItem::Branch(n) | StudyItem::Nodes(n) => n.span,
    }
}

fn item_key(item: &StudyItem) -> &'static str {
    match item {
        StudyItem::Ranges(..) => "ranges",
        StudyItem::Start(..) => "start",
        StudyItem::Pose(..) => "pose",
        StudyItem::Trajectory { .. } => "trajectory",
        StudyItem::Point(_) => "point",
        StudyItem::Branch(_) => "branch",
        StudyItem::Sections(..) => "sections",
        StudyItem::Nodes(_) => "nodes",
    }
}

/// Evaluates an expression; unknown names, unknown functions and values
/// that are not finite are errors at its span.
fn value(e: &Expr, span: Span, values: &HashMap<String, f64>, errors: &mut Diagnostics) -> f64 {
    let mut found = Vec::new();
    e.check(&|n| values.contains_key(n), &mut found);
    if !found.is_empty() {
        errors.0.extend(found);
        return 0.0;
    }
    let v = e.eval(values);
    if !v.is_finite() {
        errors.push(Diagnostic::new(span, format!("this value is {v}, not a finite number")).label("here"));
        return 0.0;
    }
    v
}

fn values_of(
    items: &[Expr],
    span: Span,
    what: &str,
    inputs: usize,
    values: &HashMap<String, f64>,
    errors: &mut Diagnostics,
) -> Vec<f64> {
    if items.len() != inputs {
        errors.push(
            Diagnostic::new(span, format!("{what} needs {inputs} values, one per actuated joint"))
                .label(format!("{} given", items.len())),
        );
    }
    items.iter().map(|e| value(e, span, values, errors)).collect()
}

/// Checks the study blocks of a file (at most one) against its actuated
/// joints `inputs` (in the model's input order) and its declared outputs'
/// names `outputs`, and evaluates them with the parameter values `values`.
///
/// Errors point at the span: a second block or a repeated key, an unknown
/// joint, a range whose low end is not below its high end, a count of
/// values other than the inputs' (the outputs' for `pose`), both `start`
/// and `pose`, a section axis other than x, y, z, a duration that is not
/// positive, nodes outside 2..=[`MAX_NODES`].
pub fn resolve(
    studies: &[Study],
    inputs: &[String],
    outputs: &[String],
    values: &HashMap<String, f64>,
) -> Result<Resolved, Diagnostics> {
    let mut errors = Diagnostics(Vec::new());
    let mut r = Resolved {
        ranges: vec![None; inputs.len()],
        ..Default::default()
    };
    if let Some(second) = studies.get(1) {
        errors.push(
            Diagnostic::new(second.span, "a mechanism has one `study` block")
                .label("a second one")
                .also(studies[0].span, "the first"),
        );
    }
    let n = inputs.len();
    let mut seen: Vec<(&str, Span)> = Vec::new();
    for item in studies.iter().flat_map(|s| &s.items) {
        let key = item_key(item);
        if let Some((_, first)) = seen.iter().find(|(k, _)| *k == key) {
            errors.push(
                Diagnostic::new(item_span(item), format!("`{key}` is given twice in the study"))
                    .label("again")
                    .also(*first, "first here"),
            );
            continue;
        }
        seen.push((key, item_span(item)));
        match item {
            StudyItem::Ranges(list, _) => {
                for (joint, lo, hi) in list {
                    let Some(i) = inputs.iter().position(|j| *j == joint.text) else {
                        errors.push(
                            Diagnostic::new(joint.span, format!("`{}` is not an actuated joint", joint.text))
                                .label("no such input")
                                .note(format!("the actuated joints: {}", inputs.join(", "))),
                        );
                        continue;
                    };
                    let (a, b) = (
                        value(lo, joint.span, values, &mut errors),
                        value(hi, joint.span, values, &mut errors),
                    );
                    if a >= b {
                        errors.push(
                            Diagnostic::new(
                                joint.span,
                                format!("the range of `{}` is {a} .. {b}: empty or inverted", joint.text),
                            )
                            .label("the low end must be below the high end"),
                        );
                    }
                    if r.ranges[i].replace((a, b)).is_some() {
                        errors.push(
                            Diagnostic::new(joint.span, format!("`{}`'s range is given twice", joint.text))
                                .label("again"),
                        );
                    }
                }
            }
            StudyItem::Start(v, span) => r.start = Some(values_of(v, *span, "`start`", n, values, &mut errors)),
            StudyItem::Pose(v, span) => {
                if v.len() != outputs.len() {
                    errors.push(
                        Diagnostic::new(
                            *span,
                            format!("`pose` needs {} values, one per declared output", outputs.len()),
                        )
                        .label(format!("{} given", v.len()))
                        .note(if outputs.is_empty() {
                            "the file declares no outputs".to_string()
                        } else {
                            format!("the outputs: {}", outputs.join(", "))
                        }),
                    );
                }
                r.pose = Some(v.iter().map(|e| value(e, *span, values, &mut errors)).collect());
            }
            StudyItem::Trajectory {
                motion,
                values: v,
                duration,
                span,
            } => {
                let what = if *motion == Motion::Sine {
                    "the amplitude"
                } else {
                    "the speed"
                };
                r.trajectory = Some((*motion, values_of(v, *span, what, n, values, &mut errors)));
                if let Some(d) = duration {
                    let t = value(d, *span, values, &mut errors);
                    if t <= 0.0 {
                        errors.push(
                            Diagnostic::new(*span, format!("the duration is {t} s; it must be positive")).label("here"),
                        );
                    }
                    r.duration = Some(t);
                }
            }
            StudyItem::Point(p) => r.point = Some(p.text.clone()),
            StudyItem::Branch(b) => match b.text.parse::<usize>() {
                Ok(k) => r.branch = Some(k),
                Err(_) => errors.push(Diagnostic::new(b.span, "a branch index is a small whole number").label("here")),
            },
            StudyItem::Nodes(k) => match k.text.parse::<usize>() {
                Ok(c) if (2..=MAX_NODES).contains(&c) => r.nodes = Some(c),
                _ => errors.push(
                    Diagnostic::new(k.span, format!("grid nodes per input must be 2 to {MAX_NODES}"))
                        .label("out of range"),
                ),
            },
            StudyItem::Sections(list, _) => {
                for (axis, e) in list {
                    match ["x", "y", "z"].iter().position(|a| *a == axis.text) {
                        Some(i) => r.sections.push((i, value(e, axis.span, values, &mut errors))),
                        None => errors.push(
                            Diagnostic::new(
                                axis.span,
                                format!("a section's axis is x, y or z, found `{}`", axis.text),
                            )
                            .label("here"),
                        ),
                    }
                }
            }
        }
    }
    if let (Some((_, start)), Some((_, pose))) = (
        seen.iter().find(|(k, _)| *k == "start"),
        seen.iter().find(|(k, _)| *k == "pose"),
    ) {
        errors.push(
            Diagnostic::new(*pose, "the sample is an input (`start`) or a pose (`pose`), not both")
                .label("a pose")
                .also(*start, "an input"),
        );
    }
    errors.into_result(r)
}
