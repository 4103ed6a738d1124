//! Every complex root of the pose equations ([`super::system`]) by
//! parameter homotopy (Morgan and Sommese 1989): the equations' roots at
//! one generic complex choice of the loci are found once per shape of
//! legs (how many spheres and circles, on which body) by monodromy
//! (loops in the loci's space, each carrying the roots known round it
//! until no loop finds a new one; Duff et al. 2019), then carried along
//! the straight segment from those loci to the loci the inputs give. The
//! segment meets no point where two roots meet (complex codimension one,
//! which a real segment misses for a generic start), so every isolated
//! root at the inputs is the end of one path (the parameter homotopy
//! theorem); paths that end at infinity or fail are counted, never
//! dropped.
//!
//! `q` and `−q` are one rotation: the equations keep both, the paths are
//! carried for one of each pair (the other's path is its mirror).

use super::system::{dot, on_stack, rotation, rows, turn, with_slopes, Body, Locus, Slopes, UNKNOWNS};
use crate::random::SplitMix;
use nalgebra::Complex;
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

type C = Complex<f64>;

/// A point of `C⁷`.
pub type Point = [C; UNKNOWNS];

/// The largest modulus (one square root: paths are stopped at 10⁷, far
/// from where |·|² overflows).
fn norm(x: &Point) -> f64 {
    x.iter().map(|c| c.norm_sqr()).fold(0.0, f64::max).sqrt()
}

/// The straight segment of loci `from + s·rate`, `rate = to − from`.
struct Segment<'a> {
    from: &'a [Locus<C>],
    rate: Vec<Locus<C>>,
}

impl<'a> Segment<'a> {
    fn new(from: &'a [Locus<C>], to: &[Locus<C>]) -> Segment<'a> {
        let rate = from.iter().zip(to).map(|(a, b)| a.zip_map(b, |x, y| y - x)).collect();
        Segment { from, rate }
    }

    /// The equations at `x` on the loci at `s`: values, Jacobian, and the
    /// derivative by `s` ([`with_slopes`]).
    fn evaluate(&self, x: &Point, s: f64) -> Slopes<C> {
        let (at, n) = on_stack(
            self.from
                .iter()
                .zip(&self.rate)
                .map(|(a, v)| a.zip_map(v, |x, y| x + y * s)),
        );
        with_slopes(x, &at[..n], Some(&self.rate[..n]))
    }
}

/// `a·z = b` by Gaussian elimination with partial pivoting; `None` where
/// a pivot vanishes.
fn solve(a: [[C; UNKNOWNS]; UNKNOWNS], b: Point) -> Option<Point> {
    solve_both(a, [b]).map(|[z]| z)
}

/// `a·z = b` for each of `K` right-hand sides, one elimination.
fn solve_both<const K: usize>(mut a: [[C; UNKNOWNS]; UNKNOWNS], mut b: [Point; K]) -> Option<[Point; K]> {
    let n = UNKNOWNS;
    for col in 0..n {
        // The pivot by |·|² (no square root: the same order).
        let piv = (col..n).max_by(|&i, &j| a[i][col].norm_sqr().total_cmp(&a[j][col].norm_sqr()))?;
        if a[piv][col].norm_sqr().partial_cmp(&0.0) != Some(core::cmp::Ordering::Greater) {
            return None;
        }
        a.swap(col, piv);
        for b in &mut b {
            b.swap(col, piv);
        }
        let inv = C::new(1.0, 0.0) / a[col][col];
        let pivot_row = a[col];
        for r in col + 1..n {
            let f = a[r][col] * inv;
            if f != C::new(0.0, 0.0) {
                for (x, t) in a[r][col..].iter_mut().zip(&pivot_row[col..]) {
                    *x -= f * t;
                }
                for b in &mut b {
                    let t = b[col];
                    b[r] -= f * t;
                }
            }
        }
    }
    let mut out = [[C::new(0.0, 0.0); UNKNOWNS]; K];
    for (z, b) in out.iter_mut().zip(&b) {
        for r in (0..n).rev() {
            let mut acc = b[r];
            for c in r + 1..n {
                acc -= a[r][c] * z[c];
            }
            z[r] = acc / a[r][r];
        }
    }
    out.iter()
        .flatten()
        .all(|c| c.re.is_finite() && c.im.is_finite())
        .then_some(out)
}

/// How a path ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum End {
    /// At a finite point, Newton's method converged there.
    Finite(Point),
    /// Its unknowns grew past 10⁷ (of the size) in the last hundredth of
    /// the path, or past 10⁴ where the step vanished there: a root at
    /// infinity.
    Infinite,
    /// The step fell below 10⁻¹³ of the path before its end: a singular
    /// end (two roots meeting) or a path the tracker lost.
    Failed,
}

/// `dx/ds` at `(x, s)`.
fn tangent(x: &Point, path: &Segment, s: f64) -> Option<Point> {
    let e = path.evaluate(x, s);
    solve(e.j, e.ds.map(|v| -v))
}

/// Newton's method at `s` from `x`: at most `steps` steps, the first at
/// most `first`, each at most a quarter of the last (Newton's quadratic
/// convergence, not a slow drift towards another root); the point where
/// a step falls below `tol` of the unknowns' size (one plus their
/// largest), or where the next one would by the contraction so far
/// (`size²/last`, no evaluation spent to confirm it), or where the steps
/// stop contracting (rounding) within 10⁻⁶ of it; `None` otherwise. With
/// the point, `dx/ds` from the last evaluation (one elimination for both;
/// at the point before the last step, which is small: the next step's
/// first slope), and the first step's length (how far the prediction
/// missed).
fn correct(x: Point, path: &Segment, s: f64, steps: usize, first: f64, tol: f64) -> Option<(Point, Point, f64)> {
    let mut x = x;
    let mut last = f64::INFINITY;
    let mut miss = 0.0;
    for k in 0..steps {
        let e = path.evaluate(&x, s);
        let [dx, slope] = solve_both(e.j, [e.f, e.ds.map(|v| -v)])?;
        let size = norm(&dx);
        let big = 1.0 + norm(&x);
        if k == 0 {
            if size > first {
                return None;
            }
            miss = size;
        }
        if size > 0.25 * last {
            return (last <= 1e-6 * big).then_some((x, slope, miss));
        }
        for i in 0..UNKNOWNS {
            x[i] -= dx[i];
        }
        // Below `tol`, or the next step, by the contraction so far
        // (Newton's: the next is about size²/last), would be.
        if size <= tol * big || (k > 0 && size * (size / last) <= tol * big) {
            return Some((x, slope, miss));
        }
        last = size;
    }
    None
}

/// How near the path the corrector brings each step's point, of the
/// unknowns' size (the end is polished to rounding).
const TOL: f64 = 1e-6;

/// The cubic through `(s0, x0)` and `(s1, x1)` with slopes `d0`, `d1`
/// there (Hermite's), at `s`: the predictor once a path has two points,
/// from what the corrector already computed (no evaluation).
fn hermite(s0: f64, x0: &Point, d0: &Point, s1: f64, x1: &Point, d1: &Point, s: f64) -> Point {
    let h0 = s1 - s0;
    let t = (s - s0) / h0;
    let (t2, t3) = (t * t, t * t * t);
    let a = 2.0 * t3 - 3.0 * t2 + 1.0;
    let b = (t3 - 2.0 * t2 + t) * h0;
    let c = -2.0 * t3 + 3.0 * t2;
    let d = (t3 - t2) * h0;
    core::array::from_fn(|i| x0[i] * a + d0[i] * b + x1[i] * c + d1[i] * d)
}

/// How far the corrector's first step may be, of the step predicted: a
/// prediction that lands farther from the path may lie nearer another.
const FIRST: f64 = 0.1;

/// The ratio of the corrector's first step to the step predicted that
/// the step length aims at (well inside [`FIRST`]).
const AIM: f64 = 0.05;

/// Carries the root `x` of the equations on `from` to `to`. Predictor:
/// the classical Runge–Kutta step on `dx/ds` for the first step, then
/// Hermite's cubic through the last two points and their slopes (which
/// the corrector's last elimination gives: no evaluation); corrector:
/// Newton's method, at most three contracting steps, the first at most
/// [`FIRST`] of the predicted step, until a step is below [`TOL`] of the
/// unknowns' size or its contraction says the next would be. The step is
/// halved where either fails; after a success it is scaled by
/// `(AIM / ρ)^⅓` within `[½, 2]` (ρ: the corrector's first step over the
/// predicted one, which grows as the step's cube), at most `hmax`. The
/// end is polished at the target by Newton's method while its steps
/// shrink.
pub fn track(x: Point, from: &[Locus<C>], to: &[Locus<C>], hmax: f64) -> End {
    let path = Segment::new(from, to);
    let mut x = x;
    let mut s = 0.0;
    let mut h = hmax / 4.0;
    // The slope at `x`, where the last corrector left it, and the point
    // before with its slope.
    let mut slope: Option<Point> = None;
    let mut before: Option<(f64, Point, Point)> = None;
    while s < 1.0 {
        h = h.min(1.0 - s);
        let step = (|| {
            let k1 = match slope {
                Some(k) => k,
                None => tangent(&x, &path, s)?,
            };
            let pred: Point = match &before {
                Some((s0, x0, d0)) => hermite(*s0, x0, d0, s, &x, &k1, s + h),
                None => {
                    let at = |k: &Point, f: f64| -> Point { core::array::from_fn(|i| x[i] + k[i] * (f * h)) };
                    let k2 = tangent(&at(&k1, 0.5), &path, s + 0.5 * h)?;
                    let k3 = tangent(&at(&k2, 0.5), &path, s + 0.5 * h)?;
                    let k4 = tangent(&at(&k3, 1.0), &path, s + h)?;
                    core::array::from_fn(|i| x[i] + (k1[i] + k2[i] * 2.0 + k3[i] * 2.0 + k4[i]) * (h / 6.0))
                }
            };
            let moved = norm(&core::array::from_fn(|i| pred[i] - x[i]));
            let first = (FIRST * moved).max(1e-9 * (1.0 + norm(&pred)));
            let (next, at, miss) = correct(pred, &path, s + h, 3, first, TOL)?;
            Some((next, at, k1, miss / moved.max(f64::MIN_POSITIVE)))
        })();
        match step {
            Some((next, at, k1, ratio)) => {
                before = Some((s, x, k1));
                x = next;
                slope = Some(at);
                s += h;
                let grow = if ratio > 0.0 {
                    (AIM / ratio).cbrt().clamp(0.5, 2.0)
                } else {
                    2.0
                };
                h = (h * grow).min(hmax);
                // Far out: a root at infinity near the end; before it, a
                // path that passes near infinity and may come back, which
                // another route should carry.
                if norm(&x) > 1e7 {
                    return if s > 0.99 { End::Infinite } else { End::Failed };
                }
            }
            None => {
                h *= 0.5;
                if h < 1e-13 {
                    return if norm(&x) > 1e4 && s > 0.99 {
                        End::Infinite
                    } else {
                        End::Failed
                    };
                }
            }
        }
    }
    polish(x, &path).map_or(End::Failed, End::Finite)
}

/// Newton's method at the path's end: steps while they shrink (at most
/// 12); the point where the last is within 10⁻⁸ of the unknowns' size
/// (one plus their largest), rounding having stopped it; `None`
/// otherwise (a singular root: the steps do not contract).
fn polish(x: Point, path: &Segment) -> Option<Point> {
    let mut x = x;
    let mut last = f64::INFINITY;
    for _ in 0..12 {
        let e = path.evaluate(&x, 1.0);
        let Some(dx) = solve(e.j, e.f) else { break };
        let size = norm(&dx);
        if size >= last {
            break;
        }
        for i in 0..UNKNOWNS {
            x[i] -= dx[i];
        }
        last = size;
        if size <= 1e-15 * (1.0 + norm(&x)) {
            break;
        }
    }
    (last <= 1e-8 * (1.0 + norm(&x))).then_some(x)
}

/// `x` or `−x`'s quaternion: the one whose largest component has a
/// positive real part (both are one rotation).
pub fn canonical(mut x: Point) -> Point {
    let big = (3..UNKNOWNS)
        .max_by(|&a, &b| x[a].norm().total_cmp(&x[b].norm()))
        .unwrap_or(3);
    if x[big].re < 0.0 {
        for v in &mut x[3..] {
            *v = -*v;
        }
    }
    x
}

/// Whether `a` and `b` are one pose: `p` the same and `q` the same up to
/// its sign (a canonical sign is no help where the largest component's
/// real part is near zero).
fn same(a: &Point, b: &Point) -> bool {
    let tol = 1e-6 * (1.0 + norm(a));
    let close = |sign: f64| (0..UNKNOWNS).all(|i| (a[i] - b[i] * if i < 3 { 1.0 } else { sign }).norm() <= tol);
    close(1.0) || close(-1.0)
}

/// The roots of one shape of legs at a generic complex choice of loci.
#[derive(Debug, Clone)]
pub struct Start {
    /// The loci.
    pub legs: Vec<Locus<C>>,
    /// Every root, one of each `±q` pair.
    pub roots: Vec<Point>,
    /// Monodromy loops run.
    pub loops: usize,
}

fn random_c(rng: &mut SplitMix) -> C {
    C::new(rng.symmetric(), rng.symmetric())
}

fn random_legs(shape: &[(Body, bool)], rng: &mut SplitMix) -> Vec<Locus<C>> {
    shape
        .iter()
        .map(|&(on, circle)| Locus {
            on,
            ball: core::array::from_fn(|_| random_c(rng)),
            centre: core::array::from_fn(|_| random_c(rng)),
            normal: circle.then(|| core::array::from_fn(|_| random_c(rng))),
            radius2: random_c(rng),
        })
        .collect()
}

/// Loci of the shape on which `x` is a root: random balls, centres and
/// normals, each circle's centre moved along its normal onto `x`'s plane,
/// each radius `x`'s.
fn legs_through(shape: &[(Body, bool)], x: &Point, rng: &mut SplitMix) -> Vec<Locus<C>> {
    let mut legs = random_legs(shape, rng);
    let p = [x[0], x[1], x[2]];
    let r = rotation(&[x[3], x[4], x[5], x[6]]);
    // Rᵀ = R⁻¹ where q·q = 1, complex or not.
    let rt: [[C; 3]; 3] = core::array::from_fn(|i| core::array::from_fn(|j| r[j][i]));
    for leg in &mut legs {
        // The ball centre, in the locus's body frame.
        let y: [C; 3] = match leg.on {
            Body::Base => {
                let t = turn(&r, &leg.ball);
                core::array::from_fn(|i| p[i] + t[i])
            }
            Body::Platform => turn(&rt, &core::array::from_fn(|i| leg.ball[i] - p[i])),
        };
        if let Some(n) = leg.normal {
            let t = (dot(&n, &y) - dot(&n, &leg.centre)) / dot(&n, &n);
            leg.centre = core::array::from_fn(|i| leg.centre[i] + n[i] * t);
        }
        let d: [C; 3] = core::array::from_fn(|i| y[i] - leg.centre[i]);
        leg.radius2 = dot(&d, &d);
    }
    legs
}

/// How far the tracker may step along a path, at most.
pub const STEP: f64 = 0.1;

/// Loops without a new root after which monodromy stops.
pub const STALL: usize = 10;

/// The start of a shape by monodromy, from the random generator's seed.
pub fn monodromy(shape: &[(Body, bool)], seed: u64) -> Start {
    let mut rng = SplitMix::new(seed);
    let mut x0: Point = core::array::from_fn(|_| random_c(&mut rng));
    let qq = x0[3] * x0[3] + x0[4] * x0[4] + x0[5] * x0[5] + x0[6] * x0[6];
    let inv = C::new(1.0, 0.0) / qq.sqrt();
    for v in &mut x0[3..] {
        *v *= inv;
    }
    let x0 = canonical(x0);
    let legs = legs_through(shape, &x0, &mut rng);
    let mut roots = vec![x0];
    let (mut stall, mut loops) = (0, 0);
    while stall < STALL && loops < 200 {
        loops += 1;
        let a = random_legs(shape, &mut rng);
        let b = random_legs(shape, &mut rng);
        let mut new = false;
        for x in roots.clone() {
            let End::Finite(y) = track(x, &legs, &a, STEP) else {
                continue;
            };
            let End::Finite(y) = track(y, &a, &b, STEP) else {
                continue;
            };
            let End::Finite(y) = track(y, &b, &legs, STEP) else {
                continue;
            };
            let y = canonical(y);
            if !roots.iter().any(|r| same(r, &y)) {
                roots.push(y);
                new = true;
            }
        }
        stall = if new { 0 } else { stall + 1 };
    }
    Start { legs, roots, loops }
}

/// The seed every shape's monodromy starts from.
const SEED: u64 = 0x5eed_2026;

/// The start of a shape, found once per process.
pub fn start(shape: &[(Body, bool)]) -> Arc<Start> {
    type Starts = Mutex<HashMap<Vec<(Body, bool)>, Arc<Start>>>;
    static STARTS: OnceLock<Starts> = OnceLock::new();
    let starts = STARTS.get_or_init(|| Mutex::new(HashMap::new()));
    if let Some(s) = starts.lock().ok().and_then(|m| m.get(shape).cloned()) {
        return s;
    }
    let s = Arc::new(monodromy(shape, SEED));
    if let Ok(mut m) = starts.lock() {
        m.entry(shape.to_vec()).or_insert_with(|| s.clone());
    }
    s
}

/// Every path's end at the real loci `target` (one per root of the start,
/// one of each `±q` pair), in the start's order. A path that fails, or
/// ends at a finite root another path ends at too (a path that jumped:
/// paths from a generic start never meet at a regular root), is carried
/// again along the same segment with a smaller step; where some still
/// fail, every path is carried again by another route, through random
/// loci on the way (at most [`RETRIES`] routes; the route with the fewest
/// doubtful paths is kept, what still fails is reported failed). Every
/// path of one route, never a mixture: a route round other loci may carry
/// a start root to another end (monodromy), and only one route's paths
/// together meet every end once.
pub fn ends(start: &Start, target: &[Locus<f64>]) -> Vec<End> {
    let to: Vec<Locus<C>> = target.iter().map(|l| l.map(|v| C::new(v, 0.0))).collect();
    let mut ends = route(start, &[&to], STEP);
    if doubtful(&ends).is_empty() {
        return ends;
    }
    // Every path again by another route, through random loci: a route
    // whose paths all end, each at its own root, is as good as the first.
    let shape: Vec<(Body, bool)> = start.legs.iter().map(|l| (l.on, l.normal.is_some())).collect();
    let mut rng = SplitMix::new(SEED ^ 0x0005_7a7e);
    for _ in 0..RETRIES {
        let mid = random_legs(&shape, &mut rng);
        let other = route(start, &[&mid, &to], STEP);
        if doubtful(&other).len() < doubtful(&ends).len() {
            ends = other;
        }
        if doubtful(&ends).is_empty() {
            break;
        }
    }
    ends
}

/// Every start root carried along the segments through `stops` in turn;
/// a path that fails or jumps is carried again along the same segments
/// with a step cap a quarter of the last (twice).
fn route(start: &Start, stops: &[&Vec<Locus<C>>], cap: f64) -> Vec<End> {
    let along = |x: Point, cap: f64| -> End {
        let mut from = &start.legs;
        let mut x = x;
        for &to in stops {
            match track(x, from, to, cap) {
                End::Finite(y) => x = y,
                other => return other,
            }
            from = to;
        }
        End::Finite(x)
    };
    let mut ends: Vec<End> = start.roots.iter().map(|&x| along(x, cap)).collect();
    let mut cap = cap;
    for _ in 0..2 {
        let redo = doubtful(&ends);
        if redo.is_empty() {
            break;
        }
        cap *= 0.25;
        for k in redo {
            ends[k] = along(start.roots[k], cap);
        }
    }
    ends
}

/// The paths that failed or end at a finite root another path ends at.
fn doubtful(ends: &[End]) -> Vec<usize> {
    (0..ends.len())
        .filter(|&k| match ends[k] {
            End::Failed => true,
            End::Finite(x) => ends
                .iter()
                .enumerate()
                .any(|(j, e)| j != k && matches!(e, End::Finite(y) if same(&x, y))),
            End::Infinite => false,
        })
        .collect()
}

/// How many other routes are tried.
pub const RETRIES: usize = 3;

/// Whether `shape` gives as many rows as unknowns.
pub fn square(shape: &[(Body, bool)]) -> bool {
    rows(shape) == UNKNOWNS
}
