//! What the report samples: the command line over the file's study block
//! over defaults, each value checked against its limits, and the table of
//! what was used and where it came from.

use super::html::{html_escape, tuple_text};
use super::loaded::{default_point, joint_unit, point_of, reach, signs, Loaded, Plan};
use super::{invalid, ReportError, ReportOptions, MAX_DURATION, MAX_GRID};
use pkm_dsl::study::{Motion, Resolved};
use pkm_runtime::model::{JointType, Model};
use pkm_runtime::velocity;
use pkm_runtime::workspace::Grid;
use std::fmt::Write as _;

/// Where a setting came from.
#[derive(Clone, Copy)]
pub(super) enum Origin {
    Command,
    Study,
    Default,
}

impl Origin {
    fn text(self) -> &'static str {
        match self {
            Origin::Command => "command line",
            Origin::Study => "study block",
            Origin::Default => "default",
        }
    }
}

/// The first of: the command line's value, the study's, a default.
fn pick<T>(command: Option<T>, study: Option<T>, default: impl FnOnce() -> T) -> (T, Origin) {
    match (command, study) {
        (Some(v), _) => (v, Origin::Command),
        (None, Some(v)) => (v, Origin::Study),
        (None, None) => (default(), Origin::Default),
    }
}

/// The grid nodes per input that keep a grid over `inputs` of them within
/// about 64 000 nodes (40 each for three, 15 for four, 9 for five, 6 for
/// six): the default for the workspace's sweep (at most three inputs) and
/// the singularities' cap over four or more.
pub(super) fn default_nodes(inputs: usize) -> usize {
    match inputs {
        1 => 721,
        2 => 200,
        n => (2..=40usize)
            .rev()
            .find(|k| k.checked_pow(n as u32).is_some_and(|t| t <= 64_000))
            .unwrap_or(2),
    }
}

#[cfg(test)]
#[test]
fn default_nodes_fit_the_grid() {
    for (n, want) in [(1, 721), (2, 200), (3, 40), (4, 15), (5, 9), (6, 6), (17, 2)] {
        assert_eq!(default_nodes(n), want, "{n} inputs");
        assert!(check_nodes(want, n).is_ok(), "{n} inputs");
    }
}

/// Checks grid nodes against their limits.
pub(super) fn check_nodes(nodes: usize, inputs: usize) -> Result<(), ReportError> {
    let total = (0..inputs).try_fold(1usize, |t, _| t.checked_mul(nodes));
    if !(2..=pkm_dsl::study::MAX_NODES).contains(&nodes) || total.is_none_or(|t| t > MAX_GRID) {
        return Err(invalid(format!(
            "--nodes {nodes}: grid nodes per input must be 2 to {} and the whole grid (nodes^{inputs}) at most {MAX_GRID} \
             nodes, i.e. at most {} per input here",
            pkm_dsl::study::MAX_NODES,
            (2..=pkm_dsl::study::MAX_NODES)
                .take_while(|k| k.checked_pow(inputs as u32).is_some_and(|t| t <= MAX_GRID))
                .last()
                .unwrap_or(2)
        )));
    }
    Ok(())
}

/// Checks a trajectory's duration against its limits.
pub(super) fn check_duration(duration: f64) -> Result<(), ReportError> {
    if !(duration > 0.0 && duration <= MAX_DURATION) {
        return Err(invalid(format!(
            "--duration {duration}: the trajectory's duration must be above 0 and at most {MAX_DURATION} s"
        )));
    }
    Ok(())
}

/// Everything the report samples, resolved.
pub(super) struct Settings {
    pub(super) ranges: (Vec<(f64, f64)>, Origin),
    pub(super) nodes: (usize, Origin),
    pub(super) branch: (usize, Origin),
    pub(super) point: (String, Origin),
    pub(super) start: (Vec<f64>, Origin),
    pub(super) motion: (Motion, Vec<f64>, Origin),
    pub(super) duration: (f64, Origin),
    pub(super) sections: (Vec<(usize, f64)>, Origin),
}

/// The start: `wanted` if some branch reaches it, else the node of a coarse
/// grid over `ranges` nearest `wanted` (relative to each range) that some
/// branch reaches.
fn reachable_start(
    model: &Model,
    plan: &Plan,
    ranges: &[(f64, f64)],
    wanted: &[f64],
    branch: Option<usize>,
) -> Option<Vec<f64>> {
    let choices = plan.choices();
    let branches: Vec<usize> = match branch {
        Some(b) => vec![b],
        None => (0..1usize << choices).collect(),
    };
    let reached = |q: &[f64]| {
        branches
            .iter()
            .any(|&b| plan.solve(model, q, &signs(choices, b)).is_ok())
    };
    if reached(wanted) {
        return Some(wanted.to_vec());
    }
    let per = match ranges.len() {
        1 => 721,
        2 => 41,
        _ => 13,
    };
    let grid = Grid {
        ranges: ranges.to_vec(),
        counts: vec![per; ranges.len()],
    };
    let mut q = vec![0.0; ranges.len()];
    let mut best: Option<(f64, Vec<f64>)> = None;
    for index in 0..grid.len() {
        grid.node(index, &mut q);
        let d: f64 = q
            .iter()
            .zip(wanted)
            .zip(ranges)
            .map(|((a, b), (lo, hi))| ((a - b) / (hi - lo)).powi(2))
            .sum();
        if best.as_ref().is_some_and(|(bd, _)| *bd <= d) {
            continue;
        }
        if reached(&q) {
            best = Some((d, q.clone()));
        }
    }
    best.map(|(_, q)| q)
}

/// Resolves the command line over the study block over the defaults, and
/// checks every value.
pub(super) fn settings(
    l: &Loaded,
    plan: &Plan,
    study: &Resolved,
    o: &ReportOptions,
    file: &str,
) -> Result<Settings, ReportError> {
    let inputs = l.model.inputs();
    let r = Resolving {
        l,
        plan,
        study,
        o,
        file,
        names: inputs.iter().map(|&j| l.model.joints[j].name.as_str()).collect(),
        inputs,
    };
    let n = r.inputs.len();
    let ranges = r.ranges()?;
    // The workspace sweeps at most three inputs (the others held); the
    // singularities' sweep over all of them takes fewer nodes each.
    let nodes = pick(o.nodes, study.nodes, || default_nodes(n.min(3)));
    check_nodes(nodes.0, n.min(3))?;
    let branch_given = r.branch_given()?;
    let start = r.start(&ranges.0, branch_given)?;
    let branch = r.branch(&start.0, branch_given)?;
    // Cranks that turn fully (every input a revolute over a whole turn).
    let full_turns = r
        .inputs
        .iter()
        .zip(&ranges.0)
        .all(|(&j, (lo, hi))| full_turn(&l.model, j, *lo, *hi));
    let motion = r.motion(&ranges.0, full_turns)?;
    let duration = pick(o.duration, study.duration, || {
        if motion.0 == Motion::ConstantSpeed && full_turns {
            std::f64::consts::TAU
        } else {
            5.0
        }
    });
    check_duration(duration.0)?;
    let point = r.point()?;
    let sections = if !o.sections.is_empty() {
        (o.sections.clone(), Origin::Command)
    } else if !study.sections.is_empty() {
        (study.sections.clone(), Origin::Study)
    } else {
        (Vec::new(), Origin::Default)
    };
    Ok(Settings {
        ranges,
        nodes,
        branch,
        point,
        start,
        motion,
        duration,
        sections,
    })
}

/// Whether joint `j` over `lo ..= hi` is a crank that turns fully.
fn full_turn(model: &Model, j: usize, lo: f64, hi: f64) -> bool {
    model.joints[j].kind != JointType::P && hi - lo >= std::f64::consts::TAU - 1e-6
}

/// What resolving the settings reads: the file, its forward plan, the study
/// block, the command line, and the actuated joints with their names.
struct Resolving<'a> {
    l: &'a Loaded,
    plan: &'a Plan,
    study: &'a Resolved,
    o: &'a ReportOptions,
    /// The file's path as its errors show it.
    file: &'a str,
    inputs: Vec<usize>,
    names: Vec<&'a str>,
}

impl Resolving<'_> {
    /// An error unless `v` has one finite value per input; `what` names it.
    fn count(&self, what: &str, v: &[f64]) -> Result<(), ReportError> {
        let n = self.inputs.len();
        if v.len() != n {
            return Err(invalid(format!(
                "{what} has {} values; {} has {n} actuated joints ({})",
                v.len(),
                self.file,
                self.names.join(", ")
            )));
        }
        if let Some(x) = v.iter().find(|x| !x.is_finite()) {
            return Err(invalid(format!("{what}: {x} is not a finite number")));
        }
        Ok(())
    }

    /// Ranges: per input, from the command line (all), the study, or the
    /// geometry (a whole turn, or ± the mechanism's reach for a slider).
    fn ranges(&self) -> Result<(Vec<(f64, f64)>, Origin), ReportError> {
        let (model, study, o) = (&self.l.model, self.study, self.o);
        let n = self.inputs.len();
        let size = reach(model);
        let ranges = if o.ranges.is_empty() {
            let mut from = Origin::Study;
            let r: Vec<(f64, f64)> = study
                .ranges
                .iter()
                .zip(&self.inputs)
                .map(|(r, &j)| {
                    r.unwrap_or_else(|| {
                        from = if study.ranges.iter().any(Option::is_some) {
                            Origin::Study
                        } else {
                            Origin::Default
                        };
                        match model.joints[j].kind {
                            JointType::P => (-size, size),
                            _ => (-std::f64::consts::PI, std::f64::consts::PI),
                        }
                    })
                })
                .collect();
            (r, from)
        } else {
            if o.ranges.len() != n {
                return Err(invalid(format!(
                    "--ranges: expected {n} ranges, one per actuated joint of {} ({}); got {}",
                    self.file,
                    self.names.join(", "),
                    o.ranges.len()
                )));
            }
            (o.ranges.clone(), Origin::Command)
        };
        for (k, (lo, hi)) in ranges.0.iter().enumerate() {
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(invalid(format!(
                    "the range of {} is {lo}:{hi}: empty or inverted",
                    self.names[k]
                )));
            }
        }
        Ok(ranges)
    }

    /// The branch the command line or the study gives, checked against the plan's.
    fn branch_given(&self) -> Result<Option<usize>, ReportError> {
        let choices = self.plan.choices();
        let given = self.o.branch.or(self.study.branch);
        if let Some(b) = given {
            if b >= 1 << choices {
                return Err(invalid(format!(
                    "--branch {b}: {} has {} branches (0 to {})",
                    self.file,
                    1usize << choices,
                    (1usize << choices) - 1
                )));
            }
        }
        Ok(given)
    }

    /// The sample input and the trajectory's start: given, else the node
    /// nearest the ranges' middles that some branch (or the given one) reaches.
    fn start(&self, ranges: &[(f64, f64)], branch_given: Option<usize>) -> Result<(Vec<f64>, Origin), ReportError> {
        let model = &self.l.model;
        // The ranges' middles; a crank that turns fully 30° past it, off the
        // dead centres that a base line along x gives at 0.
        let middle: Vec<f64> = ranges
            .iter()
            .zip(&self.inputs)
            .map(|(&(lo, hi), &j)| {
                (lo + hi) / 2.0
                    + if full_turn(model, j, lo, hi) {
                        std::f64::consts::FRAC_PI_6
                    } else {
                        0.0
                    }
            })
            .collect();
        Ok(match (&self.o.start, &self.study.start) {
            (Some(s), _) => {
                self.count("--start", s)?;
                (s.clone(), Origin::Command)
            }
            (None, Some(s)) => {
                self.count("the study's start", s)?;
                (s.clone(), Origin::Study)
            }
            (None, None) => (
                reachable_start(model, self.plan, ranges, &middle, branch_given).ok_or_else(|| {
                    invalid(format!(
                        "no node of the ranges {ranges:?} is reachable{}: give reachable ranges (--ranges or the study \
                         block)",
                        branch_given.map(|b| format!(" on branch {b}")).unwrap_or_default()
                    ))
                })?,
                Origin::Default,
            ),
        })
    }

    /// The branch: the given one, else the first reachable and regular at the start.
    fn branch(&self, start: &[f64], branch_given: Option<usize>) -> Result<(usize, Origin), ReportError> {
        if let Some(b) = branch_given {
            let from = if self.o.branch.is_some() {
                Origin::Command
            } else {
                Origin::Study
            };
            return Ok((b, from));
        }
        let (model, outputs) = (&self.l.model, &self.l.outputs);
        let choices = self.plan.choices();
        let mut fallback = None;
        for b in 0..1usize << choices {
            let Ok(v) = self.plan.solve(model, start, &signs(choices, b)) else {
                continue;
            };
            fallback.get_or_insert(b);
            let regular = outputs.is_empty()
                || velocity::jacobians(model, &v, outputs).is_ok_and(|j| j.singularity == velocity::Singularity::None);
            if regular {
                return Ok((b, Origin::Default));
            }
        }
        let b = fallback.ok_or_else(|| invalid(format!("no branch reaches the start {}", tuple_text(start, 4))))?;
        Ok((b, Origin::Default))
    }

    /// The trajectory's law and its amplitudes or speeds.
    fn motion(&self, ranges: &[(f64, f64)], full_turns: bool) -> Result<(Motion, Vec<f64>, Origin), ReportError> {
        Ok(match (&self.o.amplitude, &self.o.speed, &self.study.trajectory) {
            (Some(a), _, _) => {
                self.count("--amplitude", a)?;
                (Motion::Sine, a.clone(), Origin::Command)
            }
            (None, Some(s), _) => {
                self.count("--speed", s)?;
                (Motion::ConstantSpeed, s.clone(), Origin::Command)
            }
            (None, None, Some((m, v))) => {
                self.count("the study's trajectory", v)?;
                (*m, v.clone(), Origin::Study)
            }
            // Cranks that turn fully turn at 1 rad/s; otherwise a sine of 5 % of each range.
            _ if full_turns => (Motion::ConstantSpeed, vec![1.0; self.inputs.len()], Origin::Default),
            _ => (
                Motion::Sine,
                ranges.iter().map(|(lo, hi)| 0.05 * (hi - lo)).collect(),
                Origin::Default,
            ),
        })
    }

    /// The point followed, which must be a named point or a joint.
    fn point(&self) -> Result<(String, Origin), ReportError> {
        let model = &self.l.model;
        let point = pick(self.o.point.clone(), self.study.point.clone(), || default_point(self.l));
        if point_of(model, &point.0).is_none() {
            let mut known: Vec<String> = model.points.iter().map(|p| p.name.clone()).collect();
            known.extend(model.joints.iter().map(|j| j.name.clone()));
            return Err(invalid(format!(
                "no point `{}` in {} (its named points and joints: {})",
                point.0,
                self.file,
                known.join(", ")
            )));
        }
        Ok(point)
    }
}

/// The settings table.
pub(super) fn settings_html(l: &Loaded, s: &Settings, unit: &str) -> String {
    let model = &l.model;
    let inputs = model.inputs();
    let mut h = String::from(
        "<h2>What was sampled</h2><table><tr><th class=l>setting</th><th class=l>value</th><th class=l>from</th></tr>",
    );
    let mut row = |k: &str, v: String, from: Origin| {
        let _ = writeln!(
            h,
            "<tr><td class=l>{k}</td><td class=l>{}</td><td class=l>{}</td></tr>",
            html_escape(&v),
            from.text()
        );
    };
    for (k, &j) in inputs.iter().enumerate() {
        let (lo, hi) = s.ranges.0[k];
        row(
            &format!("range of {}", model.joints[j].name),
            format!("{lo:.4} .. {hi:.4} {}", joint_unit(model, j, unit)),
            s.ranges.1,
        );
    }
    row("grid nodes per input", s.nodes.0.to_string(), s.nodes.1);
    row("sample input (start)", tuple_text(&s.start.0, 4), s.start.1);
    row("branch", s.branch.0.to_string(), s.branch.1);
    row("point followed", s.point.0.clone(), s.point.1);
    row(
        "trajectory",
        match s.motion.0 {
            Motion::Sine => format!("sine: q = start + {}·sin(πt)", tuple_text(&s.motion.1, 4)),
            Motion::ConstantSpeed => format!("constant speed: q = start + {}·t", tuple_text(&s.motion.1, 4)),
        },
        s.motion.2,
    );
    row("duration", format!("{:.4} s", s.duration.0), s.duration.1);
    row(
        "sections",
        if s.sections.0.is_empty() {
            "none".into()
        } else {
            s.sections
                .0
                .iter()
                .map(|(k, v)| format!("{} = {v}", ["x", "y", "z"][*k]))
                .collect::<Vec<_>>()
                .join(", ")
        },
        s.sections.1,
    );
    h.push_str("</table>\n");
    h
}
