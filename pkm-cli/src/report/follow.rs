//! Sweeps that follow one assembly by continuity, as the trajectory does
//! (`pkm_runtime::workspace::follow`): the grid's start node takes the
//! followed branch's solution at the sample, every other node the solution
//! nearest the one continued from a neighbour, whichever branch of the plan
//! it is; and what the page says of where the branches meet.

use super::html::sign_text;
use super::loaded::{signs, Loaded, Plan};
use pkm_runtime::workspace::{follow, Continuity, Followed, Grid};
use std::collections::BTreeMap;

/// Every branch's solution at `given`: its index in the plan's order (as
/// `pkm fk` numbers branches) and its joint values.
pub(super) fn every_branch(l: &Loaded, plan: &Plan, given: &[f64]) -> Vec<(usize, Vec<f64>)> {
    let choices = plan.choices();
    (0..1usize << choices)
        .filter_map(|b| plan.solve(&l.model, given, &signs(choices, b)).ok().map(|v| (b, v)))
        .collect()
}

/// The grid node nearest `at` (each value to its nearest node).
pub(super) fn nearest_node(grid: &Grid, at: &[f64]) -> usize {
    let mut index = 0;
    for (i, &x) in at.iter().enumerate() {
        let (lo, hi) = grid.ranges[i];
        let n = grid.counts[i];
        let k = if n > 1 && hi > lo {
            ((x - lo) / (hi - lo) * (n - 1) as f64)
                .round()
                .clamp(0.0, (n - 1) as f64) as usize
        } else {
            0
        };
        index = index * n + k;
    }
    index
}

/// The sweep of `grid` through `plan`, following the assembly whose
/// configuration at the grid values `start` is `seed`: `given` makes the
/// plan's given values of a node's grid values; `keep` what is kept of each
/// node's configuration (its grid values and joint values).
pub(super) fn followed<T: Send>(
    l: &Loaded,
    plan: &Plan,
    grid: &Grid,
    given: impl Fn(&[f64]) -> Vec<f64> + Sync,
    start: &[f64],
    seed: &[f64],
    keep: impl Fn(&[f64], &[f64]) -> T + Sync,
) -> Vec<Option<Followed<T>>> {
    let choices = plan.choices();
    follow(
        grid,
        nearest_node(grid, start),
        seed,
        &Continuity::of(&l.model),
        1 << choices,
        |q, b| plan.solve(&l.model, &given(q), &signs(choices, b)).ok(),
        keep,
    )
}

/// What the page says of a followed sweep: the branch or branches (in
/// `pkm fk`'s numbering, of a plan with `choices` ± choices) the followed
/// assembly is on, and where it passes from one to another (two roots of a
/// step meet there). `names` name the grid's values, each with its unit.
pub(super) fn meetings<T>(
    grid: &Grid,
    nodes: &[Option<Followed<T>>],
    names: &[(String, String)],
    choices: usize,
) -> String {
    let branch_text = |b: usize| format!("branch {b} ({})", sign_text(&signs(choices, b)));
    let mut counts: BTreeMap<usize, usize> = BTreeMap::new();
    for n in nodes.iter().flatten() {
        *counts.entry(n.branch).or_default() += 1;
    }
    let passes: Vec<(usize, usize)> = nodes
        .iter()
        .enumerate()
        .filter_map(|(k, n)| {
            let n = n.as_ref()?;
            let from = n.from?;
            let before = nodes[from].as_ref()?;
            (before.branch != n.branch).then_some((from, k))
        })
        .collect();
    let follows = "The sweep follows the assembly by continuity, as the trajectory does: from the node nearest \
                   the sample, each node takes the solution nearest the one continued from its neighbour, \
                   whichever branch (as pkm fk numbers them) that is.";
    match counts.len() {
        0 => format!("{follows} No node is reached."),
        1 => format!(
            "{follows} It stays on {} throughout: no two branches meet on the nodes it reaches.",
            branch_text(*counts.keys().next().unwrap_or(&0))
        ),
        _ => {
            let on: Vec<String> = counts
                .iter()
                .map(|(b, n)| format!("{} on {n} nodes", branch_text(*b)))
                .collect();
            let mut q = vec![0.0; grid.ranges.len()];
            let mut place = |k: usize| {
                grid.node(k, &mut q);
                q.iter()
                    .zip(names)
                    .map(|(v, (name, unit))| format!("{name} = {v:.4}{}{unit}", if unit.is_empty() { "" } else { " " }))
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            const SHOWN: usize = 6;
            let list: Vec<String> = passes
                .iter()
                .take(SHOWN)
                .map(|&(a, b)| {
                    let (na, nb) = (
                        nodes[a].as_ref().map_or(0, |n| n.branch),
                        nodes[b].as_ref().map_or(0, |n| n.branch),
                    );
                    format!(
                        "from {} to {} between {} and {}",
                        branch_text(na),
                        branch_text(nb),
                        place(a),
                        place(b)
                    )
                })
                .collect();
            format!(
                "{follows} The assembly is {}: where it passes from one branch to another, two roots of a step \
                 meet (the branches' signs swap which physical assembly they are). It passes {} time{}: {}{}.",
                on.join(", "),
                passes.len(),
                if passes.len() == 1 { "" } else { "s" },
                list.join("; "),
                if passes.len() > SHOWN {
                    format!("; and {} more", passes.len() - SHOWN)
                } else {
                    String::new()
                }
            )
        }
    }
}
