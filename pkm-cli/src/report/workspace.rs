//! The workspace of the followed point: the input grid swept through the
//! forward plan on all cores, what the reachable set is (a volume, an area
//! or a length, by its dimension), its figures and sections, and the
//! `--compare` table of other files' workspaces.

use super::follow;
use super::html::{html_escape, sign_text, tuple_text, Page};
use super::loaded::{joint_unit, load, point_of, signs, world, Loaded, Plan};
use super::{invalid, ReportError, ReportOptions, Sampling};
use crate::plots;
use pkm_runtime::model::Model;
use pkm_runtime::nalgebra::{Matrix3, Vector3};
use pkm_runtime::primitives::Sign;
use pkm_runtime::workspace::{image_area, image_volume, sweep_nodes, Grid};
use std::fmt::Write as _;

/// The world axes' names.
pub(super) const AXES: [&str; 3] = ["x", "y", "z"];

/// The position of `point` of the model at every node of `grid`, on one
/// branch (all cores).
pub(super) fn sweep_point(
    model: &Model,
    plan: &Plan,
    grid: &Grid,
    signs: &[Sign],
    point: (usize, [f64; 3]),
) -> Result<Vec<Option<[f64; 3]>>, ReportError> {
    let reach = |q: &[f64]| -> Option<[f64; 3]> {
        let v = plan.solve(model, q, signs).ok()?;
        world(model, &v, point.0, point.1)
    };
    Ok(match grid.ranges.len() {
        1 => sweep_nodes::<1>(grid, |q| reach(q)),
        2 => sweep_nodes::<2>(grid, |q| reach(q)),
        3 => sweep_nodes::<3>(grid, |q| reach(q)),
        k => {
            return Err(invalid(format!(
                "the report sweeps mechanisms with 1 to 3 inputs; this one has {k}"
            )))
        }
    })
}

/// The shape of a point cloud: its centre, principal directions (rows,
/// largest spread first) and the spread (standard deviation) along each.
struct Shape {
    centre: [f64; 3],
    axes: [[f64; 3]; 3],
    spread: [f64; 3],
}

fn shape(cloud: &[[f64; 3]]) -> Shape {
    let n = cloud.len().max(1) as f64;
    let mut c = [0.0; 3];
    for p in cloud {
        for i in 0..3 {
            c[i] += p[i] / n;
        }
    }
    let mut m = Matrix3::zeros();
    for p in cloud {
        let d = Vector3::new(p[0] - c[0], p[1] - c[1], p[2] - c[2]);
        m += d * d.transpose() / n;
    }
    let e = m.symmetric_eigen();
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| e.eigenvalues[b].total_cmp(&e.eigenvalues[a]));
    let axes = order.map(|k| {
        let v = e.eigenvectors.column(k);
        [v[0], v[1], v[2]]
    });
    let spread = order.map(|k| e.eigenvalues[k].max(0.0).sqrt());
    Shape {
        centre: c,
        axes,
        spread,
    }
}

/// How many dimensions a cloud spans: a direction whose spread is below
/// 10⁻⁶ of the largest does not count.
/// A sweep of `inputs` inputs spans at most that many.
fn dimension(s: &Shape, inputs: usize) -> usize {
    if s.spread[0] <= 1e-12 {
        return 0;
    }
    s.spread.iter().filter(|x| **x > 1e-6 * s.spread[0]).count().min(inputs)
}

/// How far a cloud leaves the plane through its centre normal to its least
/// spread (its best-fitting plane): the largest distance, 0 for a flat set.
fn off_plane(s: &Shape, cloud: &[[f64; 3]]) -> f64 {
    let n = s.axes[2];
    cloud
        .iter()
        .map(|p| ((p[0] - s.centre[0]) * n[0] + (p[1] - s.centre[1]) * n[1] + (p[2] - s.centre[2]) * n[2]).abs())
        .fold(0.0, f64::max)
}

/// Whether a set of dimension 2 (two inputs) is curved: it spreads off its
/// best-fitting plane by more than 1e-6 of its largest spread (the
/// threshold [`dimension`] counts a spread by), as a spherical mechanism's
/// pointing point on its sphere.
fn curved(s: &Shape) -> bool {
    s.spread[2] > 1e-6 * s.spread[0]
}

/// The world axis (0, 1, 2) a unit direction lies along, if it does.
pub(super) fn world_axis(d: [f64; 3]) -> Option<usize> {
    (0..3).find(|&i| d[i].abs() > 1.0 - 1e-9)
}

/// The area of a flat 2-D set of points, estimated by the cells of a square
/// grid over it that hold a point; the grid's cell is sized so that a cell
/// holds about four distinct points of a uniform cover. Returns (area, cells across).
fn occupied_area(points: &[[f64; 2]]) -> (f64, usize) {
    let xr = plots::range(points.iter().map(|p| p[0]));
    let yr = plots::range(points.iter().map(|p| p[1]));
    // Distinct places, not nodes: inputs that leave the point still repeat it.
    let scale = (xr.1 - xr.0).max(yr.1 - yr.0) * 1e-9;
    let distinct: std::collections::HashSet<(i64, i64)> = points
        .iter()
        .map(|p| ((p[0] / scale).round() as i64, (p[1] / scale).round() as i64))
        .collect();
    let across = ((distinct.len() as f64 / 4.0).sqrt().floor() as usize).clamp(4, 2000);
    let (full, dx, dy) = plots::occupancy(points, xr, yr, across);
    (full.iter().filter(|f| **f).count() as f64 * dx * dy, across)
}

/// The length of the curve traced by a 1-input sweep: the sum of the steps
/// between consecutive reachable nodes.
fn curve_length(nodes: &[Option<[f64; 3]>]) -> f64 {
    nodes
        .windows(2)
        .filter_map(|w| match (w[0], w[1]) {
            (Some(a), Some(b)) => Some(((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()),
            _ => None,
        })
        .sum()
}

/// What a workspace measures, by its dimension: a volume, an area or a
/// length, with how it was measured.
pub(super) fn measure(grid: &Grid, nodes: &[Option<[f64; 3]>], unit: &str) -> String {
    let cloud: Vec<[f64; 3]> = nodes.iter().flatten().copied().collect();
    if cloud.is_empty() {
        return "empty: no node reachable".into();
    }
    let s = shape(&cloud);
    match dimension(&s, grid.ranges.len()) {
        0 => "a single point".into(),
        1 => format!(
            "a curve, length {:.4e} {unit} (the steps between consecutive reachable nodes)",
            curve_length(nodes)
        ),
        2 if curved(&s) => format!(
            "a curved surface (it leaves its best-fitting plane, normal {}, by up to {:.4e} {unit}), no volume; \
             the input grid's image has area {:.4e} {unit}² (each fully reachable grid cell split into two \
             triangles whose images' areas are summed; a place the inputs reach more than once counts each time, \
             so the surface's own area is at most this)",
            tuple_text(&s.axes[2], 3),
            off_plane(&s, &cloud),
            image_area(grid, nodes)
        ),
        2 => {
            // Occupied cells, not the sum of the grid cells' images: the map
            // from inputs to the point may cover a place more than once.
            let (u, v) = match world_axis(s.axes[2]) {
                Some(k) => {
                    let rest: Vec<usize> = (0..3).filter(|&i| i != k).collect();
                    ([rest[0], rest[1]], true)
                }
                None => ([0, 0], false),
            };
            let uv: Vec<[f64; 2]> = cloud
                .iter()
                .map(|p| {
                    if v {
                        [p[u[0]], p[u[1]]]
                    } else {
                        let d = [p[0] - s.centre[0], p[1] - s.centre[1], p[2] - s.centre[2]];
                        let dot = |a: [f64; 3]| a[0] * d[0] + a[1] * d[1] + a[2] * d[2];
                        [dot(s.axes[0]), dot(s.axes[1])]
                    }
                })
                .collect();
            let (area, across) = occupied_area(&uv);
            format!(
                "flat ({}), no volume; area ≈ {area:.4e} {unit}² (the cells of a {across} × {across} grid over the \
                 set that hold a node)",
                if v {
                    format!("in the plane {}", plane_name(u))
                } else {
                    format!("normal {}", tuple_text(&s.axes[2], 3))
                }
            )
        }
        _ => {
            if grid.ranges.len() == 3 {
                format!(
                    "a solid, volume {:.4e} {unit}³ (the image of the input grid: each fully reachable grid cell split into \
                     six tetrahedra whose images' volumes are summed)",
                    image_volume(grid, nodes)
                )
            } else {
                "a solid".into()
            }
        }
    }
}

/// A world plane's name: `xOy`.
pub(super) fn plane_name(p: [usize; 2]) -> String {
    format!("{}O{}", AXES[p[0]], AXES[p[1]])
}

/// The two world axes along which a cloud spreads most.
pub(super) fn largest_pair(cloud: &[[f64; 3]]) -> [usize; 2] {
    let extent = |i: usize| {
        let r = cloud.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p[i]), b.max(p[i]))
        });
        r.1 - r.0
    };
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| extent(b).total_cmp(&extent(a)));
    let mut pair = [order[0], order[1]];
    pair.sort_unstable();
    pair
}

/// One section of a solid workspace: the nodes within 1 % of the cloud's
/// extent of the plane.
fn section(
    page: &mut Page,
    cloud: &[[f64; 3]],
    axis: usize,
    value: f64,
    point_name: &str,
    unit: &str,
) -> Result<(), ReportError> {
    let extent = cloud.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
        (a.min(p[axis]), b.max(p[axis]))
    });
    let slab = 0.01 * (extent.1 - extent.0).max(1e-9);
    let (i, j) = match axis {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    };
    let cut: Vec<[f64; 2]> = cloud
        .iter()
        .filter(|p| (p[axis] - value).abs() <= slab)
        .map(|p| [p[i], p[j]])
        .collect();
    if cut.is_empty() {
        let _ = writeln!(
            page,
            "<p>Section {} = {value} {unit}: no reachable node within ±{slab:.2} {unit} of the plane (the workspace \
             spans {:.2} .. {:.2} {unit} along {}).</p>",
            AXES[axis], extent.0, extent.1, AXES[axis]
        );
        return Ok(());
    }
    page.scatter(
        &format!("section_{}_{value}", AXES[axis]),
        &format!("Section {} = {value} {unit} (±{slab:.2})", AXES[axis]),
        [&format!("{} ({unit})", AXES[i]), &format!("{} ({unit})", AXES[j])],
        &[(point_name.to_string(), cut)],
        false,
        &format!("Section {} = {value}, equal axis scales", AXES[axis]),
    )
}

/// The workspace of `point` on every branch of this file and of each
/// `--compare` file, swept over the same grid: one table. A file with
/// another number of inputs, no forward plan or no such point is listed
/// with the reason it is skipped.
fn compare_table(
    this: &Loaded,
    this_unit: &str,
    plan: &Plan,
    name: &str,
    o: &ReportOptions,
    grid: &Grid,
    point: &str,
) -> Result<String, ReportError> {
    let unit = this_unit;
    let mut html = format!(
        "<h3>Workspaces of {point}, every branch</h3><p>The same ranges and grid ({} nodes), each file's point \
         `{point}`, per branch index as `pkm fk` numbers them: the nodes where that branch solves (not followed by \
         continuity as the sweep above is).</p><table><tr><th class=l>mechanism</th><th>branch</th><th>reachable nodes</th>\
         <th class=l>workspace</th></tr>",
        grid.len()
    );
    let row = |html: &mut String, mech: &str, l: &Loaded, p: &Plan| -> Result<(), ReportError> {
        let Some(at) = point_of(&l.model, point) else {
            let _ = writeln!(
                html,
                "<tr><td class=l>{}</td><td colspan=3 class=l>skipped: no point `{point}`</td></tr>",
                html_escape(mech)
            );
            return Ok(());
        };
        let choices = p.choices();
        for b in 0..1usize << choices {
            let sg = signs(choices, b);
            let nodes = sweep_point(&l.model, p, grid, &sg, at)?;
            let _ = writeln!(
                html,
                "<tr><td class=l>{}</td><td>{b} ({})</td><td>{}</td><td class=l>{}</td></tr>",
                html_escape(mech),
                sign_text(&sg),
                nodes.iter().flatten().count(),
                html_escape(&measure(grid, &nodes, unit))
            );
        }
        Ok(())
    };
    row(&mut html, name, this, plan)?;
    for path in &o.compare {
        let shown = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| invalid(format!("cannot read `{shown}`: {e}")))?;
        // Another file's diagnostics belong to its text: a one-line message here.
        let (_, loaded) = load(&text, &shown, &o.params).map_err(|e| match e {
            ReportError::Source { diagnostics, .. } => {
                let at = diagnostics
                    .0
                    .first()
                    .and_then(|d| d.span)
                    .map(|s| {
                        let (line, column) = s.line_col(&text);
                        format!(":{line}:{column}")
                    })
                    .unwrap_or_default();
                invalid(format!(
                    "--compare {shown}{at}: {}",
                    ReportError::Source {
                        diagnostics,
                        rendered: String::new()
                    }
                    .message()
                ))
            }
            other => other,
        })?;
        let skip = |why: String| {
            format!(
                "<tr><td class=l>{}</td><td colspan=3 class=l>skipped: {}</td></tr>\n",
                html_escape(&shown),
                html_escape(&why)
            )
        };
        let Some(l) = loaded else {
            html.push_str(&skip("it has no geometry".into()));
            continue;
        };
        let other_unit = l
            .analysis
            .mass_and_loads
            .units
            .map_or("file unit", |u| u.length.symbol());
        if other_unit != unit {
            html.push_str(&skip(format!(
                "its lengths are in {other_unit} and this file's in {unit}: one table would mix them"
            )));
            continue;
        }
        let inputs = l.model.inputs().len();
        if inputs != grid.ranges.len() {
            html.push_str(&skip(format!(
                "it has {inputs} actuated joints and this mechanism {}: their input grids differ",
                grid.ranges.len()
            )));
            continue;
        }
        match &l.forward {
            Ok(p) => row(&mut html, &l.model.name.clone(), &l, p)?,
            Err(why) => html.push_str(&skip(format!("no closed-form forward plan ({why})"))),
        }
    }
    html.push_str("</table>\n");
    Ok(html)
}

/// The workspace of the followed point on the followed branch: what it is
/// (volume, area or length), its figures (displacement for one input, 3-D
/// view, projections or its plane), the sections asked for and the
/// `--compare` table. Returns the reachable nodes' positions.
pub(super) fn workspace(page: &mut Page, at: &Sampling, o: &ReportOptions) -> Result<Vec<[f64; 3]>, ReportError> {
    let (model, s, unit) = (&at.l.model, at.s, at.unit);
    let n = model.inputs().len();
    let point_name = s.point.0.as_str();
    // A volume, an area or a length is drawn from 1 to 3 inputs: beyond
    // the third, inputs are held at the sample's values (one node each, the
    // last in the grid's order, so the nodes are those of the swept grid).
    let swept = n.min(3);
    let grid = Grid {
        ranges: (0..n)
            .map(|i| {
                if i < swept {
                    s.ranges.0[i]
                } else {
                    (s.start.0[i], s.start.0[i])
                }
            })
            .collect(),
        counts: (0..n).map(|i| if i < swept { s.nodes.0 } else { 1 }).collect(),
    };
    let swept_grid = Grid {
        ranges: grid.ranges[..swept].to_vec(),
        counts: grid.counts[..swept].to_vec(),
    };
    let followed = follow::followed(
        at.l,
        at.plan,
        &grid,
        |q| q.to_vec(),
        &s.start.0,
        &at.sample,
        |_, v| world(model, v, at.point.0, at.point.1),
    );
    let nodes: Vec<Option<[f64; 3]>> = followed.iter().map(|f| f.as_ref().and_then(|f| f.kept)).collect();
    let cloud: Vec<[f64; 3]> = nodes.iter().flatten().copied().collect();
    let names: Vec<(String, String)> = model
        .inputs()
        .iter()
        .map(|&j| (model.joints[j].name.clone(), joint_unit(model, j, unit)))
        .collect();
    let held: Vec<String> = (swept..n)
        .map(|i| {
            format!(
                "{} held at {:.4} {} (the sample's)",
                names[i].0, s.start.0[i], names[i].1
            )
        })
        .collect();
    let _ = writeln!(
        page,
        "<h2>Workspace of {point_name}</h2><p>The assembly of branch {} ({}) at the sample, the inputs swept over {} \
         with {} nodes each{}: {} of {} nodes reached. The set is {}.</p><p>{}</p>",
        s.branch.0,
        sign_text(&at.branch_signs),
        s.ranges.0[..swept]
            .iter()
            .map(|(a, b)| format!("[{a:.4}, {b:.4}]"))
            .collect::<Vec<_>>()
            .join(" × "),
        s.nodes.0,
        if held.is_empty() {
            String::new()
        } else {
            format!("; {} (the report sweeps at most three inputs)", held.join(", "))
        },
        cloud.len(),
        grid.len(),
        html_escape(&measure(&swept_grid, &nodes, unit)),
        html_escape(&follow::meetings(&grid, &followed, &names, at.plan.choices()))
    );
    if n == 1 {
        displacement(page, at, &grid, &nodes)?;
    }
    // One input traces a curve: its points joined in order.
    let dim = cloud_figures(page, model.planar, point_name, unit, &cloud, swept, n == 1)?;
    if !s.sections.0.is_empty() {
        if dim < 3 {
            let _ = writeln!(
                page,
                "<p>Sections skipped: the workspace is {}, so a plane's section of it is not an area.</p>",
                if model.planar { "planar" } else { "flat or a curve" }
            );
        } else {
            for &(axis, value) in &s.sections.0 {
                section(page, &cloud, axis, value, point_name, unit)?;
            }
        }
    }
    if !o.compare.is_empty() {
        let table = compare_table(at.l, unit, at.plan, model.name.as_str(), o, &grid, point_name)?;
        page.html.push_str(&table);
    }
    Ok(cloud)
}

/// The figures of the workspace `cloud` (world positions, `unit`) of the
/// point `point_name`, swept over `inputs` values (`joined`: in order, a
/// curve): a solid's 3-D view and its projections on the world planes, a
/// flat set in its plane, a curve in the plane it spreads most in; a planar
/// mechanism's in its plane. Returns the set's dimension.
pub(super) fn cloud_figures(
    page: &mut Page,
    planar: bool,
    point_name: &str,
    unit: &str,
    cloud: &[[f64; 3]],
    inputs: usize,
    joined: bool,
) -> Result<usize, ReportError> {
    let label = |i: usize| format!("{} ({unit})", AXES[i]);
    let shape_of = shape(cloud);
    let dim = dimension(&shape_of, inputs);
    if !planar && dim >= 2 {
        let f = plots::solid3d(
            &page.dir.join("workspace_3d"),
            &format!(
                "Workspace of {point_name} {}",
                if dim == 2 { "(a surface)" } else { "as a solid" }
            ),
            [&label(0), &label(1), &label(2)],
            cloud,
        )?;
        let what = if dim == 2 {
            "The workspace, a surface, drawn as"
        } else {
            "The workspace as a solid:"
        };
        page.figure(
            &f,
            &format!(
                "{what} the cells of a grid over it (about 28 along its longest extent) that hold a reached node, \
                 their outer faces shaded and coloured by height, seen from two sides; the axes are ticked on the \
                 box's near edges"
            ),
        );
    }
    if !planar && dim == 2 && world_axis(shape_of.axes[2]).is_none() {
        // A tilted plane: drawn in its own coordinates.
        let (u, v) = (shape_of.axes[0], shape_of.axes[1]);
        let c = shape_of.centre;
        let uv: Vec<[f64; 2]> = cloud
            .iter()
            .map(|p| {
                let d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
                [
                    u[0] * d[0] + u[1] * d[1] + u[2] * d[2],
                    v[0] * d[0] + v[1] * d[1] + v[2] * d[2],
                ]
            })
            .collect();
        page.scatter(
            "workspace_plane",
            &format!(
                "Workspace of {point_name}, {}",
                if curved(&shape_of) {
                    "on its best-fitting plane"
                } else {
                    "in its plane"
                }
            ),
            [
                &format!("along {} ({unit})", tuple_text(&u, 3)),
                &format!("along {} ({unit})", tuple_text(&v, 3)),
            ],
            &[(point_name.to_string(), uv)],
            joined,
            &if curved(&shape_of) {
                format!(
                    "The curved workspace projected on its best-fitting plane (from its centre; it leaves the plane \
                     by up to {:.4e} {unit})",
                    off_plane(&shape_of, cloud)
                )
            } else {
                "The flat workspace in its own plane (from its centre)".to_string()
            },
        )?;
    } else {
        let planes: Vec<[usize; 2]> = if planar {
            vec![[0, 1]]
        } else if dim >= 3 {
            vec![[0, 1], [1, 2], [0, 2]]
        } else if let Some(k) = (dim == 2).then(|| world_axis(shape_of.axes[2])).flatten() {
            let rest: Vec<usize> = (0..3).filter(|&i| i != k).collect();
            vec![[rest[0], rest[1]]]
        } else {
            vec![largest_pair(cloud)]
        };
        let (title, caption) = if planes.len() > 1 {
            ("projection on", "Projection on")
        } else {
            ("in", "The workspace in")
        };
        for p in &planes {
            let name = plane_name(*p);
            let projected: Vec<[f64; 2]> = cloud.iter().map(|q| [q[p[0]], q[p[1]]]).collect();
            let dense = if !joined && plots::places(&projected).len() > plots::DENSE {
                "; a dense cloud drawn as occupied cells"
            } else {
                ""
            };
            page.scatter(
                &format!("workspace_{name}"),
                &format!("Workspace of {point_name}: {title} {name}"),
                [&label(p[0]), &label(p[1])],
                &[(point_name.to_string(), projected)],
                joined,
                &format!("{caption} {name}, equal axis scales{dense}"),
            )?;
        }
    }
    Ok(dim)
}

/// One input: the point's coordinates against it (a displacement diagram),
/// from the sweep's `nodes` over `grid`.
fn displacement(page: &mut Page, at: &Sampling, grid: &Grid, nodes: &[Option<[f64; 3]>]) -> Result<(), ReportError> {
    let (model, unit) = (&at.l.model, at.unit);
    let point_name = at.s.point.0.as_str();
    let q0 = grid.ranges[0];
    let step = (q0.1 - q0.0) / (grid.counts[0] - 1) as f64;
    let reached: Vec<(f64, [f64; 3])> = nodes
        .iter()
        .enumerate()
        .filter_map(|(i, p)| p.map(|p| (q0.0 + i as f64 * step, p)))
        .collect();
    let j = model.inputs()[0];
    let components: &[usize] = if model.planar { &[0, 1] } else { &[0, 1, 2] };
    let f = plots::curves(
        &page.dir.join("displacement"),
        &format!("{point_name} against {}", model.joints[j].name),
        [
            &format!("{} ({})", model.joints[j].name, joint_unit(model, j, unit)),
            &format!("position ({unit})"),
        ],
        &reached.iter().map(|r| r.0).collect::<Vec<_>>(),
        &components
            .iter()
            .map(|&k| (AXES[k].to_string(), reached.iter().map(|r| r.1[k]).collect()))
            .collect::<Vec<_>>(),
    )?;
    page.figure(
        &f,
        &format!("The coordinates of {point_name} against the input over the sweep"),
    );
    Ok(())
}
