//! Singularity measures (pkm-runtime's `velocity::jacobians`) on the
//! conditions seed 000 §2.3 derives by hand for mechanism A: placed exactly
//! on each condition the measure vanishes (relative σ below 1e-9), and a
//! little off it does not.

use pkm::runtime::primitives::Sign;
use pkm::runtime::velocity::{self, Singularity};
use std::collections::HashMap;

pkm::mechanism!(SeedA, file = "examples/mechanisms/seed000_a.pkm");

struct Setup {
    model: pkm::runtime::model::Model,
    outputs: Vec<pkm::runtime::newton::Output>,
}

fn setup() -> Setup {
    let path = format!("{}/examples/mechanisms/seed000_a.pkm", env!("CARGO_MANIFEST_DIR"));
    let a = pkm::dsl::analyze_source(&std::fs::read_to_string(path).unwrap()).unwrap();
    let model = pkm::dsl::plan::model(&a, &HashMap::new()).unwrap();
    let outputs = pkm::dsl::plan::newton_outputs(&a, &model, &HashMap::new()).unwrap();
    Setup { model, outputs }
}

/// (input σ, output σ, class) at the joint values `q`.
fn measure(s: &Setup, q: &[f64]) -> (f64, f64, Singularity) {
    let j = velocity::jacobians(&s.model, q, &s.outputs).unwrap();
    (j.input_sigma, j.output_sigma, j.singularity)
}

/// Every ik solution of a pose.
fn ik(pose: [f64; 4]) -> Vec<[f64; 11]> {
    SeedA::ik(&Default::default(), &pose)
        .iter()
        .filter_map(|b| b.result.as_ref().ok().map(|s| s.q))
        .collect()
}

const P3: usize = 7;

#[test]
fn table_1_is_regular() {
    let s = setup();
    let q = SeedA::fk_branch(&Default::default(), &[-106.09, 181.67, -70.29], [Sign::Plus; 2])
        .unwrap()
        .q;
    let (i, o, class) = measure(&s, &q);
    assert_eq!(class, Singularity::None, "{i:e} {o:e}");
    assert!(i > 1e-5 && o > 1e-3, "{i:e} {o:e}");
}

#[test]
fn input_singularity_when_x3_equals_x_c3() {
    let s = setup();
    let p = Default::default();
    let x_c3 = SeedA::fk_branch(&p, &[-106.09, 181.67, -70.29], [Sign::Plus; 2])
        .unwrap()
        .points[SeedA::POINTS.iter().position(|n| *n == "o").unwrap()][0];

    for (dx, singular) in [(0.0, true), (2.0, false), (-2.0, false)] {
        let q = SeedA::fk(&p, &[-106.09, 181.67, x_c3 + dx]);
        for b in q.iter().filter_map(|b| b.result.as_ref().ok()) {
            assert!((b.q[P3] - (x_c3 + dx)).abs() < 1e-12);
            let (i, o, class) = measure(&s, &b.q);
            if singular {
                assert!(
                    i < 1e-9 && matches!(class, Singularity::Input),
                    "x3 = x_C3: {i:e} {o:e}"
                );
            } else {
                assert!(i > 1e-7 && o > 1e-3, "x3 = x_C3 {dx:+}: {i:e} {o:e}");
            }
        }
    }
}

/// The paper's Table 1 pose with z and α replaced.
fn pose(z: f64, alpha: f64) -> [f64; 4] {
    [37.79, -300.0, z, alpha]
}

/// Every ik solution of `pose` is output-singular (`on`), or none is.
fn check_output(s: &Setup, pose: [f64; 4], on: bool, what: &str) -> usize {
    let mut n = 0;
    // Solutions with x1 = x2 are on another output condition (tested below).
    for q in ik(pose).into_iter().filter(|q| (q[0] - q[4]).abs() > 1e-9) {
        let (_, o, _) = measure(s, &q);
        if on {
            assert!(o < 1e-9, "{what}: output σ {o:e} at {pose:?}");
        } else {
            assert!(o > 1e-5, "{what}, off: output σ {o:e} at {pose:?}");
        }
        n += 1;
    }
    n
}

#[test]
fn output_singularity_when_sliders_meet() {
    // x1 = x2: ik lists these solutions beside the paper's four.
    let s = setup();
    let mut met = 0;
    for q in ik(pose(238.9192, -0.7097)) {
        let (_, o, _) = measure(&s, &q);
        if (q[0] - q[4]).abs() < 1e-9 {
            assert!(o < 1e-9, "x1 = x2: output σ {o:e}");
            met += 1;
        } else {
            assert!(o > 1e-3, "x1 ≠ x2: output σ {o:e}");
        }
    }
    assert_eq!(met, 4);
}

#[test]
fn output_singularity_when_c3_is_at_the_sliders_height() {
    // z_C3 = l1 = 100: the five-bar's distal links line up.
    let s = setup();
    assert!(check_output(&s, pose(100.0, -0.3), true, "z = l1") > 0);
    assert!(check_output(&s, pose(110.0, -0.3), false, "z = l1 + 10") > 0);
}

#[test]
fn output_singularity_on_f33() {
    // α = arctan((z_C3 − l1)/(y_C3 − a)) with y_C3 = −a: the platform lies
    // along C3B3, which the parallelogram's arm cannot turn.
    let s = setup();
    let z: f64 = 238.9192;
    let alpha = ((z - 100.0) / (-300.0 - 300.0)).atan();
    assert!(check_output(&s, pose(z, alpha), true, "f33 = 0") > 0);
    assert!(check_output(&s, pose(z, alpha + 0.05), false, "f33 = 0, α + 0.05") > 0);
}
