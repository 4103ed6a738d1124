//! A mechanism with no closed-form forward plan (κ ≠ 0) but an inverse
//! one: what the inverse solution shows instead of the input sweep.

use super::html::{html_escape, sign_text, tuple_text, Page};
use super::loaded::{default_point, output_columns, point_of, reach, signs, Loaded, Plan};
use super::settings::{check_duration, check_nodes};
use super::workspace::measure;
use super::{invalid, io, ReportError, ReportOptions};
use crate::drawing::{self, View};
use crate::plots;
use pkm_dsl::study::Resolved;
use pkm_runtime::model::JointType;
use pkm_runtime::newton;
use pkm_runtime::primitives::Sign;
use pkm_runtime::velocity;
use pkm_runtime::workspace::{sweep_nodes, Grid};
use std::fmt::Write as _;

/// A mechanism with no closed-form forward plan (κ ≠ 0) but an inverse one:
/// the mechanism drawn at a sample pose of its outputs, the
/// constant-orientation workspace of its output point (every pose of a grid
/// over the point's coordinates, the other outputs held, that the inverse
/// solution reaches on the branch), and an animation along a circle of poses.
pub(super) fn inverse_only(
    page: &mut Page,
    l: &Loaded,
    study: &Resolved,
    o: &ReportOptions,
    unit: &str,
    file: &str,
    why: &str,
) -> Result<(), ReportError> {
    let model = &l.model;
    let _ = writeln!(
        page,
        "<h2>No forward solution</h2><p>There is no closed-form forward plan ({}), so the input sweep and the \
         input trajectory are not available. The inverse solution gives what follows: the pose of the outputs is \
         chosen, and every joint follows.</p>",
        html_escape(why)
    );
    let first = l.analysis.geometry.outputs.first().map(|x| &x.kind);
    let (Some(plan), Some(pkm_dsl::geometry::OutputKind::Pose { .. } | pkm_dsl::geometry::OutputKind::Point { .. })) =
        (&l.inverse, first)
    else {
        let _ = writeln!(
            page,
            "<p>It has no inverse plan from a full pose or a point output either: no drawing, workspace or \
             motion to show{}.</p>",
            if l.inverse.is_some() && !l.analysis.limbs.is_empty() {
                " (the static stiffness below solves its inverse plan)"
            } else {
                ""
            }
        );
        return Ok(());
    };
    if !o.ranges.is_empty() || o.start.is_some() || o.amplitude.is_some() || o.speed.is_some() {
        return Err(invalid(format!(
            "{file} has no forward plan ({why}): --ranges, --start, --amplitude and --speed sample its inputs, \
             which it cannot solve from"
        )));
    }
    let columns = output_columns(l, unit);
    let m = columns.len();
    let choices = plan.choices();
    let point_name = default_point(l);
    let (plink, plocal) = point_of(model, &point_name).ok_or_else(|| invalid(format!("no point `{point_name}`")))?;
    // The sample pose: every output 0 (the geometry's home pose), on the
    // first branch that reaches it (regular if one is).
    let pose = vec![0.0; m];
    let branch = sample_branch(l, plan, &pose, o.branch.or(study.branch), file)?;
    let branch_signs = signs(choices, branch);
    let v = plan.solve(model, &pose, &branch_signs).map_err(|e| {
        invalid(format!(
            "{file}: branch {branch} at the pose {}: {e}",
            tuple_text(&pose, 3)
        ))
    })?;
    let poses = newton::link_poses(model, &v).map_err(|e| invalid(e.to_string()))?;
    let view = if model.planar { View::Plane } else { View::Axonometric };
    let f = drawing::draw(
        &page.dir.join("mechanism"),
        &format!("{} at the pose {}, branch {branch}", model.name, tuple_text(&pose, 3)),
        &drawing::scene(model, &poses, (plink, plocal)),
        view,
        unit,
        &point_name,
    )?;
    let _ = writeln!(
        page,
        "<h2>The mechanism at the pose {} ({})</h2>",
        tuple_text(&pose, 3),
        html_escape(&columns.join(", "))
    );
    page.figure(
        &f,
        "Links as lines between their joints (a link with three or more joints filled), joints by type, the base hatched",
    );
    let held = Held {
        l,
        plan,
        pose,
        branch,
        branch_signs,
        point: (plink, plocal),
        point_name,
        columns,
        unit,
    };
    let cloud = constant_orientation(page, &held, o.nodes.or(study.nodes))?;
    let duration = o.duration.or(study.duration).unwrap_or(std::f64::consts::TAU);
    check_duration(duration)?;
    circle(page, &held, &cloud, v, view, duration)
}

/// The branch shown at the sample `pose`: the `given` one, else the first
/// that reaches it, regular if one is.
fn sample_branch(
    l: &Loaded,
    plan: &Plan,
    pose: &[f64],
    given: Option<usize>,
    file: &str,
) -> Result<usize, ReportError> {
    let model = &l.model;
    let choices = plan.choices();
    Ok(match given {
        Some(b) if b >= 1 << choices => {
            return Err(invalid(format!(
                "--branch {b}: {file}'s inverse solution has {} branches (0 to {})",
                1usize << choices,
                (1usize << choices) - 1
            )))
        }
        Some(b) => b,
        None => (0..1usize << choices)
            .find(|&b| {
                plan.solve(model, pose, &signs(choices, b)).is_ok_and(|v| {
                    velocity::jacobians(model, &v, &l.outputs)
                        .is_ok_and(|j| j.singularity == velocity::Singularity::None)
                })
            })
            .or_else(|| (0..1usize << choices).find(|&b| plan.solve(model, pose, &signs(choices, b)).is_ok()))
            .ok_or_else(|| {
                invalid(format!(
                    "{file}: the inverse solution reaches no branch at the pose {}",
                    tuple_text(pose, 3)
                ))
            })?,
    })
}

/// What the inverse-only sections share: the file, its inverse plan, the
/// sample pose and branch, and the point followed.
struct Held<'a> {
    l: &'a Loaded,
    plan: &'a Plan,
    /// The sample pose: every output's value.
    pose: Vec<f64>,
    branch: usize,
    branch_signs: Vec<Sign>,
    /// The output point: its link and place on it.
    point: (usize, [f64; 3]),
    point_name: String,
    /// The outputs' names and units.
    columns: Vec<String>,
    unit: &'a str,
}

/// The constant-orientation workspace over the point's x and y (`nodes`
/// per coordinate, 200 by default): every pose of the grid, the other
/// outputs held at the sample, that the inverse solution reaches on the
/// branch. Returns the reachable (x, y).
fn constant_orientation(page: &mut Page, h: &Held, nodes: Option<usize>) -> Result<Vec<[f64; 2]>, ReportError> {
    let (model, plan, unit) = (&h.l.model, h.plan, h.unit);
    let (branch, point_name, columns) = (h.branch, &h.point_name, &h.columns);
    let size = reach(model);
    let nodes_per = nodes.unwrap_or(200);
    check_nodes(nodes_per, 2)?;
    let grid = Grid {
        ranges: vec![(-size, size), (-size, size)],
        counts: vec![nodes_per; 2],
    };
    let sweep = |grid: &Grid| {
        sweep_nodes::<2>(grid, |xy| {
            let mut p = h.pose.clone();
            p[0] = xy[0];
            p[1] = xy[1];
            plan.solve(model, &p, &h.branch_signs).ok().map(|_| [xy[0], xy[1], 0.0])
        })
    };
    // A first sweep over the mechanism's reach finds the set; a second as
    // fine over the set's box (a step wider each way) draws it.
    let first = sweep(&grid);
    let step = 2.0 * size / (nodes_per - 1) as f64;
    let found: Vec<[f64; 3]> = first.iter().flatten().copied().collect();
    let grid = if found.is_empty() {
        grid
    } else {
        let bound = |k: usize| {
            let (lo, hi) = found.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                (a.min(p[k]), b.max(p[k]))
            });
            (lo - step, hi + step)
        };
        Grid {
            ranges: vec![bound(0), bound(1)],
            counts: vec![nodes_per; 2],
        }
    };
    let nodes = sweep(&grid);
    let cloud: Vec<[f64; 2]> = nodes.iter().flatten().map(|p| [p[0], p[1]]).collect();
    let _ = writeln!(
        page,
        "<h2>Workspace of {point_name} at constant orientation</h2><p>The poses ({}) with {} and {} over \
         [{:.1}, {:.1}] {unit} and [{:.1}, {:.1}] {unit} ({nodes_per} nodes each; the box of the reachable set found \
         by a first sweep over ± the mechanism's reach) and the other outputs held at the sample, that branch {branch} \
         ({}) of the inverse solution reaches: {} of {} nodes. The set is {}.</p>",
        html_escape(&columns.join(", ")),
        html_escape(&columns[0]),
        html_escape(&columns[1]),
        grid.ranges[0].0,
        grid.ranges[0].1,
        grid.ranges[1].0,
        grid.ranges[1].1,
        sign_text(&h.branch_signs),
        cloud.len(),
        grid.len(),
        html_escape(&measure(&grid, &nodes, unit).replace("input grid", "grid of poses"))
    );
    if !cloud.is_empty() {
        page.scatter(
            "workspace_xOy",
            &format!("Workspace of {point_name}, orientation held"),
            [&format!("x ({unit})"), &format!("y ({unit})")],
            &[(point_name.clone(), cloud.clone())],
            false,
            "The constant-orientation workspace, equal axis scales",
        )?;
    }
    Ok(cloud)
}

/// The motion: a circle of poses about the sample, a tenth of the
/// workspace's (`cloud`'s) width across, followed from the sample's joint
/// values `start` by the nearest joint values at each step, animated over
/// `duration` seconds.
fn circle(
    page: &mut Page,
    h: &Held,
    cloud: &[[f64; 2]],
    start: Vec<f64>,
    view: View,
    duration: f64,
) -> Result<(), ReportError> {
    let (model, plan, unit, point_name) = (&h.l.model, h.plan, h.unit, &h.point_name);
    let choices = plan.choices();
    let xr = plots::range(cloud.iter().map(|p| p[0]));
    let radius = 0.1 * (xr.1 - xr.0);
    // One per value in the model's layout (a spherical joint's three
    // rotation-vector components are angles too).
    let revolute: Vec<bool> = model
        .joints
        .iter()
        .flat_map(|j| std::iter::repeat_n(j.kind != JointType::P, j.kind.dof()))
        .collect();
    let mut previous = start;
    let mut frames = Vec::new();
    for k in 0..=100 {
        let a = std::f64::consts::TAU * k as f64 / 100.0;
        let mut p = h.pose.clone();
        p[0] += radius * (1.0 - a.cos());
        p[1] += radius * a.sin();
        let Some(next) = (0..1usize << choices)
            .filter_map(|b| plan.solve(model, &p, &signs(choices, b)).ok())
            .min_by(|x, y| {
                pkm_runtime::solution::joint_distance(x, &previous, &revolute)
                    .total_cmp(&pkm_runtime::solution::joint_distance(y, &previous, &revolute))
            })
        else {
            break;
        };
        let Ok(link_poses) = newton::link_poses(model, &next) else {
            break;
        };
        frames.push(drawing::scene(model, &link_poses, h.point));
        previous = next;
    }
    if frames.len() >= 2 {
        let path = page.dir.join("animation.svg");
        drawing::animation(&path, &frames, view, duration, point_name)?;
        let svg = std::fs::read_to_string(&path).map_err(io(&path))?;
        let _ = writeln!(
            page,
            "<h2>Motion</h2><figure>{svg}<figcaption>{point_name} along a circle of radius {radius:.1} {unit} from the \
             sample pose, the orientation held; each joint by the inverse solution nearest its last value ({} frames \
             over {duration:.2} s, repeated; <a href=\"animation.svg\">SVG</a>)</figcaption></figure>",
            frames.len()
        );
    }
    Ok(())
}
