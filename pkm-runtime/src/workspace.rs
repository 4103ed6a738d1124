//! Workspace by sweeping the actuator ranges through a forward solution:
//! every node of a grid over the inputs, on all cores, keeping the points
//! a chosen platform point reaches; the volume by counting occupied voxels.

use std::collections::HashSet;

/// A regular grid over the actuators' ranges: `counts[i]` values from
/// `ranges[i].0` to `ranges[i].1`, both ends included.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    /// Each input's range.
    pub ranges: Vec<(f64, f64)>,
    /// Each input's number of values (at least 1; 1 takes the range's start).
    pub counts: Vec<usize>,
}

impl Grid {
    /// The number of nodes.
    pub fn len(&self) -> usize {
        self.counts.iter().product()
    }

    /// Whether the grid has no node.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The inputs at node `index` (the first input varies slowest).
    pub fn node(&self, mut index: usize, q: &mut [f64]) {
        for i in (0..self.counts.len()).rev() {
            let n = self.counts[i];
            let k = index % n;
            index /= n;
            let (lo, hi) = self.ranges[i];
            q[i] = if n > 1 {
                lo + (hi - lo) * k as f64 / (n - 1) as f64
            } else {
                lo
            };
        }
    }
}

/// One reachable sample: the inputs and the point reached.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample<const N: usize> {
    /// The actuators' values.
    pub q: [f64; N],
    /// The point.
    pub point: [f64; 3],
}

/// Every node of `grid` through `solve` (the point reached, or `None` where
/// the mechanism cannot assemble), split over the machine's cores. Samples
/// come back in node order.
///
/// # Example
/// A "mechanism" whose point is its inputs, reachable inside the unit disc:
/// ```
/// use pkm_runtime::workspace::{sweep, Grid};
/// let grid = Grid { ranges: vec![(-1.0, 1.0), (-1.0, 1.0)], counts: vec![21, 21] };
/// let samples = sweep::<2>(&grid, |q| (q[0].hypot(q[1]) <= 1.0).then_some([q[0], q[1], 0.0]));
/// assert_eq!(samples.len(), 317); // the nodes of a 0.1 grid inside the unit disc
/// ```
pub fn sweep<const N: usize>(grid: &Grid, solve: impl Fn(&[f64; N]) -> Option<[f64; 3]> + Sync) -> Vec<Sample<N>> {
    let mut q = [0.0; N];
    sweep_nodes(grid, solve)
        .into_iter()
        .enumerate()
        .filter_map(|(index, p)| {
            grid.node(index, &mut q);
            p.map(|point| Sample { q, point })
        })
        .collect()
}

/// As [`sweep`], one entry per node in node order (`None` where unreachable).
pub fn sweep_nodes<const N: usize>(
    grid: &Grid,
    solve: impl Fn(&[f64; N]) -> Option<[f64; 3]> + Sync,
) -> Vec<Option<[f64; 3]>> {
    let total = grid.len();
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(total.max(1));
    let chunk = total.div_ceil(threads.max(1));
    let solve = &solve;
    let parts: Vec<Vec<Option<[f64; 3]>>> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads)
            .map(|t| {
                s.spawn(move || {
                    let mut q = [0.0; N];
                    (t * chunk..((t + 1) * chunk).min(total))
                        .map(|index| {
                            grid.node(index, &mut q);
                            solve(&q)
                        })
                        .collect()
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap_or_default()).collect()
    });
    parts.concat()
}

/// The volume a three-input sweep's points fill, as the image of the input
/// grid: every grid cell whose eight corners are reachable is split into
/// six tetrahedra (along its main diagonal) and the volumes of their images
/// are summed. Exact for a map linear on each tetrahedron, so the error
/// falls as the square of the grid spacing; a map that folds over itself
/// counts the overlap twice.
pub fn image_volume(grid: &Grid, nodes: &[Option<[f64; 3]>]) -> f64 {
    let [n0, n1, n2] = match grid.counts[..] {
        [a, b, c] => [a, b, c],
        _ => return 0.0,
    };
    let at = |i: usize, j: usize, k: usize| nodes.get((i * n1 + j) * n2 + k).copied().flatten();
    // The six tetrahedra of a cube's Kuhn split: paths from corner 0 to 7.
    const PATHS: [[usize; 3]; 6] = [[1, 2, 4], [1, 4, 2], [2, 1, 4], [2, 4, 1], [4, 1, 2], [4, 2, 1]];
    let mut volume = 0.0;
    for i in 0..n0.saturating_sub(1) {
        for j in 0..n1.saturating_sub(1) {
            for k in 0..n2.saturating_sub(1) {
                let corner = |c: usize| at(i + (c >> 2 & 1), j + (c >> 1 & 1), k + (c & 1));
                let Some(corners) = (0..8).map(corner).collect::<Option<Vec<_>>>() else {
                    continue;
                };
                for path in PATHS {
                    let (a, b, c) = (path[0], path[0] | path[1], 7);
                    let o = corners[0];
                    let d = |p: [f64; 3]| [p[0] - o[0], p[1] - o[1], p[2] - o[2]];
                    let (u, v, w) = (d(corners[a]), d(corners[b]), d(corners[c]));
                    let det = u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
                        + u[2] * (v[0] * w[1] - v[1] * w[0]);
                    volume += det.abs() / 6.0;
                }
            }
        }
    }
    volume
}

/// The volume of a point cloud by occupied voxels: the number of cubes of
/// edge `h` (on a grid anchored at the origin) that hold a point, times h³.
/// It converges to the workspace's volume as the sweep gets denser and h
/// smaller (with h above the spacing of neighbouring points); compare two
/// values of h to see the resolution's effect.
pub fn voxel_volume<const N: usize>(samples: &[Sample<N>], h: f64) -> (f64, usize) {
    let cells: HashSet<[i64; 3]> = samples
        .iter()
        .map(|s| s.point.map(|x| (x / h).floor() as i64))
        .collect();
    (cells.len() as f64 * h * h * h, cells.len())
}

/// The bounding box of the points: minimum and maximum per axis.
pub fn bounds<const N: usize>(samples: &[Sample<N>]) -> Option<([f64; 3], [f64; 3])> {
    let first = samples.first()?.point;
    Some(samples.iter().fold((first, first), |(lo, hi), s| {
        (
            std::array::from_fn(|i| lo[i].min(s.point[i])),
            std::array::from_fn(|i| hi[i].max(s.point[i])),
        )
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_nodes_cover_the_ranges() {
        let g = Grid {
            ranges: vec![(0.0, 1.0), (10.0, 20.0)],
            counts: vec![2, 3],
        };
        let mut q = [0.0; 2];
        let nodes: Vec<[f64; 2]> = (0..g.len())
            .map(|i| {
                g.node(i, &mut q);
                q
            })
            .collect();
        assert_eq!(
            nodes,
            [
                [0.0, 10.0],
                [0.0, 15.0],
                [0.0, 20.0],
                [1.0, 10.0],
                [1.0, 15.0],
                [1.0, 20.0]
            ]
        );
    }

    #[test]
    fn image_volume_of_a_sheared_box_and_a_ball() {
        // A linear map: exact. The box [0,1]³ under (x + y, 2y, 3z + x): volume 6.
        let g = Grid {
            ranges: vec![(0.0, 1.0), (0.0, 1.0), (0.0, 1.0)],
            counts: vec![5, 5, 5],
        };
        let nodes = sweep_nodes::<3>(&g, |q| Some([q[0] + q[1], 2.0 * q[1], 3.0 * q[2] + q[0]]));
        assert!((image_volume(&g, &nodes) - 6.0).abs() < 1e-12);
        // Spherical coordinates onto the unit ball: 4π/3 to O(h²).
        let g = Grid {
            ranges: vec![
                (0.0, 1.0),
                (0.0, std::f64::consts::PI),
                (0.0, 2.0 * std::f64::consts::PI),
            ],
            counts: vec![41, 81, 161],
        };
        let nodes = sweep_nodes::<3>(&g, |q| {
            let (r, t, p) = (q[0], q[1], q[2]);
            Some([r * t.sin() * p.cos(), r * t.sin() * p.sin(), r * t.cos()])
        });
        let v = image_volume(&g, &nodes);
        // Chords cut the sphere: a relative error below 1e-3 at this spacing.
        assert!((v / (4.0 * std::f64::consts::PI / 3.0) - 1.0).abs() < 1e-3, "{v}");
    }

    #[test]
    fn voxel_volume_of_a_filled_cube() {
        // A cube of side 2 sampled every 0.05: voxels of 0.1 hold 8 points each.
        let g = Grid {
            ranges: vec![(0.0, 1.99), (0.0, 1.99), (0.0, 1.99)],
            counts: vec![40, 40, 40],
        };
        let s = sweep::<3>(&g, |q| Some(*q));
        let (v, n) = voxel_volume(&s, 0.1);
        assert_eq!(n, 20 * 20 * 20);
        assert!((v - 8.0).abs() < 1e-9);
        assert_eq!(bounds(&s).unwrap().1, [1.99; 3]);
    }
}
