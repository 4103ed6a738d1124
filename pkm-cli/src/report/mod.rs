//! `pkm report`: one self-contained HTML page for a `.pkm` file: the
//! settings used, the topology (text and link–joint graph), a drawing of the
//! mechanism at the sample input and its animation along the trajectory, the
//! position solutions with their singularity measures, the workspace of a
//! chosen point (3-D view, projections, sections, and its volume, area or
//! length as its dimension allows), singularity loci, the point's
//! velocity and acceleration, and for a file that declares its legs a map
//! of the platform's static stiffness. Every figure is also written as PNG, SVG and
//! CSV beside the page. Works from the file alone: what to sample comes from
//! its `study { … }` block (see `docs/report.md`), the command line
//! overriding each key, and sensible defaults for the rest.

mod assembly_modes;
mod dynamics;
mod follow;
mod html;
mod inverse;
mod loaded;
mod positions;
mod settings;
mod singularities;
mod stiffness_map;
mod trajectory;
mod workspace;

use crate::drawing::{self, View};
use crate::plots;
use html::{head, html_escape, Page};
use loaded::{load, point_of, signs, Loaded, Plan};
use pkm_runtime::primitives::Sign;
use settings::{settings, settings_html, Settings};
use singularities::named_factors;
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
#[derive(Debug, Clone, Default, clap::Args)]
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
    /// The static stiffness map's held pose: an output's value, as
    /// `--hold ZA=75` (repeatable); the two mapped values are centred on
    /// theirs. Default: angles and x, y at 0, z where `J` is best conditioned.
    #[arg(long = "hold", value_parser = parse_param, allow_hyphen_values = true)]
    pub hold: Vec<(String, f64)>,
    /// The length unit's name, for the labels of a file without a `units`
    /// block (default: "file unit"); a file with one is labelled in its
    /// unit, and another name here is an error.
    #[arg(long)]
    pub unit: Option<String>,
    /// Other `.pkm` files whose workspaces (of the same point, every
    /// branch, the same ranges) are tabled beside this one's.
    #[arg(long, value_delimiter = ',')]
    pub compare: Vec<PathBuf>,
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

/// The length unit the page labels its lengths with: the file's `units`
/// block's, else `--unit`'s name, else "file unit"; `--unit` naming another
/// unit than the file's is an error.
fn length_unit(a: &pkm_dsl::analysis::Analysis, o: &ReportOptions, file: &str) -> Result<String, ReportError> {
    match (a.mass_and_loads.units, &o.unit) {
        (Some(u), Some(given)) if given != u.length.symbol() => Err(invalid(format!(
            "--unit {given}: {file} declares its lengths in {} (its `units` block); the report labels them so",
            u.length.symbol()
        ))),
        (Some(u), _) => Ok(u.length.symbol().to_string()),
        (None, Some(given)) if given.trim().is_empty() => Err(invalid("--unit: the unit's name is empty")),
        (None, Some(given)) => Ok(given.clone()),
        (None, None) => Ok("file unit".into()),
    }
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
    let output_names: Vec<String> = a.geometry.outputs.iter().flat_map(|o| o.names.clone()).collect();
    let study = pkm_dsl::study::resolve(&ast.studies, &input_names, &output_names, &values)
        .map_err(|d| ReportError::source(d, text, file))?;
    let unit = length_unit(&a, o, file)?;
    std::fs::create_dir_all(out).map_err(io(out))?;
    let m = &a.mechanism;
    let mut page = Page {
        html: head(&format!("{} — pkm report", m.title.as_deref().unwrap_or(&m.name))),
        dir: out,
    };
    let _ = writeln!(
        page,
        "<p>From <code>{}</code>. Lengths in {} and angles in radians throughout{}.</p>",
        html_escape(file),
        html_escape(&unit),
        if a.mass_and_loads.units.is_some() {
            format!(
                " (the file's <code>units</code> block); forces in N, torques in N·{}",
                html_escape(&unit)
            )
        } else if o.unit.is_some() {
            " (the file declares no <code>units</code>: the length unit is named on the command line)".to_string()
        } else {
            " (the file declares no <code>units</code>: lengths are in the unit its numbers are in, the \
             \"file unit\")"
                .to_string()
        }
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
    page.figure(
        &f,
        "The link–joint graph: links as nodes (the base grey), joints as edges with their type; driven joints red and starred",
    );

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
                || !o.hold.is_empty()
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
        Some(l) => {
            match &l.forward {
                Ok(plan) => {
                    if study.pose.is_some() {
                        return Err(invalid(format!(
                            "{file}: the study's `pose` samples a file without a forward plan; this one has one: \
                             give its sample as an input, `start (…)`"
                        )));
                    }
                    let s = settings(&l, plan, &study, o, file)?;
                    numeric(&mut page, &l, plan, &s, o, &unit, file)?;
                }
                Err(why) => inverse::inverse_only(&mut page, &l, &study, o, &unit, file, why)?,
            }
            // 7. Static stiffness, for a file that declares its legs.
            stiffness_map::stiffness_map(&mut page, &l, &o.hold, file)?;
        }
    }
    page.html.push_str("</body></html>\n");
    let path = out.join("index.html");
    std::fs::write(&path, page.html).map_err(io(&path))?;
    Ok(path)
}

/// What the numeric sections share: the file ready to solve, its forward
/// plan, the settings resolved, and the point and branch followed.
struct Sampling<'a> {
    l: &'a Loaded,
    plan: &'a Plan,
    s: &'a Settings,
    /// The followed point: its link and place on it.
    point: (usize, [f64; 3]),
    /// The followed branch's signs.
    branch_signs: Vec<Sign>,
    /// The joint values at the sample input on the followed branch.
    sample: Vec<f64>,
    view: View,
    /// The length unit's name.
    unit: &'a str,
}

/// The page's numeric sections for a mechanism with a forward plan.
fn numeric(
    page: &mut Page,
    l: &Loaded,
    plan: &Plan,
    s: &Settings,
    o: &ReportOptions,
    unit: &str,
    file: &str,
) -> Result<(), ReportError> {
    let point_name = s.point.0.as_str();
    let point = point_of(&l.model, point_name).ok_or_else(|| invalid(format!("no point `{point_name}`")))?;
    let branch_signs = signs(plan.choices(), s.branch.0);
    let sample = plan.solve(&l.model, &s.start.0, &branch_signs).map_err(|e| {
        invalid(format!(
            "{file}: the start {} is not reachable on branch {}: {e}",
            html::tuple_text(&s.start.0, 4),
            s.branch.0
        ))
    })?;
    let at = Sampling {
        l,
        plan,
        s,
        point,
        branch_signs,
        sample,
        view: if l.model.planar { View::Plane } else { View::Axonometric },
        unit,
    };
    page.html.push_str(&settings_html(l, s, unit));

    // 2. The mechanism at the sample input; its animation goes below it.
    let sample_poses = positions::sample_drawing(page, &at)?;
    let animation_at = page.html.len();

    // 3. Position solutions and the determinants' factors at the sample input.
    positions::solutions(page, &at)?;
    let sample_factors = named_factors(l, Some(plan), &sample_poses);
    positions::factors(page, &at, &sample_factors);

    // 4. Workspace.
    let cloud = workspace::workspace(page, &at, o)?;

    // 5. Singularities over a coarser sweep.
    singularities::singularities(page, &at, &sample_factors, &cloud)?;

    // 6. Trajectory: velocity, acceleration and the animation.
    trajectory::trajectory(page, &at, animation_at)
}
