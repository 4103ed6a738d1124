//! Drawings of the mechanism itself: the links as lines between their joint
//! points (a filled polygon for a link with three or more), joints marked by
//! type, the base hatched, a P joint's guide and a parallelogram's two arms;
//! in the mechanism's plane (planar) or an axonometric view (spatial). The
//! same scene frames make an animated SVG (SMIL, no script, no network), and
//! the link–joint graph is drawn for files without geometry.

use crate::plots::{self, both, colour, err, frame, legend_strip, with_legend, Draw, Figure, Mark, PlotError};
use pkm_runtime::model::{JointType, Model, Place};
use pkm_runtime::plan::Pose3;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::fmt::Write as _;
use std::path::Path;

/// A joint label: its pixel, its place, the names drawn there.
type Label<'a> = ((i32, i32), (f64, f64), Vec<&'a str>);

/// One joint as drawn.
#[derive(Debug, Clone)]
pub struct JointMark {
    /// Its name.
    pub name: String,
    /// Its type.
    pub kind: JointType,
    /// Whether it is driven.
    pub actuated: bool,
    /// Whether it turns on the base (a revolute, spherical or parallelogram
    /// joint with the base as one link; a slider's base is its guide line).
    pub grounded: bool,
    /// Where it is (the moving side's point).
    pub at: [f64; 3],
}

/// A segment drawn besides the links.
#[derive(Debug, Clone, Copy)]
pub struct Segment {
    /// Its two ends.
    pub ends: ([f64; 3], [f64; 3]),
    /// The link whose colour it takes; `None`: a grey guide or arm.
    pub link: Option<usize>,
}

/// A configuration in world coordinates.
#[derive(Debug, Clone)]
pub struct Scene {
    /// Each moving link's joint points (the base's are not joined).
    pub links: Vec<Vec<[f64; 3]>>,
    /// Every joint.
    pub joints: Vec<JointMark>,
    /// Extra segments: P guides and parallelogram arms (grey), and the
    /// members a slide joins (a leg's cylinder to its piston), in their
    /// link's colour.
    pub segments: Vec<Segment>,
    /// The followed point.
    pub point: [f64; 3],
}

fn world(pose: &Pose3, p: [f64; 3]) -> [f64; 3] {
    let q = pose.transform_point(&p.into());
    [q.x, q.y, q.z]
}

fn direction(pose: &Pose3, v: [f64; 3]) -> [f64; 3] {
    let q = pose.transform_vector(&v.into());
    [q.x, q.y, q.z]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// The scene of `model` at link poses `poses`, following `point` (link, local).
pub fn scene(model: &Model, poses: &[Pose3], point: (usize, [f64; 3])) -> Scene {
    let mut links = vec![Vec::new(); model.links.len()];
    let mut joints = Vec::new();
    let mut segments = Vec::new();
    // The mechanism's size: guides are drawn this long either side.
    let mut size: f64 = 1e-9;
    for j in &model.joints {
        for side in 0..2 {
            links[j.links[side]].push(world(&poses[j.links[side]], j.places[side].at()));
        }
    }
    for l in &links {
        for a in l {
            for b in l {
                size = size.max(norm(sub(*a, *b)));
            }
        }
    }
    for j in &model.joints {
        let side = j.point_side();
        let at = world(&poses[j.links[side]], j.places[side].at());
        joints.push(JointMark {
            name: j.name.clone(),
            kind: j.kind,
            actuated: j.actuated,
            grounded: j.links.contains(&0) && j.kind != JointType::P,
            at,
        });
        for s in 0..2 {
            let pose = &poses[j.links[s]];
            match j.places[s] {
                Place::Line { through, along } => {
                    let (p, d) = (world(pose, through), direction(pose, along));
                    let k = 0.6 * size / norm(d).max(1e-12);
                    // The guide through the slider's point, along its direction.
                    let c = at;
                    segments.push(Segment {
                        ends: (
                            [c[0] - k * d[0], c[1] - k * d[1], c[2] - k * d[2]],
                            [c[0] + k * d[0], c[1] + k * d[1], c[2] + k * d[2]],
                        ),
                        link: None,
                    });
                    // A guide on a moving link (a leg's cylinder): the member
                    // from the guide's point to the slider's, in its colour.
                    if j.links[s] != 0 && norm(sub(p, c)) > 1e-9 * size {
                        segments.push(Segment {
                            ends: (p, c),
                            link: Some(j.links[s]),
                        });
                    }
                }
                Place::Arm { at: hinge, axis, .. } => {
                    let other = world(&poses[j.links[1 - s]], j.places[1 - s].at());
                    let a = world(pose, hinge);
                    let arm = norm(sub(other, a));
                    let d = direction(pose, axis);
                    let k = 0.15 * arm / norm(d).max(1e-12);
                    let shift = |p: [f64; 3]| [p[0] + k * d[0], p[1] + k * d[1], p[2] + k * d[2]];
                    // The parallelogram: both arms and both short sides.
                    for ends in [
                        (a, other),
                        (shift(a), shift(other)),
                        (a, shift(a)),
                        (other, shift(other)),
                    ] {
                        segments.push(Segment { ends, link: None });
                    }
                }
                _ => {}
            }
        }
    }
    links[0].clear();
    // Each link's points once.
    for l in &mut links {
        let mut unique: Vec<[f64; 3]> = Vec::new();
        for p in l.iter() {
            if !unique.iter().any(|q| norm(sub(*p, *q)) < 1e-9 * size.max(1.0)) {
                unique.push(*p);
            }
        }
        *l = unique;
    }
    Scene {
        links,
        joints,
        segments,
        point: world(&poses[point.0], point.1),
    }
}

/// How world points map to the drawing's plane.
#[derive(Debug, Clone, Copy)]
pub enum View {
    /// The xOy plane.
    Plane,
    /// An orthographic view from azimuth 35° (from −y towards +x) and elevation 25°.
    Axonometric,
}

impl View {
    /// The point's drawing coordinates.
    pub fn project(self, p: [f64; 3]) -> [f64; 2] {
        match self {
            View::Plane => [p[0], p[1]],
            View::Axonometric => {
                let (yaw, pitch) = (35f64.to_radians(), 25f64.to_radians());
                let right = [yaw.cos(), yaw.sin(), 0.0];
                let up = [-pitch.sin() * yaw.sin(), pitch.sin() * yaw.cos(), pitch.cos()];
                let dot = |a: [f64; 3]| a[0] * p[0] + a[1] * p[1] + a[2] * p[2];
                [dot(right), dot(up)]
            }
        }
    }

    fn labels(self, unit: &str) -> [String; 2] {
        match self {
            View::Plane => [format!("x ({unit})"), format!("y ({unit})")],
            View::Axonometric => [
                format!("across the view ({unit})"),
                format!("up the view, z tilted 25° ({unit})"),
            ],
        }
    }
}

/// A ring (R), a square (P), a disc (S) or a diamond (Pa), in the joint's colour.
fn marker<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    kind: JointType,
    at: (f64, f64),
    c: RGBAColor,
) -> Result<(), PlotError> {
    let fill = WHITE.filled();
    let stroke = c.stroke_width(2);
    let e = EmptyElement::at(at);
    match kind {
        JointType::R => chart
            .draw_series(std::iter::once(
                e + Circle::new((0, 0), 6, fill) + Circle::new((0, 0), 6, stroke),
            ))
            .map(|_| ()),
        JointType::P => chart
            .draw_series(std::iter::once(
                e + Rectangle::new([(-8, -6), (8, 6)], fill) + Rectangle::new([(-8, -6), (8, 6)], stroke),
            ))
            .map(|_| ()),
        JointType::S => chart
            .draw_series(std::iter::once(e + Circle::new((0, 0), 6, c.filled())))
            .map(|_| ()),
        JointType::Pa => chart
            .draw_series(std::iter::once(
                e + Polygon::new(vec![(0, -7), (7, 0), (0, 7), (-7, 0)], fill)
                    + PathElement::new(vec![(0, -7), (7, 0), (0, 7), (-7, 0), (0, -7)], stroke),
            ))
            .map(|_| ()),
    }
    .map_err(err)
}

fn kind_name(kind: JointType) -> &'static str {
    match kind {
        JointType::R => "R (revolute)",
        JointType::P => "P (prismatic)",
        JointType::S => "S (spherical)",
        JointType::Pa => "Pa (parallelogram)",
    }
}

/// The drawing's extent: every point of every scene, projected.
fn extent(scenes: &[Scene], view: View) -> ((f64, f64), (f64, f64)) {
    let pts: Vec<[f64; 2]> = scenes
        .iter()
        .flat_map(|s| {
            s.links
                .iter()
                .flatten()
                .chain(s.joints.iter().map(|j| &j.at))
                .chain(std::iter::once(&s.point))
                .map(move |p| view.project(*p))
        })
        .collect();
    let xr = plots::range(pts.iter().map(|p| p[0]));
    let yr = plots::range(pts.iter().map(|p| p[1]));
    // Room for the ground hatching below the lowest joint.
    let pad = 0.08 * (xr.1 - xr.0).max(yr.1 - yr.0);
    ((xr.0 - pad, xr.1 + pad), (yr.0 - pad, yr.1 + pad))
}

/// The part of the segment `a`–`b` inside the window `(x range, y range)`
/// (Liang–Barsky), if any: a line leaving the plot is cut at its edge, in
/// its own direction.
///
/// ```
/// use pkm_cli::drawing::clip;
/// let w = ((0.0, 10.0), (0.0, 10.0));
/// assert_eq!(clip((-10.0, 5.0), (20.0, 5.0), w), Some(((0.0, 5.0), (10.0, 5.0))));
/// // A diagonal keeps its direction: (−5, −5)–(15, 15) becomes (0, 0)–(10, 10).
/// assert_eq!(clip((-5.0, -5.0), (15.0, 15.0), w), Some(((0.0, 0.0), (10.0, 10.0))));
/// assert_eq!(clip((-5.0, 20.0), (15.0, 20.0), w), None);
/// ```
pub fn clip(a: (f64, f64), b: (f64, f64), window: ((f64, f64), (f64, f64))) -> Option<((f64, f64), (f64, f64))> {
    let ((x0, x1), (y0, y1)) = window;
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [(-dx, a.0 - x0), (dx, x1 - a.0), (-dy, a.1 - y0), (dy, y1 - a.1)] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    // NaN ends it too.
    if t0.partial_cmp(&t1).is_none_or(|o| o == std::cmp::Ordering::Greater) {
        return None;
    }
    let at = |t: f64| (a.0 + t * dx, a.1 + t * dy);
    Some((at(t0), at(t1)))
}

/// The world axes' directions in the view, at the plot's lower left: x, y
/// (and z in an axonometric view) as arrows 34 pixels long.
fn triad<DB: DrawingBackend>(chart: &mut Chart<'_, DB>, view: View) -> Result<(), PlotError> {
    let (xs, ys) = (chart.x_range(), chart.y_range());
    let corner = (xs.start, ys.start);
    let origin = (40, -40);
    for (k, name) in ["x", "y", "z"].iter().enumerate() {
        let mut e = [0.0; 3];
        e[k] = 1.0;
        let d = view.project(e);
        let length = d[0].hypot(d[1]);
        if length < 1e-6 {
            continue;
        }
        let tip = (
            origin.0 + (34.0 * d[0]).round() as i32,
            origin.1 - (34.0 * d[1]).round() as i32,
        );
        let label = (
            origin.0 + (44.0 * d[0] / length.max(0.5)).round() as i32 - 4,
            origin.1 - (44.0 * d[1] / length.max(0.5)).round() as i32 - 7,
        );
        chart
            .draw_series(std::iter::once(
                EmptyElement::at(corner)
                    + PathElement::new(vec![origin, tip], BLACK.stroke_width(2))
                    + Circle::new(tip, 2, BLACK.filled())
                    + Text::new(name.to_string(), label, ("sans-serif", 14)),
            ))
            .map_err(err)?;
    }
    Ok(())
}

/// The colour of guides and arms.
const GUIDE: RGBColor = RGBColor(150, 150, 150);

/// A chart in the mechanism's coordinates.
type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// The ground under a base joint at `at`: a bar `h` below it, hatched.
fn ground<DB: DrawingBackend>(chart: &mut Chart<'_, DB>, at: (f64, f64), h: f64) -> Result<(), PlotError> {
    let (x, y) = at;
    let y0 = y - 1.2 * h;
    chart
        .draw_series(LineSeries::new(
            vec![(x - 1.5 * h, y0), (x + 1.5 * h, y0)],
            BLACK.stroke_width(2),
        ))
        .map_err(err)?;
    chart
        .draw_series(LineSeries::new(vec![(x, y), (x, y0)], BLACK.stroke_width(1)))
        .map_err(err)?;
    for k in 0..6 {
        let xa = x - 1.5 * h + k as f64 * 0.6 * h;
        chart
            .draw_series(LineSeries::new(
                vec![(xa, y0), (xa - 0.6 * h, y0 - 0.7 * h)],
                BLACK.stroke_width(1),
            ))
            .map_err(err)?;
    }
    Ok(())
}

/// A link through its joints' points `at`: a line for two, a filled polygon
/// for three or more.
fn link<DB: DrawingBackend>(chart: &mut Chart<'_, DB>, c: RGBAColor, at: &[(f64, f64)]) -> Result<(), PlotError> {
    if at.len() >= 3 {
        chart
            .draw_series(std::iter::once(Polygon::new(at.to_vec(), c.mix(0.25).filled())))
            .map_err(err)?;
        let mut ring = at.to_vec();
        ring.push(ring[0]);
        chart
            .draw_series(LineSeries::new(ring, c.stroke_width(3)))
            .map_err(err)?;
    } else if at.len() == 2 {
        chart
            .draw_series(LineSeries::new(at.iter().copied(), c.stroke_width(4)))
            .map_err(err)?;
    }
    Ok(())
}

/// The drawing's legend: the joint types `kinds` by their marks, the driven
/// joints' colour, the followed point, guides and the base.
fn legend<DB: DrawingBackend>(
    side: &DrawingArea<DB, Shift>,
    kinds: &[JointType],
    point_name: &str,
) -> Result<(), PlotError> {
    let mut entries: Vec<(String, RGBAColor, Mark)> = kinds
        .iter()
        .map(|k| (kind_name(*k).to_string(), BLACK.to_rgba(), Mark::Dot))
        .collect();
    entries.push(("red: driven joint".into(), RGBColor(200, 0, 0).to_rgba(), Mark::Dot));
    entries.push((
        format!("{point_name}: followed point"),
        RGBColor(0, 150, 0).to_rgba(),
        Mark::Dot,
    ));
    entries.push(("grey: guide or arm".into(), GUIDE.to_rgba(), Mark::Line));
    entries.push(("hatched: base".into(), BLACK.to_rgba(), Mark::Line));
    legend_strip(side, &entries)?;
    // The legend's marks by type, over its dots.
    for (k, kind) in kinds.iter().enumerate() {
        let y = 50 + 24 * k as i32;
        draw_marker_px(side, *kind, (12, y))?;
    }
    Ok(())
}

/// The static drawing: PNG, SVG and a CSV of every joint's position.
pub fn draw(
    stem: &Path,
    title: &str,
    scene: &Scene,
    view: View,
    unit: &str,
    point_name: &str,
) -> Result<Figure, PlotError> {
    let csv = stem.with_extension("csv");
    let header = [
        "joint".to_string(),
        "type".to_string(),
        "driven".to_string(),
        format!("x ({unit})"),
        format!("y ({unit})"),
        format!("z ({unit})"),
    ];
    let header: Vec<&str> = header.iter().map(String::as_str).collect();
    plots::write_csv(
        &csv,
        &header,
        scene.joints.iter().map(|j| {
            vec![
                j.name.clone(),
                format!("{:?}", j.kind),
                j.actuated.to_string(),
                j.at[0].to_string(),
                j.at[1].to_string(),
                j.at[2].to_string(),
            ]
        }),
    )?;
    struct Drawing<'a> {
        title: &'a str,
        scene: &'a Scene,
        view: View,
        unit: &'a str,
        point_name: &'a str,
    }
    impl Draw for Drawing<'_> {
        fn on<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
            let s = self.scene;
            let v = self.view;
            let (xr, yr) = extent(std::slice::from_ref(s), v);
            let labels = v.labels(self.unit);
            let mut kinds: Vec<JointType> = Vec::new();
            for j in &s.joints {
                if !kinds.contains(&j.kind) {
                    kinds.push(j.kind);
                }
            }
            let (main, side) = with_legend(area, 1);
            let mut chart = frame(&main, self.title, [&labels[0], &labels[1]], xr, yr, true)?;
            let p = |a: [f64; 3]| {
                let q = v.project(a);
                (q[0], q[1])
            };
            // Guides leave the plot: clipped to it, never clamped (a clamped
            // end would turn the line).
            let (xs, ys) = (chart.x_range(), chart.y_range());
            let window = ((xs.start, xs.end), (ys.start, ys.end));
            for seg in &s.segments {
                let Some((a, b)) = clip(p(seg.ends.0), p(seg.ends.1), window) else {
                    continue;
                };
                let style = match seg.link {
                    Some(k) => colour(k).stroke_width(4),
                    None => GUIDE.stroke_width(2),
                };
                chart.draw_series(LineSeries::new(vec![a, b], style)).map_err(err)?;
            }
            // Ground: a bar under each base joint, hatched.
            let h = 0.025 * (xr.1 - xr.0).max(yr.1 - yr.0);
            for j in s.joints.iter().filter(|j| j.grounded) {
                ground(&mut chart, p(j.at), h)?;
            }
            for (k, l) in s.links.iter().enumerate().skip(1) {
                link(&mut chart, colour(k), &l.iter().map(|a| p(*a)).collect::<Vec<_>>())?;
            }
            for j in &s.joints {
                let c = if j.actuated {
                    RGBColor(200, 0, 0).to_rgba()
                } else {
                    BLACK.to_rgba()
                };
                marker(&mut chart, j.kind, p(j.at), c)?;
            }
            // Joints drawn within a few pixels of each other share one label.
            let mut labels: Vec<Label> = Vec::new();
            for j in &s.joints {
                let at = p(j.at);
                let px = chart.backend_coord(&at);
                match labels
                    .iter_mut()
                    .find(|(q, _, _)| (q.0 - px.0).abs() <= 6 && (q.1 - px.1).abs() <= 6)
                {
                    Some((_, _, names)) => names.push(&j.name),
                    None => labels.push((px, at, vec![&j.name])),
                }
            }
            for (_, at, names) in labels {
                chart
                    .draw_series(std::iter::once(
                        EmptyElement::at(at) + Text::new(names.join(", "), (8, -18), ("sans-serif", 13)),
                    ))
                    .map_err(err)?;
            }
            triad(&mut chart, v)?;
            chart
                .draw_series(std::iter::once(
                    EmptyElement::at(p(s.point))
                        + Circle::new((0, 0), 4, RGBColor(0, 150, 0).filled())
                        + Text::new(
                            self.point_name.to_string(),
                            (6, 4),
                            ("sans-serif", 14).into_font().color(&RGBColor(0, 120, 0)),
                        ),
                ))
                .map_err(err)?;
            if let Some(side) = side {
                legend(&side, &kinds, self.point_name)?;
            }
            Ok(())
        }
    }
    let d = Drawing {
        title,
        scene,
        view,
        unit,
        point_name,
    };
    let (png, svg) = both(stem, (1000, 700), &d)?;
    Ok(Figure { png, svg, csv })
}

fn draw_marker_px<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    kind: JointType,
    at: (i32, i32),
) -> Result<(), PlotError> {
    let e = EmptyElement::at(at);
    let fill = WHITE.filled();
    let stroke = BLACK.stroke_width(2);
    match kind {
        JointType::R => area.draw(&(e + Circle::new((0, 0), 6, fill) + Circle::new((0, 0), 6, stroke))),
        JointType::P => {
            area.draw(&(e + Rectangle::new([(-8, -6), (8, 6)], fill) + Rectangle::new([(-8, -6), (8, 6)], stroke)))
        }
        JointType::S => area.draw(&(e + Circle::new((0, 0), 6, BLACK.filled()))),
        JointType::Pa => area.draw(
            &(e + Polygon::new(vec![(0, -7), (7, 0), (0, 7), (-7, 0)], fill)
                + PathElement::new(vec![(0, -7), (7, 0), (0, 7), (-7, 0), (0, -7)], stroke)),
        ),
    }
    .map_err(err)
}

/// An animated SVG of `frames` (equal time steps over `duration` seconds,
/// repeated): the links, joints and followed point move; the point's path is
/// traced. Plain SVG with SMIL `<animate>`: it plays in a browser with no
/// script and no network.
pub fn animation(path: &Path, frames: &[Scene], view: View, duration: f64, point_name: &str) -> Result<(), PlotError> {
    let Some(first) = frames.first() else {
        return Err(PlotError("no frames to animate".into()));
    };
    let (xr, yr) = extent(frames, view);
    let title = "the animation";
    let (xr, yr) = (
        plots::checked_extent(title, "horizontal", xr)?,
        plots::checked_extent(title, "vertical", yr)?,
    );
    let (w, h) = (720.0, 540.0);
    let a = Animated {
        frames,
        first,
        view,
        w,
        h,
        scale: ((xr.1 - xr.0) / w).max((yr.1 - yr.0) / h),
        centre: ((xr.0 + xr.1) / 2.0, (yr.0 + yr.1) / 2.0),
        dur: format!("{duration:.3}s"),
    };
    let mut svg = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\" \
         font-family=\"sans-serif\" font-size=\"13\"><rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    );
    // The point's path, traced once.
    let trace: Vec<String> = frames
        .iter()
        .map(|s| {
            let (x, y) = a.px(s.point);
            format!("{x:.1},{y:.1}")
        })
        .collect();
    let _ = writeln!(
        svg,
        "<polyline points=\"{}\" fill=\"none\" stroke=\"#0a0\" stroke-dasharray=\"4 3\"/>",
        trace.join(" ")
    );
    a.segments(&mut svg);
    a.links(&mut svg);
    a.joints(&mut svg);
    let dur = &a.dur;
    let (x, y) = a.px(first.point);
    let _ = writeln!(
        svg,
        "<circle r=\"4\" cx=\"{x:.1}\" cy=\"{y:.1}\" fill=\"#0a0\">\
         <animate attributeName=\"cx\" values=\"{}\" dur=\"{dur}\" repeatCount=\"indefinite\"/>\
         <animate attributeName=\"cy\" values=\"{}\" dur=\"{dur}\" repeatCount=\"indefinite\"/></circle>\
         <text x=\"10\" y=\"20\">{} moving along the trajectory ({duration:.2} s, repeated); dashed: its path</text></svg>",
        a.values(&|s| format!("{:.1}", a.px(s.point).0)),
        a.values(&|s| format!("{:.1}", a.px(s.point).1)),
        point_name
    );
    std::fs::write(path, svg).map_err(|e| PlotError(format!("{}: {e}", path.display())))
}

/// An animation's frames and how they map onto its SVG's pixels.
struct Animated<'a> {
    frames: &'a [Scene],
    first: &'a Scene,
    view: View,
    /// The SVG's width and height in pixels.
    w: f64,
    h: f64,
    /// Units of length per pixel.
    scale: f64,
    /// The view's centre, in projected units.
    centre: (f64, f64),
    /// The animation's duration as SMIL writes it (`6.283s`).
    dur: String,
}

impl Animated<'_> {
    /// A point's place in pixels (y down).
    fn px(&self, a: [f64; 3]) -> (f64, f64) {
        let q = self.view.project(a);
        (
            self.w / 2.0 + (q[0] - self.centre.0) / self.scale,
            self.h / 2.0 - (q[1] - self.centre.1) / self.scale,
        )
    }

    /// One value per frame, `;`-separated (a SMIL `values` list).
    fn values(&self, f: &dyn Fn(&Scene) -> String) -> String {
        self.frames.iter().map(f).collect::<Vec<_>>().join(";")
    }

    /// The guides and arms, grey lines whose ends move, and the members
    /// slides join, in their links' colours. (The SVG's own viewport clips
    /// what leaves it.)
    fn segments(&self, svg: &mut String) {
        let (first, dur) = (self.first, &self.dur);
        for k in 0..first.segments.len() {
            let at = |s: &Scene, e: usize| {
                let (a, b) = s.segments.get(k).unwrap_or(&first.segments[k]).ends;
                self.px(if e == 0 { a } else { b })
            };
            let (a, b) = (at(first, 0), at(first, 1));
            let (stroke, width) = match first.segments[k].link {
                Some(l) => {
                    let c = colour(l);
                    (format!("rgb({},{},{})", c.0, c.1, c.2), 4)
                }
                None => ("#999".to_string(), 2),
            };
            let _ = write!(
                svg,
                "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"{stroke}\" stroke-width=\"{width}\">",
                a.0, a.1, b.0, b.1
            );
            for (attr, e, c) in [("x1", 0, 0), ("y1", 0, 1), ("x2", 1, 0), ("y2", 1, 1)] {
                let v = self.values(&|s| {
                    let p = at(s, e);
                    format!("{:.1}", if c == 0 { p.0 } else { p.1 })
                });
                let _ = write!(
                    svg,
                    "<animate attributeName=\"{attr}\" values=\"{v}\" dur=\"{dur}\" repeatCount=\"indefinite\"/>"
                );
            }
            svg.push_str("</line>\n");
        }
    }

    /// The links: paths through their joints (closed and filled for three
    /// or more) whose shape moves.
    fn links(&self, svg: &mut String) {
        let (first, dur) = (self.first, &self.dur);
        for (k, l) in first.links.iter().enumerate().skip(1) {
            if l.len() < 2 {
                continue;
            }
            let c = colour(k);
            let d = |s: &Scene| {
                let pts = s.links.get(k).unwrap_or(l);
                let mut d = String::new();
                for (i, p) in pts.iter().enumerate() {
                    let (x, y) = self.px(*p);
                    let _ = write!(d, "{}{x:.1} {y:.1} ", if i == 0 { "M" } else { "L" });
                }
                if pts.len() >= 3 {
                    d.push('Z');
                }
                d
            };
            let fill = if l.len() >= 3 {
                format!("rgba({},{},{},0.25)", c.0, c.1, c.2)
            } else {
                "none".into()
            };
            let _ = writeln!(
                svg,
                "<path d=\"{}\" fill=\"{fill}\" stroke=\"rgb({},{},{})\" stroke-width=\"4\" stroke-linejoin=\"round\">\
                 <animate attributeName=\"d\" values=\"{}\" dur=\"{dur}\" repeatCount=\"indefinite\"/></path>",
                d(first),
                c.0,
                c.1,
                c.2,
                self.values(&|s: &Scene| d(s))
            );
        }
    }

    /// The joints: their marks moving (driven ones red), the base ones over
    /// a fixed hatched bar.
    fn joints(&self, svg: &mut String) {
        let (first, dur) = (self.first, &self.dur);
        for (k, j) in first.joints.iter().enumerate() {
            let stroke = if j.actuated { "#c00" } else { "#000" };
            let (x, y) = self.px(j.at);
            if j.grounded {
                let _ = writeln!(
                    svg,
                    "<g stroke=\"#000\"><line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke-width=\"2\"/>{}</g>",
                    x - 14.0,
                    y + 12.0,
                    x + 14.0,
                    y + 12.0,
                    (0..5)
                        .map(|i| {
                            let xa = x - 14.0 + 7.0 * i as f64;
                            format!("<line x1=\"{xa:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\"/>", y + 12.0, xa - 6.0, y + 19.0)
                        })
                        .collect::<String>()
                );
            }
            let xs = self.values(&|s| format!("{:.1}", self.px(s.joints.get(k).map_or(j.at, |m| m.at)).0));
            let ys = self.values(&|s| format!("{:.1}", self.px(s.joints.get(k).map_or(j.at, |m| m.at)).1));
            let (shape, ax, ay, off) = match j.kind {
                JointType::P => ("rect width=\"16\" height=\"12\"", "x", "y", (-8.0, -6.0)),
                _ => ("circle r=\"6\"", "cx", "cy", (0.0, 0.0)),
            };
            let shift = |list: String, o: f64| {
                list.split(';')
                    .map(|v| format!("{:.1}", v.parse::<f64>().unwrap_or(0.0) + o))
                    .collect::<Vec<_>>()
                    .join(";")
            };
            let fill = if j.kind == JointType::S { stroke } else { "#fff" };
            let _ = writeln!(
                svg,
                "<{shape} {ax}=\"{:.1}\" {ay}=\"{:.1}\" fill=\"{fill}\" stroke=\"{stroke}\" stroke-width=\"2\">\
                 <animate attributeName=\"{ax}\" values=\"{}\" dur=\"{dur}\" repeatCount=\"indefinite\"/>\
                 <animate attributeName=\"{ay}\" values=\"{}\" dur=\"{dur}\" repeatCount=\"indefinite\"/></{}>",
                x + off.0,
                y + off.1,
                shift(xs, off.0),
                shift(ys, off.1),
                shape.split(' ').next().unwrap_or("circle")
            );
        }
    }
}

/// The link–joint graph: links as labelled nodes on a circle, joints as
/// edges labelled with name and type (driven ones red and thick).
pub fn graph(
    stem: &Path,
    title: &str,
    links: &[String],
    joints: &[(String, String, [usize; 2], bool)],
) -> Result<Figure, PlotError> {
    let csv = stem.with_extension("csv");
    plots::write_csv(
        &csv,
        &["joint", "type", "link a", "link b", "driven"],
        joints.iter().map(|(n, k, l, a)| {
            vec![
                n.clone(),
                k.clone(),
                links.get(l[0]).cloned().unwrap_or_default(),
                links.get(l[1]).cloned().unwrap_or_default(),
                a.to_string(),
            ]
        }),
    )?;
    struct Graph<'a> {
        title: &'a str,
        links: &'a [String],
        joints: &'a [(String, String, [usize; 2], bool)],
    }
    impl Draw for Graph<'_> {
        fn on<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
            let area = area.titled(self.title, ("sans-serif", 20)).map_err(err)?;
            let (w, h) = area.dim_in_pixel();
            let (cx, cy, r) = (w as f64 / 2.0, h as f64 / 2.0, 0.38 * w.min(h) as f64);
            let n = self.links.len().max(1);
            let at = |k: usize| {
                let a = std::f64::consts::FRAC_PI_2 - std::f64::consts::TAU * k as f64 / n as f64;
                ((cx + r * a.cos()) as i32, (cy - r * a.sin()) as i32)
            };
            // Several joints between one pair of links: their labels are spread.
            let mut seen: Vec<[usize; 2]> = Vec::new();
            for (name, kind, l, driven) in self.joints {
                let (a, b) = (at(l[0]), at(l[1]));
                let style = if *driven {
                    RGBColor(200, 0, 0).stroke_width(3)
                } else {
                    BLACK.stroke_width(1)
                };
                area.draw(&PathElement::new(vec![a, b], style)).map_err(err)?;
                let again = seen.iter().filter(|s| **s == *l).count() as i32;
                seen.push(*l);
                let mid = ((a.0 + b.0) / 2 + 4, (a.1 + b.1) / 2 - 8 + 16 * again);
                area.draw(&Text::new(
                    format!("{name} ({kind}{})", if *driven { "*" } else { "" }),
                    mid,
                    ("sans-serif", 13),
                ))
                .map_err(err)?;
            }
            for (k, name) in self.links.iter().enumerate() {
                let p = at(k);
                let fill = if k == 0 { RGBColor(220, 220, 220) } else { WHITE };
                area.draw(&Circle::new(p, 9, fill.filled())).map_err(err)?;
                area.draw(&Circle::new(p, 9, BLACK.stroke_width(2))).map_err(err)?;
                area.draw(&Text::new(name.clone(), (p.0 + 12, p.1 + 4), ("sans-serif", 14)))
                    .map_err(err)?;
            }
            Ok(())
        }
    }
    let d = Graph { title, links, joints };
    let (png, svg) = both(stem, (900, 760), &d)?;
    Ok(Figure { png, svg, csv })
}
