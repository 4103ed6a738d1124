//! Inverse position solutions of planar mechanisms: the plan interpreter and
//! the generated code against Newton's forward solution (3-RRR, κ = 1, so no
//! closed-form fk exists) and against the closed-form fk (round trips).

use pkm::runtime::newton::{self, NewtonOptions};
use pkm::runtime::plan::{self, Plan};
use std::collections::HashMap;
use std::f64::consts::PI;

pkm::mechanism!(ThreeRrr, file = "examples/mechanisms/planar_3rrr.pkm");
pkm::mechanism!(FourBar, file = "examples/mechanisms/four_bar.pkm");
pkm::mechanism!(SliderCrank, file = "examples/mechanisms/slider_crank.pkm");
pkm::mechanism!(Watt, file = "examples/mechanisms/watt_six_bar.pkm");

fn load(file: &str) -> (pkm::runtime::model::Model, Plan) {
    let path = format!("{}/examples/mechanisms/{file}.pkm", env!("CARGO_MANIFEST_DIR"));
    let a = pkm::dsl::analyze_source(&std::fs::read_to_string(path).unwrap()).unwrap();
    (
        pkm::dsl::plan::model(&a, &HashMap::new()).unwrap(),
        pkm::dsl::plan::inverse_plan(&a).unwrap(),
    )
}

#[test]
fn three_rrr_inverse_against_newton_forward() {
    let (model, plan) = load("planar_3rrr");
    assert_eq!(plan.branches, 3);
    let inputs = model.inputs();
    let o = model.points.iter().position(|p| p.name == "o").unwrap();
    let mut solved = 0;
    for pose in [
        [0.0, 0.0, 0.0],
        [10.0, 20.0, 0.2],
        [-30.0, 15.0, -0.3],
        [25.0, -20.0, 0.5],
    ] {
        let generated = ThreeRrr::ik(&Default::default(), &pose);
        for (branch, g) in plan::run_all(&model, &plan, &pose).into_iter().zip(&generated) {
            let (signs, result) = branch;
            assert_eq!(signs, g.signs.to_vec());
            let (Ok(sol), Ok(gen)) = (result, &g.result) else {
                assert!(g.result.is_err(), "generated solved a branch the interpreter did not");
                continue;
            };
            // Generated = interpreted.
            for (a, b) in gen.q.iter().zip(&sol.values) {
                assert!((a - b).abs() < 1e-12, "{a} vs {b}");
            }
            // Newton's forward solution from the inverse's input angles gives the pose back.
            let q: Vec<f64> = inputs.iter().map(|&j| sol.values[j]).collect();
            let guess: Vec<f64> = sol.values.iter().map(|v| v + 1e-3).collect();
            let fwd = newton::solve_fk(&model, &q, &guess, &NewtonOptions::default()).unwrap();
            let at = newton::point(&model, &fwd.poses, "o").unwrap();
            let angle = fwd.poses[model.points[o].link].rotation.euler_angles().2;
            assert!(
                (at[0] - pose[0]).abs() < 1e-9 && (at[1] - pose[1]).abs() < 1e-9,
                "{at:?} vs {pose:?}"
            );
            assert!((angle - pose[2]).abs() < 1e-9, "{angle} vs {}", pose[2]);
            solved += 1;
        }
    }
    assert!(solved >= 16, "only {solved} branches solved");
}

/// The difference of two values modulo 2π (angles; small length differences are unchanged).
fn diff(a: f64, b: f64) -> f64 {
    ((a - b + PI).rem_euclid(2.0 * PI) - PI).abs()
}

/// fk then ik: some inverse branch returns the input; every inverse branch's
/// forward solution gives the output back.
macro_rules! round_trip {
    ($ty:ident, $input:expr, $output:expr, $range:expr) => {{
        let params = Default::default();
        for k in 0..100 {
            let q = $range.0 + ($range.1 - $range.0) * k as f64 / 100.0;
            for f in $ty::fk(&params, &[q]).iter().filter_map(|b| b.result.as_ref().ok()) {
                let out = f.q[$output];
                let back = $ty::ik(&params, &[out]);
                let inputs: Vec<f64> = back
                    .iter()
                    .filter_map(|b| b.result.as_ref().ok())
                    .map(|s| s.q[$input])
                    .collect();
                assert!(
                    inputs.iter().any(|x| diff(*x, q) < 1e-9),
                    "{}: q = {q}, back {inputs:?}",
                    stringify!($ty)
                );
                for s in back.iter().filter_map(|b| b.result.as_ref().ok()) {
                    let again = $ty::fk(&params, &[s.q[$input]]);
                    assert!(
                        again
                            .iter()
                            .filter_map(|b| b.result.as_ref().ok())
                            .any(|g| diff(g.q[$output], out) < 1e-9),
                        "{}: ik∘fk at q = {q}",
                        stringify!($ty)
                    );
                }
            }
        }
    }};
}

#[test]
fn round_trips_of_one_dof_mechanisms() {
    // Joint orders: four-bar R1..R4 (input R1 = 0, output R4 = 3); slider-crank R1, R2, R3, P1 (input 0, output 3);
    // Watt R1..R7 (input 0, output R7 = 6).
    round_trip!(FourBar, 0, 3, (-PI, PI));
    round_trip!(SliderCrank, 0, 3, (-PI, PI));
    round_trip!(Watt, 0, 6, (-PI, PI));
    assert_eq!(FourBar::OUTPUTS, ["psi"]);
    assert_eq!(ThreeRrr::OUTPUTS, ["x", "y", "phi"]);
}
