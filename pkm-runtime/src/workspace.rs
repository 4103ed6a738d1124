//! Workspace by sweeping the actuator ranges through a forward solution:
//! every node of a grid over the inputs, on all cores, keeping the points
//! a chosen platform point reaches; the volume by counting occupied voxels.
//! A sweep may also follow one assembly by continuity ([`follow`]): at each
//! node the solution nearest the one continued from a neighbour, whichever
//! branch of the plan it is, as a trajectory follows it ([`Continuity`]).

use std::collections::{HashMap, HashSet};

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
            q[i] = self.value(i, k);
        }
    }

    /// Input `i`'s `k`-th value.
    pub fn value(&self, i: usize, k: usize) -> f64 {
        let (lo, hi) = self.ranges[i];
        let n = self.counts[i];
        if n > 1 {
            lo + (hi - lo) * k as f64 / (n - 1) as f64
        } else {
            lo
        }
    }
}

/// How many threads a sweep of `total` nodes takes: one per core, at most
/// one per node, at least one.
fn threads(total: usize) -> usize {
    std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(total.max(1))
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
    let threads = threads(total);
    let chunk = total.div_ceil(threads);
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

/// How two configurations of one mechanism are compared when an assembly
/// is followed by continuity: by their joint values, a revolute's (and a
/// ball's rotation components') difference wrapped to (−π, π], a slide's
/// divided by the mechanism's size, so that a turn of 1 rad and a slide of
/// the size weigh the same.
#[derive(Debug, Clone, PartialEq)]
pub struct Continuity {
    /// Per value (as [`crate::model::Model::value_offsets`]): whether it is an angle.
    pub angular: Vec<bool>,
    /// The length a slide's difference is divided by.
    pub size: f64,
}

impl Continuity {
    /// The comparison for `model`'s joint values (its size from
    /// [`crate::kinematics::model_scale`]).
    pub fn of(model: &crate::model::Model) -> Continuity {
        Continuity {
            angular: model
                .joints
                .iter()
                .flat_map(|j| std::iter::repeat_n(j.kind != crate::model::JointType::P, j.kind.dof()))
                .collect(),
            size: crate::kinematics::model_scale(model),
        }
    }

    /// Value `i`'s difference `a − b`, in the comparison's units.
    fn difference(&self, i: usize, a: f64, b: f64) -> f64 {
        if self.angular.get(i).copied().unwrap_or(false) {
            crate::solution::wrap_angle(a - b)
        } else {
            (a - b) / self.size
        }
    }

    /// The distance between two configurations.
    ///
    /// ```
    /// use pkm_runtime::workspace::Continuity;
    /// let c = Continuity { angular: vec![true, false], size: 100.0 };
    /// // 3.1 and −3.1 rad are 0.083 rad apart; 30 mm of a 100 mm mechanism is 0.3.
    /// let d = c.distance(&[3.1, 0.0], &[-3.1, 30.0]);
    /// assert!((d - (0.0832_f64.powi(2) + 0.09).sqrt()).abs() < 1e-4);
    /// ```
    pub fn distance(&self, a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .enumerate()
            .map(|(i, (x, y))| self.difference(i, *x, *y))
            .fold(0.0, |acc, d| d.mul_add(d, acc))
            .sqrt()
    }

    /// Where a followed configuration goes next: one more step of the last
    /// one, `last + (last − before)` (angles' steps wrapped), or `last`
    /// when there is no step before it. Where two branches cross (a dyad
    /// through its double root) both are as near the last configuration,
    /// and the one that goes on smoothly is the one nearest this. A last
    /// step longer than [`LONGEST_STEP`] is not one of a smooth motion (a
    /// jump through a degenerate configuration, where the plan picks one of
    /// a continuum) and is not extrapolated: the prediction is `last`.
    pub fn predict(&self, last: &[f64], before: Option<&[f64]>) -> Vec<f64> {
        match before.filter(|b| self.distance(last, b) <= LONGEST_STEP) {
            Some(b) => last
                .iter()
                .zip(b)
                .enumerate()
                .map(|(i, (x, y))| {
                    x + if self.angular.get(i).copied().unwrap_or(false) {
                        crate::solution::wrap_angle(x - y)
                    } else {
                        x - y
                    }
                })
                .collect(),
            None => last.to_vec(),
        }
    }

    /// The candidate nearest `predicted` (the first of equals), if any.
    pub fn nearest<'a, B>(&self, candidates: &'a [(B, Vec<f64>)], predicted: &[f64]) -> Option<&'a (B, Vec<f64>)> {
        candidates.iter().min_by(|x, y| {
            self.distance(&x.1, predicted)
                .total_cmp(&self.distance(&y.1, predicted))
        })
    }
}

/// The longest step ([`Continuity::distance`]: half a radian, or half the
/// mechanism's size) that [`Continuity::predict`] extrapolates.
pub const LONGEST_STEP: f64 = 0.5;

/// One node of a followed sweep ([`follow`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Followed<T> {
    /// The branch (its index in the plan's order) the followed assembly is on here.
    pub branch: usize,
    /// The neighbouring node it was continued from (`None` at the start).
    pub from: Option<usize>,
    /// What the caller kept of it.
    pub kept: T,
}

/// How near the prediction, as a fraction of the last step, the branch a
/// followed sweep continues from must be for [`follow`] not to solve the
/// others.
pub const FOLLOW_TOLERANCE: f64 = 0.1;

/// `f` over `items` on the machine's cores, in order.
fn on_all_cores<I: Sync, O: Send>(items: &[I], f: impl Fn(&I) -> O + Sync) -> Vec<O> {
    let threads = if items.len() < 64 { 1 } else { threads(items.len()) };
    if threads == 1 {
        return items.iter().map(f).collect();
    }
    let chunk = items.len().div_ceil(threads);
    let f = &f;
    std::thread::scope(|s| {
        let handles: Vec<_> = items
            .chunks(chunk)
            .map(|part| s.spawn(move || part.iter().map(f).collect::<Vec<O>>()))
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().unwrap_or_else(|p| std::panic::resume_unwind(p)))
            .collect()
    })
}

/// A sweep that follows one assembly by continuity, as a trajectory does:
/// from node `start` (where the solution nearest `seed` is taken) outwards,
/// breadth first over the grid's neighbours (one step along one input),
/// each node takes the solution nearest the configuration continued from
/// the neighbour it was reached from ([`Continuity::predict`] along that
/// direction), whichever of the `branches` it is. `solve` gives a branch's
/// solution at a node's inputs (its joint values), `keep` what is kept of
/// the chosen one. A node the followed assembly cannot reach (no branch
/// solves there, or reached only across such nodes) is `None`. Each
/// breadth-first level is solved on all cores.
///
/// The branch of the node it is continued from is solved first, and kept
/// when its solution is within a tenth of the last step of the prediction
/// ([`FOLLOW_TOLERANCE`]). Else (the start's neighbours, where there is no
/// last step, and near a crossing, where the followed root leaves the
/// prediction by a fraction of a step) the nearest of it and the branches
/// one choice away is taken: where two roots of a step meet they swap by
/// that step's choice. A node where none of them solves is not reached.
/// Only the start node solves every branch.
///
/// # Example
/// Two roots `±|q|` that swap at `q = 0`: branch 0 is `+|q|`, branch 1
/// `−|q|`. The assembly `x = q` followed from `q = −1` (branch 1) is
/// branch 0 past the crossing, where a fixed branch index would turn back.
/// ```
/// use pkm_runtime::workspace::{follow, Continuity, Grid};
/// let grid = Grid { ranges: vec![(-1.0, 1.0)], counts: vec![21] };
/// let c = Continuity { angular: vec![false], size: 1.0 };
/// let root = |q: &[f64], b: usize| Some(vec![if b == 0 { q[0].abs() } else { -q[0].abs() }]);
/// let followed = follow(&grid, 0, &[-1.0], &c, 2, root, |_, v| v[0]);
/// for (k, node) in followed.iter().enumerate() {
///     let node = node.as_ref().unwrap();
///     let q = grid.value(0, k);
///     assert!((node.kept - q).abs() < 1e-12);
///     // At the crossing both roots are 0: either branch is the assembly.
///     if q.abs() > 1e-12 {
///         assert_eq!(node.branch, if q > 0.0 { 0 } else { 1 });
///     }
/// }
/// ```
pub fn follow<T: Send>(
    grid: &Grid,
    start: usize,
    seed: &[f64],
    continuity: &Continuity,
    branches: usize,
    solve: impl Fn(&[f64], usize) -> Option<Vec<f64>> + Sync,
    keep: impl Fn(&[f64], &[f64]) -> T + Sync,
) -> Vec<Option<Followed<T>>> {
    let total = grid.len();
    let mut out: Vec<Option<Followed<T>>> = (0..total).map(|_| None).collect();
    if start >= total {
        return out;
    }
    let n = grid.counts.len();
    let strides: Vec<usize> = (0..n).map(|i| grid.counts[i + 1..].iter().product()).collect();
    let digit = |index: usize, i: usize| index / strides[i] % grid.counts[i];
    // One node to solve: it, the node it is continued from, and the node
    // one step before that along the same direction, if the grid has it.
    struct Next {
        node: usize,
        from: Option<usize>,
        before: Option<usize>,
    }
    // The branch and configuration chosen at each node of the last two levels.
    type Level = HashMap<usize, (usize, Vec<f64>)>;
    let mut seen = vec![false; total];
    seen[start] = true;
    let mut level = vec![Next {
        node: start,
        from: None,
        before: None,
    }];
    let mut last: Level = HashMap::new();
    let mut earlier: Level = HashMap::new();
    while !level.is_empty() {
        let solved = on_all_cores(&level, |next| {
            let mut q = vec![0.0; n];
            grid.node(next.node, &mut q);
            let from = next.from.and_then(|f| last.get(&f));
            let predicted = match from {
                Some((_, v)) => {
                    continuity.predict(v, next.before.and_then(|b| earlier.get(&b)).map(|(_, v)| v.as_slice()))
                }
                None => seed.to_vec(),
            };
            let every = |bs: &mut dyn Iterator<Item = usize>| -> Vec<(usize, Vec<f64>)> {
                bs.filter_map(|b| solve(&q, b).map(|v| (b, v))).collect()
            };
            let all = match from {
                Some((branch, v)) => {
                    let own = solve(&q, *branch);
                    let step = continuity.distance(v, &predicted);
                    match own {
                        // The branch continued from, alone, when it goes on as predicted.
                        Some(own) if continuity.distance(&own, &predicted) <= FOLLOW_TOLERANCE * step => {
                            let kept = keep(&q, &own);
                            return Some((*branch, own, kept));
                        }
                        // Else it and the branches one choice away.
                        own => {
                            let mut near =
                                every(&mut (0..usize::BITS).map(|k| branch ^ (1 << k)).filter(|&b| b < branches));
                            near.extend(own.map(|own| (*branch, own)));
                            near
                        }
                    }
                }
                None => every(&mut (0..branches)),
            };
            let (branch, values) = continuity.nearest(&all, &predicted)?;
            let kept = keep(&q, values);
            Some((*branch, values.clone(), kept))
        });
        earlier = std::mem::take(&mut last);
        let mut following = Vec::new();
        for (next, solved) in level.iter().zip(solved) {
            let Some((branch, values, kept)) = solved else {
                continue;
            };
            let node = next.node;
            out[node] = Some(Followed {
                branch,
                from: next.from,
                kept,
            });
            last.insert(node, (branch, values));
            for (i, (&stride, &count)) in strides.iter().zip(&grid.counts).enumerate().take(n) {
                let d = digit(node, i);
                // One step down along input i, then one step up.
                for (to, back) in [
                    (d > 0).then(|| (node - stride, (d + 1 < count).then(|| node + stride))),
                    (d + 1 < count).then(|| (node + stride, (d > 0).then(|| node - stride))),
                ]
                .into_iter()
                .flatten()
                {
                    if !seen[to] {
                        seen[to] = true;
                        following.push(Next {
                            node: to,
                            from: Some(node),
                            before: back,
                        });
                    }
                }
            }
        }
        level = following;
    }
    out
}

/// What a batch sweep's solver fills: the lanes' given values (one slice
/// per input), the point's x, y and z, and whether each lane is reachable.
pub type Lanes<'a, const N: usize> = ([&'a [f64]; N], [&'a mut [f64]; 3], &'a mut [bool]);

/// A batch sweep's points, structure of arrays in node order: `ok[i]`
/// says whether node i is reachable; its point is `(x[i], y[i], z[i])`
/// (zeros where it is not).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Points {
    /// x of each node's point.
    pub x: Vec<f64>,
    /// y of each node's point.
    pub y: Vec<f64>,
    /// z of each node's point.
    pub z: Vec<f64>,
    /// Whether each node is reachable.
    pub ok: Vec<bool>,
}

impl Points {
    /// As [`sweep_nodes`] returns them: one entry per node, `None` where
    /// unreachable.
    pub fn nodes(&self) -> Vec<Option<[f64; 3]>> {
        (0..self.ok.len())
            .map(|i| self.ok[i].then(|| [self.x[i], self.y[i], self.z[i]]))
            .collect()
    }
}

/// Why a batch sweep stopped.
#[derive(Debug, Clone, PartialEq)]
pub enum SweepError<E> {
    /// The grid does not have one range per input of the solver.
    Dimensions {
        /// The grid's number of ranges.
        grid: usize,
        /// The solver's number of inputs.
        inputs: usize,
    },
    /// The solver refused a chunk (its slices, not a lane: lanes that
    /// cannot be solved are `ok = false`).
    Solver(E),
}

impl<E: std::fmt::Display> std::fmt::Display for SweepError<E> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SweepError::Dimensions { grid, inputs } => {
                write!(f, "the grid has {grid} ranges for a solver of {inputs} inputs")
            }
            SweepError::Solver(e) => write!(f, "the batch solver failed: {e}"),
        }
    }
}

impl<E: std::fmt::Debug + std::fmt::Display> std::error::Error for SweepError<E> {}

/// How many nodes a batch sweep hands its solver at once: the input
/// buffers (8 KiB per input) stay in the first-level cache.
pub const SWEEP_CHUNK: usize = 1024;

/// Every node of `grid` through a batch solver, on all cores: each thread
/// takes a contiguous share of the nodes, fills structure-of-arrays input
/// buffers [`SWEEP_CHUNK`] nodes at a time and has `solve` write the
/// point and the reachable flag of each straight into the result (a
/// generated `fk_point_batch` fits: see benches/workspace.rs). The same
/// nodes, with the same values, as [`sweep_nodes`].
///
/// # Example
/// The unit disc again, eight lanes at a time or not:
/// ```
/// use pkm_runtime::workspace::{sweep_batch, Grid, Lanes};
/// let grid = Grid { ranges: vec![(-1.0, 1.0), (-1.0, 1.0)], counts: vec![21, 21] };
/// let points = sweep_batch::<2, ()>(&grid, |(given, [x, y, z], ok): Lanes<2>| {
///     for i in 0..ok.len() {
///         let (u, v) = (given[0][i], given[1][i]);
///         ok[i] = u.hypot(v) <= 1.0;
///         (x[i], y[i], z[i]) = if ok[i] { (u, v, 0.0) } else { (0.0, 0.0, 0.0) };
///     }
///     Ok(())
/// })
/// .unwrap();
/// assert_eq!(points.ok.iter().filter(|&&ok| ok).count(), 317);
/// ```
pub fn sweep_batch<const N: usize, E: Send>(
    grid: &Grid,
    solve: impl Fn(Lanes<N>) -> Result<(), E> + Sync,
) -> Result<Points, SweepError<E>> {
    if grid.counts.len() != N || grid.ranges.len() != N {
        return Err(SweepError::Dimensions {
            grid: grid.counts.len().max(grid.ranges.len()),
            inputs: N,
        });
    }
    let total = grid.len();
    // Each input's values.
    let values: Vec<Vec<f64>> = (0..N)
        .map(|a| (0..grid.counts[a]).map(|k| grid.value(a, k)).collect())
        .collect();
    let mut points = Points {
        x: vec![0.0; total],
        y: vec![0.0; total],
        z: vec![0.0; total],
        ok: vec![false; total],
    };
    if total == 0 {
        return Ok(points);
    }
    let threads = threads(total);
    // Whole chunks per thread, so that only the last chunk is short.
    let share = total.div_ceil(threads).div_ceil(SWEEP_CHUNK) * SWEEP_CHUNK;
    let (solve, values) = (&solve, &values);
    let Points { x, y, z, ok } = &mut points;
    let results: Vec<Result<(), E>> = std::thread::scope(|s| {
        let handles: Vec<_> = x
            .chunks_mut(share)
            .zip(y.chunks_mut(share))
            .zip(z.chunks_mut(share))
            .zip(ok.chunks_mut(share))
            .enumerate()
            .map(|(t, (((x, y), z), ok))| {
                s.spawn(move || {
                    let mut buffers = [[0.0; SWEEP_CHUNK]; N];
                    let chunks = x
                        .chunks_mut(SWEEP_CHUNK)
                        .zip(y.chunks_mut(SWEEP_CHUNK))
                        .zip(z.chunks_mut(SWEEP_CHUNK))
                        .zip(ok.chunks_mut(SWEEP_CHUNK));
                    for (c, (((x, y), z), ok)) in chunks.enumerate() {
                        let start = t * share + c * SWEEP_CHUNK;
                        let lanes = ok.len();
                        fill(grid, values, start, lanes, &mut buffers);
                        let given: [&[f64]; N] = std::array::from_fn(|a| &buffers[a][..lanes]);
                        solve((given, [x, y, z], ok))?;
                    }
                    Ok(())
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|p| std::panic::resume_unwind(p)))
            .collect()
    });
    for r in results {
        r.map_err(SweepError::Solver)?;
    }
    Ok(points)
}

/// The inputs of nodes `start..start + lanes` into `buffers[input]`: runs of
/// the last input (the fastest) copied from its values, the others held.
fn fill<const N: usize>(
    grid: &Grid,
    values: &[Vec<f64>],
    start: usize,
    lanes: usize,
    buffers: &mut [[f64; SWEEP_CHUNK]; N],
) {
    let mut digit = [0usize; N];
    let mut index = start;
    for a in (0..N).rev() {
        digit[a] = index % grid.counts[a];
        index /= grid.counts[a];
    }
    let last = N - 1;
    let mut j = 0;
    while j < lanes {
        let run = (grid.counts[last] - digit[last]).min(lanes - j);
        buffers[last][j..j + run].copy_from_slice(&values[last][digit[last]..digit[last] + run]);
        for a in 0..last {
            buffers[a][j..j + run].fill(values[a][digit[a]]);
        }
        j += run;
        digit[last] += run;
        // Carry into the slower inputs.
        let mut a = last;
        while a > 0 && digit[a] == grid.counts[a] {
            digit[a] = 0;
            a -= 1;
            digit[a] += 1;
        }
    }
}

/// The area a two-input sweep's points cover, as the image of the input
/// grid: every grid cell whose four corners are reachable is split into two
/// triangles (along its diagonal) and the areas of their images, in space,
/// are summed: a curved surface's area (a spherical mechanism's pointing
/// point), which a projection onto a plane would shrink. Exact for a map
/// linear on each triangle, so the error falls as the square of the grid
/// spacing; a map that folds over itself counts the overlap twice.
pub fn image_area(grid: &Grid, nodes: &[Option<[f64; 3]>]) -> f64 {
    let [n0, n1] = match grid.counts[..] {
        [a, b] => [a, b],
        _ => return 0.0,
    };
    let at = |i: usize, j: usize| nodes.get(i * n1 + j).copied().flatten();
    let half_cross = |o: [f64; 3], a: [f64; 3], b: [f64; 3]| {
        let (u, v) = (
            [a[0] - o[0], a[1] - o[1], a[2] - o[2]],
            [b[0] - o[0], b[1] - o[1], b[2] - o[2]],
        );
        let c = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt() / 2.0
    };
    let mut area = 0.0;
    for i in 0..n0.saturating_sub(1) {
        for j in 0..n1.saturating_sub(1) {
            if let (Some(a), Some(b), Some(c), Some(d)) = (at(i, j), at(i + 1, j), at(i, j + 1), at(i + 1, j + 1)) {
                area += half_cross(a, b, d) + half_cross(a, d, c);
            }
        }
    }
    area
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
    fn image_area_of_a_sheared_square_and_a_sphere() {
        // A linear map: exact. The square [0,1]² under (x + y, 2y, 3x): the
        // parallelogram spanned by (1, 0, 3) and (1, 2, 0), |(−6, 3, 2)| = 7.
        let g = Grid {
            ranges: vec![(0.0, 1.0), (0.0, 1.0)],
            counts: vec![5, 7],
        };
        let nodes = sweep_nodes::<2>(&g, |q| Some([q[0] + q[1], 2.0 * q[1], 3.0 * q[0]]));
        assert!((image_area(&g, &nodes) - 7.0).abs() < 1e-12);
        // Spherical coordinates onto the unit sphere: 4π to O(h²); a
        // quarter of the nodes unreachable (φ > 3π/2) leaves 3π.
        let g = Grid {
            ranges: vec![(0.0, std::f64::consts::PI), (0.0, 2.0 * std::f64::consts::PI)],
            counts: vec![181, 361],
        };
        let sphere = |t: f64, p: f64| [t.sin() * p.cos(), t.sin() * p.sin(), t.cos()];
        let nodes = sweep_nodes::<2>(&g, |q| Some(sphere(q[0], q[1])));
        let a = image_area(&g, &nodes);
        assert!((a / (4.0 * std::f64::consts::PI) - 1.0).abs() < 1e-4, "{a}");
        let nodes = sweep_nodes::<2>(&g, |q| {
            (q[1] <= 1.5 * std::f64::consts::PI + 1e-9).then(|| sphere(q[0], q[1]))
        });
        let a = image_area(&g, &nodes);
        assert!((a / (3.0 * std::f64::consts::PI) - 1.0).abs() < 1e-4, "{a}");
        // Not a two-input grid: no area.
        assert_eq!(
            image_area(
                &Grid {
                    ranges: vec![(0.0, 1.0)],
                    counts: vec![3]
                },
                &[None; 3]
            ),
            0.0
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
    fn batch_sweep_visits_the_nodes_of_sweep_nodes() {
        // Chunks that end inside a run of the last input (7 does not divide
        // 1024), a short last chunk, a single-value input.
        let g = Grid {
            ranges: vec![(-1.0, 2.0), (0.0, 5.0), (3.0, 3.5), (-0.25, 0.25)],
            counts: vec![13, 1, 23, 7],
        };
        // Reachable where the second coordinate's node is even: a pattern of
        // the values, so a misplaced value shows.
        let point = |q: [f64; 4]| {
            let reachable = ((q[2] - 3.0) / 0.5 * 22.0).round() as i64 % 2 == 0;
            reachable.then_some([q[0] + q[1], q[2] * q[3], q[3] - q[0]])
        };
        let expected = sweep_nodes::<4>(&g, |q| point(*q));
        let got = sweep_batch::<4, ()>(&g, |(given, [x, y, z], ok): Lanes<4>| {
            for i in 0..ok.len() {
                let p = point([given[0][i], given[1][i], given[2][i], given[3][i]]);
                ok[i] = p.is_some();
                [x[i], y[i], z[i]] = p.unwrap_or_default();
            }
            Ok(())
        })
        .unwrap();
        assert_eq!(got.ok.len(), 13 * 23 * 7);
        assert!(got.ok.iter().any(|&o| o) && got.ok.iter().any(|&o| !o));
        assert_eq!(got.nodes(), expected);
    }

    #[test]
    fn batch_sweep_errors() {
        let g = Grid {
            ranges: vec![(0.0, 1.0), (0.0, 1.0)],
            counts: vec![3000, 2],
        };
        let e = sweep_batch::<3, &str>(&g, |_| Ok(())).unwrap_err();
        assert_eq!(e, SweepError::Dimensions { grid: 2, inputs: 3 });
        assert_eq!(e.to_string(), "the grid has 2 ranges for a solver of 3 inputs");
        // The solver's own error comes back.
        let e = sweep_batch::<2, &str>(&g, |_| Err("lengths")).unwrap_err();
        assert_eq!(e, SweepError::Solver("lengths"));
        // An empty grid: no call, no point.
        let empty = Grid {
            ranges: vec![(0.0, 1.0)],
            counts: vec![0],
        };
        assert_eq!(sweep_batch::<1, ()>(&empty, |_| Err(())), Ok(Points::default()));
    }

    #[test]
    fn follow_goes_round_an_unreachable_patch_and_through_a_crossing() {
        // Roots ±|q0| (branches 0 and 1), unreachable where |q0| < 0.3 and
        // q1 < 0.5; an island q0 > 0.8, q1 < −0.8 walled off by unreachable
        // nodes. The assembly x = q0 from (−1, −1) crosses at q0 = 0 above
        // the patch and comes down on the far side still x = q0: branch 0,
        // where a fixed branch 1 gives −q0. The island is not reached.
        let grid = Grid {
            ranges: vec![(-1.0, 1.0), (-1.0, 1.0)],
            counts: vec![21, 21],
        };
        let c = Continuity {
            angular: vec![false],
            size: 1.0,
        };
        let wall = |q: &[f64]| (q[0] - 0.75).abs() < 0.06 && q[1] < -0.75 || (q[1] + 0.75).abs() < 0.06 && q[0] > 0.75;
        let reachable = |q: &[f64]| !(wall(q) || q[0].abs() < 0.3 && q[1] < 0.5);
        let island = |q: &[f64]| q[0] > 0.8 && q[1] < -0.8;
        let followed = follow(
            &grid,
            0,
            &[-1.0],
            &c,
            2,
            |q, b| reachable(q).then(|| vec![if b == 0 { q[0].abs() } else { -q[0].abs() }]),
            |_, v| v[0],
        );
        let mut q = [0.0; 2];
        for (k, node) in followed.iter().enumerate() {
            grid.node(k, &mut q);
            match node {
                Some(node) => {
                    assert!(reachable(&q) && !island(&q), "{q:?}");
                    assert!((node.kept - q[0]).abs() < 1e-12, "{q:?}: {}", node.kept);
                }
                None => assert!(!reachable(&q) || island(&q), "{q:?} not reached"),
            }
        }
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
