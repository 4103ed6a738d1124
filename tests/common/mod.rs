//! Helpers shared by integration tests.

/// The largest difference of `a` from `b`: angles (where `angle` says so)
/// modulo 2π, in radians; lengths relative to `scale`.
pub fn max_error(a: &[f64], b: &[f64], angle: &[bool], scale: f64) -> f64 {
    a.iter()
        .zip(b)
        .zip(angle)
        .map(|((a, b), &angle)| {
            if angle {
                pkm::runtime::plan::wrap_angle(a - b).abs()
            } else {
                (a - b).abs() / scale
            }
        })
        .fold(0.0, f64::max)
}
