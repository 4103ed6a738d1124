//! Inverse position solutions of planar mechanisms: the plan interpreter and
//! the generated code against Newton's forward solution (3-RRR, κ = 1, so no
//! closed-form fk exists) and against the closed-form fk (round trips).

mod common;

use pkm::runtime::kinematics;
use pkm::runtime::newton::{self, NewtonOptions};
use pkm::runtime::spatial::{self, Plan};

pkm::mechanism!(ThreeRrr, file = "examples/mechanisms/planar_3rrr.pkm");
pkm::mechanism!(FourBar, file = "examples/mechanisms/four_bar.pkm");
pkm::mechanism!(SliderCrank, file = "examples/mechanisms/slider_crank.pkm");
pkm::mechanism!(Watt, file = "examples/mechanisms/watt_six_bar.pkm");

fn load(file: &str) -> (pkm::runtime::model::Model, Plan) {
    let (a, model) = common::example(file);
    (model, pkm::dsl::planner::inverse_plan(&a).unwrap())
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
        for (branch, g) in spatial::run_all(&model, &plan, &pose).into_iter().zip(&generated) {
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
            let at = kinematics::point(&model, &fwd.poses, "o").unwrap();
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

#[test]
fn output_names() {
    assert_eq!(FourBar::OUTPUTS, ["psi"]);
    assert_eq!(ThreeRrr::OUTPUTS, ["x", "y", "phi"]);
    assert_eq!(ThreeRrr::OUTPUT_ANGLES, [false, false, true]);
}
