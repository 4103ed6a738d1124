//! Inverse position solutions of planar mechanisms: the plan interpreter and
//! the generated code against Newton's forward solution (3-RRR, κ = 1, so no
//! closed-form fk exists) and against the closed-form fk (round trips).

use crate::common;
use crate::mechanisms::{FourBar, ThreeRpr, ThreeRrr};

use pkm::runtime::kinematics;
use pkm::runtime::newton::{self, NewtonOptions};
use pkm::runtime::plan::{self, Plan};

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

/// The 3-RPR's inverse (each leg's guide through the platform's pin,
/// `guide`): by hand, leg i's slide is ±|A_i − (p + R(φ)·b_i)|
/// (A_i at radius 250 and b_i at 60, at 210°, 330° and 90°), on each of
/// the 2³ branches; generated = interpreted; and Newton's forward solution
/// from the slides gives the pose back. Not at the home pose (0, 0, 0):
/// there the three legs' lines meet at o, a forward singularity (the
/// platform turns about o to first order), where Newton's forward solution
/// lands 9e-7 rad off.
#[test]
fn three_rpr_inverse_by_hand_and_against_newton_forward() {
    let (model, plan) = load("planar_3rpr");
    assert_eq!(plan.branches, 3);
    let inputs = model.inputs();
    let o = model.points.iter().position(|p| p.name == "o").unwrap();
    let (r, p) = (250.0f64, 60.0f64);
    let at = |radius: f64, degrees: f64| {
        let a = degrees.to_radians();
        [radius * a.cos(), radius * a.sin()]
    };
    let base = [at(r, 210.0), at(r, 330.0), [0.0, r]];
    let platform = [at(p, 210.0), at(p, 330.0), [0.0, p]];
    let mut solved = 0;
    for pose in [
        [5.0, -10.0, 0.25],
        [10.0, 20.0, 0.2],
        [-30.0, 15.0, -0.3],
        [25.0, -20.0, 0.5],
    ] {
        let [x, y, phi]: [f64; 3] = pose;
        let legs: Vec<f64> = (0..3)
            .map(|i| {
                let [bx, by] = platform[i];
                let w = [x + phi.cos() * bx - phi.sin() * by, y + phi.sin() * bx + phi.cos() * by];
                (w[0] - base[i][0]).hypot(w[1] - base[i][1])
            })
            .collect();
        let generated = ThreeRpr::ik(&Default::default(), &pose);
        assert_eq!(generated.len(), 8);
        for (branch, g) in plan::run_all(&model, &plan, &pose).into_iter().zip(&generated) {
            let (signs, result) = branch;
            assert_eq!(signs, g.signs.to_vec());
            let (Ok(sol), Ok(gen)) = (result, &g.result) else {
                panic!("{pose:?} {signs:?}: every branch of this pose assembles");
            };
            for (a, b) in gen.q.iter().zip(&sol.values) {
                assert!((a - b).abs() < 1e-12 * b.abs().max(1.0), "{a} vs {b}");
            }
            for (i, &j) in inputs.iter().enumerate() {
                let s = sol.values[j];
                assert!(
                    (s.abs() - legs[i]).abs() < 1e-12 * legs[i],
                    "leg {i}: {s} vs ±{}",
                    legs[i]
                );
                assert_eq!(
                    s > 0.0,
                    signs[i] == pkm::runtime::primitives::Sign::Plus,
                    "leg {i}'s sense"
                );
            }
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
    assert_eq!(solved, 32);
}

#[test]
fn output_names() {
    assert_eq!(FourBar::OUTPUTS, ["psi"]);
    assert_eq!(ThreeRrr::OUTPUTS, ["x", "y", "phi"]);
    assert_eq!(ThreeRrr::OUTPUT_ANGLES, [false, false, true]);
}
