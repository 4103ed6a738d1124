//! Two paths that must agree: the closed-form plan (interpreter) and the
//! reference Newton solver, started near each branch, at random inputs.

mod common;

use pkm::dsl::screw::SplitMix;
use pkm::runtime::kinematics;
use pkm::runtime::model::Model;
use pkm::runtime::newton::{self, NewtonOptions};
use pkm::runtime::spatial;
use std::collections::HashMap;
use std::f64::consts::PI;

/// A solved branch: its signs, and its joint values and joint points (3-D).
type Solved = (Vec<pkm::runtime::primitives::Sign>, Vec<f64>, Vec<[f64; 3]>);

/// Every solved branch at the given inputs.
type Solver = Box<dyn Fn(&Model, &[f64]) -> Vec<Solved>>;

/// The model and the closed-form forward solver (its plan run by the
/// interpreter) of an example.
fn load(file: &str) -> (Model, Solver) {
    load_text(&common::example_text(file).0)
}

/// The model and the closed-form forward solver of a mechanism's text.
fn load_text(text: &str) -> (Model, Solver) {
    let a = pkm::dsl::analyze_source(text).unwrap();
    let model = pkm::dsl::numeric::model(&a, &HashMap::new()).unwrap();
    let plan = pkm::dsl::planner::forward_plan(&a).unwrap();
    let solve: Solver = Box::new(move |model, q| {
        spatial::run_all(model, &plan, q)
            .into_iter()
            .filter_map(|(signs, r)| r.ok().map(|s| (signs, s)))
            .map(|(signs, s)| {
                let points = (0..model.joints.len())
                    .map(|j| kinematics::joint_point(model, &s.poses, j))
                    .collect();
                (signs, s.values, points)
            })
            .collect()
    });
    (model, solve)
}

/// Uniform in [lo, hi) from the analysis's own deterministic generator.
fn uniform(rng: &mut SplitMix, lo: f64, hi: f64) -> f64 {
    lo + (hi - lo) * (rng.symmetric() + 1.0) / 2.0
}

/// For `samples` random inputs in `ranges`: every branch the plan solves is
/// found again by Newton from a start perturbed by 1e-3 (radians or mm), and
/// every joint point agrees to 1e-9 of the mechanism's size.
fn check(file: &str, ranges: &[(f64, f64)], samples: usize) {
    let (model, solve) = load(file);
    check_solver(file, &model, &solve, ranges, samples);
}

/// [`check`] for a loaded model and solver, `file` naming it in failures.
fn check_solver(file: &str, model: &Model, solve: &Solver, ranges: &[(f64, f64)], samples: usize) {
    let scale = kinematics::model_scale(model);
    let mut rng = SplitMix::new(0x5eed);
    let mut solved = 0;
    for _ in 0..samples {
        let q: Vec<f64> = ranges.iter().map(|&(lo, hi)| uniform(&mut rng, lo, hi)).collect();
        for (signs, values, points) in solve(model, &q) {
            let guess: Vec<f64> = values.iter().map(|v| v + uniform(&mut rng, -1e-3, 1e-3)).collect();
            let reference = newton::solve_fk(model, &q, &guess, &NewtonOptions::default())
                .unwrap_or_else(|e| panic!("{file} {q:?} {signs:?}: Newton failed: {e}"));
            for (j, a) in points.iter().enumerate() {
                let b = kinematics::joint_point(model, &reference.poses, j);
                let err = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
                assert!(
                    err <= 1e-9 * scale,
                    "{file} {q:?} {signs:?} joint {}: {err}",
                    model.joints[j].name
                );
            }
            solved += 1;
        }
    }
    assert!(solved >= samples, "{file}: only {solved} solved branches");
}

#[test]
fn four_bar() {
    check("four_bar", &[(-PI, PI)], 200);
}

#[test]
fn slider_crank() {
    check("slider_crank", &[(-PI, PI)], 200);
}

#[test]
fn inverted_slider_crank() {
    check("inverted_slider_crank", &[(-PI, PI)], 200);
}

/// The RPR dyad's other forms (`guide_through`): the rocker's guide off
/// its pivot by 15, and the guide on the block with the rocker's slider
/// point off the pivot, each checked against Newton as the examples are.
#[test]
fn inverted_slider_crank_offset_guides() {
    let (text, _) = common::example_text("inverted_slider_crank");
    let base = "rocker { P1 = through (0, 0) along x; R3 = (0, 0); point T = (l, 0); }";
    let block = "block  { R2 = (0, 0); P1 = (0, 0); }";
    assert!(text.contains(base) && text.contains(block));
    let offset = text.replace(
        base,
        "rocker { P1 = through (0, 15) along x; R3 = (0, 0); point T = (l, 0); }",
    );
    let on_block = text
        .replace(block, "block  { R2 = (0, 0); P1 = through (5, 0) along (1, 1); }")
        .replace(base, "rocker { P1 = (30, -10); R3 = (0, 0); point T = (l, 0); }");
    for (name, text) in [("offset guide", offset), ("guide on the block", on_block)] {
        let (model, solve) = load_text(&text);
        check_solver(name, &model, &solve, &[(-PI, PI)], 200);
    }
}

#[test]
fn crank_shaper() {
    check("crank_shaper", &[(-PI, PI)], 200);
}

#[test]
fn cylinder_rocker() {
    check("cylinder_rocker", &[(-60.0, 300.0)], 200);
}

/// By hand: with the stroke s the cylinder is |R2R3| = c + s long, and the
/// rocker closes the triangle R1–R2–R3 (a = 150, R3 = (300, −80), c = 200):
/// ψ = atan2(−80, 300) ± acos((a² + |R1R3|² − (c + s)²)/(2a·|R1R3|)).
#[test]
fn cylinder_rocker_by_hand() {
    let (model, solve) = load("cylinder_rocker");
    let (a, c, r13) = (150.0f64, 200.0f64, 300.0f64.hypot(80.0));
    for s in [0.0, 60.0, 150.0, 255.0] {
        let l = c + s;
        let half = ((a * a + r13 * r13 - l * l) / (2.0 * a * r13)).acos();
        let base = (-80.0f64).atan2(300.0);
        let mut want = [base + half, base - half].map(|p| p.sin().atan2(p.cos()));
        let mut got: Vec<f64> = solve(&model, &[s]).iter().map(|(_, q, _)| q[0]).collect();
        want.sort_by(f64::total_cmp);
        got.sort_by(f64::total_cmp);
        assert_eq!(got.len(), 2, "s = {s}");
        for (g, w) in got.iter().zip(want) {
            assert!((g - w).abs() < 1e-13, "s = {s}: ψ {g} vs {w}");
        }
    }
}

#[test]
fn five_bar() {
    check("five_bar", &[(1.2, 2.8), (0.3, 1.9)], 200);
}

#[test]
fn seed003_punch() {
    check("seed003_punch", &[(-PI, PI)], 200);
}

#[test]
fn watt_six_bar() {
    check("watt_six_bar", &[(-PI, PI)], 200);
}

#[test]
fn seed000_a() {
    check("seed000_a", &[(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)], 200);
}

#[test]
fn seed000_a_u() {
    check("seed000_a_u", &[(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)], 200);
}

/// Seed 000 A declared with the U joint U1 and with the revolutes R3, R4
/// and their cross written out: at the same inputs the same branches, every
/// joint of both files at the same value and point, and the U's two axes
/// through R3's and R4's common point. (U1.a and U1.b are R3 and R4 measured
/// from other cross frames: not compared.)
#[test]
fn seed000_a_u_is_seed000_a() {
    let (written, solve_written) = load("seed000_a");
    let (universal, solve_universal) = load("seed000_a_u");
    let index = |m: &Model, name: &str| m.joints.iter().position(|j| j.name == name).unwrap();
    let shared: Vec<(usize, usize)> = written
        .joints
        .iter()
        .enumerate()
        .filter_map(|(j, joint)| Some((j, universal.joints.iter().position(|k| k.name == joint.name)?)))
        .collect();
    assert_eq!(shared.len(), 9, "every joint but R3 and R4");
    let centre = [
        (index(&written, "R3"), index(&universal, "U1.a")),
        (index(&written, "R4"), index(&universal, "U1.b")),
    ];
    let mut rng = SplitMix::new(11);
    let mut compared = 0;
    for _ in 0..200 {
        let q = [(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)].map(|(lo, hi)| uniform(&mut rng, lo, hi));
        let a = solve_written(&written, &q);
        let b = solve_universal(&universal, &q);
        assert_eq!(a.len(), b.len(), "branches at {q:?}");
        for ((signs_a, qa, pa), (signs_b, qb, pb)) in a.iter().zip(&b) {
            assert_eq!(signs_a, signs_b);
            for &(i, k) in &shared {
                assert!((qa[i] - qb[k]).abs() < 1e-9, "{} at {q:?}", written.joints[i].name);
            }
            for &(i, k) in shared.iter().chain(&centre) {
                let d = (0..3).map(|c| (pa[i][c] - pb[k][c]).abs()).fold(0.0, f64::max);
                assert!(d < 1e-9, "point of {} at {q:?}: {d:e}", written.joints[i].name);
            }
            compared += 1;
        }
    }
    assert!(compared > 200, "{compared} branches compared");
}

/// The U's convention by hand (docs/language.md, "U joints"): U1's first
/// axis is y on c2, whose joint frame there is (x, −z, y) = Rx(−π/2); its
/// second axis is x on the platform and on the cross, so its turn is
/// Rx(U1.b) in either frame. The platform is therefore turned against c2 by
/// Rx(−π/2)·Rz(U1.a)·Rx(U1.b), and both frames' origins are the U's centre.
#[test]
fn seed000_a_u_turns_by_its_two_values() {
    use pkm::runtime::nalgebra::{Rotation3, Vector3};
    let a = pkm::dsl::analyze_source(&common::example_text("seed000_a_u").0).unwrap();
    let model = pkm::dsl::numeric::model(&a, &HashMap::new()).unwrap();
    let plan = pkm::dsl::planner::forward_plan(&a).unwrap();
    let link = |n: &str| model.links.iter().position(|l| l == n).unwrap();
    let joint = |n: &str| model.joints.iter().position(|j| j.name == n).unwrap();
    let (c2, platform, ua, ub) = (link("c2"), link("platform"), joint("U1.a"), joint("U1.b"));
    let mut rng = SplitMix::new(5);
    let mut compared = 0;
    for _ in 0..50 {
        let q = [(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)].map(|(lo, hi)| uniform(&mut rng, lo, hi));
        for s in spatial::run_all(&model, &plan, &q)
            .into_iter()
            .filter_map(|(_, r)| r.ok())
        {
            let (tc, tp) = (s.poses[c2], s.poses[platform]);
            let relative = (tc.rotation.inverse() * tp.rotation).to_rotation_matrix();
            let by_hand = Rotation3::from_axis_angle(&Vector3::x_axis(), -PI / 2.0)
                * Rotation3::from_axis_angle(&Vector3::z_axis(), s.values[ua])
                * Rotation3::from_axis_angle(&Vector3::x_axis(), s.values[ub]);
            assert!((relative.matrix() - by_hand.matrix()).norm() < 1e-12, "at {q:?}");
            assert!(
                (tc.translation.vector - tp.translation.vector).norm() < 1e-9,
                "at {q:?}"
            );
            compared += 1;
        }
    }
    assert!(compared > 50, "{compared} branches");
}

#[test]
fn seed000_b() {
    check("seed000_b", &[(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)], 200);
}

#[test]
fn five_bar_pa() {
    check("five_bar_pa", &[(-PI, PI), (-PI, PI), (-300.0, 300.0)], 200);
}
