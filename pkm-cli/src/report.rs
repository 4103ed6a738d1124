//! `pkm report`: one self-contained HTML page for a `.pkm` file: the
//! settings used, the topology (text and link–joint graph), a drawing of the
//! mechanism at the sample input and its animation along the trajectory, the
//! position solutions with their singularity measures, the workspace of a
//! chosen point (3-D view, projections, sections, and its volume, area or
//! length as its dimension allows), singularity loci, and the point's
//! velocity and acceleration. Every figure is also written as PNG, SVG and
//! CSV beside the page. Works from the file alone: what to sample comes from
//! its `study { … }` block (see `docs/report.md`), the command line
//! overriding each key, and sensible defaults for the rest.

use crate::drawing::{self, Scene, View};
use crate::plots::{self, Figure, Style};
use pkm_dsl::study::{Motion, Resolved};
use pkm_runtime::model::{JointType, Model};
use pkm_runtime::nalgebra::{Matrix3, Vector3};
use pkm_runtime::newton::{self, Output};
use pkm_runtime::primitives::Sign;
use pkm_runtime::spatial::Pose3;
use pkm_runtime::workspace::{image_volume, sweep_nodes, Grid};
use pkm_runtime::{singular, velocity};
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The most nodes a workspace sweep may have (all inputs together): its
/// memory and run time stay bounded (about 32 MB and a few seconds per
/// million nodes).
pub const MAX_GRID: usize = 1_000_000;

/// The longest trajectory, in seconds.
pub const MAX_DURATION: f64 = 1.0e4;

/// What the report samples (also the `pkm report` command line's options).
/// Each overrides the file's `study` block.
#[derive(Debug, Clone, clap::Args)]
pub struct ReportOptions {
    /// Override a parameter: `--param l1=120`.
    #[arg(long = "param", value_parser = parse_param)]
    pub params: Vec<(String, f64)>,
    /// Each actuator's range for the workspace sweep: `--ranges=-250:0,0:250,-300:300`.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true, value_parser = parse_range)]
    pub ranges: Vec<(f64, f64)>,
    /// Grid nodes per input in the sweep (2 to 1000, and at most 10⁶ nodes in all).
    #[arg(long)]
    pub nodes: Option<usize>,
    /// The assembly branch swept and followed (its index in `signs_of` order);
    /// default: the first that is reachable and regular at the sample.
    #[arg(long)]
    pub branch: Option<usize>,
    /// The point shown (a named point or a joint); default: the first pose or point output's point.
    #[arg(long)]
    pub point: Option<String>,
    /// The sample input and the trajectory's start; default: the ranges' middles
    /// (or the reachable node nearest them).
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub start: Option<Vec<f64>>,
    /// A sine trajectory: input i is start_i + amplitude_i·sin(πt).
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true, conflicts_with = "speed")]
    pub amplitude: Option<Vec<f64>>,
    /// A constant-speed trajectory: input i is start_i + speed_i·t.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub speed: Option<Vec<f64>>,
    /// The trajectory's duration in seconds (above 0, at most 10⁴).
    #[arg(long, allow_hyphen_values = true)]
    pub duration: Option<f64>,
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
            nodes: None,
            branch: None,
            point: None,
            start: None,
            amplitude: None,
            speed: None,
            duration: None,
            sections: Vec::new(),
            unit: "mm".into(),
            compare: Vec::new(),
        }
    }
}

/// Why a report could not be written. Its `Display` text is complete (one
/// `error:`, the file's path); [`ReportError::message`] is one line without
/// the prefix, for callers that print their own.
#[derive(Debug, Clone)]
pub enum ReportError {
    /// The file's diagnostics (at their spans in the file's text).
    Source {
        /// The diagnostics, for callers that render or serialise them.
        diagnostics: pkm_dsl::Diagnostics,
        /// Them rendered with the file's path, line, column and caret.
        rendered: String,
    },
    /// An option or study value out of range, or nothing to sample.
    Invalid(String),
    /// Writing the page or a figure failed.
    Write(String),
}

impl ReportError {
    /// One line naming the cause, without `error: `.
    pub fn message(&self) -> String {
        match self {
            ReportError::Source { diagnostics, .. } => {
                let first = diagnostics.0.first().map(|d| d.message.clone()).unwrap_or_default();
                match diagnostics.0.len() {
                    0 | 1 => first,
                    k => format!("{first} (and {} more)", k - 1),
                }
            }
            ReportError::Invalid(s) | ReportError::Write(s) => s.clone(),
        }
    }

    fn source(diagnostics: pkm_dsl::Diagnostics, text: &str, file: &str) -> ReportError {
        let rendered = diagnostics.render(text, file);
        ReportError::Source { diagnostics, rendered }
    }
}

impl std::fmt::Display for ReportError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ReportError::Source { rendered, .. } => f.write_str(rendered.trim_end()),
            ReportError::Invalid(s) | ReportError::Write(s) => write!(f, "error: {s}"),
        }
    }
}

impl std::error::Error for ReportError {}

impl From<plots::PlotError> for ReportError {
    fn from(e: plots::PlotError) -> Self {
        ReportError::Write(e.0)
    }
}

fn invalid(s: impl Into<String>) -> ReportError {
    ReportError::Invalid(s.into())
}

fn io(path: &Path) -> impl Fn(std::io::Error) -> ReportError + '_ {
    move |e| ReportError::Write(format!("{}: {e}", path.display()))
}

/// `name=value`, as `--param` and `--pose` take it.
///
/// ```
/// assert_eq!(pkm_cli::report::parse_param("l1 = 120"), Ok(("l1".to_string(), 120.0)));
/// ```
pub fn parse_param(s: &str) -> Result<(String, f64), String> {
    let (k, v) = s
        .split_once('=')
        .ok_or_else(|| format!("expected name=value, found `{s}`"))?;
    let v: f64 = v.trim().parse().map_err(|e| format!("`{v}` is not a number: {e}"))?;
    Ok((k.trim().to_string(), v))
}

/// `low:high`, with low below high.
///
/// ```
/// assert_eq!(pkm_cli::report::parse_range("-250:0"), Ok((-250.0, 0.0)));
/// assert!(pkm_cli::report::parse_range("5").is_err());
/// assert!(pkm_cli::report::parse_range("3:1").is_err());
/// assert!(pkm_cli::report::parse_range("1:1").is_err());
/// ```
pub fn parse_range(s: &str) -> Result<(f64, f64), String> {
    let (a, b) = s
        .split_once(':')
        .ok_or_else(|| format!("expected low:high, found `{s}`"))?;
    let num = |x: &str| {
        x.trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("`{x}` is not a finite number"))
    };
    let (lo, hi) = (num(a)?, num(b)?);
    if lo >= hi {
        return Err(format!(
            "the range {lo}:{hi} is empty or inverted: low must be below high"
        ));
    }
    Ok((lo, hi))
}

/// `x=60`: a section plane by its axis and value.
///
/// ```
/// assert_eq!(pkm_cli::report::parse_section("y=-85"), Ok((1, -85.0)));
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
    fn factors(&self, model: &Model, poses: &[Pose3]) -> Vec<singular::Factor> {
        match self {
            AnyPlan::Planar(p) => singular::planar_factors(model, p, poses),
            AnyPlan::Spatial(p) => singular::spatial_factors(model, p, poses),
        }
    }
}

/// A `.pkm` file ready to solve: its analysis, numeric model, outputs and plans.
struct Loaded {
    analysis: pkm_dsl::analysis::Analysis,
    model: Model,
    outputs: Vec<Output>,
    /// The forward plan, or why there is none (κ ≠ 0).
    forward: Result<AnyPlan, String>,
    /// The inverse plan, if the file declares outputs.
    inverse: Option<AnyPlan>,
    /// The parameter values used.
    values: HashMap<String, f64>,
}

/// The first line of a diagnostic's message (without `error: `).
fn headline(d: &pkm_dsl::Diagnostics) -> String {
    d.0.first().map(|x| x.message.clone()).unwrap_or_default()
}

/// The analysis and parameter values of a file; `Ok(None)` for the model
/// when the file has no geometry.
fn load(
    text: &str,
    file: &str,
    params: &[(String, f64)],
) -> Result<(pkm_dsl::analysis::Analysis, Option<Loaded>), ReportError> {
    let render = |d: pkm_dsl::Diagnostics| ReportError::source(d, text, file);
    let a = pkm_dsl::analyze_source(text).map_err(render)?;
    // Only the overrides: the others, derived ones included, are resolved from them.
    let values = pkm_dsl::params::overrides(&a, params).map_err(|e| {
        invalid(match e {
            pkm_dsl::params::ParamError::Unknown { name, known, .. } => {
                format!(
                    "{file}: --param {name}: no such parameter (the parameters: {})",
                    known.join(", ")
                )
            }
            pkm_dsl::params::ParamError::NotFinite { name, value } => {
                format!("--param {name}={value}: not a finite number")
            }
            e => format!("{file}: --param {}: {e}", e.name()),
        })
    })?;
    if !a.geometry.complete {
        return Ok((a, None));
    }
    let model = pkm_dsl::plan::model(&a, &values).map_err(render)?;
    let outputs = pkm_dsl::plan::newton_outputs(&a, &model, &values).map_err(render)?;
    // Every parameter's value, for the study block's expressions.
    let values = pkm_dsl::plan::parameter_values(&a, &values).map_err(render)?;
    let (forward, inverse) = if model.planar {
        (
            pkm_dsl::plan::forward_plan(&a)
                .map(AnyPlan::Planar)
                .map_err(|d| headline(&d)),
            pkm_dsl::plan::inverse_plan(&a).ok().map(AnyPlan::Planar),
        )
    } else {
        (
            pkm_dsl::plan3::forward_plan(&a)
                .map(AnyPlan::Spatial)
                .map_err(|d| headline(&d)),
            pkm_dsl::plan3::inverse_plan(&a).ok().map(AnyPlan::Spatial),
        )
    };
    Ok((
        a.clone(),
        Some(Loaded {
            analysis: a,
            model,
            outputs,
            forward,
            inverse,
            values,
        }),
    ))
}

/// The position of `point` of the model at every node of `grid`, on one
/// branch (all cores).
fn sweep_point(
    model: &Model,
    plan: &AnyPlan,
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

/// `+−+`: a branch's signs as text.
fn sign_text(s: &[Sign]) -> String {
    if s.is_empty() {
        return "(one)".into();
    }
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

/// Numbers as `(a, b, c)` with `digits` decimals.
fn tuple_text(v: &[f64], digits: usize) -> String {
    format!(
        "({})",
        v.iter().map(|x| format!("{x:.digits$}")).collect::<Vec<_>>().join(", ")
    )
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

/// The world axis (0, 1, 2) a unit direction lies along, if it does.
fn world_axis(d: [f64; 3]) -> Option<usize> {
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
    let (dx, dy) = ((xr.1 - xr.0) / across as f64, (yr.1 - yr.0) / across as f64);
    let mut full = vec![false; across * across];
    for p in points {
        let i = (((p[0] - xr.0) / dx) as usize).min(across - 1);
        let j = (((p[1] - yr.0) / dy) as usize).min(across - 1);
        full[i * across + j] = true;
    }
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
fn measure(grid: &Grid, nodes: &[Option<[f64; 3]>], unit: &str) -> String {
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

fn plane_name(p: [usize; 2]) -> String {
    let axes = ["x", "y", "z"];
    format!("{}O{}", axes[p[0]], axes[p[1]])
}

/// Where a setting came from.
#[derive(Clone, Copy)]
enum Origin {
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

/// The default grid nodes per input: about 64 000 nodes at most.
fn default_nodes(inputs: usize) -> usize {
    match inputs {
        1 => 721,
        2 => 200,
        _ => 40,
    }
}

/// Checks grid nodes against their limits.
fn check_nodes(nodes: usize, inputs: usize) -> Result<(), ReportError> {
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

/// The mechanism's size: the largest distance between two joint places on
/// one link, summed over links (an upper bound of its reach).
fn reach(model: &Model) -> f64 {
    let mut per_link = vec![0.0f64; model.links.len()];
    for a in &model.joints {
        for b in &model.joints {
            for (sa, la) in a.links.iter().enumerate() {
                for (sb, lb) in b.links.iter().enumerate() {
                    if la == lb {
                        let (p, q) = (a.places[sa].at(), b.places[sb].at());
                        let d = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
                        per_link[*la] = per_link[*la].max(d);
                    }
                }
            }
        }
    }
    per_link.iter().skip(1).sum::<f64>().max(1.0)
}

/// The unit of joint `j`'s value.
fn joint_unit(model: &Model, j: usize, unit: &str) -> String {
    match model.joints[j].kind {
        JointType::P => unit.to_string(),
        _ => "rad".into(),
    }
}

/// Everything the report samples, resolved.
struct Settings {
    ranges: (Vec<(f64, f64)>, Origin),
    nodes: (usize, Origin),
    branch: (usize, Origin),
    point: (String, Origin),
    start: (Vec<f64>, Origin),
    motion: (Motion, Vec<f64>, Origin),
    duration: (f64, Origin),
    sections: (Vec<(usize, f64)>, Origin),
}

/// The default followed point: the first pose or point output's point; with
/// no outputs, the last slider's point, else the last joint off the base.
fn default_point(l: &Loaded) -> String {
    let a = &l.analysis;
    let model = &l.model;
    let named = a.geometry.outputs.iter().find_map(|out| match &out.kind {
        pkm_dsl::geometry::OutputKind::Pose { point, .. } | pkm_dsl::geometry::OutputKind::Point { point, .. } => {
            Some(match point {
                pkm_runtime::plan::PointRef::Named(k) => a.geometry.points[*k].name.clone(),
                pkm_runtime::plan::PointRef::Joint(j) => model.joints[*j].name.clone(),
            })
        }
        _ => None,
    });
    named
        .or_else(|| {
            model
                .joints
                .iter()
                .rev()
                .find(|j| j.kind == JointType::P)
                .map(|j| j.name.clone())
        })
        .or_else(|| {
            model
                .joints
                .iter()
                .rev()
                .find(|j| !j.links.contains(&0))
                .map(|j| j.name.clone())
        })
        .unwrap_or_else(|| model.joints.last().map(|j| j.name.clone()).unwrap_or_default())
}

/// The start: `wanted` if some branch reaches it, else the node of a coarse
/// grid over `ranges` nearest `wanted` (relative to each range) that some
/// branch reaches.
fn reachable_start(
    model: &Model,
    plan: &AnyPlan,
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
fn settings(
    l: &Loaded,
    plan: &AnyPlan,
    study: &Resolved,
    o: &ReportOptions,
    file: &str,
) -> Result<Settings, ReportError> {
    let model = &l.model;
    let inputs = model.inputs();
    let n = inputs.len();
    let names: Vec<&str> = inputs.iter().map(|&j| model.joints[j].name.as_str()).collect();
    let count = |what: &str, v: &[f64]| -> Result<(), ReportError> {
        if v.len() != n {
            return Err(invalid(format!(
                "{what} has {} values; {file} has {n} actuated joints ({})",
                v.len(),
                names.join(", ")
            )));
        }
        if let Some(x) = v.iter().find(|x| !x.is_finite()) {
            return Err(invalid(format!("{what}: {x} is not a finite number")));
        }
        Ok(())
    };
    // Ranges: per input, from the command line (all), the study, or the geometry.
    let size = reach(model);
    let ranges = if o.ranges.is_empty() {
        let mut from = Origin::Study;
        let r: Vec<(f64, f64)> = study
            .ranges
            .iter()
            .zip(&inputs)
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
                "--ranges: expected {n} ranges, one per actuated joint of {file} ({}); got {}",
                names.join(", "),
                o.ranges.len()
            )));
        }
        (o.ranges.clone(), Origin::Command)
    };
    for (k, (lo, hi)) in ranges.0.iter().enumerate() {
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            return Err(invalid(format!(
                "the range of {} is {lo}:{hi}: empty or inverted",
                names[k]
            )));
        }
    }
    let nodes = pick(o.nodes, study.nodes, || default_nodes(n));
    check_nodes(nodes.0, n)?;
    let choices = plan.choices();
    let branch_given = o.branch.or(study.branch);
    if let Some(b) = branch_given {
        if b >= 1 << choices {
            return Err(invalid(format!(
                "--branch {b}: {file} has {} branches (0 to {})",
                1usize << choices,
                (1usize << choices) - 1
            )));
        }
    }
    // The ranges' middles; a crank that turns fully 30° past it, off the
    // dead centres that a base line along x gives at 0.
    let middle: Vec<f64> = ranges
        .0
        .iter()
        .zip(&inputs)
        .map(|((lo, hi), &j)| {
            let full = model.joints[j].kind != JointType::P && hi - lo >= std::f64::consts::TAU - 1e-6;
            (lo + hi) / 2.0 + if full { std::f64::consts::FRAC_PI_6 } else { 0.0 }
        })
        .collect();
    let start = match (&o.start, &study.start) {
        (Some(s), _) => {
            count("--start", s)?;
            (s.clone(), Origin::Command)
        }
        (None, Some(s)) => {
            count("the study's start", s)?;
            (s.clone(), Origin::Study)
        }
        (None, None) => (
            reachable_start(model, plan, &ranges.0, &middle, branch_given).ok_or_else(|| {
                invalid(format!(
                    "no node of the ranges {:?} is reachable{}: give reachable ranges (--ranges or the study block)",
                    ranges.0,
                    branch_given.map(|b| format!(" on branch {b}")).unwrap_or_default()
                ))
            })?,
            Origin::Default,
        ),
    };
    // The branch: the given one, else the first reachable and regular at the start.
    let branch = match branch_given {
        Some(b) => (
            b,
            if o.branch.is_some() {
                Origin::Command
            } else {
                Origin::Study
            },
        ),
        None => {
            let mut fallback = None;
            let mut chosen = None;
            for b in 0..1usize << choices {
                let Ok(v) = plan.solve(model, &start.0, &signs(choices, b)) else {
                    continue;
                };
                fallback.get_or_insert(b);
                let regular = l.outputs.is_empty()
                    || velocity::jacobians(model, &v, &l.outputs)
                        .is_ok_and(|j| j.singularity == velocity::Singularity::None);
                if regular {
                    chosen = Some(b);
                    break;
                }
            }
            (
                chosen
                    .or(fallback)
                    .ok_or_else(|| invalid(format!("no branch reaches the start {}", tuple_text(&start.0, 4))))?,
                Origin::Default,
            )
        }
    };
    let full_turns = inputs
        .iter()
        .zip(&ranges.0)
        .all(|(&j, (lo, hi))| model.joints[j].kind != JointType::P && hi - lo >= std::f64::consts::TAU - 1e-6);
    let motion = match (&o.amplitude, &o.speed, &study.trajectory) {
        (Some(a), _, _) => {
            count("--amplitude", a)?;
            (Motion::Sine, a.clone(), Origin::Command)
        }
        (None, Some(s), _) => {
            count("--speed", s)?;
            (Motion::ConstantSpeed, s.clone(), Origin::Command)
        }
        (None, None, Some((m, v))) => {
            count("the study's trajectory", v)?;
            (*m, v.clone(), Origin::Study)
        }
        // Cranks that turn fully turn at 1 rad/s; otherwise a sine of 5 % of each range.
        _ if full_turns => (Motion::ConstantSpeed, vec![1.0; n], Origin::Default),
        _ => (
            Motion::Sine,
            ranges.0.iter().map(|(lo, hi)| 0.05 * (hi - lo)).collect(),
            Origin::Default,
        ),
    };
    let duration = pick(o.duration, study.duration, || {
        if motion.0 == Motion::ConstantSpeed && full_turns {
            std::f64::consts::TAU
        } else {
            5.0
        }
    });
    if !(duration.0 > 0.0 && duration.0 <= MAX_DURATION) {
        return Err(invalid(format!(
            "--duration {}: the trajectory's duration must be above 0 and at most {MAX_DURATION} s",
            duration.0
        )));
    }
    let point = pick(o.point.clone(), study.point.clone(), || default_point(l));
    if point_of(model, &point.0).is_none() {
        let mut known: Vec<String> = model.points.iter().map(|p| p.name.clone()).collect();
        known.extend(model.joints.iter().map(|j| j.name.clone()));
        return Err(invalid(format!(
            "no point `{}` in {file} (its named points and joints: {})",
            point.0,
            known.join(", ")
        )));
    }
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

/// The page's head: title and style.
fn head(title: &str) -> String {
    let title = html_escape(title);
    format!(
        "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>{title}</title>\
         <style>body{{font-family:sans-serif;max-width:64em;margin:auto;padding:0 1em}}\
         pre{{background:#f6f6f6;padding:1em;overflow:auto}}table{{border-collapse:collapse;margin:0.5em 0}}\
         td,th{{border:1px solid #ccc;padding:2px 6px;text-align:right}}th{{background:#f0f0f0}}\
         td.l,th.l{{text-align:left}}figure{{margin:1em 0}}figure img,figure svg{{max-width:100%;height:auto}}\
         figcaption{{color:#444}}</style></head><body><h1>{title}</h1>\n"
    )
}

/// Writes the report for the mechanism text `text` (read from `file`, the
/// name its errors show) into `out` (created if needed); returns the page's
/// path.
///
/// # Example
/// A four-bar with no options: its crank turns fully at 1 rad/s, and the
/// figures of its coupler point are in its plane.
/// ```
/// let text = std::fs::read_to_string("../examples/mechanisms/four_bar.pkm").unwrap();
/// let options = pkm_cli::report::ReportOptions { nodes: Some(90), point: Some("E".into()), ..Default::default() };
/// let out = std::env::temp_dir().join("pkm-doc-report");
/// let page = pkm_cli::report::write_report(&text, "four_bar.pkm", &options, &out).unwrap();
/// let html = std::fs::read_to_string(page).unwrap();
/// assert!(html.contains("Workspace of E"));
/// assert!(html.contains("a curve, length"));
/// ```
pub fn write_report(text: &str, file: &str, o: &ReportOptions, out: &Path) -> Result<PathBuf, ReportError> {
    let (a, loaded) = load(text, file, &o.params)?;
    let ast = pkm_dsl::parse(text).map_err(|d| ReportError::source(pkm_dsl::Diagnostics::from(d), text, file))?;
    let input_names: Vec<String> = a
        .mechanism
        .joints
        .iter()
        .filter(|j| j.actuated)
        .map(|j| j.name.clone())
        .collect();
    let values = loaded
        .as_ref()
        .map(|l| l.values.clone())
        .unwrap_or_else(|| a.geometry.nominal());
    let study =
        pkm_dsl::study::resolve(&ast.studies, &input_names, &values).map_err(|d| ReportError::source(d, text, file))?;
    std::fs::create_dir_all(out).map_err(io(out))?;
    let m = &a.mechanism;
    let mut page = head(&format!("{} — pkm report", m.title.as_deref().unwrap_or(&m.name)));
    let _ = writeln!(
        page,
        "<p>From <code>{}</code>. Lengths in {} and angles in radians throughout.</p>",
        html_escape(file),
        html_escape(&o.unit)
    );

    // 1. Topology.
    let _ = writeln!(page, "<h2>Topology</h2><pre>{}</pre>", html_escape(&a.report()));
    let joints: Vec<(String, String, [usize; 2], bool)> = m
        .joints
        .iter()
        .map(|j| (j.name.clone(), j.kind.symbol().to_string(), j.links, j.actuated))
        .collect();
    let links: Vec<String> = m.links.iter().map(|l| l.name.clone()).collect();
    let f = drawing::graph(
        &out.join("topology"),
        &format!("{}: links (nodes) and joints (edges)", m.name),
        &links,
        &joints,
    )?;
    page.push_str(&figure_html(
        &f,
        "The link–joint graph: links as nodes (the base grey), joints as edges with their type; driven joints red and starred",
    ));

    match loaded {
        None => {
            let numeric = !o.ranges.is_empty()
                || o.nodes.is_some()
                || o.branch.is_some()
                || o.point.is_some()
                || o.start.is_some()
                || o.amplitude.is_some()
                || o.speed.is_some()
                || o.duration.is_some()
                || !o.sections.is_empty()
                || !o.compare.is_empty();
            if numeric {
                return Err(invalid(format!(
                    "{file} has no geometry: the sampling options need a `parameters` and a `geometry` block"
                )));
            }
            let _ = writeln!(
                page,
                "<h2>No geometry</h2><p>This file declares no <code>parameters</code> and <code>geometry</code>: the \
                 report holds its topology only. Positions, workspace, singularities and motion need the joints \
                 placed on their links.</p>"
            );
        }
        Some(l) => match &l.forward {
            Ok(plan) => {
                let s = settings(&l, plan, &study, o, file)?;
                numeric(&mut page, &l, plan, &s, o, out, file)?;
            }
            Err(why) => inverse_only(&mut page, &l, &study, o, out, file, why)?,
        },
    }
    page.push_str("</body></html>\n");
    let path = out.join("index.html");
    std::fs::write(&path, page).map_err(io(&path))?;
    Ok(path)
}

/// The settings table.
fn settings_html(l: &Loaded, s: &Settings, unit: &str) -> String {
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

/// The names and units of the declared outputs' values, in order.
fn output_columns(l: &Loaded, unit: &str) -> Vec<String> {
    let mut cols = Vec::new();
    for out in &l.analysis.geometry.outputs {
        for (k, name) in out.names.iter().enumerate() {
            let u = match &out.kind {
                pkm_dsl::geometry::OutputKind::Pose { .. } => {
                    let positions = if l.model.planar { 2 } else { 3 };
                    if k < positions {
                        unit.to_string()
                    } else {
                        "rad".into()
                    }
                }
                pkm_dsl::geometry::OutputKind::Point { .. } => unit.to_string(),
                pkm_dsl::geometry::OutputKind::Joint(j) => joint_unit(&l.model, *j, unit),
            };
            cols.push(format!("{name} ({u})"));
        }
    }
    cols
}

fn class_text(s: velocity::Singularity) -> &'static str {
    match s {
        velocity::Singularity::None => "regular",
        velocity::Singularity::Input => "input singular",
        velocity::Singularity::Output => "output singular",
        velocity::Singularity::Combined => "input and output singular",
    }
}

/// The page's numeric sections for a mechanism with a forward plan.
fn numeric(
    page: &mut String,
    l: &Loaded,
    plan: &AnyPlan,
    s: &Settings,
    o: &ReportOptions,
    out: &Path,
    file: &str,
) -> Result<(), ReportError> {
    let model = &l.model;
    let outputs = &l.outputs;
    let unit = o.unit.as_str();
    let n = model.inputs().len();
    let point_name = s.point.0.as_str();
    let (plink, plocal) = point_of(model, point_name).ok_or_else(|| invalid(format!("no point `{point_name}`")))?;
    let choices = plan.choices();
    let branch_signs = signs(choices, s.branch.0);
    let start = &s.start.0;
    let view = if model.planar { View::Plane } else { View::Axonometric };
    page.push_str(&settings_html(l, s, unit));

    // 2. The mechanism at the sample input.
    let sample = plan.solve(model, start, &branch_signs).map_err(|e| {
        invalid(format!(
            "{file}: the start {} is not reachable on branch {}: {e}",
            tuple_text(start, 4),
            s.branch.0
        ))
    })?;
    let sample_poses = newton::link_poses(model, &sample).map_err(|e| invalid(e.to_string()))?;
    let scene = drawing::scene(model, &sample_poses, (plink, plocal));
    let f = drawing::draw(
        &out.join("mechanism"),
        &format!("{} at q = {}, branch {}", model.name, tuple_text(start, 3), s.branch.0),
        &scene,
        view,
        unit,
        point_name,
    )?;
    let _ = writeln!(page, "<h2>The mechanism at the sample input</h2>");
    page.push_str(&figure_html(
        &f,
        &format!(
            "Links as lines between their joints (a link with three or more joints filled), joints by type, the base \
             hatched; {}",
            if model.planar {
                "in the mechanism's plane"
            } else {
                "an axonometric view (azimuth 35°, elevation 25°)"
            }
        ),
    ));
    let animation_at = page.len();

    // 3. Position solutions and singularity measures at the sample input.
    let columns = output_columns(l, unit);
    let point_axes = if model.planar { "x, y" } else { "x, y, z" };
    let _ = writeln!(
        page,
        "<h2>Position solutions at q = {}</h2><p>Every branch of the closed-form forward solution. σ_in and σ_out are \
         the relative smallest singular values of the velocity equations (0 at an input or output singularity){}.</p>\
         <table><tr><th>branch</th><th>signs</th><th>{point_name} ({point_axes}) ({unit})</th>{}<th>σ_in</th><th>σ_out</th>\
         <th class=l>class</th></tr>",
        tuple_text(start, 4),
        if outputs.is_empty() { "; they need declared outputs, and this file has none" } else { "" },
        columns.iter().map(|c| format!("<th>{}</th>", html_escape(c))).collect::<String>()
    );
    for b in 0..1usize << choices {
        let sg = signs(choices, b);
        let label = sign_text(&sg);
        let mark = if b == s.branch.0 { " (followed)" } else { "" };
        match plan.solve(model, start, &sg) {
            Ok(v) => {
                let poses = newton::link_poses(model, &v).map_err(|e| invalid(e.to_string()))?;
                let p = poses[plink].transform_point(&plocal.into());
                let p = if model.planar {
                    vec![p.x, p.y]
                } else {
                    vec![p.x, p.y, p.z]
                };
                let outs = pose_outputs(model, &poses, outputs);
                let (si, so, class) = if outputs.is_empty() {
                    ("—".to_string(), "—".to_string(), "— (no outputs)".to_string())
                } else {
                    match velocity::jacobians(model, &v, outputs) {
                        Ok(j) => (
                            format!("{:.3e}", j.input_sigma),
                            format!("{:.3e}", j.output_sigma),
                            class_text(j.singularity).to_string(),
                        ),
                        Err(e) => ("—".into(), "—".into(), e.to_string()),
                    }
                };
                let _ = writeln!(
                    page,
                    "<tr><td>{b}{mark}</td><td>{label}</td><td>{}</td>{}<td>{si}</td><td>{so}</td><td class=l>{}</td></tr>",
                    tuple_text(&p, 4),
                    outs.iter().map(|x| format!("<td>{x:.6}</td>")).collect::<String>(),
                    html_escape(&class)
                );
            }
            Err(e) => {
                let _ = writeln!(
                    page,
                    "<tr><td>{b}</td><td>{label}</td><td colspan={} class=l>no solution: {}</td></tr>",
                    4 + columns.len(),
                    html_escape(&e)
                );
            }
        }
    }
    page.push_str("</table>\n");

    // The determinants' factors on the followed branch at the sample.
    let sample_factors = named_factors(l, plan, &sample_poses);
    if !sample_factors.is_empty() {
        let _ = writeln!(
            page,
            "<h3>Determinant factors on branch {} ({})</h3><p>Each step of a closed-form plan solves one joint from \
             one scalar equation; in the plan's order the velocity equations are triangular and each determinant is \
             the product of the steps' derivatives. A factor is a step's derivative normalised to [0, 1] (the sine \
             of the angle at which a point's path meets the surface it must reach): 0 is a singularity, and the \
             condition says where. The forward plan's factors are det J_o's (output singularities), the inverse \
             plan's det J_i's (input singularities).</p><table><tr><th>factor</th><th>value (1)</th>\
             <th class=l>vanishes when</th></tr>",
            s.branch.0,
            sign_text(&branch_signs)
        );
        for (label, value, what) in &sample_factors {
            let _ = writeln!(
                page,
                "<tr><td>{label}</td><td>{value:.4}</td><td class=l>{}</td></tr>",
                html_escape(what)
            );
        }
        page.push_str("</table>\n");
    }

    // 4. Workspace.
    let grid = Grid {
        ranges: s.ranges.0.clone(),
        counts: vec![s.nodes.0; n],
    };
    let nodes = sweep_point(model, plan, &grid, &branch_signs, (plink, plocal))?;
    let cloud: Vec<[f64; 3]> = nodes.iter().flatten().copied().collect();
    let shape_of = shape(&cloud);
    let dim = dimension(&shape_of, n);
    let _ = writeln!(
        page,
        "<h2>Workspace of {point_name}</h2><p>Branch {} ({}), the inputs swept over {} with {} nodes each: {} of {} \
         nodes reachable. The set is {}.</p>",
        s.branch.0,
        sign_text(&branch_signs),
        s.ranges
            .0
            .iter()
            .map(|(a, b)| format!("[{a:.4}, {b:.4}]"))
            .collect::<Vec<_>>()
            .join(" × "),
        s.nodes.0,
        cloud.len(),
        grid.len(),
        html_escape(&measure(&grid, &nodes, unit))
    );
    let axes = ["x", "y", "z"];
    let label = |i: usize| format!("{} ({unit})", axes[i]);
    let joined = Style {
        equal_axes: true,
        joined: n == 1,
    };
    let planes: Vec<[usize; 2]> = if model.planar {
        vec![[0, 1]]
    } else if dim >= 3 {
        vec![[0, 1], [1, 2], [0, 2]]
    } else if let Some(k) = (dim == 2).then(|| world_axis(shape_of.axes[2])).flatten() {
        let rest: Vec<usize> = (0..3).filter(|&i| i != k).collect();
        vec![[rest[0], rest[1]]]
    } else {
        vec![largest_pair(&cloud)]
    };
    if n == 1 {
        // One input: the point's coordinates against it (a displacement diagram).
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
            &out.join("displacement"),
            &format!("{point_name} against {}", model.joints[j].name),
            [
                &format!("{} ({})", model.joints[j].name, joint_unit(model, j, unit)),
                &format!("position ({unit})"),
            ],
            &reached.iter().map(|r| r.0).collect::<Vec<_>>(),
            &components
                .iter()
                .map(|&k| (axes[k].to_string(), reached.iter().map(|r| r.1[k]).collect()))
                .collect::<Vec<_>>(),
        )?;
        page.push_str(&figure_html(
            &f,
            &format!("The coordinates of {point_name} against the input over the sweep"),
        ));
    }
    if !model.planar && dim >= 2 {
        let f = plots::cloud3d(
            &out.join("workspace_3d"),
            &format!("Workspace of {point_name}: 3-D view"),
            [&label(0), &label(1), &label(2)],
            &cloud,
        )?;
        page.push_str(&figure_html(
            &f,
            &format!(
                "The workspace in 3-D (equal scales; at most {} nodes drawn)",
                plots::DENSE
            ),
        ));
    }
    if !model.planar && dim == 2 && world_axis(shape_of.axes[2]).is_none() {
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
        let f = plots::scatter(
            &out.join("workspace_plane"),
            &format!("Workspace of {point_name}, in its plane"),
            [
                &format!("along {} ({unit})", tuple_text(&u, 3)),
                &format!("along {} ({unit})", tuple_text(&v, 3)),
            ],
            &[(point_name.to_string(), uv)],
            joined,
        )?;
        page.push_str(&figure_html(
            &f,
            "The flat workspace in its own plane (from its centre)",
        ));
    } else {
        for p in &planes {
            let name = plane_name(*p);
            let f = plots::scatter(
                &out.join(format!("workspace_{name}")),
                &format!(
                    "Workspace of {point_name}: {} {name}",
                    if planes.len() > 1 { "projection on" } else { "in" }
                ),
                [&label(p[0]), &label(p[1])],
                &[(
                    point_name.to_string(),
                    cloud.iter().map(|q| [q[p[0]], q[p[1]]]).collect(),
                )],
                joined,
            )?;
            page.push_str(&figure_html(
                &f,
                &format!(
                    "{} {name}, equal axis scales{}",
                    if planes.len() > 1 {
                        "Projection on"
                    } else {
                        "The workspace in"
                    },
                    if cloud.len() > plots::DENSE {
                        "; a dense cloud drawn as occupied cells"
                    } else {
                        ""
                    }
                ),
            ));
        }
    }
    if !s.sections.0.is_empty() {
        if dim < 3 {
            let _ = writeln!(
                page,
                "<p>Sections skipped: the workspace is {}, so a plane's section of it is not an area.</p>",
                if model.planar { "planar" } else { "flat or a curve" }
            );
        } else {
            for &(axis, value) in &s.sections.0 {
                sections(page, &cloud, axis, value, point_name, unit, out)?;
            }
        }
    }
    if !o.compare.is_empty() {
        page.push_str(&compare_table(l, plan, model.name.as_str(), o, &grid, point_name)?);
    }

    // 5. Singularities over a coarser sweep.
    singularities(
        page,
        l,
        plan,
        s,
        &branch_signs,
        (plink, plocal),
        &sample_factors,
        &cloud,
        unit,
        out,
    )?;

    // 6. Trajectory: velocity, acceleration and the animation.
    trajectory(page, l, plan, s, (plink, plocal), view, unit, out, animation_at)
}

/// The two world axes along which a cloud spreads most.
fn largest_pair(cloud: &[[f64; 3]]) -> [usize; 2] {
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
fn sections(
    page: &mut String,
    cloud: &[[f64; 3]],
    axis: usize,
    value: f64,
    point_name: &str,
    unit: &str,
    out: &Path,
) -> Result<(), ReportError> {
    let axes = ["x", "y", "z"];
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
            axes[axis], extent.0, extent.1, axes[axis]
        );
        return Ok(());
    }
    let f = plots::scatter(
        &out.join(format!("section_{}_{value}", axes[axis])),
        &format!("Section {} = {value} {unit} (±{slab:.2})", axes[axis]),
        [&format!("{} ({unit})", axes[i]), &format!("{} ({unit})", axes[j])],
        &[(point_name.to_string(), cut)],
        Style {
            equal_axes: true,
            joined: false,
        },
    )?;
    page.push_str(&figure_html(
        &f,
        &format!("Section {} = {value}, equal axis scales", axes[axis]),
    ));
    Ok(())
}

/// Every factor of det J_o (the forward plan's) and det J_i (the inverse
/// plan's) at `poses`: a label (`J_o step 3`), its value, what it says.
fn named_factors(l: &Loaded, plan: &AnyPlan, poses: &[Pose3]) -> Vec<(String, f64, String)> {
    plan_factors(l, plan, poses)
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
    plan: &'a AnyPlan,
    poses: &'a [Pose3],
) -> impl Iterator<Item = (&'static str, singular::Factor)> + 'a {
    [("J_o", Some(plan)), ("J_i", l.inverse.as_ref())]
        .into_iter()
        .flat_map(move |(jacobian, p)| {
            p.map(|p| p.factors(&l.model, poses))
                .unwrap_or_default()
                .into_iter()
                .map(move |f| (jacobian, f))
        })
}

/// The workspace of `point` on every branch of this file and of each
/// `--compare` file, swept over the same grid: one table. A file with
/// another number of inputs, no forward plan or no such point is listed
/// with the reason it is skipped.
fn compare_table(
    this: &Loaded,
    plan: &AnyPlan,
    name: &str,
    o: &ReportOptions,
    grid: &Grid,
    point: &str,
) -> Result<String, ReportError> {
    let unit = o.unit.as_str();
    let mut html = format!(
        "<h3>Workspaces of {point}, every branch</h3><p>The same ranges and grid ({} nodes), each file's point \
         `{point}`.</p><table><tr><th class=l>mechanism</th><th>branch</th><th>reachable nodes</th>\
         <th class=l>workspace</th></tr>",
        grid.len()
    );
    let row = |html: &mut String, mech: &str, l: &Loaded, p: &AnyPlan| -> Result<(), ReportError> {
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

/// Singularity measures over a coarser sweep of the followed branch: the
/// near-singular nodes by σ (when outputs are declared) and by each
/// determinant factor, in the workspace's plane.
#[allow(clippy::too_many_arguments)]
fn singularities(
    page: &mut String,
    l: &Loaded,
    plan: &AnyPlan,
    s: &Settings,
    branch_signs: &[Sign],
    point: (usize, [f64; 3]),
    named: &[(String, f64, String)],
    cloud: &[[f64; 3]],
    unit: &str,
    out: &Path,
) -> Result<(), ReportError> {
    const NEAR: f64 = 0.05;
    let model = &l.model;
    let outputs = &l.outputs;
    let n = s.ranges.0.len();
    let cap = match n {
        1 => s.nodes.0,
        2 => 140,
        _ => 27,
    };
    let coarse = Grid {
        ranges: s.ranges.0.clone(),
        counts: vec![s.nodes.0.min(cap); n],
    };
    let pair = if model.planar { [0, 1] } else { largest_pair(cloud) };
    let axes = ["x", "y", "z"];
    let labels = [
        format!("{} ({unit})", axes[pair[0]]),
        format!("{} ({unit})", axes[pair[1]]),
    ];
    let mut measured: Vec<([f64; 3], f64, f64)> = Vec::new();
    let mut factor_values: Vec<Vec<f64>> = Vec::new();
    let mut q = vec![0.0; n];
    for index in 0..coarse.len() {
        coarse.node(index, &mut q);
        let Ok(v) = plan.solve(model, &q, branch_signs) else {
            continue;
        };
        let Ok(poses) = newton::link_poses(model, &v) else {
            continue;
        };
        let p = poses[point.0].transform_point(&point.1.into());
        let (si, so) = if outputs.is_empty() {
            (f64::NAN, f64::NAN)
        } else {
            match velocity::jacobians(model, &v, outputs) {
                Ok(j) => (j.input_sigma, j.output_sigma),
                Err(_) => continue,
            }
        };
        measured.push(([p.x, p.y, p.z], si, so));
        factor_values.push(plan_factors(l, plan, &poses).map(|(_, f)| f.value).collect());
    }
    let _ = writeln!(page, "<h2>Singularities</h2>");
    let at = |m: &([f64; 3], f64, f64)| [m.0[pair[0]], m.0[pair[1]]];
    let near_style = Style {
        equal_axes: true,
        joined: false,
    };
    if outputs.is_empty() {
        let _ = writeln!(
            page,
            "<p>This file declares no outputs, so σ_in and σ_out (which measure the outputs' rates) are not defined; \
             the determinant factors below need no outputs. {} nodes of the followed branch were measured.</p>",
            measured.len()
        );
    } else {
        let quantile = |k: usize| {
            let mut v: Vec<f64> = measured.iter().map(|m| if k == 0 { m.1 } else { m.2 }).collect();
            v.sort_by(f64::total_cmp);
            v.get(v.len() / 20).copied().unwrap_or(0.0)
        };
        let (qi, qo) = (quantile(0), quantile(1));
        let near = |k: usize, limit: f64| -> Vec<[f64; 2]> {
            measured
                .iter()
                .filter(|m| (if k == 0 { m.1 } else { m.2 }) <= limit)
                .map(at)
                .collect()
        };
        let combined = measured
            .iter()
            .filter(|m| m.1 < velocity::SINGULAR && m.2 < velocity::SINGULAR)
            .count();
        let _ = writeln!(
            page,
            "<p>Over {} nodes of the followed branch ({} per input): the smallest σ_in is {:.3e}, the smallest σ_out \
             {:.3e}; {combined} nodes are singular in both senses at once (threshold {:e}).</p>",
            measured.len(),
            coarse.counts[0],
            measured.iter().map(|m| m.1).fold(f64::INFINITY, f64::min),
            measured.iter().map(|m| m.2).fold(f64::INFINITY, f64::min),
            velocity::SINGULAR
        );
        let all: Vec<[f64; 2]> = measured.iter().map(at).collect();
        let f = plots::scatter(
            &out.join("singularity_loci"),
            "Near-singular configurations (lowest 5 % of each measure)",
            [&labels[0], &labels[1]],
            &[
                ("all measured nodes".to_string(), all),
                (format!("input: σ_in ≤ {qi:.2e}"), near(0, qi)),
                (format!("output: σ_out ≤ {qo:.2e}"), near(1, qo)),
            ],
            near_style,
        )?;
        page.push_str(&figure_html(
            &f,
            &format!("Near-singular configurations of the point, on {}", plane_name(pair)),
        ));
    }
    if named.is_empty() {
        return Ok(());
    }
    let mut series = vec![(
        "all measured nodes".to_string(),
        measured.iter().map(at).collect::<Vec<_>>(),
    )];
    let _ = writeln!(
        page,
        "<h3>Which factor comes near 0</h3><p>Over the same nodes, each determinant factor's smallest value, and \
         (figure) the nodes where it is below {NEAR}.</p><table><tr><th>factor</th><th>smallest (1)</th>\
         <th>nodes below {NEAR}</th><th class=l>vanishes when</th></tr>"
    );
    for (k, (label, _, what)) in named.iter().enumerate() {
        let value = |i: usize| factor_values[i].get(k).copied().unwrap_or(f64::INFINITY);
        let smallest = (0..factor_values.len()).map(value).fold(f64::INFINITY, f64::min);
        let near: Vec<[f64; 2]> = (0..factor_values.len())
            .filter(|&i| value(i) < NEAR)
            .map(|i| at(&measured[i]))
            .collect();
        let _ = writeln!(
            page,
            "<tr><td>{label}</td><td>{smallest:.3e}</td><td>{}</td><td class=l>{}</td></tr>",
            near.len(),
            html_escape(what)
        );
        if !near.is_empty() {
            series.push((label.clone(), near));
        }
    }
    page.push_str("</table>\n");
    if series.len() > 1 {
        let f = plots::scatter(
            &out.join("singularity_factors"),
            &format!("Nodes where a determinant factor is below {NEAR}"),
            [&labels[0], &labels[1]],
            &series,
            near_style,
        )?;
        page.push_str(&figure_html(
            &f,
            &format!(
                "Near-vanishing factors, on {} (grey: every node measured)",
                plane_name(pair)
            ),
        ));
    }
    Ok(())
}

/// The trajectory: the point's velocity and acceleration along it, and the
/// mechanism's animation (inserted into the page at `animation_at`).
#[allow(clippy::too_many_arguments)]
fn trajectory(
    page: &mut String,
    l: &Loaded,
    plan: &AnyPlan,
    s: &Settings,
    point: (usize, [f64; 3]),
    view: View,
    unit: &str,
    out: &Path,
    animation_at: usize,
) -> Result<(), ReportError> {
    const STEPS: usize = 500;
    const FRAMES: usize = 100;
    let model = &l.model;
    let n = s.start.0.len();
    let choices = plan.choices();
    let revolute: Vec<bool> = model.joints.iter().map(|j| j.kind != JointType::P).collect();
    let (start, (motion, rates)) = (&s.start.0, (s.motion.0, &s.motion.1));
    let dt = s.duration.0 / STEPS as f64;
    let mut previous: Option<Vec<f64>> = None;
    let (mut ts, mut vel, mut acc) = (Vec::new(), vec![Vec::new(); 4], vec![Vec::new(); 4]);
    let mut frames: Vec<Scene> = Vec::new();
    let mut stopped = String::new();
    for k in 0..=STEPS {
        let t = k as f64 * dt;
        let w = std::f64::consts::PI;
        let (q, qd, qdd): (Vec<f64>, Vec<f64>, Vec<f64>) = match motion {
            Motion::Sine => (
                (0..n).map(|i| start[i] + rates[i] * (w * t).sin()).collect(),
                (0..n).map(|i| rates[i] * w * (w * t).cos()).collect(),
                (0..n).map(|i| -rates[i] * w * w * (w * t).sin()).collect(),
            ),
            Motion::ConstantSpeed => (
                (0..n).map(|i| start[i] + rates[i] * t).collect(),
                rates.clone(),
                vec![0.0; n],
            ),
        };
        let candidates: Vec<Vec<f64>> = match &previous {
            None => plan.solve(model, &q, &signs(choices, s.branch.0)).into_iter().collect(),
            Some(_) => (0..1usize << choices)
                .filter_map(|b| plan.solve(model, &q, &signs(choices, b)).ok())
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
            stopped = format!(
                "; it stops at t = {t:.3} s, where no branch reaches q = {}",
                tuple_text(&q, 4)
            );
            break;
        };
        let a = match velocity::accelerations(model, &v, &qd, &qdd) {
            Ok(a) => a,
            Err(e) => {
                stopped = format!("; it stops at t = {t:.3} s: {e}");
                break;
            }
        };
        let poses = newton::link_poses(model, &v).map_err(|e| invalid(e.to_string()))?;
        let p = poses[point.0].transform_point(&point.1.into()).coords;
        let twist = a.velocities.twists[point.0];
        let pv = twist.at(&p);
        let pa = velocity::point_acceleration(&twist, &a.twists[point.0], &p);
        if k % (STEPS / FRAMES) == 0 {
            frames.push(drawing::scene(model, &poses, point));
        }
        ts.push(t);
        for i in 0..3 {
            vel[i].push(pv[i]);
            acc[i].push(pa[i]);
        }
        vel[3].push(pv.norm());
        acc[3].push(pa.norm());
        previous = Some(v);
    }
    let point_name = s.point.0.as_str();
    let law = match motion {
        Motion::Sine => format!("q(t) = {} + {}·sin(πt)", tuple_text(start, 4), tuple_text(rates, 4)),
        Motion::ConstantSpeed => format!("q(t) = {} + {}·t", tuple_text(start, 4), tuple_text(rates, 4)),
    };
    let _ = writeln!(
        page,
        "<h2>Velocity and acceleration of {point_name}</h2><p>Inputs {law}, 0 ≤ t ≤ {:.4} s, along the branch that \
         continues from branch {} ({} steps){stopped}; rates from the differentiated loop equations.</p>",
        s.duration.0,
        s.branch.0,
        ts.len(),
    );
    let components: &[usize] = if model.planar { &[0, 1, 3] } else { &[0, 1, 2, 3] };
    let names = ["x", "y", "z", "magnitude"];
    for (stem, title, axis, data) in [
        ("velocity", "Velocity", format!("v ({unit}/s)"), &vel),
        ("acceleration", "Acceleration", format!("a ({unit}/s²)"), &acc),
    ] {
        let series: Vec<(String, Vec<f64>)> = components
            .iter()
            .map(|&i| (names[i].to_string(), data[i].clone()))
            .collect();
        let f = plots::curves(
            &out.join(stem),
            &format!("{title} of {point_name}"),
            ["t (s)", &axis],
            &ts,
            &series,
        )?;
        page.push_str(&figure_html(
            &f,
            &format!("{title} of {point_name}: components and magnitude"),
        ));
    }
    if frames.len() >= 2 {
        let path = out.join("animation.svg");
        let played = ts.last().copied().unwrap_or(s.duration.0).max(1e-3);
        drawing::animation(&path, &frames, view, played, point_name)?;
        let svg = std::fs::read_to_string(&path).map_err(io(&path))?;
        let html = format!(
            "<figure>{svg}<figcaption>The mechanism along the trajectory, {} frames over {played:.2} s, repeated \
             (<a href=\"animation.svg\">SVG</a>)</figcaption></figure>\n",
            frames.len()
        );
        page.insert_str(animation_at, &html);
    }
    Ok(())
}

/// The declared outputs' values from link poses.
fn pose_outputs(model: &Model, poses: &[Pose3], outputs: &[Output]) -> Vec<f64> {
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

/// A mechanism with no closed-form forward plan (κ ≠ 0) but an inverse one:
/// the mechanism drawn at a sample pose of its outputs, the
/// constant-orientation workspace of its output point (every pose of a grid
/// over the point's coordinates, the other outputs held, that the inverse
/// solution reaches on the branch), and an animation along a circle of poses.
fn inverse_only(
    page: &mut String,
    l: &Loaded,
    study: &Resolved,
    o: &ReportOptions,
    out: &Path,
    file: &str,
    why: &str,
) -> Result<(), ReportError> {
    let model = &l.model;
    let unit = o.unit.as_str();
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
            "<p>It has no inverse plan from a pose or point output either: nothing numeric to show.</p>"
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
    let branch = match o.branch.or(study.branch) {
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
                plan.solve(model, &pose, &signs(choices, b)).is_ok_and(|v| {
                    velocity::jacobians(model, &v, &l.outputs)
                        .is_ok_and(|j| j.singularity == velocity::Singularity::None)
                })
            })
            .or_else(|| (0..1usize << choices).find(|&b| plan.solve(model, &pose, &signs(choices, b)).is_ok()))
            .ok_or_else(|| {
                invalid(format!(
                    "{file}: the inverse solution reaches no branch at the pose {}",
                    tuple_text(&pose, 3)
                ))
            })?,
    };
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
        &out.join("mechanism"),
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
    page.push_str(&figure_html(
        &f,
        "Links as lines between their joints (a link with three or more joints filled), joints by type, the base hatched",
    ));
    // The constant-orientation workspace over the point's x and y.
    let size = reach(model);
    let nodes_per = o.nodes.or(study.nodes).unwrap_or(200);
    check_nodes(nodes_per, 2)?;
    let grid = Grid {
        ranges: vec![(-size, size), (-size, size)],
        counts: vec![nodes_per; 2],
    };
    let held = pose.clone();
    let sweep = |grid: &Grid| {
        sweep_nodes::<2>(grid, |xy| {
            let mut p = held.clone();
            p[0] = xy[0];
            p[1] = xy[1];
            plan.solve(model, &p, &branch_signs).ok().map(|_| [xy[0], xy[1], 0.0])
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
        sign_text(&branch_signs),
        cloud.len(),
        grid.len(),
        html_escape(&measure(&grid, &nodes, unit).replace("input grid", "grid of poses"))
    );
    if !cloud.is_empty() {
        let f = plots::scatter(
            &out.join("workspace_xOy"),
            &format!("Workspace of {point_name}, orientation held"),
            [&format!("x ({unit})"), &format!("y ({unit})")],
            &[(point_name.clone(), cloud.clone())],
            Style {
                equal_axes: true,
                joined: false,
            },
        )?;
        page.push_str(&figure_html(
            &f,
            "The constant-orientation workspace, equal axis scales",
        ));
    }
    // A circle of poses about the sample, a tenth of the workspace's width
    // across, followed by the nearest joint values at each step.
    let xr = plots::range(cloud.iter().map(|p| p[0]));
    let radius = 0.1 * (xr.1 - xr.0);
    let duration = o.duration.or(study.duration).unwrap_or(std::f64::consts::TAU);
    if !(duration > 0.0 && duration <= MAX_DURATION) {
        return Err(invalid(format!(
            "--duration {duration}: the trajectory's duration must be above 0 and at most {MAX_DURATION} s"
        )));
    }
    let revolute: Vec<bool> = model.joints.iter().map(|j| j.kind != JointType::P).collect();
    let mut previous = v.clone();
    let mut frames = Vec::new();
    for k in 0..=100 {
        let a = std::f64::consts::TAU * k as f64 / 100.0;
        let mut p = pose.clone();
        p[0] += radius * (1.0 - a.cos());
        p[1] += radius * a.sin();
        let Some(next) = (0..1usize << choices)
            .filter_map(|b| plan.solve(model, &p, &signs(choices, b)).ok())
            .min_by(|x, y| {
                pkm_runtime::plan::joint_distance(x, &previous, &revolute)
                    .total_cmp(&pkm_runtime::plan::joint_distance(y, &previous, &revolute))
            })
        else {
            break;
        };
        let Ok(link_poses) = newton::link_poses(model, &next) else {
            break;
        };
        frames.push(drawing::scene(model, &link_poses, (plink, plocal)));
        previous = next;
    }
    if frames.len() >= 2 {
        let path = out.join("animation.svg");
        drawing::animation(&path, &frames, view, duration, &point_name)?;
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
