//! Shared helpers for the primitives' unit tests (test builds only).

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
