//! Curves over a shared abscissa ([`curves`]), a gap where a value is not finite.

use super::LEGEND_WIDTH;
use super::{both, colour, err, frame, legend_strip, range, with_legend, write_csv, Draw, Figure, Mark, PlotError};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

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
