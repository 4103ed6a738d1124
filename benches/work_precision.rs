//! Work-precision: time per call against the error versus a 70-digit
//! reference, for fk and ik of four_bar, slider_crank, seed000_a and
//! seed000_b, of the generated code, the plan interpreter, and Newton at
//! tolerances 1e-6 … 1e-14.
//!
//! The reference and the points are those of `tests/testsuite/reference.rs`
//! (`tests/common/work_precision.rs`): 8 points per mechanism inside its
//! workspace, each solved on one branch. The error of a method is its worst
//! over the points of the joint values (angles in radians modulo 2π,
//! lengths relative to the model's scale) and, for fk, of the outputs. Its
//! time per call is criterion's median time to solve all the points,
//! divided by their number. Newton starts, as in `benches/solvers.rs`, from the
//! generated solution with the first input (or output) moved by 0.05.
//!
//! Writes `docs/work-precision.csv` and `docs/work-precision.png`:
//! `cargo bench --bench work_precision`.

#[path = "../tests/common/mod.rs"]
mod common;
#[path = "../tests/common/work_precision.rs"]
mod work_precision;

/// The mechanisms `work_precision` solves (the test suite declares them in
/// its own `mechanisms` module).
mod mechanisms {
    pkm::mechanism!(pub FourBar, file = "examples/mechanisms/four_bar.pkm");
    pkm::mechanism!(pub SliderCrank, file = "examples/mechanisms/slider_crank.pkm");
    pkm::mechanism!(pub SeedA, file = "examples/mechanisms/seed000_a.pkm");
    pkm::mechanism!(pub SeedB, file = "examples/mechanisms/seed000_b.pkm");
}

use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::Duration;

use criterion::{Criterion, SamplingMode};
use pkm::runtime::newton;
use pkm::runtime::reference::{max_error, output_values};
use plotters::prelude::*;
use work_precision::{cases, newton_options, signs, Case};

/// Newton's tolerances (scaled residual norm).
const TOLERANCES: [f64; 5] = [1e-6, 1e-8, 1e-10, 1e-12, 1e-14];

/// One measured method.
struct Row {
    mechanism: &'static str,
    direction: &'static str,
    method: &'static str,
    /// Newton's tolerance.
    tolerance: Option<f64>,
    /// Median time per call, ns.
    time_ns: f64,
    /// Worst joint-value error.
    joint_error: f64,
    /// Worst output error (fk only).
    output_error: Option<f64>,
    /// Points where the method returned no solution.
    failures: usize,
}

impl Row {
    fn error(&self) -> f64 {
        self.joint_error.max(self.output_error.unwrap_or(0.0))
    }
}

/// A method of one direction: solves point `k`, giving the joint values and
/// (for fk, where the method returns them) the outputs.
type Solve<'a> = Box<dyn Fn(usize) -> Option<(Vec<f64>, Option<Vec<f64>>)> + 'a>;

/// Criterion's median time (ns) of `group/id`, from the estimates it wrote:
/// the median rather than the mean, as other processes share the machine.
fn median_ns(dir: &Path, group: &str, id: &str) -> Option<f64> {
    let path = dir.join(group).join(id).join("new").join("estimates.json");
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(path).ok()?).ok()?;
    json["median"]["point_estimate"].as_f64()
}

/// Times `solve` over every point, measures its errors, and returns the row.
#[allow(clippy::too_many_arguments)]
fn measure(
    c: &mut Criterion,
    dir: &Path,
    case: &Case,
    fk: bool,
    method: &'static str,
    tolerance: Option<f64>,
    solve: Solve,
) -> Row {
    let n = case.points.len();
    let direction = if fk { "fk" } else { "ik" };
    let group_name = format!("{}_{direction}", case.name);
    let id = match tolerance {
        Some(t) => format!("{method}_{t:e}"),
        None => method.to_string(),
    };
    // Criterion keeps the last run's estimates: remove them, so that a
    // method a filter skips is seen as not timed rather than timed earlier.
    let _ = std::fs::remove_file(dir.join(&group_name).join(&id).join("new").join("estimates.json"));
    let mut group = c.benchmark_group(&group_name);
    group.sampling_mode(SamplingMode::Flat);
    group.bench_function(&id, |b| {
        b.iter(|| {
            for k in 0..n {
                black_box(solve(black_box(k)));
            }
        })
    });
    group.finish();
    let time_ns = median_ns(dir, &group_name, &id).map_or(f64::NAN, |t| t / n as f64);
    let (mut joint_error, mut output_error, mut failures) = (0.0f64, 0.0f64, 0);
    for (k, p) in case.points.iter().enumerate() {
        let Some((values, outputs)) = solve(k) else {
            failures += 1;
            continue;
        };
        let reference = if fk { &p.fk } else { &p.ik };
        joint_error = joint_error.max(max_error(&values, &reference.values, &case.value_angles, case.scale));
        if fk {
            // Methods that return joint values only: their outputs in f64 from them.
            let outputs = outputs.unwrap_or_else(|| output_values(&case.model, &case.outputs, &values).unwrap());
            output_error = output_error.max(max_error(&outputs, &p.fk_outputs, &case.output_angles, case.scale));
        }
    }
    Row {
        mechanism: case.name,
        direction,
        method,
        tolerance,
        time_ns,
        joint_error,
        output_error: fk.then_some(output_error),
        failures,
    }
}

/// Every method of one direction of one case.
fn measure_case(c: &mut Criterion, dir: &Path, case: &Case, fk: bool, rows: &mut Vec<Row>) {
    let n_values = case.model.value_offsets().1;
    let n_outputs = case.output_angles.len();
    let generated: Solve = if fk {
        Box::new(|k| {
            let (mut values, mut outputs) = (vec![0.0; n_values], vec![0.0; n_outputs]);
            (case.generated.fk)(&case.points[k].inputs, &mut values, &mut outputs).then_some((values, Some(outputs)))
        })
    } else {
        Box::new(|k| {
            let mut values = vec![0.0; n_values];
            let p = &case.points[k];
            (case.generated.ik)(&p.outputs, p.ik_signs, &mut values).then_some((values, None))
        })
    };
    rows.push(measure(c, dir, case, fk, "generated", None, generated));
    let fk_signs = signs(case.generated.fk_signs, case.branches[0]);
    let ik_signs: Vec<_> = case
        .points
        .iter()
        .map(|p| signs(p.ik_signs, case.branches[1]))
        .collect();
    let interpreter: Solve = if fk {
        Box::new(|k| {
            let v = case.interpreter[0].run(&case.model, &case.points[k].inputs, &fk_signs)?;
            Some((v, None))
        })
    } else {
        Box::new(|k| {
            let v = case.interpreter[1].run(&case.model, &case.points[k].outputs, &ik_signs[k])?;
            Some((v, None))
        })
    };
    rows.push(measure(c, dir, case, fk, "interpreter", None, interpreter));
    for tolerance in TOLERANCES {
        let options = newton_options(tolerance);
        let newton: Solve = if fk {
            Box::new(move |k| {
                let p = &case.points[k];
                let s = newton::solve_fk(&case.model, &p.inputs, &p.fk_guess, &options).ok()?;
                Some((s.values, None))
            })
        } else {
            Box::new(move |k| {
                let p = &case.points[k];
                let s = newton::solve_ik(&case.model, &case.outputs, &p.outputs, &p.ik_guess, &options).ok()?;
                Some((s.values, None))
            })
        };
        rows.push(measure(c, dir, case, fk, "newton", Some(tolerance), newton));
    }
}

fn write_csv(path: &Path, rows: &[Row]) -> Result<(), Box<dyn std::error::Error>> {
    let mut w = csv::Writer::from_path(path)?;
    w.write_record([
        "mechanism",
        "direction",
        "method",
        "tolerance",
        "time_per_call_ns",
        "joint_error",
        "output_error",
        "error",
        "failures",
    ])?;
    for r in rows {
        w.write_record([
            r.mechanism.to_string(),
            r.direction.to_string(),
            r.method.to_string(),
            r.tolerance.map_or(String::new(), |t| format!("{t:e}")),
            format!("{:.1}", r.time_ns),
            format!("{:.3e}", r.joint_error),
            r.output_error.map_or(String::new(), |e| format!("{e:.3e}")),
            format!("{:.3e}", r.error()),
            r.failures.to_string(),
        ])?;
    }
    w.flush()?;
    Ok(())
}

/// The font of the figure's text (DejaVu Sans, in `assets/fonts`).
const FONT: &[u8] = include_bytes!("../pkm-cli/assets/fonts/DejaVuSans.ttf");

/// The time axis's range, µs: the same in every panel, so panels compare.
const TIME_RANGE_US: (f64, f64) = (0.1, 1000.0);
/// The error axis's range.
const ERROR_RANGE: (f64, f64) = (1e-17, 1e-4);

/// Log-log panels, fk above ik, one column per mechanism: the generated
/// code and the interpreter as single markers, Newton as a line through its
/// tolerances (a label is left out where it would cover the one before).
fn plot(path: &Path, rows: &[Row], mechanisms: &[&'static str]) -> Result<(), Box<dyn std::error::Error>> {
    plotters::style::register_font("sans-serif", FontStyle::Normal, FONT).map_err(|_| "font")?;
    let root = BitMapBackend::new(path, (1800, 1000)).into_drawing_area();
    root.fill(&WHITE)?;
    let (title, body) = root.split_vertically(60);
    title.draw(&Text::new(
        "Work-precision: time per call against the worst error versus a 70-digit reference \
         (8 points per mechanism; lower left is better)",
        (20, 18),
        ("sans-serif", 24),
    ))?;
    let (panels, legend) = body.split_vertically(880);
    let panels = panels.split_evenly((2, mechanisms.len()));
    let fk_or_ik = ["fk", "ik"];
    let grey = RGBColor(150, 150, 150);
    for (i, area) in panels.iter().enumerate() {
        let (direction, mechanism) = (fk_or_ik[i / mechanisms.len()], mechanisms[i % mechanisms.len()]);
        let mine: Vec<&Row> = rows
            .iter()
            .filter(|r| r.mechanism == mechanism && r.direction == direction && r.time_ns.is_finite())
            .collect();
        let mut chart = ChartBuilder::on(area)
            .caption(format!("{mechanism} {direction}"), ("sans-serif", 24))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(60)
            .build_cartesian_2d(
                (ERROR_RANGE.0..ERROR_RANGE.1).log_scale(),
                (TIME_RANGE_US.0..TIME_RANGE_US.1).log_scale(),
            )?;
        chart
            .configure_mesh()
            .x_desc("worst error (rad, or length / scale)")
            .y_desc("time per call (µs)")
            .x_labels(7)
            .y_labels(5)
            .x_label_formatter(&|x| format!("{x:.0e}"))
            .y_label_formatter(&|y| format!("{y}"))
            .label_style(("sans-serif", 15))
            .axis_desc_style(("sans-serif", 16))
            .light_line_style(WHITE)
            .draw()?;
        // f64's machine epsilon: no f64 answer is reliably closer.
        let eps = f64::EPSILON;
        chart.draw_series(LineSeries::new(
            [(eps, TIME_RANGE_US.0), (eps, TIME_RANGE_US.1)],
            grey.stroke_width(1),
        ))?;
        chart.draw_series(std::iter::once(
            EmptyElement::at((eps, TIME_RANGE_US.1))
                + Text::new("f64 ε", (4, 4), ("sans-serif", 14).into_font().color(&grey)),
        ))?;
        let at = |r: &Row| (r.error().max(ERROR_RANGE.0), r.time_ns / 1000.0);
        let newton: Vec<&&Row> = mine.iter().filter(|r| r.method == "newton").collect();
        chart.draw_series(LineSeries::new(newton.iter().map(|r| at(r)), BLACK.stroke_width(2)))?;
        chart.draw_series(newton.iter().map(|r| Circle::new(at(r), 5, BLACK.filled())))?;
        let mut placed: Vec<(i32, i32)> = Vec::new();
        for r in &newton {
            let pixel = chart.backend_coord(&at(r));
            if placed
                .iter()
                .any(|p| (p.0 - pixel.0).abs() < 45 && (p.1 - pixel.1).abs() < 16)
            {
                continue;
            }
            placed.push(pixel);
            let label = format!("{:.0e}", r.tolerance.unwrap_or(0.0));
            chart.draw_series(std::iter::once(
                EmptyElement::at(at(r)) + Text::new(label, (7, -18), ("sans-serif", 14)),
            ))?;
        }
        for r in mine.iter().filter(|r| r.method == "interpreter") {
            chart.draw_series(std::iter::once(TriangleMarker::new(at(r), 10, BLUE.filled())))?;
        }
        for r in mine.iter().filter(|r| r.method == "generated") {
            chart.draw_series(std::iter::once(Circle::new(at(r), 9, RED.stroke_width(3))))?;
        }
    }
    let style = ("sans-serif", 20);
    legend.draw(&Circle::new((40, 30), 9, RED.stroke_width(3)))?;
    legend.draw(&Text::new("generated code (one branch)", (60, 19), style))?;
    legend.draw(&TriangleMarker::new((380, 30), 10, BLUE.filled()))?;
    legend.draw(&Text::new("plan interpreter (one branch)", (400, 19), style))?;
    legend.draw(&PathElement::new(vec![(720, 30), (760, 30)], BLACK.stroke_width(2)))?;
    legend.draw(&Circle::new((740, 30), 5, BLACK.filled()))?;
    legend.draw(&Text::new(
        "Newton, labelled with its tolerance (scaled residual); errors below 1e-17 drawn at 1e-17",
        (775, 19),
        style,
    ))?;
    root.present()?;
    Ok(())
}

/// Redraws the figure from the rows of a CSV written by [`write_csv`].
fn rows_from_csv(path: &Path) -> Result<Vec<Row>, Box<dyn std::error::Error>> {
    let mut rows = Vec::new();
    let leak = |s: &str| -> &'static str { Box::leak(s.to_string().into_boxed_str()) };
    for record in csv::Reader::from_path(path)?.records() {
        let r = record?;
        let number = |i: usize| r[i].parse::<f64>().ok();
        rows.push(Row {
            mechanism: leak(&r[0]),
            direction: leak(&r[1]),
            method: leak(&r[2]),
            tolerance: number(3),
            time_ns: number(4).unwrap_or(f64::NAN),
            joint_error: number(5).unwrap_or(f64::NAN),
            output_error: number(6),
            failures: r[8].parse()?,
        });
    }
    Ok(rows)
}

fn main() {
    let manifest = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let docs = manifest.join("docs");
    if std::env::var_os("WORK_PRECISION_REPLOT").is_some() {
        // Only redraw docs/work-precision.png from docs/work-precision.csv.
        let rows = rows_from_csv(&docs.join("work-precision.csv")).expect("read docs/work-precision.csv");
        let mut names: Vec<&'static str> = rows.iter().map(|r| r.mechanism).collect();
        names.dedup();
        plot(&docs.join("work-precision.png"), &rows, &names).expect("draw docs/work-precision.png");
        return;
    }
    let dir = manifest.join("target").join("work-precision");
    let mut c = Criterion::default()
        .output_directory(&dir)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(1))
        .sample_size(10)
        .configure_from_args();
    let cases = cases();
    let mut rows = Vec::new();
    for case in &cases {
        for fk in [true, false] {
            measure_case(&mut c, &dir, case, fk, &mut rows);
        }
    }
    c.final_summary();
    if rows.iter().any(|r| !r.time_ns.is_finite()) {
        // A filtered or test-mode run measured only some methods: keep the committed files.
        eprintln!("work_precision: some methods were not timed; docs/ left as it was");
        return;
    }
    write_csv(&docs.join("work-precision.csv"), &rows).expect("write docs/work-precision.csv");
    let names: Vec<&'static str> = cases.iter().map(|c| c.name).collect();
    plot(&docs.join("work-precision.png"), &rows, &names).expect("draw docs/work-precision.png");
    for r in &rows {
        println!(
            "{:<13} {} {:<11} {:>7} {:>12.1} ns  error {:.2e}  failures {}",
            r.mechanism,
            r.direction,
            r.method,
            r.tolerance.map_or(String::new(), |t| format!("{t:e}")),
            r.time_ns,
            r.error(),
            r.failures
        );
    }
}
