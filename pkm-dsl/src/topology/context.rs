//! The generic configurations the analysis computes on: the mechanism's
//! joints placed at random (seeded) generic instances, the velocity systems
//! and ranks of sub-mechanisms, and the idle motions to discount.

use super::*;
use crate::diagnostics::{Diagnostic, Diagnostics};
use crate::limits::MAX_ORDERING_WORK;
use crate::semantics::mechanism::{DirectionClasses, JointKind, Mechanism};
use nalgebra::DMatrix;
use screw::{Instance, VelocitySystem};
use std::collections::HashMap;

pub(super) struct Context<'a> {
    pub(super) mech: &'a Mechanism,
    pub(super) classes: DirectionClasses,
    pub(super) primary: Vec<Instance>,
    pub(super) check: Vec<Instance>,
    pub(super) incidence: Vec<Vec<usize>>,
    pub(super) rank_memo: HashMap<u64, usize>,
    pub(super) evaluations: usize,
    /// Multiply-adds spent in rank computations so far (see [`MAX_ANALYSIS_WORK`]).
    pub(super) work: u64,
    /// Local (idle) DOF of each sub-mechanism, by joint mask.
    pub(super) idle_memo: HashMap<u64, usize>,
    /// Per primary instance: the velocity system of the whole mechanism and
    /// its kernel, used by several steps of the analysis.
    pub(super) whole: Vec<(VelocitySystem, DMatrix<f64>)>,
    /// Per primary instance: the idle motions of the whole mechanism as joint
    /// rates (one row per joint variable, one column per idle DOF), and the
    /// rows of each joint.
    pub(super) idle_rates: Vec<(DMatrix<f64>, Vec<std::ops::Range<usize>>)>,
}
impl Context<'_> {
    pub(super) fn joint_mask(&self, joints: &[usize]) -> u64 {
        joints.iter().fold(0, |m, j| m | 1 << j)
    }

    /// Σf of the joints in `mask`, less the local (idle) DOF of that
    /// sub-mechanism: local DOF are not counted in f.
    pub(super) fn f_of(&mut self, mask: u64) -> usize {
        let f: usize = (0..self.mech.joints.len())
            .filter(|j| mask >> j & 1 == 1)
            .map(|j| self.mech.joints[j].kind.dof())
            .sum();
        f - self.idle_of(mask).min(f)
    }

    /// The local DOF that sub-mechanism `mask` contains: the idle motions of
    /// the whole mechanism whose joint rates vanish outside it.
    pub(super) fn idle_of(&mut self, mask: u64) -> usize {
        if let Some(&i) = self.idle_memo.get(&mask) {
            return i;
        }
        // The generic count is the least; none is below zero, so a
        // configuration that finds none settles it.
        let mut least: Option<usize> = None;
        for (rates, rows) in &self.idle_rates {
            let outside: Vec<usize> = (0..self.mech.joints.len())
                .filter(|j| mask >> j & 1 == 0)
                .flat_map(|j| rows[j].clone())
                .collect();
            let mut m = DMatrix::zeros(outside.len(), rates.ncols());
            for (r, &row) in outside.iter().enumerate() {
                m.set_row(r, &rates.row(row));
            }
            self.work += svd_work(m.nrows(), m.ncols());
            let idle = rates.ncols() - screw::rank_of_part(&m, screw::column_scale(rates)).min(rates.ncols());
            least = Some(least.map_or(idle, |l| l.min(idle)));
            if idle == 0 {
                break;
            }
        }
        let i = least.unwrap_or(0);
        self.idle_memo.insert(mask, i);
        i
    }

    /// Whether the ordering has spent its budget: [`SEARCH_BUDGET`]
    /// sub-mechanisms or [`MAX_ORDERING_WORK`] multiply-adds.
    pub(super) fn over_budget(&self) -> bool {
        self.evaluations > SEARCH_BUDGET || self.work > MAX_ORDERING_WORK
    }

    pub(super) fn actuators_of(&self, mask: u64) -> usize {
        (0..self.mech.joints.len())
            .filter(|j| mask >> j & 1 == 1 && self.mech.joints[*j].actuated)
            .count()
    }

    /// The generic rank of the loop equations of the joints in `mask`.
    pub(super) fn loop_rank(&mut self, mask: u64) -> usize {
        if let Some(&r) = self.rank_memo.get(&mask) {
            return r;
        }
        self.evaluations += 1;
        // The generic rank is the largest; a configuration that reaches the
        // most the equations' shape allows settles it.
        let mut r = 0;
        for inst in &self.primary {
            let sys = VelocitySystem::new(self.mech, inst, mask);
            self.work += svd_work(sys.loops.nrows(), sys.loops.ncols());
            r = r.max(sys.loop_rank());
            if r >= sys.max_loop_rank() {
                break;
            }
        }
        self.rank_memo.insert(mask, r);
        r
    }

    /// Σf − Σξ − I of the sub-mechanism: the running sum of Δ.
    pub(super) fn running(&mut self, mask: u64) -> i64 {
        self.f_of(mask) as i64 - self.loop_rank(mask) as i64 - self.actuators_of(mask) as i64
    }

    pub(super) fn known_links(&self, mask: u64) -> u64 {
        let mut k = 1u64;
        for (j, joint) in self.mech.joints.iter().enumerate() {
            if mask >> j & 1 == 1 {
                k |= 1 << joint.links[0] | 1 << joint.links[1];
            }
        }
        k
    }

    /// Every SOC that can come next: a path of unused joints whose end links
    /// are known and whose inner links are new.
    pub(super) fn candidates(&self, used: u64) -> Vec<Candidate> {
        let known = self.known_links(used);
        let mut out: Vec<Candidate> = Vec::new();
        let mut seen: Vec<u64> = Vec::new();
        for start in 0..self.mech.links.len() {
            if known >> start & 1 == 0 {
                continue;
            }
            let mut stack: Vec<(usize, Vec<usize>, u64)> = vec![(start, Vec::new(), 0)];
            while let Some((cur, path, inner)) = stack.pop() {
                for &j in self.incidence[cur].iter().rev() {
                    if used >> j & 1 == 1 || path.contains(&j) {
                        continue;
                    }
                    let o = self.mech.joints[j].other(cur);
                    let mut p = path.clone();
                    p.push(j);
                    if known >> o & 1 == 1 {
                        let m = self.joint_mask(&p);
                        if !seen.contains(&m) {
                            seen.push(m);
                            out.push((p, [start, o]));
                        }
                    } else if inner >> o & 1 == 0 && out.len() < CANDIDATE_CAP {
                        stack.push((o, p, inner | 1 << o));
                    }
                }
            }
        }
        out
    }
}
pub(super) fn context(mech: &Mechanism) -> Result<Context<'_>, Diagnostics> {
    let classes = DirectionClasses::new(&mech.joints, &mech.relations);
    let realize = |seeds: &[u64]| -> Result<Vec<Instance>, Diagnostic> {
        seeds.iter().map(|&s| screw::realize(mech, &classes, s)).collect()
    };
    let primary = realize(&PRIMARY_SEEDS)?;
    let check = realize(&CHECK_SEEDS)?;
    Ok(context_with(mech, classes, primary, check))
}

/// The analysis's context at given configurations: `primary` for the
/// ranks, `check` for the cross-check.
pub(super) fn context_at(mech: &Mechanism, primary: Vec<Instance>, check: Vec<Instance>) -> Context<'_> {
    context_with(
        mech,
        DirectionClasses::new(&mech.joints, &mech.relations),
        primary,
        check,
    )
}

/// [`context_at`] with the direction classes already made.
fn context_with(
    mech: &Mechanism,
    classes: DirectionClasses,
    primary: Vec<Instance>,
    check: Vec<Instance>,
) -> Context<'_> {
    let whole: Vec<(VelocitySystem, DMatrix<f64>)> = primary
        .iter()
        .map(|inst| {
            let sys = VelocitySystem::new(mech, inst, all_joints(mech.joints.len()));
            let kernel = sys.kernel();
            (sys, kernel)
        })
        .collect();
    let idle_rates = primary
        .iter()
        .zip(&whole)
        .map(|(inst, (sys, kernel))| idle_motions(mech, inst, sys, kernel))
        .collect();
    Context {
        whole,
        idle_rates,
        mech,
        incidence: mech.incidence(),
        classes,
        primary,
        check,
        rank_memo: HashMap::new(),
        evaluations: 0,
        work: 0,
        idle_memo: HashMap::new(),
    }
}
/// The idle (local) motions of the whole mechanism at one instance: motions
/// in which no R, H, C, U or S joint's point moves (seen from either of its
/// links) and no P joint slides, such as the spin of an S–S link or of an
/// S–P–S leg about the line of its centres. Returned as joint rates, with the
/// rows of each joint.
pub(super) fn idle_motions(
    mech: &Mechanism,
    inst: &Instance,
    sys: &VelocitySystem,
    kernel: &DMatrix<f64>,
) -> (DMatrix<f64>, Vec<std::ops::Range<usize>>) {
    let k = kernel.ncols();
    let mut conditions: Vec<DMatrix<f64>> = Vec::new();
    for (j, joint) in mech.joints.iter().enumerate() {
        let c = sys.joint_col[j].expect("every joint is in the system");
        if joint.kind == JointKind::P {
            conditions.push(kernel.rows(c, 1).into_owned());
            continue;
        }
        for &link in &joint.links {
            let t = sys.relative_twists(kernel, 0, link);
            conditions.push(screw::at_point(&t, &inst.points[j]).1);
        }
    }
    let total: usize = conditions.iter().map(|m| m.nrows()).sum();
    let mut rows = DMatrix::zeros(total, k);
    let mut r = 0;
    for m in &conditions {
        rows.view_mut((r, 0), (m.nrows(), k)).copy_from(m);
        r += m.nrows();
    }
    let z = if k == 0 {
        DMatrix::zeros(0, 0)
    } else {
        screw::null_space(&rows)
    };
    let motions = kernel * &z;
    let mut ranges = Vec::new();
    let mut rates = DMatrix::zeros(mech.total_dof(), z.ncols());
    let mut next = 0;
    for (j, joint) in mech.joints.iter().enumerate() {
        let c = sys.joint_col[j].expect("every joint is in the system");
        let f = joint.kind.dof();
        if z.ncols() > 0 {
            rates.view_mut((next, 0), (f, z.ncols())).copy_from(&motions.rows(c, f));
        }
        ranges.push(next..next + f);
        next += f;
    }
    (rates, ranges)
}
