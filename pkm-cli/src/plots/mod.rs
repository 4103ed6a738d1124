//! Plots for the report: every figure as PNG and SVG (plotters) with
//! labelled axes and units, and its data as CSV (the `csv` crate) beside it.
//! Legends sit in a strip beside the chart, never over the data; clouds of
//! more than [`DENSE`] points are drawn as occupied cells so that an SVG stays
//! small; sets in physical space are drawn with equal axis scales.
//!
//! This file holds what every figure shares (the chart's frame, legend,
//! colours, both back ends, the CSV beside it); each kind of figure has its
//! file: `scatter.rs`, `curves.rs`, `heat.rs` (heat maps), `solid.rs` (solids
//! in 3-D), and `ticks.rs` the ticks' values and labels.

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

mod curves;
mod heat;
mod scatter;
mod solid;
mod ticks;

pub use curves::curves;
pub use heat::{heat_map, HeatStyle};
pub use scatter::{occupancy, places, scatter, Style};
pub use solid::{solid3d, Voxels};
pub use ticks::{tick, tick_within};

/// The font the PNGs draw text with (DejaVu Sans, in `assets/fonts`), so no
/// system font library is needed.
const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// Above this many points a scatter draws occupied cells instead of points.
pub const DENSE: usize = 5_000;

/// The most rows a scatter's CSV holds; a larger set is written every k-th point.
pub const CSV_ROWS: usize = 200_000;

/// The width of the legend strip beside a chart, in pixels.
const LEGEND_WIDTH: u32 = 210;

fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // The bytes are a valid font; a failure would only lose PNG text.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// What went wrong writing a figure.
#[derive(Debug)]
pub struct PlotError(pub String);

impl std::fmt::Display for PlotError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for PlotError {}

pub(crate) fn err(e: impl std::fmt::Debug) -> PlotError {
    PlotError(format!("{e:?}"))
}

/// The files one figure was written to.
#[derive(Debug, Clone)]
pub struct Figure {
    /// The PNG.
    pub png: PathBuf,
    /// The SVG.
    pub svg: PathBuf,
    /// The data.
    pub csv: PathBuf,
}

/// Writes `rows` under `header` as CSV (quoted where a field needs it).
///
/// ```
/// let path = std::env::temp_dir().join("pkm-doc-csv.csv");
/// pkm_cli::plots::write_csv(&path, &["set", "x (mm)"], [vec!["a, b".to_string(), "1".to_string()]]).unwrap();
/// assert_eq!(std::fs::read_to_string(path).unwrap(), "set,x (mm)\n\"a, b\",1\n");
/// ```
pub fn write_csv<R: AsRef<[String]>>(
    path: &Path,
    header: &[&str],
    rows: impl IntoIterator<Item = R>,
) -> Result<(), PlotError> {
    let mut w = csv::Writer::from_path(path).map_err(|e| PlotError(format!("{}: {e}", path.display())))?;
    w.write_record(header).map_err(err)?;
    for r in rows {
        w.write_record(r.as_ref()).map_err(err)?;
    }
    w.flush().map_err(|e| PlotError(format!("{}: {e}", path.display())))
}

/// A value's range padded by 5 %, (−1, 1) when there is none.
pub(crate) fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
    if !lo.is_finite() || !hi.is_finite() {
        return (-1.0, 1.0);
    }
    let pad = ((hi - lo) * 0.05).max(1e-9 * hi.abs().max(lo.abs()).max(1.0));
    (lo - pad, hi + pad)
}

/// The largest magnitude a figure's extent may reach: beyond it the
/// extent's span, or the squares a drawing takes of it, would overflow.
pub const MAX_EXTENT: f64 = 1e150;

/// `r`, the extent along `axis` of the figure `title`, if a chart can be
/// drawn over it: both ends finite and within ±[`MAX_EXTENT`], the high end
/// above the low one by more than rounding (10⁻¹² of their size), else an
/// error that says why. Every extent goes through this before it reaches
/// plotters, whose tick routine does not return on an infinite extent.
///
/// ```
/// use pkm_cli::plots::checked_extent;
/// assert_eq!(checked_extent("f", "x", (-1.0, 2.0)).unwrap(), (-1.0, 2.0));
/// assert!(checked_extent("f", "x", (-1.05e308, 60.0)).is_err());
/// assert!(checked_extent("f", "y", (0.0, f64::INFINITY)).is_err());
/// assert!(checked_extent("f", "y", (1e20, 1e20)).is_err());
/// ```
pub fn checked_extent(title: &str, axis: &str, r: (f64, f64)) -> Result<(f64, f64), PlotError> {
    let (lo, hi) = r;
    let why = if !(lo.is_finite() && hi.is_finite()) {
        Some("it is not finite".to_string())
    } else if lo.abs().max(hi.abs()) > MAX_EXTENT {
        Some(format!("it reaches beyond ±{MAX_EXTENT:e}"))
    } else if hi - lo <= 1e-12 * lo.abs().max(hi.abs()) {
        Some("its span is below rounding".to_string())
    } else {
        None
    };
    match why {
        Some(why) => Err(PlotError(format!(
            "the figure \"{title}\" cannot be drawn: its {axis} extent {lo:e} .. {hi:e} is out of range ({why}); \
             is a coordinate or a parameter of the file too large?"
        ))),
        None => Ok(r),
    }
}

/// A figure that can draw itself on any plotters back end.
pub(crate) trait Draw {
    fn on<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<(), PlotError>;
}

/// Draws on both back ends.
pub(crate) fn both(stem: &Path, size: (u32, u32), d: &impl Draw) -> Result<(PathBuf, PathBuf), PlotError> {
    register_font();
    let png = stem.with_extension("png");
    let svg = stem.with_extension("svg");
    {
        let area = BitMapBackend::new(&png, size).into_drawing_area();
        area.fill(&WHITE).map_err(err)?;
        d.on(&area)?;
        area.present().map_err(err)?;
    }
    {
        let area = SVGBackend::new(&svg, size).into_drawing_area();
        area.fill(&WHITE).map_err(err)?;
        d.on(&area)?;
        area.present().map_err(err)?;
    }
    Ok((png, svg))
}

/// Widens the shorter of two ranges so that a unit spans as many pixels on
/// both axes of a `width` × `height` plot.
fn equalise(xr: (f64, f64), yr: (f64, f64), width: f64, height: f64) -> ((f64, f64), (f64, f64)) {
    let scale = ((xr.1 - xr.0) / width).max((yr.1 - yr.0) / height);
    let widen = |r: (f64, f64), pixels: f64| {
        let c = (r.0 + r.1) / 2.0;
        (c - scale * pixels / 2.0, c + scale * pixels / 2.0)
    };
    (widen(xr, width), widen(yr, height))
}

/// Pixels around a chart's plot: (left, right, top, bottom).
const MARGIN: i32 = 12;
const X_LABELS: i32 = 45;
const Y_LABELS: i32 = 75;
const CAPTION: i32 = 34;

/// A chart with its caption, labelled axes and mesh drawn; with `equal`, one
/// unit spans as many pixels on both axes.
pub(crate) fn frame<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    title: &str,
    labels: [&str; 2],
    xr: (f64, f64),
    yr: (f64, f64),
    equal: bool,
) -> Result<ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>, PlotError> {
    let (w, h) = area.dim_in_pixel();
    let (xr, yr) = (
        checked_extent(title, labels[0], xr)?,
        checked_extent(title, labels[1], yr)?,
    );
    let (xr, yr) = if equal {
        equalise(
            xr,
            yr,
            f64::from(w as i32 - 2 * MARGIN - Y_LABELS).max(1.0),
            f64::from(h as i32 - 2 * MARGIN - X_LABELS - CAPTION).max(1.0),
        )
    } else {
        (xr, yr)
    };
    let (xr, yr) = (
        checked_extent(title, labels[0], xr)?,
        checked_extent(title, labels[1], yr)?,
    );
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 20))
        .margin(MARGIN)
        .x_label_area_size(X_LABELS)
        .y_label_area_size(Y_LABELS)
        .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(labels[0])
        .y_desc(labels[1])
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    Ok(chart)
}

/// How a legend entry is marked.
#[derive(Clone, Copy)]
pub(crate) enum Mark {
    Dot,
    Line,
}

/// The legend in its own strip: a mark and a name per entry.
pub(crate) fn legend_strip<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[(String, RGBAColor, Mark)],
) -> Result<(), PlotError> {
    for (k, (name, colour, mark)) in entries.iter().enumerate() {
        let y = 50 + 24 * k as i32;
        match mark {
            Mark::Dot => area.draw(&Circle::new((12, y), 5, colour.filled())).map_err(err)?,
            Mark::Line => area
                .draw(&PathElement::new(vec![(2, y), (24, y)], colour.stroke_width(3)))
                .map_err(err)?,
        }
        area.draw(&Text::new(name.clone(), (30, y - 8), ("sans-serif", 14)))
            .map_err(err)?;
    }
    Ok(())
}

/// Splits off a legend strip on the right when there is a legend.
pub(crate) fn with_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: usize,
) -> (DrawingArea<DB, Shift>, Option<DrawingArea<DB, Shift>>) {
    if entries == 0 {
        return (area.clone(), None);
    }
    let (w, _) = area.dim_in_pixel();
    let (main, side) = area.split_horizontally(w.saturating_sub(LEGEND_WIDTH));
    (main, Some(side))
}

/// The colour of series `k`.
pub(crate) fn colour(k: usize) -> RGBAColor {
    const COLOURS: [RGBColor; 8] = [
        RGBColor(31, 119, 180),
        RGBColor(214, 39, 40),
        RGBColor(44, 160, 44),
        RGBColor(255, 127, 14),
        RGBColor(148, 103, 189),
        RGBColor(140, 86, 75),
        RGBColor(227, 119, 194),
        RGBColor(23, 190, 207),
    ];
    COLOURS[k % COLOURS.len()].to_rgba()
}

/// The viridis colour map at `t` in [0, 1] (its nine stops, linearly
/// between them): dark blue–purple for low, yellow for high, readable in
/// grey and by colour-blind readers.
pub(crate) fn viridis(t: f64) -> RGBColor {
    const STOPS: [(u8, u8, u8); 9] = [
        (68, 1, 84),
        (71, 44, 122),
        (59, 81, 139),
        (44, 113, 142),
        (33, 144, 141),
        (39, 173, 129),
        (92, 200, 99),
        (170, 220, 50),
        (253, 231, 37),
    ];
    let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 };
    let x = t * (STOPS.len() - 1) as f64;
    let k = (x.floor() as usize).min(STOPS.len() - 2);
    let f = x - k as f64;
    let mix = |a: u8, b: u8| (f64::from(a) + f * (f64::from(b) - f64::from(a))).round() as u8;
    let (a, b) = (STOPS[k], STOPS[k + 1]);
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}
