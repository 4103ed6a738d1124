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

/// A solved branch: its signs, its joint values in the model's layout
/// (`Solution::model_values`: the Newton reference's) and joint points (3-D).
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
                (signs, s.model_values(model), points)
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
fn seed000_b() {
    check("seed000_b", &[(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)], 200);
}

#[test]
fn five_bar_pa() {
    check("five_bar_pa", &[(-PI, PI), (-PI, PI), (-300.0, 300.0)], 200);
}

#[test]
fn rssr() {
    check("rssr", &[(-PI, PI)], 200);
}

/// By hand: with the crank at θ, S1 = a(cos θ, sin θ, 0); the rocker turns
/// about +x through (d, e, h), S2 = (d, e + b cos ψ, h + b sin ψ); the
/// coupler keeps |S1S2| = l, so
/// `2b(e − a sin θ)·cos ψ + 2bh·sin ψ = l² − (d − a cos θ)² − (e − a sin θ)² − h² − b²`,
/// `A cos ψ + B sin ψ = C`, ψ = atan2(B, A) ± acos(C/√(A² + B²)).
#[test]
fn rssr_by_hand() {
    let (model, solve) = load("rssr");
    let (a, b, l, d, e, h) = (40.0f64, 120.0f64, 160.0f64, 100.0f64, 40.0f64, 60.0f64);
    for theta in [-3.0, -1.5, -0.4, 0.0, 0.9, 2.0, PI] {
        let (s, c) = theta.sin_cos();
        let (aa, bb) = (2.0 * b * (e - a * s), 2.0 * b * h);
        let cc = l * l - (d - a * c).powi(2) - (e - a * s).powi(2) - h * h - b * b;
        let (base, half) = (bb.atan2(aa), (cc / aa.hypot(bb)).acos());
        let mut want = [base + half, base - half].map(|p| p.sin().atan2(p.cos()));
        // ψ is the last joint (R2), the last value of the model's layout.
        let mut got: Vec<f64> = solve(&model, &[theta]).iter().map(|(_, q, _)| q[q.len() - 1]).collect();
        want.sort_by(f64::total_cmp);
        got.sort_by(f64::total_cmp);
        assert_eq!(got.len(), 2, "θ = {theta}");
        for (g, w) in got.iter().zip(want) {
            assert!((g - w).abs() < 1e-13, "θ = {theta}: ψ {g} vs {w}");
        }
    }
}

#[test]
fn rssp() {
    check("rssp", &[(-PI, PI)], 200);
}

/// By hand: with the crank at θ, S1 = a(cos θ, sin θ, 0); the slider's S2 =
/// (0, e, h) + s·(1, 0, 1)/√2; |S1S2| = l gives the quadratic
/// `s² + 2s·(w·g) + |w|² − l² = 0` with `w = (0, e, h) − S1`, `g` the unit
/// guide: s = −w·g ± √((w·g)² − |w|² + l²).
#[test]
fn rssp_by_hand() {
    let (model, solve) = load("rssp");
    let (a, l, e, h) = (40.0f64, 160.0f64, 50.0f64, 30.0f64);
    let g = [0.5f64.sqrt(), 0.0, 0.5f64.sqrt()];
    for theta in [-3.0, -1.5, -0.4, 0.0, 0.9, 2.0, PI] {
        let w = [-a * theta.cos(), e - a * theta.sin(), h];
        let wg = w[0] * g[0] + w[2] * g[2];
        let ww = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
        let half = (wg * wg - ww + l * l).sqrt();
        let mut want = [-wg + half, -wg - half];
        // s is the last joint (P1), the last value of the model's layout.
        let mut got: Vec<f64> = solve(&model, &[theta]).iter().map(|(_, q, _)| q[q.len() - 1]).collect();
        want.sort_by(f64::total_cmp);
        got.sort_by(f64::total_cmp);
        assert_eq!(got.len(), 2, "θ = {theta}");
        for (g, w) in got.iter().zip(want) {
            assert!((g - w).abs() < 1e-12 * l, "θ = {theta}: s {g} vs {w}");
        }
    }
}

/// The coupler's idle spin by the plan's convention (the smallest turn
/// from the world's axes carrying its drawn S1→S2 line, +x, onto the
/// centres' line) against nalgebra's `rotation_between` at the plan's
/// centres and at Newton's (whose own spin is whatever its least squares
/// left): both give the plan's coupler orientation.
#[test]
fn rssr_coupler_spin_by_the_convention() {
    use pkm::runtime::nalgebra::{UnitQuaternion, Vector3};
    let text = common::example_text("rssr").0;
    let a = pkm::dsl::analyze_source(&text).unwrap();
    let model = pkm::dsl::numeric::model(&a, &HashMap::new()).unwrap();
    let plan = pkm::dsl::planner::forward_plan(&a).unwrap();
    let coupler = model.links.iter().position(|l| l == "coupler").unwrap();
    let [s1, s2] = ["S1", "S2"].map(|n| model.joints.iter().position(|j| j.name == n).unwrap());
    let convention = |poses: &[pkm::runtime::nalgebra::Isometry3<f64>]| {
        let [p, q] = [s1, s2].map(|j| Vector3::from(kinematics::joint_point(&model, poses, j)));
        UnitQuaternion::rotation_between(&Vector3::x(), &(q - p)).unwrap()
    };
    let mut rng = SplitMix::new(3);
    for theta in [-3.0, -1.5, -0.4, 0.0, 0.9, 2.0, PI] {
        for (signs, s) in spatial::run_all(&model, &plan, &[theta]) {
            let s = s.unwrap();
            let plan_turn = s.poses[coupler].rotation;
            let e = plan_turn.angle_to(&convention(&s.poses));
            assert!(
                e < 1e-14,
                "θ = {theta} {signs:?}: the plan's coupler is {e:e} rad off the convention"
            );
            let guess: Vec<f64> = s
                .model_values(&model)
                .iter()
                .map(|v| v + uniform(&mut rng, -1e-2, 1e-2))
                .collect();
            let reference = newton::solve_fk(&model, &[theta], &guess, &NewtonOptions::default()).unwrap();
            let spin = reference.poses[coupler].rotation.angle_to(&plan_turn);
            let e = convention(&reference.poses).angle_to(&plan_turn);
            assert!(
                e < 1e-9,
                "θ = {theta} {signs:?}: Newton's centres, by the convention, {e:e} rad off (its own spin {spin:e})"
            );
        }
    }
}
