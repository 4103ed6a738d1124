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

/// Two circles' crossings, by hand: centres `c1`, `c2`, radii `r1`, `r2`;
/// none where they miss.
fn crossings(c1: [f64; 2], r1: f64, c2: [f64; 2], r2: f64) -> Vec<[f64; 2]> {
    let (dx, dy) = (c2[0] - c1[0], c2[1] - c1[1]);
    let d = dx.hypot(dy);
    let a = (r1 * r1 - r2 * r2 + d * d) / (2.0 * d);
    let h2 = r1 * r1 - a * a;
    if h2 < 0.0 {
        return vec![];
    }
    let h = h2.sqrt();
    let (ux, uy) = (dx / d, dy / d);
    let m = [c1[0] + a * ux, c1[1] + a * uy];
    vec![[m[0] - h * uy, m[1] + h * ux], [m[0] + h * uy, m[1] - h * ux]]
}

/// The five-bar with its tool point E off the joints (`five_bar_tool.pkm`:
/// E = (80, 30) on right_distal, whose R4 is at its origin and R3 at
/// (b2, 0)), by hand: R4 is where the circle about E of radius |E R4| =
/// √7300 crosses the circle of radius a2 about R5; right_distal's x axis
/// is E − R4 turned back by atan2(30, 80), R3 = R4 + b2·x; R2 is where
/// the circle of radius a1 about R1 crosses that of radius b1 about R3.
/// Every assembly by hand is one ok branch of the plan, and no branch is
/// ok beyond them.
#[test]
fn five_bar_tool_point_by_hand() {
    let (model, plan) = load("five_bar_tool");
    // Two ± choices: four branches.
    assert_eq!(plan.branches, 2);
    let joint = |name: &str| model.joints.iter().position(|j| j.name == name).unwrap();
    let (r2, r3, r4) = (joint("R2"), joint("R3"), joint("R4"));
    let (r1_at, r5_at, e) = ([-50.0, 0.0], [50.0, 0.0], [80.0f64, 30.0f64]);
    let (a1, b1, a2, b2) = (120.0, 160.0, 120.0, 160.0);
    let back = e[1].atan2(e[0]);
    let mut compared = 0;
    for pose in [[40.0, 140.0], [80.0, 22.0], [-20.0, 180.0], [0.0, 120.0], [60.0, 60.0]] {
        let mut by_hand = Vec::new();
        for p4 in crossings(pose, e[0].hypot(e[1]), r5_at, a2) {
            let (dx, dy) = (pose[0] - p4[0], pose[1] - p4[1]);
            let n = dx.hypot(dy);
            let (c, s) = (back.cos(), back.sin());
            let x = [(c * dx + s * dy) / n, (-s * dx + c * dy) / n];
            let p3 = [p4[0] + b2 * x[0], p4[1] + b2 * x[1]];
            for p2 in crossings(r1_at, a1, p3, b1) {
                by_hand.push([p2, p3, p4]);
            }
        }
        let all = plan::run_all(&model, &plan, &pose);
        let solved: Vec<[[f64; 2]; 3]> = all
            .iter()
            .filter_map(|(_, r)| r.as_ref().ok())
            .map(|s| {
                [r2, r3, r4].map(|j| {
                    let p = kinematics::joint_point(&model, &s.poses, j);
                    [p[0], p[1]]
                })
            })
            .collect();
        assert_eq!(solved.len(), by_hand.len(), "at {pose:?}: {all:?}");
        let far = |a: &[[f64; 2]; 3], b: &[[f64; 2]; 3]| {
            (0..3)
                .map(|i| (a[i][0] - b[i][0]).hypot(a[i][1] - b[i][1]))
                .fold(0.0, f64::max)
        };
        for h in &by_hand {
            let d = solved.iter().map(|s| far(s, h)).fold(f64::INFINITY, f64::min);
            assert!(d < 1e-9, "at {pose:?}: {h:?} is {d:e} from every branch");
            compared += 1;
        }
    }
    assert!(compared >= 12, "only {compared} assemblies compared");
}
