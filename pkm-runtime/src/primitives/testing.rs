//! Shared helpers for the primitives' unit tests (test builds only).

use super::{Error, LinePoint, Roots2, TANGENCY_TOL};

/// Expected shape of a primitive's outcome.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Want {
    /// Two distinct branches (or, for single-solution primitives, a solution).
    Two,
    /// A double root.
    Tangent,
    /// `Error::Unreachable` with this `by` (checked to 1e-9 relative), or any `by` if NaN.
    Unreachable(f64),
    /// `Error::Degenerate`.
    Degenerate,
}

/// `|x − y|` for angles, modulo 2π.
pub(crate) fn angle_diff(x: f64, y: f64) -> f64 {
    let d = x - y;
    d.sin().atan2(d.cos()).abs()
}

/// Euclidean distance.
pub(crate) fn dist<const N: usize>(a: [f64; N], b: [f64; N]) -> f64 {
    a.iter()
        .zip(b.iter())
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

/// Rodrigues rotation of `v` by `theta` about the unit axis `k` through `o`.
pub(crate) fn rotate(o: [f64; 3], k: [f64; 3], theta: f64, v: [f64; 3]) -> [f64; 3] {
    let n = (k[0] * k[0] + k[1] * k[1] + k[2] * k[2]).sqrt();
    let k = [k[0] / n, k[1] / n, k[2] / n];
    let p = [v[0] - o[0], v[1] - o[1], v[2] - o[2]];
    let kxp = [
        k[1] * p[2] - k[2] * p[1],
        k[2] * p[0] - k[0] * p[2],
        k[0] * p[1] - k[1] * p[0],
    ];
    let kp = k[0] * p[0] + k[1] * p[1] + k[2] * p[2];
    let (s, c) = theta.sin_cos();
    core::array::from_fn(|i| o[i] + p[i] * c + kxp[i] * s + k[i] * kp * (1.0 - c))
}

/// Checks a line's hits with a circle (N = 2) or sphere (N = 3) of `circle
/// = (centre, radius)`: the outcome has the wanted shape; each hit is on the
/// circle (to 1e-14 of `scale`, twice the tangency tolerance when tangent)
/// and on the line `start + t·unit(dir)` at its own `t`; `Plus` has the larger
/// `t`; and the `t`s are `exact_t` when given. Errors: the wanted kind, and
/// an `Unreachable` `by` as [`check_by`].
pub(crate) fn check_line_hits<const N: usize>(
    result: Result<Roots2<LinePoint<f64, N>>, Error<f64>>,
    want: Want,
    circle: ([f64; N], f64),
    start: [f64; N],
    dir: [f64; N],
    exact_t: Option<[f64; 2]>,
    scale: f64,
) {
    let (c, r) = circle;
    match (result, want) {
        (Ok(roots), Want::Two | Want::Tangent) => {
            assert_eq!(roots.is_tangent(), want == Want::Tangent, "{roots:?}");
            let tol = if roots.is_tangent() { 2.0 * TANGENCY_TOL } else { 1e-14 } * scale;
            let n = dist(dir, [0.0; N]);
            for hit in roots.branches() {
                assert!((dist(hit.point, c) - r).abs() <= tol, "{hit:?}");
                let on_line: [f64; N] = core::array::from_fn(|i| start[i] + hit.t * dir[i] / n);
                assert!(dist(on_line, hit.point) <= 1e-14 * scale, "{hit:?}");
            }
            let [p, m] = roots.branches();
            assert!(p.t >= m.t);
            if let Some([tp, tm]) = exact_t {
                assert!(
                    (p.t - tp).abs() <= 1e-14 * scale && (m.t - tm).abs() <= 1e-14 * scale,
                    "{roots:?}"
                );
            }
        }
        (Err(Error::Unreachable { by, .. }), Want::Unreachable(b)) => check_by(by, b),
        (Err(Error::Degenerate { .. }), Want::Degenerate) => {}
        (other, _) => panic!("line {start:?} + t·{dir:?} against ({c:?}, {r}): wanted {want:?}, got {other:?}"),
    }
}

/// Asserts that an `Unreachable` `by` matches the wanted value (NaN: any positive value).
pub(crate) fn check_by(by: f64, want: f64) {
    assert!(by > 0.0, "by = {by}");
    if !want.is_nan() {
        assert!((by - want).abs() <= 1e-9 * want, "by = {by}, wanted {want}");
    }
}

/// A tiny deterministic generator of test data (no dependency, no allocation).
pub(crate) struct Lcg(pub(crate) u64);

impl Lcg {
    /// Uniform in `[lo, hi)`.
    pub(crate) fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        lo + (hi - lo) * ((self.0 >> 11) as f64 / (1u64 << 53) as f64)
    }

    /// A point with coordinates uniform in `[-s, s)`.
    pub(crate) fn point(&mut self, s: f64) -> [f64; 3] {
        [self.uniform(-s, s), self.uniform(-s, s), self.uniform(-s, s)]
    }
}
