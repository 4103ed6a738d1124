//! Heat maps over a grid ([`heat_map`]), on the viridis scale with a
//! colour bar beside them, linear or logarithmic, nodes marked as asked
//! ([`HeatStyle`]).

use super::ticks::{snap, tick, tick_within};
use super::{both, checked_extent, err, viridis, write_csv, Draw, Figure, PlotError};
use super::{CAPTION, MARGIN, X_LABELS, Y_LABELS};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// The width of a heat map's colour bar strip, in pixels.
const BAR_WIDTH: u32 = 150;
/// The mark legend's line height, and the characters of 12-pixel sans
/// that fit its line (the strip less the cross: 126 px at ≤ 6.5 px each).
const LINE: i32 = 14;
const MARK_CHARS: usize = 19;

/// `text` in lines of at most `width` characters, broken between words
/// (a longer word keeps its own line).
fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    for word in text.split_whitespace() {
        match lines.last_mut() {
            Some(l) if l.chars().count() + 1 + word.chars().count() <= width => {
                l.push(' ');
                l.push_str(word);
            }
            _ => lines.push(word.to_string()),
        }
    }
    lines
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
    /// The values are counts: the colour bar is ticked at whole numbers
    /// only.
    pub counts: bool,
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
            // The colour bar: a column of 100 bands from the least value to
            // the greatest, the mark's legend under it in lines that fit
            // the strip.
            let mark_lines = wrap(self.style.mark_label, MARK_CHARS);
            let (top, bottom) = (
                CAPTION + MARGIN,
                X_LABELS
                    + MARGIN
                    + if self.style.marked.is_empty() {
                        0
                    } else {
                        16 + LINE * mark_lines.len() as i32
                    },
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
                    } else if self.style.counts {
                        // A count's ticks: the whole numbers alone.
                        if (v - v.round()).abs() <= 1e-9 * span.max(1.0) {
                            format!("{}", v.round())
                        } else {
                            String::new()
                        }
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
                let y = h as i32 - 10 - LINE * mark_lines.len() as i32;
                bar.draw(
                    &(EmptyElement::at((14, y))
                        + PathElement::new(vec![(-4, -4), (4, 4)], RED.stroke_width(2))
                        + PathElement::new(vec![(-4, 4), (4, -4)], RED.stroke_width(2))),
                )
                .map_err(err)?;
                for (k, line) in mark_lines.iter().enumerate() {
                    bar.draw(&Text::new(
                        line.clone(),
                        (24, y - 7 + LINE * k as i32),
                        ("sans-serif", 12),
                    ))
                    .map_err(err)?;
                }
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

#[cfg(test)]
mod tests {
    /// The mark legend broken between words to the strip's width.
    #[test]
    fn legend_lines_fit_the_strip() {
        assert_eq!(
            super::wrap("a root only possible (a fold)", super::MARK_CHARS),
            ["a root only", "possible (a fold)"]
        );
        assert_eq!(super::wrap("ill-conditioned", super::MARK_CHARS), ["ill-conditioned"]);
        assert_eq!(super::wrap("", 5), Vec::<String>::new());
    }
}
