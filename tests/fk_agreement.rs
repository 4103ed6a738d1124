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
fn spherical_four_bar() {
    check("spherical_four_bar", &[(-PI, PI)], 200);
}

/// The spherical four-bar placed the other way: every joint r from the
/// centre along its axis (the axes pointing away from it), so the points
/// move and the planner solves it with the existing loci (the coupler's R3
/// on the plane the rocker's R3 circles in), not by the cone.
const SPHERICAL_ON_THE_SPHERE: &str = "mechanism spherical_on_sphere {
    capabilities fk;
    base R1* [crank] - R2 [coupler] - R3 [rocker] - R4 base;
    R1 ∧ R2 ∧ R3 ∧ R4;
    parameters { r = 100; a1 = deg(30); a2 = deg(70); a3 = deg(60); a4 = deg(80); }
    geometry {
        base    { R1 = (0, 0, r) along z; R4 = (r * sin(a4), 0, r * cos(a4)) along (sin(a4), 0, cos(a4)); }
        crank   { R1 = (0, 0, r) along z; R2 = (r * sin(a1), 0, r * cos(a1)) along (sin(a1), 0, cos(a1));
                  point B = (r * sin(a1), 0, r * cos(a1)); }
        coupler { R2 = (0, 0, r) along z; R3 = (r * sin(a2), 0, r * cos(a2)) along (sin(a2), 0, cos(a2)); }
        rocker  { R4 = (0, 0, r) along z; R3 = (r * sin(a3), 0, r * cos(a3)) along (sin(a3), 0, cos(a3));
                  point C = (r * sin(a3), 0, r * cos(a3)); }
    }
}";

/// By hand, the spherical Freudenstein equation. The centre at the origin,
/// R1 along z, R4 along a4 = (sin α4, 0, cos α4) (the base's geometry);
/// the crank's R2 axis u2 = (sin α1 cos θ, sin α1 sin θ, cos α1), θ the
/// crank's dihedral angle from the plane of R1 and R4; the rocker's R3 axis
/// u3 = cos α3·a4 + sin α3 (cos ψ·e1 + sin ψ·y), e1 = (cos α4, 0, −sin α4),
/// ψ the rocker's dihedral angle about R4 from that plane. The coupler
/// keeps u2·u3 = cos α2:
/// `A cos ψ + B sin ψ = C`, A = sin α3 (sin α1 cos α4 cos θ − cos α1 sin α4),
/// B = sin α3 sin α1 sin θ, C = cos α2 − cos α3 (sin α1 sin α4 cos θ + cos α1 cos α4),
/// so ψ = atan2(B, A) ± acos(C/√(A² + B²)). Each branch's point C (R3's
/// axis on the sphere of radius r, on the rocker) gives ψ, its point B
/// (R2's axis, on the crank) gives θ; the joint R4 is ψ less a constant
/// (its zero). Both placements: the example's, R3 at the centre (the
/// forward plan turns the coupler by the cone), and
/// [`SPHERICAL_ON_THE_SPHERE`]'s (the existing loci).
#[test]
fn spherical_four_bar_by_hand() {
    let (example, _) = common::example_text("spherical_four_bar");
    for text in [example.as_str(), SPHERICAL_ON_THE_SPHERE] {
        let a = pkm::dsl::analyze_source(text).unwrap();
        let model = pkm::dsl::numeric::model(&a, &HashMap::new()).unwrap();
        let plan = pkm::dsl::planner::forward_plan(&a).unwrap();
        let cones = plan
            .steps
            .iter()
            .filter(|s| matches!(s, spatial::Step::Cone { .. }))
            .count();
        assert_eq!(cones, usize::from(text == example), "{}", a.mechanism.name);
        spherical_freudenstein(&model, &plan);
    }
}

fn spherical_freudenstein(model: &Model, plan: &spatial::Plan) {
    let [a1, a2, a3, a4] = [30.0f64, 70.0, 60.0, 80.0].map(f64::to_radians);
    let r = 100.0;
    let wrap = |x: f64| x.sin().atan2(x.cos());
    let named = |n: &str| model.points.iter().position(|p| p.name == n).unwrap();
    let r4 = model.joints.iter().position(|j| j.name == "R4").unwrap();
    let mut offset: Option<f64> = None;
    for k in 0..24 {
        let theta = -PI + 0.2618 * k as f64 + 0.01;
        let (a, b) = (
            a3.sin() * (a1.sin() * a4.cos() * theta.cos() - a1.cos() * a4.sin()),
            a3.sin() * a1.sin() * theta.sin(),
        );
        let c = a2.cos() - a3.cos() * (a1.sin() * a4.sin() * theta.cos() + a1.cos() * a4.cos());
        let half = (c / a.hypot(b)).acos();
        let mut want = [b.atan2(a) + half, b.atan2(a) - half].map(wrap);
        let world = |s: &spatial::Solution, n: usize| spatial::at(&s.poses[model.points[n].link], model.points[n].at);
        let mut got: Vec<(f64, f64)> = spatial::run_all(model, plan, &[theta])
            .into_iter()
            .filter_map(|(_, s)| s.ok())
            .map(|s| {
                // R2's dihedral angle is the input: the crank's zero is the base's.
                let pb = world(&s, named("B"));
                assert!(wrap(pb[1].atan2(pb[0]) - theta).abs() < 1e-12);
                let u = world(&s, named("C")).map(|x| x / r);
                ((u[1]).atan2(u[0] * a4.cos() - u[2] * a4.sin()), s.values[r4])
            })
            .collect();
        assert_eq!(got.len(), 2, "θ = {theta}");
        want.sort_by(f64::total_cmp);
        got.sort_by(|x, y| x.0.total_cmp(&y.0));
        for ((psi, joint), w) in got.iter().zip(want) {
            assert!((psi - w).abs() < 1e-12, "θ = {theta}: ψ {psi} vs {w}");
            let o = wrap(psi - joint);
            let first = *offset.get_or_insert(o);
            assert!(
                wrap(o - first).abs() < 1e-12,
                "θ = {theta}: R4's zero moved: {o} vs {first}"
            );
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
