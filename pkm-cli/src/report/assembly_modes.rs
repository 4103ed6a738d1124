//! Assembly modes of a coupled mechanism whose file asks for `fk_numeric`
//! (κ = 1): how many real assemblies the forward solution has over a plane
//! of two inputs, the others held at the sample's, each node solved with
//! every root certified or reported possible (`docs/certified.md`). Where
//! the count changes, two assemblies meet: the forward singularity locus,
//! whose nodes the map crosses where a root there is only possible.

use super::html::{html_escape, Page};
use super::loaded::{reach, Loaded};
use super::ReportError;
use crate::plots;
use pkm_runtime::model::JointType;
use std::f64::consts::PI;
use std::fmt::Write as _;

/// Nodes per side of the map (each node a forward solution with every
/// root certified: about 50 ms for the planar 3-RPR by the interpreter).
const NODES: usize = 15;

/// The section, for a file that asks for `fk_numeric` and has at least two
/// inputs; `given` the inputs at the sample (the inverse solution's).
pub(super) fn assembly_modes(page: &mut Page, l: &Loaded, given: &[f64], unit: &str) -> Result<(), ReportError> {
    let a = &l.analysis;
    if a.topology.kappa == 0 || !a.mechanism.wants(pkm_dsl::mechanism::Capability::FkNumeric) || given.len() < 2 {
        return Ok(());
    }
    let Ok(vp) = pkm_dsl::planner_numeric::forward_numeric_plan(a) else {
        return Ok(());
    };
    let model = &l.model;
    let inputs = &vp.plan.inputs[..vp.plan.inputs.len() - 1];
    let size = reach(model);
    // A revolute over its turn about the sample; a slide over half its
    // value (or half the mechanism's reach) either side.
    let axis = |k: usize| -> (Vec<f64>, String) {
        let j = &model.joints[inputs[k]];
        let (lo, hi, u) = if j.kind == JointType::P {
            let half = if given[k].abs() > 0.0 {
                0.5 * given[k].abs()
            } else {
                0.5 * size
            };
            (given[k] - half, given[k] + half, unit)
        } else {
            (given[k] - PI, given[k] + PI, "rad")
        };
        let nodes = (0..NODES)
            .map(|i| lo + (hi - lo) * i as f64 / (NODES - 1) as f64)
            .collect();
        (nodes, format!("{} ({u})", j.name))
    };
    let ((xs, xl), (ys, yl)) = (axis(0), axis(1));
    // Each node's count, and whether a root there is only possible; the
    // rows shared among the machine's threads.
    let solve_row = |x: f64| -> Vec<(f64, bool)> {
        let mut at = given.to_vec();
        ys.iter()
            .map(|&y| {
                at[0] = x;
                at[1] = y;
                match pkm_runtime::fk_numeric::solve(model, &vp, &at) {
                    Ok(found) => (
                        (found.len() + found.unresolved.len()) as f64,
                        found.iter().any(|f| !f.kind.certified()) || !found.unresolved.is_empty(),
                    ),
                    Err(_) => (f64::NAN, false),
                }
            })
            .collect()
    };
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get()).min(NODES);
    let mut rows: Vec<Vec<(f64, bool)>> = vec![Vec::new(); NODES];
    std::thread::scope(|scope| {
        let chunks: Vec<_> = rows.chunks_mut(NODES.div_ceil(threads)).enumerate().collect();
        let per = NODES.div_ceil(threads);
        for (c, chunk) in chunks {
            let (xs, solve_row) = (&xs, &solve_row);
            scope.spawn(move || {
                for (k, row) in chunk.iter_mut().enumerate() {
                    *row = solve_row(xs[c * per + k]);
                }
            });
        }
    });
    let counts: Vec<f64> = rows.iter().flatten().map(|r| r.0).collect();
    let possible: Vec<bool> = rows.iter().flatten().map(|r| r.1).collect();
    let held: Vec<String> = inputs
        .iter()
        .zip(given)
        .skip(2)
        .map(|(&j, v)| {
            let u = if model.joints[j].kind == JointType::P {
                unit
            } else {
                "rad"
            };
            format!("{} = {v:.4} {u}", model.joints[j].name)
        })
        .collect();
    let held = if held.is_empty() {
        String::new()
    } else {
        format!(", {} held", held.join(", "))
    };
    let most = counts.iter().copied().filter(|c| c.is_finite()).fold(0.0, f64::max);
    let at_sample = pkm_runtime::fk_numeric::solve(model, &vp, given).map_or(0, |f| f.len());
    let _ = writeln!(
        page,
        "<h2>Assembly modes</h2><p>The forward solution by the virtual variable {} finds every real assembly \
         at given inputs, each root certified or reported possible (docs/certified.md). At the sample's inputs it \
         has {at_sample}; over the plane below, up to {most}. Where the count changes, two assemblies meet: the \
         forward singularity locus.</p>",
        html_escape(&model.joints[vp.joint].name)
    );
    let marks = possible;
    let f = plots::heat_map(
        &page.dir.join("assembly_modes"),
        &format!("{}: real assemblies", model.name),
        [&xl, &yl],
        &xs,
        &ys,
        &counts,
        "real assemblies",
        &plots::HeatStyle {
            log: false,
            marked: &marks,
            mark_label: "a root only possible (a fold)",
            counts: true,
        },
    )?;
    page.figure(
        &f,
        &format!(
            "The number of real assemblies of the forward solution over {xl} × {yl}{held}, {NODES} × {NODES} \
             nodes: where it changes, two assemblies meet (a forward singularity); a cross marks a node where a \
             root is only possible (within 10⁻¹² of the range of a fold)"
        ),
    );
    Ok(())
}
