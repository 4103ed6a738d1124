//! The order of the single open chains: a search for the order that
//! keeps each SOC's constraint degree smallest (greedy first, exhaustive
//! within a budget), the ordered SOCs with their ξ_L and Δ, and the SKCs
//! they form.

use super::*;
use crate::diagnostics::{Diagnostic, Diagnostics};
use crate::limits::MAX_ORDERING_WORK;
use crate::semantics::mechanism::Mechanism;
use std::collections::HashMap;

/// How many sub-mechanisms the exhaustive ordering search may evaluate
/// before it gives up (and says so).
pub(super) const SEARCH_BUDGET: usize = 4_000;
/// The most candidate SOCs one state may have before the search gives up.
pub(super) const CANDIDATE_CAP: usize = 4096;
/// The multiply-adds of one singular value decomposition of an r × c matrix, roughly.
pub(super) fn svd_work(r: usize, c: usize) -> u64 {
    (r * c * r.min(c)) as u64
}
/// The mask of all `n` joints (n ≤ 64).
pub(super) fn all_joints(n: usize) -> u64 {
    if n == 64 {
        u64::MAX
    } else {
        (1u64 << n) - 1
    }
}
pub(super) type Cost = (i64, i64);
/// A candidate SOC: its joints in path order and its two end links.
pub(super) type Candidate = (Vec<usize>, [usize; 2]);
pub(super) struct Search<'c, 'a> {
    pub(super) ctx: &'c mut Context<'a>,
    pub(super) all: u64,
    pub(super) best: HashMap<u64, Option<(Cost, usize)>>,
    pub(super) choices: HashMap<u64, Vec<Candidate>>,
    pub(super) exhausted: bool,
}
impl Search<'_, '_> {
    /// The least (Σ|Δ|, −#SKC) that completes the decomposition from `used`.
    pub(super) fn solve(&mut self, used: u64) -> Option<Cost> {
        if used == self.all {
            return Some((0, 0));
        }
        if let Some(b) = self.best.get(&used) {
            return b.map(|(c, _)| c);
        }
        if self.ctx.over_budget() {
            self.exhausted = true;
            return None;
        }
        let run_before = self.ctx.running(used);
        let cands = self.ctx.candidates(used);
        if cands.len() >= CANDIDATE_CAP {
            self.exhausted = true;
            return None;
        }
        let mut best: Option<(Cost, usize)> = None;
        for (i, (path, _)) in cands.iter().enumerate() {
            if self.ctx.over_budget() {
                self.exhausted = true;
                return None;
            }
            let next = used | self.ctx.joint_mask(path);
            let run_after = self.ctx.running(next);
            if run_after < 0 {
                continue;
            }
            let delta = run_after - run_before;
            let step = (delta.abs(), if run_after == 0 { -1 } else { 0 });
            if let Some(rest) = self.solve(next) {
                let total = (step.0 + rest.0, step.1 + rest.1);
                if best.is_none_or(|(b, _)| total < b) {
                    best = Some((total, i));
                }
            }
        }
        self.best.insert(used, best);
        self.choices.insert(used, cands);
        best.map(|(c, _)| c)
    }
}
/// A greedy ordering (least |Δ| at each step, first candidate on ties), if it
/// reaches the end with every Δ = 0.
pub(super) fn greedy_order(ctx: &mut Context, all: u64) -> Option<Vec<Candidate>> {
    let mut used = 0u64;
    let mut order = Vec::new();
    while used != all {
        let run_before = ctx.running(used);
        let cands = ctx.candidates(used);
        let mut pick = None;
        for c in cands {
            // Out of budget: the search that follows stops at once and says so.
            if ctx.over_budget() {
                return None;
            }
            let next = used | ctx.joint_mask(&c.0);
            if ctx.running(next) == run_before && run_before == 0 {
                pick = Some(c);
                break;
            }
        }
        let c = pick?;
        used |= ctx.joint_mask(&c.0);
        order.push(c);
    }
    Some(order)
}
/// The order of single open chains: greedy first, a step of least |Δ| each
/// time. If it reaches Σ|Δ| = 0 it is optimal (every Δ is 0, so every SOC
/// is its own SKC: the most SKCs); otherwise the bounded exhaustive search
/// for the least Σ|Δ|.
pub(super) fn soc_order(
    mech: &Mechanism,
    ctx: &mut Context,
    all: u64,
    loops: usize,
) -> Result<Vec<Candidate>, Diagnostics> {
    Ok(match greedy_order(ctx, all) {
        Some(order) => order,
        None => {
            let mut search = Search {
                ctx,
                all,
                best: HashMap::new(),
                choices: HashMap::new(),
                exhausted: false,
            };
            let found = search.solve(0);
            let exhausted = search.exhausted;
            let Search { best, choices, .. } = search;
            if found.is_none() {
                let d = if exhausted {
                    Diagnostic::new(
                        mech.name_span(),
                        format!(
                            "the ordered SOC search gave up after {} sub-mechanisms and {:.1e} multiply-adds ({} loops); the limits are {SEARCH_BUDGET} and {MAX_ORDERING_WORK:.1e}",
                            ctx.evaluations, ctx.work as f64, loops
                        ),
                    )
                    .label("too many orderings to compare")
                    .note(
                        "no ordering was found whose Σ|Δ| is zero; the exhaustive search for the least Σ|Δ| is bounded",
                    )
                } else {
                    let first = mech
                        .joints
                        .iter()
                        .find(|j| j.actuated)
                        .map_or(mech.name_span(), |j| j.span);
                    Diagnostic::new(
                        first,
                        "no ordering of single open chains keeps every running Σ Δ non-negative: the actuators cannot drive this mechanism",
                    )
                    .label("actuated here")
                };
                return Err(d.into());
            }
            let mut order = Vec::new();
            let mut used = 0u64;
            while used != all {
                let (_, i) = best[&used].expect("a solved state has a choice");
                let c = choices[&used][i].clone();
                used |= ctx.joint_mask(&c.0);
                order.push(c);
            }
            order
        }
    })
}
/// The SOCs of the chosen order, with their ξ_L and Δ.
pub(super) fn ordered_socs(ctx: &mut Context, order: Vec<Candidate>) -> Vec<Soc> {
    let mut socs = Vec::new();
    let mut used = 0u64;
    let mut run_before = 0i64;
    for (mut path, mut ends) in order {
        // Write a chain that ends on the base from its other end, as the papers do.
        if ends[0] == 0 && ends[1] != 0 {
            path.reverse();
            ends = [ends[1], ends[0]];
        }
        let mask = ctx.joint_mask(&path);
        let xi = ctx.loop_rank(used | mask) - ctx.loop_rank(used);
        let run_after = ctx.running(used | mask);
        socs.push(Soc {
            dof: ctx.f_of(mask),
            actuators: ctx.actuators_of(mask),
            xi,
            delta: (run_after - run_before) as i32,
            notation: notation(ctx, &path),
            joints: path,
            ends,
        });
        used |= mask;
        run_before = run_after;
    }
    socs
}
/// The SKCs: the SOCs grouped where the running Σ Δ returns to zero, each
/// with its coupling degree κ = Σ|Δ|/2; and the mechanism's κ, the largest.
pub(super) fn sub_kinematic_chains(socs: &[Soc]) -> (Vec<Skc>, usize) {
    let mut skcs = Vec::new();
    let mut start = 0;
    let mut run = 0;
    for (j, soc) in socs.iter().enumerate() {
        run += soc.delta;
        if run == 0 {
            let kappa = socs[start..=j]
                .iter()
                .map(|s| s.delta.unsigned_abs() as usize)
                .sum::<usize>()
                / 2;
            skcs.push(Skc {
                socs: start..j + 1,
                kappa,
                kind: None,
            });
            start = j + 1;
        }
    }
    let kappa = skcs.iter().map(|s| s.kappa).max().unwrap_or(0);
    (skcs, kappa)
}
/// ξ_Lj and Δ_j of a given ordering of SOCs (each a list of joint names), for
/// studying orderings other than the chosen one.
pub fn evaluate_order(mech: &Mechanism, order: &[&[&str]]) -> Result<Vec<(usize, i32)>, Diagnostics> {
    let mut ctx = context(mech)?;
    let mut used = 0u64;
    let mut out = Vec::new();
    for soc in order {
        let mut mask = 0u64;
        for name in *soc {
            let j = mech
                .joint_index(name)
                .ok_or_else(|| Diagnostic::global(format!("unknown joint `{name}`")))?;
            mask |= 1 << j;
        }
        let xi = ctx.loop_rank(used | mask) - ctx.loop_rank(used);
        let delta = ctx.f_of(mask) as i64 - ctx.actuators_of(mask) as i64 - xi as i64;
        out.push((xi, delta as i32));
        used |= mask;
    }
    Ok(out)
}
