//! `pkm report`: one self-contained HTML page for a `.pkm` file: the
//! topology report, the position solutions at a sample input with their
//! singularity measures, the workspace of a chosen point (projections,
//! sections, volume), singularity loci over the sweep, and the velocity and
//! acceleration of that point along a sine trajectory. Every figure is also
//! written as PNG, SVG and CSV beside the page. Works from the file alone,
//! through the plan interpreter.

use crate::plots::{self, Figure};
use pkm_runtime::model::Model;
use pkm_runtime::newton::{self, Output};
use pkm_runtime::primitives::Sign;
use pkm_runtime::workspace::{image_volume, sweep_nodes, Grid};
use pkm_runtime::{singular, velocity};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// What the report samples (also the `pkm report` command line's options).
#[derive(Debug, Clone, clap::Args)]
pub struct ReportOptions {
    /// Override a parameter: `--param l1=120`.
    #[arg(long = "param", value_parser = parse_param)]
    pub params: Vec<(String, f64)>,
    /// Each actuator's range for the workspace sweep: `--ranges=-250:0,0:250,-300:300`.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true, required = true, value_parser = parse_range)]
    pub ranges: Vec<(f64, f64)>,
    /// Grid nodes per input in the sweep.
    #[arg(long, default_value_t = 60)]
    pub nodes: usize,
    /// The assembly branch swept and followed (its index in `signs_of` order).
    #[arg(long, default_value_t = 0)]
    pub branch: usize,
    /// The point shown (a named point or a joint); default: the first pose or point output's point.
    #[arg(long)]
    pub point: Option<String>,
    /// The sample input and the trajectory's centre; default: the ranges' middles.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub start: Option<Vec<f64>>,
    /// The trajectory: input i is start_i + amplitude_i·sin(πt); default 5 % of each range.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub amplitude: Option<Vec<f64>>,
    /// The trajectory's duration in seconds.
    #[arg(long, default_value_t = 5.0)]
    pub duration: f64,
    /// Workspace sections: `--sections x=60,y=-85,z=300`.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true, value_parser = parse_section)]
    pub sections: Vec<(usize, f64)>,
    /// The length unit's name, for labels.
    #[arg(long, default_value = "mm")]
    pub unit: String,
    /// Other `.pkm` files whose workspaces (of the same point, every
    /// branch, the same ranges) are tabled beside this one's.
    #[arg(long, value_delimiter = ',')]
    pub compare: Vec<PathBuf>,
}

impl Default for ReportOptions {
    fn default() -> Self {
        ReportOptions {
            params: Vec::new(),
            ranges: Vec::new(),
            nodes: 60,
            branch: 0,
            point: None,
            start: None,
            amplitude: None,
            duration: 5.0,
            sections: Vec::new(),
            unit: "mm".into(),
            compare: Vec::new(),
        }
    }
}

/// `name=value`, as `--param` and `--pose` take it.
///
/// ```
/// assert_eq!(pkm::report::parse_param("l1 = 120"), Ok(("l1".to_string(), 120.0)));
/// ```
pub fn parse_param(s: &str) -> Result<(String, f64), String> {
    let (k, v) = s
        .split_once('=')
        .ok_or_else(|| format!("expected name=value, found `{s}`"))?;
    let v: f64 = v.trim().parse().map_err(|e| format!("`{v}` is not a number: {e}"))?;
    Ok((k.trim().to_string(), v))
}

/// `low:high`.
///
/// ```
/// assert_eq!(pkm::report::parse_range("-250:0"), Ok((-250.0, 0.0)));
/// assert!(pkm::report::parse_range("5").is_err());
/// ```
pub fn parse_range(s: &str) -> Result<(f64, f64), String> {
    let (a, b) = s
        .split_once(':')
        .ok_or_else(|| format!("expected low:high, found `{s}`"))?;
    let num = |x: &str| {
        x.trim()
            .parse::<f64>()
            .map_err(|e| format!("`{x}` is not a number: {e}"))
    };
    Ok((num(a)?, num(b)?))
}

/// `x=60`: a section plane by its axis and value.
///
/// ```
/// assert_eq!(pkm::report::parse_section("y=-85"), Ok((1, -85.0)));
/// ```
pub fn parse_section(s: &str) -> Result<(usize, f64), String> {
    let (axis, v) = parse_param(s)?;
    let i = ["x", "y", "z"]
        .iter()
        .position(|a| *a == axis)
        .ok_or_else(|| format!("a section's axis is x, y or z, found `{axis}`"))?;
    Ok((i, v))
}

/// A solution plan run by the interpreter, planar or spatial.
enum AnyPlan {
    Planar(pkm_runtime::plan::Plan),
    Spatial(pkm_runtime::spatial::Plan),
}

impl AnyPlan {
    fn choices(&self) -> usize {
        match self {
            AnyPlan::Planar(p) => p.branches,
            AnyPlan::Spatial(p) => p.branches,
        }
    }

    /// The joint values of one branch, or why there is none.
    fn solve(&self, model: &Model, q: &[f64], signs: &[Sign]) -> Result<Vec<f64>, String> {
        match self {
            AnyPlan::Planar(p) => pkm_runtime::plan::run(model, p, q, signs).map(|s| s.values),
            AnyPlan::Spatial(p) => pkm_runtime::spatial::run(model, p, q, signs).map(|s| s.values),
        }
        .map_err(|e| e.to_string())
    }

    /// Its steps' determinant factors at the link poses `poses`.
    fn factors(&self, model: &Model, poses: &[pkm_runtime::spatial::Pose3]) -> Vec<singular::Factor> {
        match self {
            AnyPlan::Planar(p) => singular::planar_factors(model, p, poses),
            AnyPlan::Spatial(p) => singular::spatial_factors(model, p, poses),
        }
    }
}

/// A `.pkm` file ready to solve: its analysis, numeric model, outputs and plans.
struct Loaded {
    analysis: pkm_dsl::report::Analysis,
    model: Model,
    outputs: Vec<Output>,
    forward: AnyPlan,
    /// The inverse plan, if the file declares outputs.
    inverse: Option<AnyPlan>,
}

fn load(text: &str, params: &[(String, f64)]) -> Result<Loaded, String> {
    let render = |d: pkm_dsl::Diagnostics| d.render(text, "input");
    let a = pkm_dsl::analyze_source(text).map_err(render)?;
    let values = params.iter().cloned().collect();
    let model = pkm_dsl::plan::model(&a, &values).map_err(render)?;
    let outputs = pkm_dsl::plan::newton_outputs(&a, &model, &values).map_err(render)?;
    let (forward, inverse) = if model.planar {
        (
            AnyPlan::Planar(pkm_dsl::plan::forward_plan(&a).map_err(render)?),
            pkm_dsl::plan::inverse_plan(&a).ok().map(AnyPlan::Planar),
        )
    } else {
        (
            AnyPlan::Spatial(pkm_dsl::plan3::forward_plan(&a).map_err(render)?),
            pkm_dsl::plan3::inverse_plan(&a).ok().map(AnyPlan::Spatial),
        )
    };
    Ok(Loaded {
        analysis: a,
        model,
        outputs,
        forward,
        inverse,
    })
}

/// The position of `point` of `l` at every node of `grid`, on one branch
/// (all cores).
fn sweep_point(
    l: &Loaded,
    grid: &Grid,
    signs: &[Sign],
    point: (usize, [f64; 3]),
) -> Result<Vec<Option<[f64; 3]>>, String> {
    let reach = |q: &[f64]| -> Option<[f64; 3]> {
        let v = l.forward.solve(&l.model, q, signs).ok()?;
        world(&l.model, &v, point.0, point.1)
    };
    Ok(match grid.ranges.len() {
        1 => sweep_nodes::<1>(grid, |q| reach(q)),
        2 => sweep_nodes::<2>(grid, |q| reach(q)),
        3 => sweep_nodes::<3>(grid, |q| reach(q)),
        _ => return Err("the report sweeps mechanisms with 1 to 3 inputs".into()),
    })
}

/// The workspace volume of `point` on every branch of this file and of each
/// `--compare` file, swept over the same grid: one table.
fn volume_table(this: &Loaded, name: &str, o: &ReportOptions, grid: &Grid, point: &str) -> Result<String, String> {
    let mut files = vec![(name.to_string(), None)];
    for path in &o.compare {
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let l = load(&text, &o.params).map_err(|e| format!("{}: {e}", path.display()))?;
        files.push((l.model.name.clone(), Some(l)));
    }
    let mut html = format!(
        "<h3>Workspace volumes of {point}, every branch</h3><p>The same ranges and grid ({} nodes); \
         the volume by the method above.</p><table><tr><th>mechanism</th><th>branch</th><th>reachable nodes</th>\
         <th>volume ({}³)</th></tr>",
        grid.len(),
        o.unit
    );
    for (name, other) in &files {
        let l = other.as_ref().unwrap_or(this);
        let at = point_of(&l.model, point).ok_or(format!("{name} has no point `{point}`"))?;
        let choices = l.forward.choices();
        for b in 0..1usize << choices {
            let s = signs(choices, b);
            let nodes = sweep_point(l, grid, &s, at)?;
            let reachable = nodes.iter().flatten().count();
            let _ = writeln!(
                html,
                "<tr><td>{}</td><td>{b} ({})</td><td>{reachable}</td><td>{:.4e}</td></tr>",
                html_escape(name),
                sign_text(&s),
                image_volume(grid, &nodes)
            );
        }
    }
    html.push_str("</table>\n");
    Ok(html)
}

/// Every factor of det J_o (the forward plan's) and det J_i (the inverse
/// plan's) at `poses`: a label (`J_o step 3`), its value, what it says.
fn named_factors(l: &Loaded, poses: &[pkm_runtime::spatial::Pose3]) -> Vec<(String, f64, String)> {
    plan_factors(l, poses)
        .map(|(jacobian, f)| {
            (
                format!("{jacobian} step {}", f.step),
                f.value,
                f.describe(&l.model, poses),
            )
        })
        .collect()
}

/// The factors alone, forward plan's then inverse plan's, each with its
/// Jacobian's name (the order of [`named_factors`]).
fn plan_factors<'a>(
    l: &'a Loaded,
    poses: &'a [pkm_runtime::spatial::Pose3],
) -> impl Iterator<Item = (&'static str, singular::Factor)> + 'a {
    [("J_o", Some(&l.forward)), ("J_i", l.inverse.as_ref())]
        .into_iter()
        .flat_map(move |(jacobian, plan)| {
            plan.map(|p| p.factors(&l.model, poses))
                .unwrap_or_default()
                .into_iter()
                .map(move |f| (jacobian, f))
        })
}

/// Where each determinant factor comes near 0 over the sweep: a figure (the
/// nodes where it is below 0.05, projected on xOz) and a table naming it.
/// `named` are the factors as named at the sample ([`named_factors`]).
fn factor_loci(
    named: &[(String, f64, String)],
    o: &ReportOptions,
    out: &Path,
    measured: &[([f64; 3], f64, f64)],
    values: &[Vec<f64>],
) -> Result<String, String> {
    const NEAR: f64 = 0.05;
    if named.is_empty() {
        return Ok(String::new());
    }
    let mut series = Vec::new();
    let mut html = format!(
        "<h3>Which factor comes near 0</h3><p>Over the same nodes, each determinant factor's smallest value, \
         and (figure) the nodes where it is below {NEAR}.</p><table><tr><th>factor</th><th>smallest</th>\
         <th>nodes below {NEAR}</th><th style=\"text-align:left\">vanishes when</th></tr>"
    );
    for (k, (label, _, what)) in named.iter().enumerate() {
        let at = |i: usize| values[i].get(k).copied().unwrap_or(f64::INFINITY);
        let smallest = (0..values.len()).map(at).fold(f64::INFINITY, f64::min);
        let near: Vec<[f64; 2]> = (0..values.len().min(measured.len()))
            .filter(|&i| at(i) < NEAR)
            .map(|i| [measured[i].0[0], measured[i].0[2]])
            .collect();
        let _ = writeln!(
            html,
            "<tr><td>{label}</td><td>{smallest:.3e}</td><td>{}</td><td style=\"text-align:left\">{}</td></tr>",
            near.len(),
            html_escape(what)
        );
        if !near.is_empty() {
            series.push((label.clone(), near));
        }
    }
    html.push_str("</table>\n");
    if !series.is_empty() {
        let f = plots::scatter(
            &out.join("singularity_factors"),
            &format!("Nodes where a determinant factor is below {NEAR}"),
            [&format!("x ({})", o.unit), &format!("z ({})", o.unit)],
            &series,
        )
        .map_err(|e| e.to_string())?;
        html.push_str(&figure_html(&f, "Near-vanishing factors, projected on xOz"));
    }
    Ok(html)
}

/// `+−+`: a branch's signs as text.
fn sign_text(s: &[Sign]) -> String {
    s.iter().map(|x| if *x == Sign::Plus { '+' } else { '−' }).collect()
}

fn signs(choices: usize, index: usize) -> Vec<Sign> {
    (0..choices)
        .map(|k| if index >> k & 1 == 1 { Sign::Minus } else { Sign::Plus })
        .collect()
}

/// A point of the model by name: a named point or a joint's point.
fn point_of(model: &Model, name: &str) -> Option<(usize, [f64; 3])> {
    if let Some(p) = model.points.iter().find(|p| p.name == name) {
        return Some((p.link, p.at));
    }
    let j = model.joints.iter().position(|j| j.name == name)?;
    let joint = &model.joints[j];
    let side = joint.point_side();
    Some((joint.links[side], joint.places[side].at()))
}

fn world(model: &Model, values: &[f64], link: usize, local: [f64; 3]) -> Option<[f64; 3]> {
    let poses = newton::link_poses(model, values).ok()?;
    let p = poses[link].transform_point(&local.into());
    Some([p.x, p.y, p.z])
}

fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

/// A figure inline (its PNG as a data URI, so the page stands alone) with
/// links to the files beside the page.
fn figure_html(f: &Figure, caption: &str) -> String {
    use base64::Engine as _;
    let png = std::fs::read(&f.png).unwrap_or_default();
    let data = base64::engine::general_purpose::STANDARD.encode(png);
    let name = |p: &PathBuf| {
        p.file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default()
    };
    format!(
        "<figure><img alt=\"{0}\" src=\"data:image/png;base64,{data}\"><figcaption>{0} (<a href=\"{1}\">PNG</a>, \
         <a href=\"{2}\">SVG</a>, <a href=\"{3}\">CSV</a>)</figcaption></figure>\n",
        html_escape(caption),
        name(&f.png),
        name(&f.svg),
        name(&f.csv)
    )
}

/// Writes the report for the mechanism text `text` into `out` (created if
/// needed); returns the page's path.
///
/// # Example
/// A four-bar's coupler point E over a full crank turn:
/// ```
/// let text = std::fs::read_to_string("examples/mechanisms/four_bar.pkm").unwrap();
/// let options = pkm::report::ReportOptions {
///     ranges: vec![(-3.1, 3.1)],
///     nodes: 40,
///     point: Some("E".into()),
///     ..Default::default()
/// };
/// let out = std::env::temp_dir().join("pkm-doc-report");
/// let page = pkm::report::write_report(&text, &options, &out).unwrap();
/// assert!(std::fs::read_to_string(page).unwrap().contains("Workspace of E"));
/// ```
pub fn write_report(text: &str, o: &ReportOptions, out: &Path) -> Result<PathBuf, String> {
    let loaded = load(text, &o.params)?;
    let Loaded {
        analysis: a,
        model,
        outputs,
        forward,
        ..
    } = &loaded;
    let inputs = model.inputs();
    let n = inputs.len();
    if o.ranges.len() != n {
        return Err(format!(
            "expected {n} ranges (one per actuator), got {}",
            o.ranges.len()
        ));
    }
    std::fs::create_dir_all(out).map_err(|e| e.to_string())?;
    let unit = &o.unit;
    let point_name = o.point.clone().or_else(|| {
        a.geometry.outputs.iter().find_map(|out| match &out.kind {
            pkm_dsl::geometry::OutputKind::Pose { point, .. } | pkm_dsl::geometry::OutputKind::Point { point, .. } => {
                Some(match point {
                    pkm_runtime::plan::PointRef::Named(k) => a.geometry.points[*k].name.clone(),
                    pkm_runtime::plan::PointRef::Joint(j) => model.joints[*j].name.clone(),
                })
            }
            _ => None,
        })
    });
    let point_name = point_name.ok_or("no point to follow: give --point")?;
    let (plink, plocal) = point_of(model, &point_name).ok_or(format!("no point `{point_name}`"))?;
    let start = o
        .start
        .clone()
        .unwrap_or_else(|| o.ranges.iter().map(|(lo, hi)| (lo + hi) / 2.0).collect());
    let amplitude = o
        .amplitude
        .clone()
        .unwrap_or_else(|| o.ranges.iter().map(|(lo, hi)| 0.05 * (hi - lo)).collect());
    if start.len() != n || amplitude.len() != n {
        return Err(format!("--start and --amplitude need {n} values each"));
    }
    let choices = forward.choices();
    let branch_signs = signs(choices, o.branch);
    let revolute: Vec<bool> = model
        .joints
        .iter()
        .map(|j| j.kind != pkm_runtime::model::JointType::P)
        .collect();
    let mut page = String::new();
    let title = html_escape(&format!("{} — pkm report", model.name));
    let _ = writeln!(
        page,
        "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>{title}</title>\
         <style>body{{font-family:sans-serif;max-width:60em;margin:auto}}pre{{background:#f6f6f6;padding:1em;overflow:auto}}\
         table{{border-collapse:collapse}}td,th{{border:1px solid #ccc;padding:2px 6px;text-align:right}}\
         figure{{margin:1em 0}}figure img{{max-width:100%;height:auto}}</style></head><body><h1>{title}</h1>"
    );

    // 1. Topology.
    let _ = writeln!(page, "<h2>Topology</h2><pre>{}</pre>", html_escape(&a.report()));

    // 2. Position solutions and singularity measures at the sample input.
    let _ = writeln!(
        page,
        "<h2>Position solutions at q = {start:?}</h2><p>Every branch of the closed-form forward solution; \
         σ_in and σ_out are the relative smallest singular values of the velocity equations (0 at an input \
         or output singularity).</p><table><tr><th>signs</th><th>{point_name} ({unit})</th><th>outputs</th>\
         <th>σ_in</th><th>σ_out</th><th>class</th></tr>"
    );
    for b in 0..1usize << choices {
        let s = signs(choices, b);
        let label = sign_text(&s);
        match forward.solve(model, &start, &s) {
            Ok(v) => {
                let p = world(model, &v, plink, plocal).unwrap_or([f64::NAN; 3]);
                let poses = newton::link_poses(model, &v).map_err(|e| e.to_string())?;
                let outs = pose_outputs(model, &poses, outputs);
                let (si, so, class) = match velocity::jacobians(model, &v, outputs) {
                    Ok(j) => (j.input_sigma, j.output_sigma, format!("{:?}", j.singularity)),
                    Err(e) => (f64::NAN, f64::NAN, e.to_string()),
                };
                let _ = writeln!(
                    page,
                    "<tr><td>{label}</td><td>({:.4}, {:.4}, {:.4})</td><td>{}</td><td>{si:.3e}</td><td>{so:.3e}</td><td>{class}</td></tr>",
                    p[0],
                    p[1],
                    p[2],
                    outs.iter().map(|x| format!("{x:.6}")).collect::<Vec<_>>().join(", ")
                );
            }
            Err(e) => {
                let _ = writeln!(
                    page,
                    "<tr><td>{label}</td><td colspan=5 style=\"text-align:left\">{}</td></tr>",
                    html_escape(&e)
                );
            }
        }
    }
    page.push_str("</table>\n");

    // The determinants' factors on the followed branch at the sample.
    let mut sample_factors = Vec::new();
    if let Ok(v) = forward.solve(model, &start, &branch_signs) {
        let poses = newton::link_poses(model, &v).map_err(|e| e.to_string())?;
        sample_factors = named_factors(&loaded, &poses);
        let _ = writeln!(
            page,
            "<h3>Determinant factors on branch {} ({})</h3><p>Each step of a closed-form plan solves one joint from \
             one scalar equation; in the plan's order the velocity equations are triangular and each determinant is \
             the product of the steps' derivatives. A factor is a step's derivative normalised to [0, 1] (the sine \
             of the angle at which a point's path meets the surface it must reach): 0 is a singularity, and the \
             condition says where. The forward plan's factors are det J_o's (output singularities), the inverse \
             plan's det J_i's (input singularities).</p><table><tr><th>factor</th><th>value</th>\
             <th style=\"text-align:left\">vanishes when</th></tr>",
            o.branch,
            sign_text(&branch_signs)
        );
        for (label, value, what) in &sample_factors {
            let _ = writeln!(
                page,
                "<tr><td>{label}</td><td>{value:.4}</td><td style=\"text-align:left\">{}</td></tr>",
                html_escape(what)
            );
        }
        page.push_str("</table>\n");
    }

    // 3. Workspace.
    let grid = Grid {
        ranges: o.ranges.clone(),
        counts: vec![o.nodes; n],
    };
    let nodes = sweep_point(&loaded, &grid, &branch_signs, (plink, plocal))?;
    let cloud: Vec<[f64; 3]> = nodes.iter().flatten().copied().collect();
    let volume = (n == 3).then(|| image_volume(&grid, &nodes));
    let axes = ["x", "y", "z"];
    let _ = writeln!(
        page,
        "<h2>Workspace of {point_name}</h2><p>Branch {} ({}), inputs swept over {:?} with {} nodes each: \
         {} of {} nodes reachable.{}</p>",
        o.branch,
        sign_text(&branch_signs),
        o.ranges,
        o.nodes,
        cloud.len(),
        grid.len(),
        volume
            .map(|v| format!(
                " Volume {v:.4e} {unit}³ (the image of the input grid: each fully reachable grid cell split into six \
                 tetrahedra whose images' volumes are summed)."
            ))
            .unwrap_or_default()
    );
    if n == 3 {
        page.push_str(&volume_table(&loaded, &model.name, o, &grid, &point_name)?);
    }
    for (i, j, plane) in [(0, 1, "xOy"), (1, 2, "yOz"), (0, 2, "xOz")] {
        let f = plots::scatter(
            &out.join(format!("workspace_{plane}")),
            &format!("Workspace of {point_name}: projection on {plane}"),
            [&format!("{} ({unit})", axes[i]), &format!("{} ({unit})", axes[j])],
            &[(point_name.clone(), cloud.iter().map(|p| [p[i], p[j]]).collect())],
        )
        .map_err(|e| e.to_string())?;
        page.push_str(&figure_html(&f, &format!("Projection on {plane}")));
    }
    for &(axis, value) in &o.sections {
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
        let f = plots::scatter(
            &out.join(format!("section_{}_{value}", axes[axis])),
            &format!("Section {} = {value} {unit} (±{slab:.2})", axes[axis]),
            [&format!("{} ({unit})", axes[i]), &format!("{} ({unit})", axes[j])],
            &[(point_name.clone(), cut)],
        )
        .map_err(|e| e.to_string())?;
        page.push_str(&figure_html(&f, &format!("Section {} = {value}", axes[axis])));
    }

    // 4. Singularity loci over a coarser sweep.
    let coarse = Grid {
        ranges: o.ranges.clone(),
        counts: vec![(o.nodes / 3).max(8); n],
    };
    let mut measured: Vec<([f64; 3], f64, f64)> = Vec::new();
    // Each node's determinant factors (forward plan's, then inverse plan's).
    let mut factor_values: Vec<Vec<f64>> = Vec::new();
    let mut q = vec![0.0; n];
    for index in 0..coarse.len() {
        coarse.node(index, &mut q);
        let Ok(v) = forward.solve(model, &q, &branch_signs) else {
            continue;
        };
        let (Some(p), Ok(j)) = (world(model, &v, plink, plocal), velocity::jacobians(model, &v, outputs)) else {
            continue;
        };
        measured.push((p, j.input_sigma, j.output_sigma));
        let poses = newton::link_poses(model, &v).map_err(|e| e.to_string())?;
        factor_values.push(plan_factors(&loaded, &poses).map(|(_, f)| f.value).collect());
    }
    let quantile = |k: usize| {
        let mut s: Vec<f64> = measured.iter().map(|m| if k == 0 { m.1 } else { m.2 }).collect();
        s.sort_by(f64::total_cmp);
        s.get(s.len() / 20).copied().unwrap_or(0.0)
    };
    let (qi, qo) = (quantile(0), quantile(1));
    let near = |k: usize, limit: f64| -> Vec<[f64; 2]> {
        measured
            .iter()
            .filter(|m| (if k == 0 { m.1 } else { m.2 }) <= limit)
            .map(|m| [m.0[0], m.0[2]])
            .collect()
    };
    let f = plots::scatter(
        &out.join("singularity_loci"),
        "Near-singular configurations (lowest 5 % of each measure)",
        [&format!("x ({unit})"), &format!("z ({unit})")],
        &[
            (format!("input, σ_in ≤ {qi:.2e}"), near(0, qi)),
            (format!("output, σ_out ≤ {qo:.2e}"), near(1, qo)),
        ],
    )
    .map_err(|e| e.to_string())?;
    let combined = measured
        .iter()
        .filter(|m| m.1 < velocity::SINGULAR && m.2 < velocity::SINGULAR)
        .count();
    let _ = writeln!(
        page,
        "<h2>Singularities</h2><p>Over a {}-node sweep of the same branch: the smallest σ_in is {:.3e}, the smallest \
         σ_out {:.3e}; {combined} nodes are singular in both senses at once (threshold {:e}).</p>",
        measured.len(),
        measured.iter().map(|m| m.1).fold(f64::INFINITY, f64::min),
        measured.iter().map(|m| m.2).fold(f64::INFINITY, f64::min),
        velocity::SINGULAR
    );
    page.push_str(&figure_html(&f, "Near-singular configurations, projected on xOz"));
    page.push_str(&factor_loci(&sample_factors, o, out, &measured, &factor_values)?);

    // 5. Trajectory: velocity and acceleration of the point.
    let steps = 500;
    let dt = o.duration / steps as f64;
    let mut previous: Option<Vec<f64>> = None;
    let (mut ts, mut vel, mut acc) = (Vec::new(), vec![Vec::new(); 4], vec![Vec::new(); 4]);
    let mut stopped = None;
    for k in 0..=steps {
        let t = k as f64 * dt;
        let w = std::f64::consts::PI;
        let q: Vec<f64> = (0..n).map(|i| start[i] + amplitude[i] * (w * t).sin()).collect();
        let qd: Vec<f64> = (0..n).map(|i| amplitude[i] * w * (w * t).cos()).collect();
        let qdd: Vec<f64> = (0..n).map(|i| -amplitude[i] * w * w * (w * t).sin()).collect();
        let candidates: Vec<Vec<f64>> = match &previous {
            None => forward.solve(model, &q, &branch_signs).into_iter().collect(),
            Some(_) => (0..1usize << choices)
                .filter_map(|b| forward.solve(model, &q, &signs(choices, b)).ok())
                .collect(),
        };
        let chosen = match &previous {
            None => candidates.into_iter().next(),
            Some(p) => candidates.into_iter().min_by(|x, y| {
                pkm_runtime::plan::joint_distance(x, p, &revolute)
                    .total_cmp(&pkm_runtime::plan::joint_distance(y, p, &revolute))
            }),
        };
        let Some(v) = chosen else {
            stopped = Some(t);
            break;
        };
        let a = match velocity::accelerations(model, &v, &qd, &qdd) {
            Ok(a) => a,
            Err(e) => {
                stopped = Some(t);
                let _ = write!(
                    page,
                    "<p>The trajectory stops at t = {t:.3} s: {}</p>",
                    html_escape(&e.to_string())
                );
                break;
            }
        };
        let poses = newton::link_poses(model, &v).map_err(|e| e.to_string())?;
        let p = poses[plink].transform_point(&plocal.into()).coords;
        let twist = a.velocities.twists[plink];
        let pv = twist.at(&p);
        let pa = velocity::point_acceleration(&twist, &a.twists[plink], &p);
        ts.push(t);
        for i in 0..3 {
            vel[i].push(pv[i]);
            acc[i].push(pa[i]);
        }
        vel[3].push(pv.norm());
        acc[3].push(pa.norm());
        previous = Some(v);
    }
    let _ =
        writeln!(
        page,
        "<h2>Velocity and acceleration of {point_name}</h2><p>Inputs q_i(t) = {start:?}_i + {amplitude:?}_i·sin(πt), \
         0 ≤ t ≤ {} s, along the branch that continues from branch {} ({} steps){}; rates from the differentiated \
         loop equations.</p>",
        o.duration,
        o.branch,
        ts.len(),
        stopped.map(|t| format!(", stopped at t = {t:.3} s")).unwrap_or_default()
    );
    let names = ["x", "y", "z", "magnitude"];
    let series = |d: &[Vec<f64>]| -> Vec<(String, Vec<f64>)> {
        names.iter().zip(d).map(|(n, v)| (n.to_string(), v.clone())).collect()
    };
    for (stem, title, axis, data) in [
        ("velocity", "Velocity", format!("v ({unit}/s)"), &vel),
        ("acceleration", "Acceleration", format!("a ({unit}/s²)"), &acc),
    ] {
        let f = plots::curves(
            &out.join(stem),
            &format!("{title} of {point_name}"),
            ["t (s)", &axis],
            &ts,
            &series(data),
        )
        .map_err(|e| e.to_string())?;
        page.push_str(&figure_html(&f, title));
    }

    page.push_str("</body></html>\n");
    let path = out.join("index.html");
    std::fs::write(&path, page).map_err(|e| e.to_string())?;
    Ok(path)
}

/// The declared outputs' values from link poses.
fn pose_outputs(model: &Model, poses: &[pkm_runtime::spatial::Pose3], outputs: &[Output]) -> Vec<f64> {
    let mut v = Vec::new();
    for o in outputs {
        match *o {
            Output::Pose { link, local, about } => {
                let p = pkm_runtime::spatial::at(&poses[link], local);
                v.extend_from_slice(if model.planar { &p[..2] } else { &p[..] });
                if let Some(k) = about {
                    v.push(pkm_runtime::spatial::angle_about(&poses[link], k));
                }
            }
            Output::Point { link, local } => {
                let p = pkm_runtime::spatial::at(&poses[link], local);
                v.extend_from_slice(if model.planar { &p[..2] } else { &p[..] });
            }
            Output::Joint(j) => {
                let joint = &model.joints[j];
                v.push(pkm_runtime::spatial::joint_value(
                    &pkm_runtime::spatial::Joint3::of(joint),
                    &poses[joint.links[0]],
                    &poses[joint.links[1]],
                ));
            }
        }
    }
    v
}
