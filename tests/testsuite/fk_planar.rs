//! Forward position solutions of planar κ = 0 mechanisms by the plan
//! interpreter (the one for planar and spatial mechanisms alike), against numbers from independent sources: seed 003's
//! equations (1)–(4) written out here, textbook closed forms, and the joint
//! conventions of the numeric model (`joint_transform`, a 3-D code path).

use crate::common;

use pkm::runtime::model::{joint_transform, Model};
use pkm::runtime::plan::{run, run_all, Plan, Solution};
use pkm::runtime::primitives::Sign::{self, Minus, Plus};
use pkm::runtime::solution::SolveError;
use std::collections::HashMap;
use std::f64::consts::PI;

fn load(file: &str, params: &[(&str, f64)]) -> (Model, Plan) {
    let (text, path) = common::example_text(file);
    let a = pkm::dsl::analyze_source(&text).unwrap_or_else(|e| panic!("{}", e.render(&text, &path)));
    let values: HashMap<String, f64> = params.iter().map(|(k, v)| (k.to_string(), *v)).collect();
    (
        pkm::dsl::numeric::model(&a, &values).unwrap(),
        pkm::dsl::planner::forward_plan(&a).unwrap(),
    )
}

fn point(model: &Model, sol: &Solution, name: &str) -> [f64; 2] {
    let j = model.joints.iter().position(|j| j.name == name).unwrap();
    let [x, y, z] = pkm::runtime::newton::joint_point(model, &sol.poses, j);
    assert_eq!(z, 0.0, "a planar mechanism's point {name} left its plane");
    [x, y]
}

fn value(model: &Model, sol: &Solution, name: &str) -> f64 {
    sol.values[model.joints.iter().position(|j| j.name == name).unwrap()]
}

fn assert_close(what: &str, got: f64, want: f64) {
    assert!(
        (got - want).abs() <= 1e-9 * want.abs().max(1.0),
        "{what}: {got} vs {want}"
    );
}

/// Seed 003 §2.1, eqs. (1)–(4), with Table 1's dimensions, written out by hand.
fn seed003_paper(phi: f64) -> [[f64; 2]; 5] {
    let (m, n, l1, l2, l8, l4, l7) = (235.0, 205.0, 40.0, 117.0, 80.0, 170.0, 108.96f64);
    let b = [m + l1 * phi.cos(), n + l1 * phi.sin()];
    // (1): l1 cos φ = l2 cos φ1, C below B (sin φ1 > 0).
    let phi1 = (l1 * phi.cos() / l2).acos();
    let c = [m, b[1] - l2 * phi1.sin()];
    let theta = (l2 / 2.0 / l8).acos();
    let d = [m + l8 * (theta + phi1).cos(), c[1] + l8 * (theta + phi1).sin()];
    // (3) with the + arccos, then G on the circle of radius l7 about H.
    let l_dh = d[0].hypot(d[1]);
    let phi3 = ((l7 * l7 + l_dh * l_dh - l4 * l4) / (2.0 * l7 * l_dh)).acos() + (d[1] / d[0]).atan();
    let g = [l7 * phi3.cos(), l7 * phi3.sin()];
    // l5 = l7 and (4): φ4 = π − φ3, so F = (2 l7 cos φ3, 0).
    let f = [2.0 * l7 * phi3.cos(), 0.0];
    [b, c, d, g, f]
}

#[test]
fn seed003_punch_over_a_full_crank_turn() {
    let (model, plan) = load("seed003_punch", &[]);
    assert_eq!(plan.branches, 3);
    for k in 0..360 {
        let phi = k as f64 * PI / 180.0;
        let want = seed003_paper(phi);
        // The paper's branch: C below B (−), G by the + arccos (−: right of D→H),
        // F the intersection other than H. The SOC3 dyad (G–F–P2) is tangent
        // where F passes through H (cos φ3 = 0, near φ = 150°), and its ± branches
        // exchange there: F is the larger x (+) before and the smaller (−) after.
        let f_sign = if want[4][0] >= 0.0 { Plus } else { Minus };
        let sol = run(&model, &plan, &[phi], &[Minus, Minus, f_sign]).unwrap();
        for (name, w) in ["B", "C", "D", "G", "F"].iter().zip(want) {
            let p = point(&model, &sol, name);
            assert_close(&format!("{name}.x at φ = {k}°"), p[0], w[0]);
            assert_close(&format!("{name}.y at φ = {k}°"), p[1], w[1]);
        }
        // The two slider outputs: Y_C (slider 3 on x = m) and X_F (slider 6 on the x axis).
        assert_close("Y_C", value(&model, &sol, "P1"), want[1][1]);
        assert_close("X_F", value(&model, &sol, "P2"), want[4][0]);
    }
}

#[test]
fn slider_crank_closed_form() {
    let (r, l) = (50.0, 180.0f64);
    let (model, plan) = load("slider_crank", &[]);
    for k in 0..72 {
        let th = k as f64 * 5.0 * PI / 180.0;
        let root = (l * l - (r * th.sin()).powi(2)).sqrt();
        let plus = run(&model, &plan, &[th], &[Plus]).unwrap();
        let minus = run(&model, &plan, &[th], &[Minus]).unwrap();
        assert_close("x+", value(&model, &plus, "P1"), r * th.cos() + root);
        assert_close("x−", value(&model, &minus, "P1"), r * th.cos() - root);
    }
}

#[test]
fn four_bar_coupler_joint_by_circle_intersection() {
    let (l1, l2, l3, l4) = (100.0, 250.0, 200.0, 300.0f64);
    let (model, plan) = load("four_bar", &[]);
    for k in 0..36 {
        let th = k as f64 * 10.0 * PI / 180.0;
        let b = [l1 * th.cos(), l1 * th.sin()];
        let dx = [l4 - b[0], -b[1]];
        let d = dx[0].hypot(dx[1]);
        // Law of cosines from B towards D, then ± the height.
        let a = (l2 * l2 - l3 * l3 + d * d) / (2.0 * d);
        let h = (l2 * l2 - a * a).sqrt();
        let mid = [b[0] + a * dx[0] / d, b[1] + a * dx[1] / d];
        let left = [mid[0] - h * dx[1] / d, mid[1] + h * dx[0] / d];
        let right = [mid[0] + h * dx[1] / d, mid[1] - h * dx[0] / d];
        for (sign, want) in [(Plus, left), (Minus, right)] {
            let sol = run(&model, &plan, &[th], &[sign]).unwrap();
            let p = point(&model, &sol, "R3");
            assert_close("R3.x", p[0], want[0]);
            assert_close("R3.y", p[1], want[1]);
        }
    }
}

#[test]
fn five_bar_distal_joint() {
    let (model, plan) = load("five_bar", &[]);
    let (d, a1, b1) = (100.0, 120.0, 160.0f64);
    for (q1, q5) in [(2.0f64, 1.0f64), (1.6, 0.9), (2.5, 0.3)] {
        for (signs, sol) in run_all(&model, &plan, &[q1, q5]) {
            let sol = sol.unwrap_or_else(|e| panic!("{signs:?}: {e}"));
            let p2 = [-d / 2.0 + a1 * q1.cos(), a1 * q1.sin()];
            let p4 = [d / 2.0 + a1 * q5.cos(), a1 * q5.sin()];
            let p3 = point(&model, &sol, "R3");
            assert_close("|R3 − R2|", (p3[0] - p2[0]).hypot(p3[1] - p2[1]), b1);
            assert_close("|R3 − R4|", (p3[0] - p4[0]).hypot(p3[1] - p4[1]), b1);
        }
    }
}

/// Every joint value the interpreter reports reproduces the poses through
/// the model's own joint conventions (3-D isometries, another code path).
#[test]
fn joint_values_follow_the_model_conventions() {
    for (file, q) in [
        ("four_bar", vec![0.7]),
        ("slider_crank", vec![2.0]),
        ("five_bar", vec![2.0, 1.0]),
        ("seed003_punch", vec![1.2]),
    ] {
        let (model, plan) = load(file, &[]);
        for (signs, sol) in run_all(&model, &plan, &q) {
            let Ok(sol) = sol else { continue };
            let iso = |l: usize| sol.poses[l];
            for (j, joint) in model.joints.iter().enumerate() {
                let via = iso(joint.links[0]) * joint_transform(joint, &[sol.values[j]]);
                let direct = iso(joint.links[1]);
                let err = (via.translation.vector - direct.translation.vector).norm()
                    + via.rotation.angle_to(&direct.rotation);
                assert!(err < 1e-9, "{file} {signs:?} joint {}: {err}", joint.name);
            }
        }
    }
}

#[test]
fn out_of_reach_is_a_typed_error() {
    // With a 10 mm coupler and the crank at π, |BD| = 400 > l2 + l3 = 210: every
    // branch says why and by how much (190 mm), naming the loop R2–R3–R4
    // that cannot close (R3, the dyad's middle joint, was named alone before).
    let (model, plan) = load("four_bar", &[("l2", 10.0)]);
    for (signs, result) in run_all(&model, &plan, &[PI]) {
        match result {
            Err(SolveError::Unreachable { joint, by, .. }) => {
                assert_eq!(joint, "R2–R3–R4");
                assert_close("by", by, 400.0 - 210.0);
            }
            other => panic!("{signs:?}: {other:?}"),
        }
    }
    assert!(matches!(
        run(&model, &plan, &[f64::NAN], &[Sign::Plus]),
        Err(SolveError::BadInput { .. })
    ));
}

#[test]
fn watt_six_bar_second_dyad_closes() {
    // Independent check of the second loop: R6 lies at f from R5 and at g from R7 = (420, −60).
    let (f, g) = (200.0, 170.0f64);
    let (model, plan) = load("watt_six_bar", &[]);
    assert_eq!(plan.branches, 2);
    for k in 0..36 {
        let th = k as f64 * 10.0 * PI / 180.0;
        for (signs, sol) in run_all(&model, &plan, &[th]) {
            let Ok(sol) = sol else { continue };
            let (p5, p6, p7) = (
                point(&model, &sol, "R5"),
                point(&model, &sol, "R6"),
                point(&model, &sol, "R7"),
            );
            assert_close(&format!("|R6 − R5| {signs:?}"), (p6[0] - p5[0]).hypot(p6[1] - p5[1]), f);
            assert_close(&format!("|R6 − R7| {signs:?}"), (p6[0] - p7[0]).hypot(p6[1] - p7[1]), g);
            assert_close("R7.x", p7[0], 420.0);
        }
    }
}
