//! Scatters of 2-D point sets ([`scatter`]): each place once ([`places`]),
//! a dense set drawn as its occupied cells ([`occupancy`]).

use super::{both, colour, err, frame, legend_strip, range, with_legend, write_csv, Draw, Figure, Mark, PlotError};
use super::{CSV_ROWS, DENSE, LEGEND_WIDTH};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Cells across a dense scatter's plot (its SVG holds at most this squared
/// rectangles per set).
const CELLS: usize = 120;

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
