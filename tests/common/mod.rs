//! Helpers shared by integration tests (each test file uses part of them).
#![allow(dead_code)]

/// An example mechanism of `examples/mechanisms/` by its file stem: its
/// analysis and its model at the nominal parameters.
pub fn example(stem: &str) -> (pkm::dsl::Analysis, pkm::runtime::model::Model) {
    let path = format!("{}/examples/mechanisms/{stem}.pkm", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let a = pkm::dsl::analyze_source(&text).unwrap_or_else(|d| panic!("{path}: {}", d.render(&text, &path)));
    let model =
        pkm::dsl::plan::model(&a, &Default::default()).unwrap_or_else(|d| panic!("{path}: {}", d.render(&text, &path)));
    (a, model)
}

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
