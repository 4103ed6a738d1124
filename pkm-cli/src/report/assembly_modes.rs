//! Assembly modes of a coupled mechanism whose file asks for `fk_numeric`
//! (κ = 1), or whose legs each end in a ball (κ ≥ 2, the pose equations,
//! `pkm_runtime::ball_legs`): how many real assemblies the forward
//! solution has over a plane of two inputs, the others held at the
//! sample's, each node solved with every root certified or reported
//! possible (`docs/certified.md`). Where the count changes, two assemblies
//! meet: the forward singularity locus, whose nodes the map crosses where
//! a root there is only possible.

use super::html::{html_escape, Page};
use super::loaded::{reach, Loaded};
use super::ReportError;
use crate::plots;
use pkm_runtime::model::JointType;
use std::f64::consts::PI;
use std::fmt::Write as _;

/// Nodes per side of the map (each node a forward solution with every
/// root certified: about 50 ms for the planar 3-RPR by the interpreter,
/// 20 ms for the 3-RPS and 80 ms for the 6-UPS by the pose equations).
const NODES: usize = 15;

/// A node of the map: its real assemblies.
#[derive(Clone, Default)]
struct Node {
    count: usize,
    possible: bool,
    points: Vec<([f64; 3], bool)>,
}

/// How the forward solution finds every assembly.
enum Forward {
    /// κ = 1: a virtual variable.
    Virtual(Box<pkm_runtime::fk_numeric::VirtualPlan>),
    /// Legs ending in balls: the pose equations, each root's joints by the
    /// inverse plan.
    Balls(Box<(pkm_runtime::ball_legs::BallLegs, pkm_runtime::plan::Plan)>),
}

impl Forward {
    fn of(l: &Loaded) -> Option<Forward> {
        let a = &l.analysis;
        if a.topology.kappa == 0 {
            return None;
        }
        if pkm_dsl::planner_numeric::by_virtual_variable(a) {
            return pkm_dsl::planner_numeric::forward_numeric_plan(a)
                .ok()
                .map(|vp| Forward::Virtual(Box::new(vp)));
        }
        let inverse = l.inverse.as_ref().ok()?;
        if l.forward.is_ok() {
            return None;
        }
        let legs = pkm_runtime::ball_legs::BallLegs::for_outputs(&l.model, &l.outputs).ok()?;
        // The start of the legs' shape, found once before the threads share it.
        let _ = pkm_runtime::ball_legs::homotopy::start(&legs.shape);
        Some(Forward::Balls(Box::new((legs, inverse.clone()))))
    }

    /// The actuated joints the map's inputs are, in order.
    fn inputs(&self, l: &Loaded) -> Vec<usize> {
        match self {
            Forward::Virtual(vp) => vp.plan.inputs[..vp.plan.inputs.len() - 1].to_vec(),
            Forward::Balls(_) => l.model.inputs(),
        }
    }

    /// The real assemblies at `at`: how many, whether one is only possible
    /// (or a root has no verified assembly), and each one's output point
    /// (the first declared output's link and point) with whether it is
    /// certified.
    fn solve(&self, l: &Loaded, at: &[f64]) -> Option<Node> {
        let point = |poses: &[pkm_runtime::plan::Pose3]| -> Option<[f64; 3]> {
            use pkm_runtime::newton::Output;
            match *l.outputs.first()? {
                Output::Pose { link, local, .. }
                | Output::Point { link, local }
                | Output::Parts { link, local, .. } => {
                    let p = poses.get(link)? * pkm_runtime::nalgebra::Point3::from(local);
                    Some([p.x, p.y, p.z])
                }
                Output::Joint(_) => None,
            }
        };
        match self {
            Forward::Virtual(vp) => pkm_runtime::fk_numeric::solve(&l.model, vp, at).ok().map(|found| Node {
                count: found.len() + found.unresolved.len(),
                possible: found.iter().any(|f| !f.kind.certified()) || !found.unresolved.is_empty(),
                points: found
                    .iter()
                    .filter_map(|f| point(&f.solution.poses).map(|p| (p, f.kind.certified())))
                    .collect(),
            }),
            Forward::Balls(b) => b.0.solve(&l.model, &b.1, &l.outputs, at).ok().map(|all| {
                let r = &all.roots;
                Node {
                    count: all.assemblies.len() + all.unmet.len(),
                    possible: r.roots.iter().any(|x| x.cert.is_none()) || r.failed > 0 || !all.unmet.is_empty(),
                    points: all
                        .assemblies
                        .iter()
                        .filter_map(|a| point(&a.solution.poses).map(|p| (p, r.roots[a.root].cert.is_some())))
                        .collect(),
                }
            }),
        }
    }

    /// The method, for the text.
    fn method(&self, l: &Loaded) -> String {
        match self {
            Forward::Virtual(vp) => {
                format!(
                    "by the virtual variable {}",
                    html_escape(&l.model.joints[vp.joint].name)
                )
            }
            Forward::Balls(_) => "by the pose equations (each leg's ball on its circle or sphere)".to_string(),
        }
    }
}

/// The section, for a file that asks for `fk_numeric` and has at least two
/// inputs; `given` the inputs at the sample (the inverse solution's).
pub(super) fn assembly_modes(page: &mut Page, l: &Loaded, given: &[f64], unit: &str) -> Result<(), ReportError> {
    if given.len() < 2 {
        return Ok(());
    }
    let Some(forward) = Forward::of(l) else {
        return Ok(());
    };
    let model = &l.model;
    let inputs = &forward.inputs(l);
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
    let solve_row = |x: f64| -> Vec<Option<Node>> {
        let mut at = given.to_vec();
        ys.iter()
            .map(|&y| {
                at[0] = x;
                at[1] = y;
                forward.solve(l, &at)
            })
            .collect()
    };
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get()).min(NODES);
    let mut rows: Vec<Vec<Option<Node>>> = vec![Vec::new(); NODES];
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
    let counts: Vec<f64> = rows
        .iter()
        .flatten()
        .map(|r| r.as_ref().map_or(f64::NAN, |n| n.count as f64))
        .collect();
    let possible: Vec<bool> = rows
        .iter()
        .flatten()
        .map(|r| r.as_ref().is_some_and(|n| n.possible))
        .collect();
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
    let at_sample = forward.solve(l, given).map_or(0, |n| n.count);
    let _ = writeln!(
        page,
        "<h2>Assembly modes</h2><p>The forward solution {} finds every real assembly \
         at given inputs, each root certified or reported possible (docs/certified.md). At the sample's inputs it \
         has {at_sample}; over the plane below, up to {most}. Where the count changes, two assemblies meet: the \
         forward singularity locus.</p>",
        forward.method(l)
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
    // The workspace through the forward solution: every assembly's output
    // point over the same plane of inputs.
    let (i, j, plane) = if model.planar {
        (0, 1, ["x", "y"])
    } else {
        (0, 2, ["x", "z"])
    };
    let mut sets: Vec<(String, Vec<[f64; 2]>)> =
        vec![("certified".into(), Vec::new()), ("possible".into(), Vec::new())];
    for node in rows.iter().flatten().flatten() {
        for (p, certified) in &node.points {
            sets[usize::from(!certified)].1.push([p[i], p[j]]);
        }
    }
    sets.retain(|(_, v)| !v.is_empty());
    if !sets.is_empty() {
        let point_name = "the first output's point";
        let labels = [format!("{} ({unit})", plane[0]), format!("{} ({unit})", plane[1])];
        page.scatter(
            "assembly_workspace",
            &format!("{}: workspace through the forward solution", model.name),
            [&labels[0], &labels[1]],
            &sets,
            false,
            &format!(
                "The workspace through the forward solution: {point_name} at every real assembly over the same \
                 {NODES} × {NODES} inputs ({xl} × {yl}{held}), projected on the {}{} plane; a root only possible \
                 shown apart",
                plane[0], plane[1]
            ),
        )?;
    }
    Ok(())
}
