//! Plots for the report: every figure as PNG and SVG (plotters) with
//! labelled axes and units, and its data as CSV beside it.

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// The font the PNGs draw text with (DejaVu Sans, in `assets/fonts`), so no
/// system font library is needed.
const FONT: &[u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");

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

fn err(e: impl std::fmt::Display) -> PlotError {
    PlotError(e.to_string())
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

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
    if !lo.is_finite() || !hi.is_finite() {
        return (-1.0, 1.0);
    }
    let pad = ((hi - lo) * 0.05).max(1e-9);
    (lo - pad, hi + pad)
}

/// A figure that can draw itself on any plotters back end.
trait Draw {
    fn on<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<(), PlotError>;
}

/// Draws on both back ends.
fn both(stem: &Path, size: (u32, u32), d: &impl Draw) -> Result<(PathBuf, PathBuf), PlotError> {
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

/// A chart with its caption, labelled axes and mesh drawn.
fn frame<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    title: &str,
    labels: [&str; 2],
    xr: (f64, f64),
    yr: (f64, f64),
) -> Result<ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>, PlotError> {
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)
        .map_err(|e| err(format!("{e:?}")))?;
    chart
        .configure_mesh()
        .x_desc(labels[0])
        .y_desc(labels[1])
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(|e| err(format!("{e:?}")))?;
    Ok(chart)
}

/// The series' legend, boxed.
fn legend<'a, DB: DrawingBackend + 'a>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
) -> Result<(), PlotError> {
    chart
        .configure_series_labels()
        .label_font(("sans-serif", 14))
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| err(format!("{e:?}")))
}

/// A scatter of 2-D point sets, one colour each, with axis labels (units
/// included in the labels).
///
/// ```
/// let stem = std::env::temp_dir().join("pkm-doc-scatter");
/// let f = pkm::plots::scatter(&stem, "Unit square", ["x (mm)", "y (mm)"], &[("corners".into(), vec![[0.0, 0.0], [1.0, 1.0]])]).unwrap();
/// assert!(std::fs::read_to_string(f.csv).unwrap().starts_with("set,x (mm),y (mm)"));
/// ```
pub fn scatter(
    stem: &Path,
    title: &str,
    labels: [&str; 2],
    sets: &[(String, Vec<[f64; 2]>)],
) -> Result<Figure, PlotError> {
    let all = || sets.iter().flat_map(|(_, v)| v.iter());
    let xr = range(all().map(|p| p[0]));
    let yr = range(all().map(|p| p[1]));
    let csv = stem.with_extension("csv");
    let mut text = format!("set,{},{}\n", labels[0], labels[1]);
    for (name, points) in sets {
        for p in points {
            text.push_str(&format!("{name},{},{}\n", p[0], p[1]));
        }
    }
    std::fs::write(&csv, text).map_err(err)?;
    struct Scatter<'a> {
        title: &'a str,
        labels: [&'a str; 2],
        sets: &'a [(String, Vec<[f64; 2]>)],
        xr: (f64, f64),
        yr: (f64, f64),
    }
    impl Draw for Scatter<'_> {
        fn on<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
            let mut chart = frame(area, self.title, self.labels, self.xr, self.yr)?;
            for (k, (name, points)) in self.sets.iter().enumerate() {
                let colour = Palette99::pick(k).to_rgba();
                chart
                    .draw_series(
                        points
                            .iter()
                            .map(|p| Circle::new((p[0], p[1]), 1, colour.mix(0.4).filled())),
                    )
                    .map_err(|e| err(format!("{e:?}")))?
                    .label(name.clone())
                    .legend(move |(x, y)| Circle::new((x + 8, y), 4, colour.filled()));
            }
            if self.sets.len() > 1 {
                legend(&mut chart)?;
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
    };
    let (png, svg) = both(stem, (800, 640), &d)?;
    Ok(Figure { png, svg, csv })
}

/// Curves over a shared abscissa: `series` are (name, values) with the same
/// length as `x`.
///
/// ```
/// let stem = std::env::temp_dir().join("pkm-doc-curves");
/// let t = [0.0, 0.5, 1.0];
/// let f = pkm::plots::curves(&stem, "Ramp", ["t (s)", "v (mm/s)"], &t, &[("v".into(), vec![0.0, 1.0, 2.0])]).unwrap();
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
    let mut text = labels[0].to_string();
    for (name, _) in series {
        text.push(',');
        text.push_str(name);
    }
    text.push('\n');
    for (i, t) in x.iter().enumerate() {
        text.push_str(&t.to_string());
        for (_, v) in series {
            text.push_str(&format!(",{}", v[i]));
        }
        text.push('\n');
    }
    std::fs::write(&csv, text).map_err(err)?;
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
            let mut chart = frame(area, self.title, self.labels, self.xr, self.yr)?;
            for (k, (name, v)) in self.series.iter().enumerate() {
                let colour = Palette99::pick(k).to_rgba();
                chart
                    .draw_series(LineSeries::new(
                        self.x.iter().zip(v).map(|(a, b)| (*a, *b)),
                        colour.stroke_width(2),
                    ))
                    .map_err(|e| err(format!("{e:?}")))?
                    .label(name.clone())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2)));
            }
            legend(&mut chart)?;
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
    let (png, svg) = both(stem, (800, 520), &d)?;
    Ok(Figure { png, svg, csv })
}
