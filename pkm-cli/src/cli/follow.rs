//! `pkm fk FILE --csv TRAJECTORY --follow-from POSE`: the forward position
//! along a trajectory of inputs, from the assembly the mechanism is in at
//! a known pose, each row the previous row's assembly continued
//! ([`pkm_runtime::fk_follow`]): `tracked` (Newton from the previous
//! assembly and a certificate that no other lies between them),
//! `resolved` (the certificate failed; the full forward solution's
//! assembly nearest the previous, κ = 1), or `possible` (a verified
//! assembly whose continuity nothing proves, κ ≥ 2). A row that reaches
//! no assembly says why, and the next row starts again from the last
//! assembly reached.
//!
//! Any mechanism with an inverse plan: a κ = 1 file asking for
//! `fk_numeric` follows its virtual variable (and resolves by its full
//! solution); every other follows the pose its inverse plan is given.

use super::csv::Solver;
use super::failure::{Failure, Kind};
use super::solve::{input_columns, input_values, load, ordered_pose, output_names, output_values, Configuration};
use super::solve::{Loaded, Request, Units};
use super::table::{number_of, Branch, Cell, Column};
use pkm_runtime::fk_follow::{self, Followed};
use pkm_runtime::fk_numeric::VirtualPlan;
use pkm_runtime::plan::Plan;
use std::cell::RefCell;

/// `pkm fk --follow-from`: the file loaded and planned once, the
/// trajectory's assembly carried from row to row.
pub struct Follow<'r> {
    r: &'r Request<'r>,
    l: Loaded,
    inverse: Plan,
    /// The virtual plan of a κ = 1 file asking for `fk_numeric`.
    numeric: Option<VirtualPlan>,
    /// The closed-form forward plan of a coupled file its steps close all
    /// the same (three spheres): an unproven step is resolved by it.
    forward: Option<Plan>,
    /// A coupled file whose legs each end in a ball, without either: an
    /// unproven step is resolved by every assembly of the pose equations.
    balls: Option<pkm_runtime::ball_legs::BallLegs>,
    /// The actuated joints, in the order a row gives them.
    inputs: Vec<usize>,
    /// Whether each of the inverse plan's given values is an angle.
    angles: Vec<bool>,
    /// The last assembly reached.
    last: RefCell<Followed>,
}

impl<'r> Follow<'r> {
    /// Loads and plans the file of `r`, and assembles it at `pose` (the
    /// declared outputs by name) on the inverse plan's branch `branch`
    /// (the first that solves when `None`).
    pub fn new(r: &'r Request<'r>, pose: &[(String, f64)], branch: Option<usize>) -> Result<Follow<'r>, Failure> {
        let l = load(r)?;
        let inverse = l.compiled.inverse().cloned().map_err(|d| r.parse_failure(d))?;
        let ordered = ordered_pose(r, &l, pose)?;
        let angles: Vec<bool> = output_names(&l).into_iter().map(|(_, a)| a).collect();
        let branches = 1usize << inverse.branches;
        let tried: Vec<usize> = match branch {
            Some(b) if b >= branches => {
                return Err(Failure::input(format!(
                    "--branch {b}: the inverse plan has {branches} branches, numbered from 0"
                )))
            }
            Some(b) => vec![b],
            None => (0..branches).collect(),
        };
        let mut why = String::new();
        let mut start = None;
        for b in tried {
            match fk_follow::at_pose(&l.model, &inverse, &ordered, b) {
                Ok(s) => {
                    start = Some(s);
                    break;
                }
                Err(e) => why = e.to_string(),
            }
        }
        let Some(start) = start else {
            return Err(Failure::new(
                Kind::Unreachable,
                format!("--follow-from: no assembly at the start pose ({why})"),
            ));
        };
        let wants_numeric = pkm_dsl::planner_numeric::by_virtual_variable(&l.compiled.analysis);
        let numeric = if wants_numeric {
            Some(pkm_dsl::planner_numeric::forward_numeric_plan(&l.compiled.analysis).map_err(|d| r.parse_failure(d))?)
        } else {
            None
        };
        let inputs = l.model.inputs();
        // The virtual plan's start: its assembly at the start's inputs
        // that is the start pose's.
        let start = match &numeric {
            None => start,
            Some(vp) => {
                let q: Vec<f64> = inputs.iter().map(|&j| start.solution.values[j]).collect();
                let all =
                    pkm_runtime::fk_numeric::solve(&l.model, vp, &q).map_err(|e| Failure::input(e.to_string()))?;
                let scale = pkm_runtime::kinematics::model_scale(&l.model);
                let same = all
                    .iter()
                    .find(|a| fk_follow::distance(&a.solution, &start.solution, scale) <= 1e-9)
                    .ok_or_else(|| {
                        Failure::new(
                            Kind::Unreachable,
                            "--follow-from: the forward solution does not find the start pose's assembly".to_string(),
                        )
                    })?;
                Followed::from_assembly(same)
            }
        };
        let forward = if numeric.is_none() {
            l.compiled.forward().ok().cloned()
        } else {
            None
        };
        let balls = (numeric.is_none() && forward.is_none() && l.compiled.analysis.topology.kappa != 0)
            .then(|| pkm_runtime::ball_legs::BallLegs::for_outputs(&l.model, &l.outputs).ok())
            .flatten();
        Ok(Follow {
            r,
            l,
            inverse,
            numeric,
            forward,
            balls,
            inputs,
            angles,
            last: RefCell::new(start),
        })
    }
}

impl Solver for Follow<'_> {
    fn given(&self) -> Vec<Column> {
        input_columns(self.r, &self.l, &self.inputs)
    }

    fn columns(&self) -> Vec<Column> {
        let units = Units::of(self.r, &self.l);
        let mut columns = vec![Column {
            name: "follow".into(),
            unit: None,
            csv_only: false,
        }];
        columns.extend(
            output_names(&self.l)
                .into_iter()
                .map(|(name, angle)| Column::new(name, units.of_kind(angle))),
        );
        columns
    }

    fn choices(&self) -> usize {
        self.numeric
            .as_ref()
            .map_or(self.inverse.branches, |vp| vp.plan.branches)
    }

    fn branches(&self, given: &[f64]) -> Result<Vec<Branch>, Failure> {
        let q = input_values(self.r, &self.l.model, &self.inputs, "--csv", given)?;
        let mut last = self.last.borrow_mut();
        let next = match &self.numeric {
            Some(vp) => fk_follow::by_virtual(&self.l.model, vp, &q, &last),
            None => match (&self.forward, &self.balls) {
                (Some(f), _) => fk_follow::by_pose_or_forward(&self.l.model, &self.inverse, f, &self.angles, &q, &last),
                (None, Some(b)) => fk_follow::by_pose_or_balls(
                    &self.l.model,
                    &self.inverse,
                    b,
                    &self.l.outputs,
                    &self.angles,
                    &q,
                    &last,
                ),
                (None, None) => fk_follow::by_pose(&self.l.model, &self.inverse, &self.angles, &q, &last),
            },
        };
        let signs = last.signs.clone();
        let row = match next {
            Ok(n) => {
                let c = Configuration {
                    poses: n.solution.poses.clone(),
                    values: n.solution.values.clone(),
                };
                let mut cells = vec![Cell::Text(n.how.text())];
                cells.extend(
                    output_values(&self.l, &c)
                        .into_iter()
                        .zip(&self.angles)
                        .map(|(v, &a)| Cell::Num(self.r.shown_value(v, a))),
                );
                let b = Branch {
                    number: number_of(&n.signs),
                    signs: n.signs.clone(),
                    values: Ok(cells),
                };
                *last = n;
                b
            }
            Err(e) => Branch {
                number: number_of(&signs),
                signs,
                values: Err(e.to_string()),
            },
        };
        Ok(vec![row])
    }
}
