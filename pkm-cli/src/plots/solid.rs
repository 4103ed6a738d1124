//! Solids in 3-D ([`solid3d`]): a cloud of points as its occupied cubic
//! cells ([`Voxels`]), their outer faces shaded, seen from two sides
//! by a camera (`Camera`).

use super::ticks::{nice_ticks, tick};
use super::{both, checked_extent, equalise, err, range, viridis, write_csv, Draw, Figure, PlotError};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

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
