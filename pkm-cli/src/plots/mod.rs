//! Plots for the report: every figure as PNG and SVG (plotters) with
//! labelled axes and units, and its data as CSV (the `csv` crate) beside it.
//! Legends sit in a strip beside the chart, never over the data; clouds of
//! more than [`DENSE`] points are drawn as occupied cells so that an SVG stays
//! small; sets in physical space are drawn with equal axis scales.

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// The font the PNGs draw text with (DejaVu Sans, in `assets/fonts`), so no
/// system font library is needed.
const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// Above this many points a scatter draws occupied cells instead of points.
pub const DENSE: usize = 5_000;

/// Cells across a dense scatter's plot (its SVG holds at most this squared
/// rectangles per set).
const CELLS: usize = 120;

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

/// Which cells of a square grid, `across` × `across` over `xr` × `yr`,
/// hold a point (cell `(i, j)` at `i · across + j`), and a cell's width and
/// height. A point on the upper edge counts in the last cell.
///
/// ```
/// let (full, dx, dy) = pkm_cli::plots::occupancy(&[[0.0, 0.0], [1.0, 1.0], [0.2, 0.7]], (0.0, 1.0), (0.0, 1.0), 2);
/// assert_eq!(full, [true, true, false, true]);
/// assert_eq!((dx, dy), (0.5, 0.5));
/// ```
pub fn occupancy(points: &[[f64; 2]], xr: (f64, f64), yr: (f64, f64), across: usize) -> (Vec<bool>, f64, f64) {
    let (dx, dy) = ((xr.1 - xr.0) / across as f64, (yr.1 - yr.0) / across as f64);
    let mut full = vec![false; across * across];
    for p in points {
        let i = (((p[0] - xr.0) / dx) as usize).min(across - 1);
        let j = (((p[1] - yr.0) / dy) as usize).min(across - 1);
        full[i * across + j] = true;
    }
    (full, dx, dy)
}

/// The occupied cells of a dense point set: each cell's lower-left and
/// upper-right corners, over `xr` × `yr` cut into [`CELLS`] per side; an
/// empty cell between two occupied ones counts as occupied.
fn cells(points: &[[f64; 2]], xr: (f64, f64), yr: (f64, f64)) -> Vec<[(f64, f64); 2]> {
    let (full, dx, dy) = occupancy(points, xr, yr, CELLS);
    // A cell between two full ones (across or up) is filled too: a lattice of
    // samples coarser than the cells leaves one-cell stripes otherwise.
    let at = |i: usize, j: usize| full[i * CELLS + j];
    let closed: Vec<bool> = (0..CELLS * CELLS)
        .map(|k| {
            let (i, j) = (k / CELLS, k % CELLS);
            full[k]
                || (i > 0 && i + 1 < CELLS && at(i - 1, j) && at(i + 1, j))
                || (j > 0 && j + 1 < CELLS && at(i, j - 1) && at(i, j + 1))
        })
        .collect();
    (0..CELLS * CELLS)
        .filter(|&k| closed[k])
        .map(|k| {
            let (x, y) = (xr.0 + (k / CELLS) as f64 * dx, yr.0 + (k % CELLS) as f64 * dy);
            [(x, y), (x + dx, y + dy)]
        })
        .collect()
}

/// Each place of `points` once, in order: points within 10⁻⁹ of the set's
/// extent of an earlier one are left out.
///
/// ```
/// let p = pkm_cli::plots::places(&[[0.0, 0.0], [1.0, 1.0], [0.0, 1e-12], [1.0, 0.0]]);
/// assert_eq!(p, [[0.0, 0.0], [1.0, 1.0], [1.0, 0.0]]);
/// ```
pub fn places(points: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let xr = range(points.iter().map(|p| p[0]));
    let yr = range(points.iter().map(|p| p[1]));
    let scale = (xr.1 - xr.0).max(yr.1 - yr.0) * 1e-9;
    let mut seen = std::collections::HashSet::new();
    points
        .iter()
        .filter(|p| seen.insert(((p[0] / scale).round() as i64, (p[1] / scale).round() as i64)))
        .copied()
        .collect()
}

/// How a scatter is drawn.
#[derive(Debug, Clone, Copy, Default)]
pub struct Style {
    /// One unit spans as many pixels on both axes (physical space).
    pub equal_axes: bool,
    /// Join each set's points in order (a curve traced by a 1-input sweep).
    pub joined: bool,
}

/// A scatter of 2-D point sets, one colour each, with axis labels (units
/// included in the labels); each place once (unless joined); the CSV holds
/// every place (set, x, y), or every k-th when there are more than [`CSV_ROWS`].
///
/// ```
/// let stem = std::env::temp_dir().join("pkm-doc-scatter");
/// let sets = [("corners".to_string(), vec![[0.0, 0.0], [1.0, 1.0]])];
/// let f = pkm_cli::plots::scatter(&stem, "Unit square", ["x (mm)", "y (mm)"], &sets, Default::default()).unwrap();
/// assert!(std::fs::read_to_string(f.csv).unwrap().starts_with("set,x (mm),y (mm)"));
/// ```
pub fn scatter(
    stem: &Path,
    title: &str,
    labels: [&str; 2],
    sets: &[(String, Vec<[f64; 2]>)],
    style: Style,
) -> Result<Figure, PlotError> {
    let all = || sets.iter().flat_map(|(_, v)| v.iter());
    let xr = range(all().map(|p| p[0]));
    let yr = range(all().map(|p| p[1]));
    // Each place once (a point the inputs leave still repeats): whether a
    // cloud is dense is a matter of places, not of nodes.
    let owned: Vec<(String, Vec<[f64; 2]>)>;
    let sets = if style.joined {
        sets
    } else {
        owned = sets
            .iter()
            .map(|(name, points)| (name.clone(), places(points)))
            .collect();
        &owned[..]
    };
    let csv = stem.with_extension("csv");
    let total: usize = sets.iter().map(|(_, v)| v.len()).sum();
    let stride = total.div_ceil(CSV_ROWS).max(1);
    write_csv(
        &csv,
        &["set", labels[0], labels[1]],
        sets.iter().flat_map(|(name, points)| {
            points
                .iter()
                .step_by(stride)
                .map(move |p| vec![name.clone(), p[0].to_string(), p[1].to_string()])
        }),
    )?;
    struct Scatter<'a> {
        title: &'a str,
        labels: [&'a str; 2],
        sets: &'a [(String, Vec<[f64; 2]>)],
        xr: (f64, f64),
        yr: (f64, f64),
        style: Style,
    }
    impl Draw for Scatter<'_> {
        fn on<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
            let named = if self.sets.len() > 1 { self.sets.len() } else { 0 };
            let (main, side) = with_legend(area, named);
            let mut chart = frame(&main, self.title, self.labels, self.xr, self.yr, self.style.equal_axes)?;
            let mut entries = Vec::new();
            for (k, (name, points)) in self.sets.iter().enumerate() {
                let c = colour(k);
                if self.style.joined {
                    chart
                        .draw_series(LineSeries::new(points.iter().map(|p| (p[0], p[1])), c.stroke_width(2)))
                        .map_err(err)?;
                } else if points.len() > DENSE {
                    // Cells of the plot's own ranges, so a cell is a few pixels.
                    let (x, y) = (chart.x_range(), chart.y_range());
                    chart
                        .draw_series(
                            cells(points, (x.start, x.end), (y.start, y.end))
                                .into_iter()
                                .map(|[a, b]| Rectangle::new([a, b], c.mix(0.6).filled())),
                        )
                        .map_err(err)?;
                } else {
                    chart
                        .draw_series(points.iter().map(|p| Circle::new((p[0], p[1]), 2, c.mix(0.5).filled())))
                        .map_err(err)?;
                }
                entries.push((name.clone(), c, if self.style.joined { Mark::Line } else { Mark::Dot }));
            }
            if let Some(side) = side {
                legend_strip(&side, &entries)?;
            }
            Ok(())
        }
    }
    let d = Scatter {
        title,
        labels,
        sets,
        xr,
        yr,
        style,
    };
    let width = if sets.len() > 1 { 800 + LEGEND_WIDTH } else { 800 };
    let (png, svg) = both(stem, (width, 680), &d)?;
    Ok(Figure { png, svg, csv })
}

/// A view of 3-D space from azimuth `azimuth` and elevation `elevation`
/// (radians; azimuth 0 looks from −y towards +y, positive turns the viewer
/// towards +x): a point's place across and up the view, and its distance
/// towards the viewer.
#[derive(Debug, Clone, Copy)]
struct Camera {
    right: [f64; 3],
    up: [f64; 3],
    toward: [f64; 3],
}

impl Camera {
    fn new(azimuth: f64, elevation: f64) -> Camera {
        let (a, e) = (azimuth, elevation);
        Camera {
            right: [a.cos(), a.sin(), 0.0],
            up: [-e.sin() * a.sin(), e.sin() * a.cos(), e.cos()],
            toward: [a.sin() * e.cos(), -a.cos() * e.cos(), e.sin()],
        }
    }

    fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
        a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    }

    /// Across and up the view.
    fn project(&self, p: [f64; 3]) -> (f64, f64) {
        (Camera::dot(self.right, p), Camera::dot(self.up, p))
    }
}

/// A cloud of points as a solid: the cubic cells of a grid over it that
/// hold a point (a gap of one cell between two full ones filled), each
/// cell `edge` wide from `origin`, `dims` cells per axis.
#[derive(Debug, Clone)]
pub struct Voxels {
    /// The grid's lowest corner.
    pub origin: [f64; 3],
    /// A cell's edge.
    pub edge: f64,
    /// Cells per axis.
    pub dims: [usize; 3],
    /// Whether each cell is full (index `(i · dims[1] + j) · dims[2] + k`).
    pub full: Vec<bool>,
}

impl Voxels {
    /// The cells of `points`, about `across` along the cloud's longest
    /// extent (at least 1).
    ///
    /// ```
    /// // The 11³ nodes of a cube of side 10, cells of edge 10 / 5 = 2 centred
    /// // on it: 6 a side (the nodes at 0 and at 10 in cells of their own),
    /// // every one full, the cube grown by half a cell each side: 12³.
    /// let pts: Vec<[f64; 3]> = (0..1331).map(|n| [(n / 121) as f64, (n / 11 % 11) as f64, (n % 11) as f64]).collect();
    /// let v = pkm_cli::plots::Voxels::of(&pts, 5);
    /// assert_eq!(v.dims, [6, 6, 6]);
    /// assert_eq!(v.full.iter().filter(|f| **f).count(), v.full.len());
    /// assert!((v.volume() - 1728.0).abs() < 1e-9);
    /// ```
    pub fn of(points: &[[f64; 3]], across: usize) -> Voxels {
        let lo: [f64; 3] = std::array::from_fn(|i| points.iter().map(|p| p[i]).fold(f64::INFINITY, f64::min));
        let hi: [f64; 3] = std::array::from_fn(|i| points.iter().map(|p| p[i]).fold(f64::NEG_INFINITY, f64::max));
        let longest = (0..3).map(|i| hi[i] - lo[i]).fold(0.0, f64::max);
        let edge = if longest > 0.0 && longest.is_finite() {
            longest / across.max(1) as f64
        } else {
            1.0
        };
        let dims: [usize; 3] =
            std::array::from_fn(|i| (((hi[i] - lo[i]) / edge).floor() as usize + 1).clamp(1, 4 * across.max(1)));
        // Centred on the cloud along each axis.
        let origin: [f64; 3] = std::array::from_fn(|i| (lo[i] + hi[i]) / 2.0 - dims[i] as f64 * edge / 2.0);
        let index = |c: [usize; 3]| (c[0] * dims[1] + c[1]) * dims[2] + c[2];
        let mut full = vec![false; dims[0] * dims[1] * dims[2]];
        for p in points.iter().filter(|p| p.iter().all(|x| x.is_finite())) {
            let c: [usize; 3] = std::array::from_fn(|i| (((p[i] - origin[i]) / edge) as usize).min(dims[i] - 1));
            full[index(c)] = true;
        }
        // A cell between two full ones along an axis is full: a lattice of
        // samples coarser than the cells leaves one-cell holes otherwise.
        let at = |full: &[bool], c: [usize; 3], axis: usize, d: isize| {
            let k = c[axis] as isize + d;
            if k < 0 || k >= dims[axis] as isize {
                return false;
            }
            let mut n = c;
            n[axis] = k as usize;
            full[index(n)]
        };
        let mut closed = full.clone();
        for i in 0..dims[0] {
            for j in 0..dims[1] {
                for k in 0..dims[2] {
                    let c = [i, j, k];
                    if (0..3).any(|a| at(&full, c, a, -1) && at(&full, c, a, 1)) {
                        closed[index(c)] = true;
                    }
                }
            }
        }
        Voxels {
            origin,
            edge,
            dims,
            full: closed,
        }
    }

    /// The full cells' volume.
    pub fn volume(&self) -> f64 {
        self.full.iter().filter(|f| **f).count() as f64 * self.edge.powi(3)
    }

    fn is_full(&self, c: [isize; 3]) -> bool {
        if (0..3).any(|i| c[i] < 0 || c[i] >= self.dims[i] as isize) {
            return false;
        }
        self.full[(c[0] as usize * self.dims[1] + c[1] as usize) * self.dims[2] + c[2] as usize]
    }

    /// The boundary faces: each a full cell's face whose neighbour is
    /// empty, as its four corners and outward normal.
    fn faces(&self) -> Vec<([[f64; 3]; 4], [f64; 3])> {
        let mut faces = Vec::new();
        let d = self.dims;
        for i in 0..d[0] {
            for j in 0..d[1] {
                for k in 0..d[2] {
                    let c = [i as isize, j as isize, k as isize];
                    if !self.is_full(c) {
                        continue;
                    }
                    for axis in 0..3 {
                        for side in [0isize, 1] {
                            let mut n = c;
                            n[axis] += 2 * side - 1;
                            if self.is_full(n) {
                                continue;
                            }
                            // The face's four corners, in order round it.
                            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                            let corner = |a: usize, b: usize| {
                                let mut g = [c[0] as f64, c[1] as f64, c[2] as f64];
                                g[axis] += side as f64;
                                g[u] += a as f64;
                                g[v] += b as f64;
                                std::array::from_fn(|m| self.origin[m] + g[m] * self.edge)
                            };
                            let mut normal = [0.0; 3];
                            normal[axis] = (2 * side - 1) as f64;
                            faces.push(([corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)], normal));
                        }
                    }
                }
            }
        }
        faces
    }
}

/// Tick values over `lo ..= hi`: about five, at 1, 2 or 5 times a power of ten.
fn nice_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let span = hi - lo;
    if !(span > 0.0 && span.is_finite()) {
        return vec![lo];
    }
    let raw = span / 5.0;
    let power = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * power)
        .find(|s| span / s <= 6.0)
        .unwrap_or(10.0 * power);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last).map(|k| k as f64 * step).collect()
}

/// A solid seen in 3-D: the cloud `points` drawn as its occupied cells
/// ([`Voxels`], about 28 across) whose outer faces are shaded (lit from
/// the upper left, coloured by height on the viridis scale), from two
/// sides (azimuth 35° and 215°, elevation 25°), each in its box with the
/// axes `labels` (x, y, z) ticked on the box's near edges and a triad.
/// The CSV holds the full cells' centres.
///
/// ```
/// let stem = std::env::temp_dir().join("pkm-doc-solid");
/// let ball: Vec<[f64; 3]> = (0..8000)
///     .map(|n| [(n / 400) as f64 - 10.0, (n / 20 % 20) as f64 - 10.0, (n % 20) as f64 - 10.0])
///     .filter(|p| p[0] * p[0] + p[1] * p[1] + p[2] * p[2] <= 100.0)
///     .collect();
/// let f = pkm_cli::plots::solid3d(&stem, "Ball", ["x (mm)", "y (mm)", "z (mm)"], &ball).unwrap();
/// assert!(std::fs::read_to_string(f.csv).unwrap().starts_with("x (mm),y (mm),z (mm)"));
/// ```
pub fn solid3d(stem: &Path, title: &str, labels: [&str; 3], points: &[[f64; 3]]) -> Result<Figure, PlotError> {
    let finite: Vec<[f64; 3]> = points
        .iter()
        .copied()
        .filter(|p| p.iter().all(|x| x.is_finite()))
        .collect();
    if finite.is_empty() {
        return Err(PlotError(format!("the figure \"{title}\" has no point to draw")));
    }
    for (i, label) in labels.iter().enumerate() {
        let r = range(finite.iter().map(|p| p[i]));
        checked_extent(title, label, r)?;
    }
    let voxels = Voxels::of(&finite, 28);
    let csv = stem.with_extension("csv");
    let d = voxels.dims;
    write_csv(
        &csv,
        &labels,
        (0..voxels.full.len()).filter(|&n| voxels.full[n]).map(|n| {
            let c = [n / (d[1] * d[2]), n / d[2] % d[1], n % d[2]];
            (0..3)
                .map(|i| (voxels.origin[i] + (c[i] as f64 + 0.5) * voxels.edge).to_string())
                .collect::<Vec<_>>()
        }),
    )?;
    struct Solid<'a> {
        title: &'a str,
        labels: [&'a str; 3],
        voxels: &'a Voxels,
        faces: Vec<([[f64; 3]; 4], [f64; 3])>,
    }
    impl Solid<'_> {
        fn panel<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>, azimuth: f64) -> Result<(), PlotError> {
            let cam = Camera::new(azimuth.to_radians(), 25f64.to_radians());
            let v = self.voxels;
            let lo = v.origin;
            let hi: [f64; 3] = std::array::from_fn(|i| v.origin[i] + v.dims[i] as f64 * v.edge);
            let box_corner =
                |c: usize| -> [f64; 3] { std::array::from_fn(|i| if c >> i & 1 == 1 { hi[i] } else { lo[i] }) };
            let projected: Vec<(f64, f64)> = (0..8).map(|c| cam.project(box_corner(c))).collect();
            let xr = range(projected.iter().map(|p| p.0));
            let yr = range(projected.iter().map(|p| p.1));
            let (w, h) = area.dim_in_pixel();
            // Room round the box for the ticks and names.
            let (xr, yr) = equalise(
                (xr.0 - 0.18 * (xr.1 - xr.0), xr.1 + 0.18 * (xr.1 - xr.0)),
                (yr.0 - 0.18 * (yr.1 - yr.0), yr.1 + 0.12 * (yr.1 - yr.0)),
                f64::from(w),
                f64::from(h) - 30.0,
            );
            let mut chart = ChartBuilder::on(area)
                .caption(format!("seen from azimuth {azimuth:.0}°"), ("sans-serif", 15))
                .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)
                .map_err(err)?;
            let centre = cam.project(std::array::from_fn(|i| (lo[i] + hi[i]) / 2.0));
            // The box's twelve edges, thin, under the solid.
            let grey = RGBColor(170, 170, 170);
            for a in 0..8usize {
                for i in 0..3 {
                    let b = a | 1 << i;
                    if b != a {
                        chart
                            .draw_series(LineSeries::new(vec![projected[a], projected[b]], grey.stroke_width(1)))
                            .map_err(err)?;
                    }
                }
            }
            // The faces that look towards the viewer, far ones first.
            let light = {
                let l = [
                    cam.toward[0] + 0.6 * cam.up[0] - 0.4 * cam.right[0],
                    cam.toward[1] + 0.6 * cam.up[1] - 0.4 * cam.right[1],
                    cam.toward[2] + 0.6 * cam.up[2] - 0.4 * cam.right[2],
                ];
                let n = Camera::dot(l, l).sqrt();
                l.map(|x| x / n)
            };
            let mut shown: Vec<&([[f64; 3]; 4], [f64; 3])> = self
                .faces
                .iter()
                .filter(|(_, n)| Camera::dot(*n, cam.toward) > 1e-9)
                .collect();
            let depth = |f: &([[f64; 3]; 4], [f64; 3])| {
                let c: [f64; 3] = std::array::from_fn(|i| (f.0[0][i] + f.0[2][i]) / 2.0);
                Camera::dot(c, cam.toward)
            };
            shown.sort_by(|a, b| depth(a).total_cmp(&depth(b)));
            let zspan = (hi[2] - lo[2]).max(f64::MIN_POSITIVE);
            chart
                .draw_series(shown.iter().map(|(corners, normal)| {
                    let height = (corners.iter().map(|c| c[2]).sum::<f64>() / 4.0 - lo[2]) / zspan;
                    let base = viridis(height);
                    let shade = 0.5 + 0.5 * Camera::dot(*normal, light).max(0.0);
                    let c = RGBColor(
                        (f64::from(base.0) * shade) as u8,
                        (f64::from(base.1) * shade) as u8,
                        (f64::from(base.2) * shade) as u8,
                    );
                    Polygon::new(corners.iter().map(|p| cam.project(*p)).collect::<Vec<_>>(), c.filled())
                }))
                .map_err(err)?;
            // Each axis ticked along the box edge nearest the viewer, the
            // labels pushed outwards from the box's centre.
            let near = |i: usize| if cam.toward[i] < 0.0 { lo[i] } else { hi[i] };
            for axis in 0..3 {
                let (a, b) = match axis {
                    0 => (1, 2),
                    1 => (0, 2),
                    _ => (0, 1),
                };
                let mut at = [0.0; 3];
                at[a] = near(a);
                // x and y along the bottom; z up the side away from the viewer's right.
                at[b] = if axis == 2 {
                    if cam.right[b] > 0.0 {
                        lo[b]
                    } else {
                        hi[b]
                    }
                } else {
                    lo[b]
                };
                if axis == 2 {
                    at[a] = if cam.right[a] > 0.0 { lo[a] } else { hi[a] };
                }
                let ticks = nice_ticks(lo[axis], hi[axis]);
                let mid = {
                    let mut m = at;
                    m[axis] = (lo[axis] + hi[axis]) / 2.0;
                    cam.project(m)
                };
                let (ox, oy) = (mid.0 - centre.0, mid.1 - centre.1);
                let on = (ox * ox + oy * oy).sqrt().max(f64::MIN_POSITIVE);
                let out = ((ox / on * 14.0) as i32, (-oy / on * 14.0) as i32);
                let mut last: Option<(i32, i32)> = None;
                for t in ticks {
                    let mut p = at;
                    p[axis] = t;
                    let q = cam.project(p);
                    // A tick's label needs room: one too near the last drawn is left out.
                    let px = chart.backend_coord(&q);
                    if last.is_some_and(|l| (l.0 - px.0).pow(2) + (l.1 - px.1).pow(2) < 30 * 30) {
                        continue;
                    }
                    last = Some(px);
                    chart
                        .draw_series(std::iter::once(
                            EmptyElement::at(q)
                                + Circle::new((0, 0), 2, BLACK.filled())
                                + Text::new(tick(t), (out.0 * 2 - 12, out.1 * 2 - 6), ("sans-serif", 12)),
                        ))
                        .map_err(err)?;
                }
                chart
                    .draw_series(std::iter::once(
                        EmptyElement::at(mid)
                            + Text::new(
                                self.labels[axis].to_string(),
                                (out.0 * 5 - 20, out.1 * 5 - 6),
                                ("sans-serif", 14),
                            ),
                    ))
                    .map_err(err)?;
            }
            // The triad at the lower left.
            let origin = (40, -40);
            for (k, name) in ["x", "y", "z"].iter().enumerate() {
                let mut e = [0.0; 3];
                e[k] = 1.0;
                let d = cam.project(e);
                let tip = (origin.0 + (30.0 * d.0) as i32, origin.1 - (30.0 * d.1) as i32);
                chart
                    .draw_series(std::iter::once(
                        EmptyElement::at((xr.0, yr.0))
                            + PathElement::new(vec![origin, tip], BLACK.stroke_width(2))
                            + Text::new(
                                name.to_string(),
                                (origin.0 + (40.0 * d.0) as i32 - 4, origin.1 - (40.0 * d.1) as i32 - 7),
                                ("sans-serif", 13),
                            ),
                    ))
                    .map_err(err)?;
            }
            Ok(())
        }
    }
    impl Draw for Solid<'_> {
        fn on<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
            let area = area.titled(self.title, ("sans-serif", 20)).map_err(err)?;
            let (w, _) = area.dim_in_pixel();
            let (left, right) = area.split_horizontally(w / 2);
            self.panel(&left, 35.0)?;
            self.panel(&right, 215.0)
        }
    }
    let d = Solid {
        title,
        labels,
        faces: voxels.faces(),
        voxels: &voxels,
    };
    let (png, svg) = both(stem, (1100, 560), &d)?;
    Ok(Figure { png, svg, csv })
}

/// Curves over a shared abscissa: `series` are (name, values) with the same
/// length as `x`; the legend sits beside the plot. A value that is not
/// finite is a gap in its curve and an empty field in the CSV.
///
/// ```
/// let stem = std::env::temp_dir().join("pkm-doc-curves");
/// let t = [0.0, 0.5, 1.0];
/// let f = pkm_cli::plots::curves(&stem, "Ramp", ["t (s)", "v (mm/s)"], &t, &[("v".into(), vec![0.0, 1.0, 2.0])]).unwrap();
/// assert_eq!(std::fs::read_to_string(f.csv).unwrap().lines().count(), 4);
/// ```
pub fn curves(
    stem: &Path,
    title: &str,
    labels: [&str; 2],
    x: &[f64],
    series: &[(String, Vec<f64>)],
) -> Result<Figure, PlotError> {
    let xr = range(x.iter().copied());
    let yr = range(series.iter().flat_map(|(_, v)| v.iter().copied()));
    let csv = stem.with_extension("csv");
    let mut header = vec![labels[0]];
    header.extend(series.iter().map(|(n, _)| n.as_str()));
    write_csv(
        &csv,
        &header,
        x.iter().enumerate().map(|(i, t)| {
            let mut row = vec![t.to_string()];
            row.extend(series.iter().map(|(_, v)| {
                v.get(i)
                    .filter(|x| x.is_finite())
                    .map(|x| x.to_string())
                    .unwrap_or_default()
            }));
            row
        }),
    )?;
    struct Curves<'a> {
        title: &'a str,
        labels: [&'a str; 2],
        x: &'a [f64],
        series: &'a [(String, Vec<f64>)],
        xr: (f64, f64),
        yr: (f64, f64),
    }
    impl Draw for Curves<'_> {
        fn on<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
            let (main, side) = with_legend(area, self.series.len());
            let mut chart = frame(&main, self.title, self.labels, self.xr, self.yr, false)?;
            let mut entries = Vec::new();
            for (k, (name, v)) in self.series.iter().enumerate() {
                let c = colour(k);
                // A value that is not a number leaves a gap: each run of
                // finite points is its own line.
                let points: Vec<(f64, f64)> = self.x.iter().zip(v).map(|(a, b)| (*a, *b)).collect();
                for run in points.split(|(a, b)| !(a.is_finite() && b.is_finite())) {
                    chart
                        .draw_series(LineSeries::new(run.iter().copied(), c.stroke_width(2)))
                        .map_err(err)?;
                }
                entries.push((name.clone(), c, Mark::Line));
            }
            if let Some(side) = side {
                legend_strip(&side, &entries)?;
            }
            Ok(())
        }
    }
    let d = Curves {
        title,
        labels,
        x,
        series,
        xr,
        yr,
    };
    let (png, svg) = both(stem, (800 + LEGEND_WIDTH, 520), &d)?;
    Ok(Figure { png, svg, csv })
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

/// The width of a heat map's colour bar strip, in pixels.
const BAR_WIDTH: u32 = 150;

/// `v` as 0 when it is within rounding (10⁻⁹ of `span`) of it.
fn snap(v: f64, span: f64) -> f64 {
    if v.abs() <= 1e-9 * span.abs() {
        0.0
    } else {
        v
    }
}

/// A tick label: three significant digits, a power of ten for large or
/// small values, never `-0`.
///
/// ```
/// assert_eq!(pkm_cli::plots::tick(-0.0), "0");
/// assert_eq!(pkm_cli::plots::tick(0.25), "0.25");
/// assert_eq!(pkm_cli::plots::tick(12_500_000.0), "1.25e7");
/// ```
pub fn tick(v: f64) -> String {
    tick_digits(v, 3)
}

/// A tick label on an axis spanning `span`: as [`tick`], with as many more
/// significant digits as it takes to read a hundredth of the span, so
/// that ticks a tenth of it apart read differently (a colour bar over a
/// narrow range).
///
/// ```
/// assert_eq!(pkm_cli::plots::tick_within(19_100.0, 1.0e4), "1.91e4");
/// assert_eq!(pkm_cli::plots::tick_within(19_103.5, 5.0), "19103.5");
/// ```
pub fn tick_within(v: f64, span: f64) -> String {
    let extra = if v != 0.0 && span > 0.0 && span.is_finite() {
        ((v.abs() / (0.01 * span)).log10().floor() as i32 - 2).clamp(0, 12) as usize
    } else {
        0
    };
    tick_digits(v, 3 + extra)
}

/// `v` to `significant` digits, fixed between 10⁻³ and 10⁴ (further while
/// the digits ask for it), else with a power of ten; no trailing zeros.
fn tick_digits(v: f64, significant: usize) -> String {
    if v == 0.0 || !v.is_finite() {
        return if v.is_finite() { "0".into() } else { v.to_string() };
    }
    let a = v.abs();
    let magnitude = a.log10().floor() as i32;
    let fixed_up_to = 4.max(significant as i32);
    let text = if (-3..fixed_up_to).contains(&magnitude) {
        let digits = (significant as i32 - 1 - magnitude).max(0) as usize;
        format!("{v:.digits$}")
    } else {
        let digits = significant - 1;
        format!("{v:.digits$e}")
    };
    // Trailing zeros of the mantissa go.
    let (mantissa, exponent) = text.split_once('e').map_or((text.as_str(), ""), |(m, e)| (m, e));
    let mantissa = if mantissa.contains('.') {
        mantissa.trim_end_matches('0').trim_end_matches('.')
    } else {
        mantissa
    };
    let mantissa = if mantissa == "-0" { "0" } else { mantissa };
    if exponent.is_empty() {
        mantissa.to_string()
    } else {
        format!("{mantissa}e{exponent}")
    }
}

/// The edges of node `k`'s cell on the axis of node values `v` (at least
/// two): half a step either side of it.
fn cell_edges(v: &[f64], k: usize) -> (f64, f64) {
    let n = v.len();
    let lo = if k == 0 { v[1] - v[0] } else { v[k] - v[k - 1] };
    let hi = if k + 1 == n {
        v[n - 1] - v[n - 2]
    } else {
        v[k + 1] - v[k]
    };
    (v[k] - lo / 2.0, v[k] + hi / 2.0)
}

/// How a heat map colours and marks its nodes.
#[derive(Debug, Clone, Copy, Default)]
pub struct HeatStyle<'a> {
    /// Colour by the logarithm of the value (when every finite value is
    /// above 0; else linear): a map over decades reads in each of them.
    pub log: bool,
    /// Nodes marked with a cross (one flag per value, or empty for none).
    pub marked: &'a [bool],
    /// What a cross means (the legend under the colour bar and the CSV's
    /// last column's name).
    pub mark_label: &'a str,
}

/// A heat map of `values` over the grid `xs` × `ys` (`values[i · ys.len() + j]`
/// at `(xs[i], ys[j])`, each node's cell centred on it): the colour bar
/// beside it labelled `value_label`, linear or logarithmic (`style.log`); a
/// node whose value is not finite is left blank (white); a node
/// `style.marked` is crossed. The CSV has one row per node, its value empty
/// where there is none, and a column of the marks when `style` gives them.
///
/// ```
/// let stem = std::env::temp_dir().join("pkm-doc-heat");
/// let f = pkm_cli::plots::heat_map(&stem, "Heat", ["x (mm)", "y (mm)"], &[0.0, 1.0], &[0.0, 1.0],
///     &[1.0, 2.0, f64::NAN, 4.0], "k (N/mm)", &Default::default()).unwrap();
/// let csv = std::fs::read_to_string(f.csv).unwrap();
/// assert_eq!(csv.lines().nth(3), Some("1,0,"));
/// ```
#[allow(clippy::too_many_arguments)]
pub fn heat_map(
    stem: &Path,
    title: &str,
    labels: [&str; 2],
    xs: &[f64],
    ys: &[f64],
    values: &[f64],
    value_label: &str,
    style: &HeatStyle,
) -> Result<Figure, PlotError> {
    if xs.len() < 2 || ys.len() < 2 || values.len() != xs.len() * ys.len() {
        return Err(PlotError(format!(
            "a heat map needs at least 2 × 2 nodes and one value per node ({} × {} nodes, {} values)",
            xs.len(),
            ys.len(),
            values.len()
        )));
    }
    let marked = |n: usize| style.marked.get(n).copied().unwrap_or(false);
    // The marks' column whenever there are marks to give, crossed or not.
    let any_marked = !style.marked.is_empty();
    let csv = stem.with_extension("csv");
    let mut header = vec![labels[0], labels[1], value_label];
    if any_marked {
        header.push(style.mark_label);
    }
    write_csv(
        &csv,
        &header,
        (0..values.len()).map(|n| {
            let v = values[n];
            let mut row = vec![
                xs[n / ys.len()].to_string(),
                ys[n % ys.len()].to_string(),
                if v.is_finite() { v.to_string() } else { String::new() },
            ];
            if any_marked {
                row.push(marked(n).to_string());
            }
            row
        }),
    )?;
    let (nx, ny) = (xs.len(), ys.len());
    let xr = checked_extent(title, labels[0], (cell_edges(xs, 0).0, cell_edges(xs, nx - 1).1))?;
    let yr = checked_extent(title, labels[1], (cell_edges(ys, 0).0, cell_edges(ys, ny - 1).1))?;
    let finite = || values.iter().copied().filter(|v| v.is_finite());
    let log = style.log && finite().next().is_some() && finite().all(|v| v > 0.0);
    // The colour scale's variable: the value or its decimal logarithm.
    let scaled = |v: f64| if log { v.log10() } else { v };
    let (lo, hi) = finite().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(scaled(v)), b.max(scaled(v)))
    });
    let (lo, hi) = if lo.is_finite() { (lo, hi) } else { (0.0, 1.0) };
    let span = if hi > lo { hi - lo } else { 1.0 };
    checked_extent(title, value_label, (lo, lo + span))?;
    struct Heat<'a> {
        title: &'a str,
        labels: [&'a str; 2],
        xs: &'a [f64],
        ys: &'a [f64],
        values: &'a [f64],
        value_label: &'a str,
        style: &'a HeatStyle<'a>,
        log: bool,
        xr: (f64, f64),
        yr: (f64, f64),
        lo: f64,
        span: f64,
    }
    impl Draw for Heat<'_> {
        fn on<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
            let (w, _) = area.dim_in_pixel();
            let (main, bar) = area.split_horizontally(w.saturating_sub(BAR_WIDTH));
            let ny = self.ys.len();
            let (xr, yr, lo, span) = (self.xr, self.yr, self.lo, self.span);
            let scaled = |v: f64| if self.log { v.log10() } else { v };
            let mut chart = ChartBuilder::on(&main)
                .caption(self.title, ("sans-serif", 20))
                .margin(MARGIN)
                .x_label_area_size(X_LABELS)
                .y_label_area_size(Y_LABELS)
                .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)
                .map_err(err)?;
            chart
                .configure_mesh()
                .disable_mesh()
                .x_desc(self.labels[0])
                .y_desc(self.labels[1])
                .x_label_formatter(&|v| tick(snap(*v, xr.1 - xr.0)))
                .y_label_formatter(&|v| tick(snap(*v, yr.1 - yr.0)))
                .label_style(("sans-serif", 14))
                .draw()
                .map_err(err)?;
            let cells = (0..self.values.len()).filter(|&n| self.values[n].is_finite()).map(|n| {
                let (x0, x1) = cell_edges(self.xs, n / ny);
                let (y0, y1) = cell_edges(self.ys, n % ny);
                let c = viridis((scaled(self.values[n]) - lo) / span);
                Rectangle::new([(x0, y0), (x1, y1)], c.filled())
            });
            chart.draw_series(cells).map_err(err)?;
            let crosses = (0..self.values.len())
                .filter(|&n| self.style.marked.get(n).copied().unwrap_or(false))
                .map(|n| {
                    let at = (self.xs[n / ny], self.ys[n % ny]);
                    EmptyElement::at(at)
                        + PathElement::new(vec![(-4, -4), (4, 4)], RED.stroke_width(2))
                        + PathElement::new(vec![(-4, 4), (4, -4)], RED.stroke_width(2))
                });
            chart.draw_series(crosses).map_err(err)?;
            // The colour bar: a column of 100 bands from the least value to the greatest.
            let (top, bottom) = (
                CAPTION + MARGIN,
                X_LABELS + MARGIN + if self.style.marked.is_empty() { 0 } else { 30 },
            );
            let mut scale = ChartBuilder::on(&bar)
                .margin_top(top)
                .margin_bottom(bottom)
                .margin_left(8)
                .margin_right(22)
                .y_label_area_size(0)
                .right_y_label_area_size(BAR_WIDTH as i32 - 70)
                .build_cartesian_2d(0.0..1.0, lo..lo + span)
                .map_err(err)?
                .set_secondary_coord(0.0..1.0, lo..lo + span);
            let label = if self.log {
                format!("{} (log scale)", self.value_label)
            } else {
                self.value_label.to_string()
            };
            let value = |v: f64| if self.log { 10f64.powf(v) } else { v };
            scale
                .configure_secondary_axes()
                .y_desc(label)
                .y_label_formatter(&|v| {
                    if self.log {
                        tick(value(*v))
                    } else {
                        tick_within(snap(*v, span), span)
                    }
                })
                .label_style(("sans-serif", 14))
                .draw()
                .map_err(err)?;
            let bands = 100;
            scale
                .draw_series((0..bands).map(|k| {
                    let (a, b) = (k as f64 / bands as f64, (k + 1) as f64 / bands as f64);
                    Rectangle::new(
                        [(0.0, lo + a * span), (1.0, lo + b * span)],
                        viridis((a + b) / 2.0).filled(),
                    )
                }))
                .map_err(err)?;
            if self.style.marked.iter().any(|&m| m) {
                let (_, h) = bar.dim_in_pixel();
                let y = h as i32 - 24;
                bar.draw(
                    &(EmptyElement::at((14, y))
                        + PathElement::new(vec![(-4, -4), (4, 4)], RED.stroke_width(2))
                        + PathElement::new(vec![(-4, 4), (4, -4)], RED.stroke_width(2))),
                )
                .map_err(err)?;
                bar.draw(&Text::new(
                    self.style.mark_label.to_string(),
                    (24, y - 7),
                    ("sans-serif", 12),
                ))
                .map_err(err)?;
            }
            Ok(())
        }
    }
    let d = Heat {
        title,
        labels,
        xs,
        ys,
        values,
        value_label,
        style,
        log,
        xr,
        yr,
        lo,
        span,
    };
    let (png, svg) = both(stem, (700 + BAR_WIDTH, 600), &d)?;
    Ok(Figure { png, svg, csv })
}
