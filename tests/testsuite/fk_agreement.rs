//! Two paths that must agree: the closed-form plan (interpreter) and the
//! reference Newton solver, started near each branch, at random inputs.

use crate::common;

use pkm::dsl::screw::SplitMix;
use pkm::runtime::kinematics;
use pkm::runtime::model::Model;
use pkm::runtime::newton::{self, NewtonOptions};
use pkm::runtime::plan;
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
    (model, solver(plan))
}

/// The closed-form forward solver of a plan, run by the interpreter.
fn solver(plan: plan::Plan) -> Solver {
    let solve: Solver = Box::new(move |model, q| {
        plan::run_all(model, &plan, q)
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
    solve
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

/// The RPR dyad's other forms (`guide`): the rocker's guide off
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
fn scotch_yoke() {
    check("scotch_yoke", &[(-PI, PI)], 200);
}

/// The assemblies `solve` finds at the driving value `input`: as many as
/// `want` has, and joint `joint`'s value in each one of `want` (to 1e-12;
/// angles as the solver gives them, in (−π, π]), every wanted value met.
/// Returns them for further checks.
fn roots_by_hand(model: &Model, solve: &Solver, joint: &str, input: f64, want: &[f64]) -> Vec<Vec<f64>> {
    let j = model.joints.iter().position(|x| x.name == joint).unwrap();
    let solved: Vec<Vec<f64>> = solve(model, &[input]).into_iter().map(|(_, q, _)| q).collect();
    let got: Vec<f64> = solved.iter().map(|q| q[j]).collect();
    assert_eq!(got.len(), want.len(), "at {input}: {joint} {got:?} vs {want:?}");
    let near = |a: f64, b: f64| (a - b).abs() < 1e-12;
    for w in want {
        assert!(got.iter().any(|&g| near(g, *w)), "at {input}: {joint} {got:?}, no {w}");
    }
    for g in &got {
        assert!(
            want.iter().any(|&w| near(*g, w)),
            "at {input}: {joint} {g} is none of {want:?}"
        );
    }
    solved
}

/// A joint's value by hand as a function of the driving angle.
type ByHand = fn(f64) -> f64;

/// A one-assembly mechanism driven by one angle, by hand: at crank angles
/// θ round the turn, the forward plan finds one assembly, and each joint
/// of `want` has the value its formula gives (to 1e-12 of `size`).
fn one_assembly_by_hand(file: &str, size: f64, want: &[(&str, ByHand)]) {
    let (model, solve) = load(file);
    let at = |name: &str| model.joints.iter().position(|j| j.name == name).unwrap();
    for theta in [0.0, 0.3, 1.0, PI / 2.0, 2.5, -0.7, -PI / 2.0, PI] {
        let solved = solve(&model, &[theta]);
        assert_eq!(solved.len(), 1, "{file}, θ = {theta}");
        let q = &solved[0].1;
        for (joint, value) in want {
            let (got, by_hand) = (q[at(joint)], value(theta));
            assert!(
                (got - by_hand).abs() <= 1e-12 * size,
                "{file}, θ = {theta}: {joint} {got} vs {by_hand}"
            );
        }
    }
}

/// By hand: the slot (along y through the yoke's origin, at x = s) passes
/// the crank pin (r cos θ, r sin θ), r = 60: s = r cos θ, and the block
/// sits r sin θ up the slot. One assembly.
#[test]
fn scotch_yoke_by_hand() {
    one_assembly_by_hand(
        "scotch_yoke",
        60.0,
        &[("P2", |t| 60.0 * t.cos()), ("P1", |t| 60.0 * t.sin())],
    );
}

#[test]
fn trammel() {
    check("trammel", &[(-PI, PI)], 200);
}

/// By hand: the elliptical trammel driven at R1, between block1 (sliding
/// along x) and the bar (length l = 200): block1 keeps the base's
/// orientation, so the bar stands at θ, and its pin R2 is on block2's
/// guide, the y axis, where s + l cos θ = 0: s = −l cos θ, and block2 sits
/// l sin θ up its guide (`beyond`, a slide onto a slider's line). One assembly.
#[test]
fn trammel_by_hand() {
    one_assembly_by_hand(
        "trammel",
        200.0,
        &[("P1", |t| -200.0 * t.cos()), ("P2", |t| 200.0 * t.sin())],
    );
}

#[test]
fn inverted_slider_crank_block_driven() {
    check("inverted_slider_crank_block_driven", &[(-PI, PI)], 200);
}

/// By hand: the inverted slider-crank driven at R2 (crank–block, value θ),
/// r = 50, d = 120. The rocker keeps the block's orientation, ψ = θ₁ + θ,
/// and its line through R3 = (d, 0) passes the crank pin r(cos θ₁, sin θ₁):
/// `r sin(θ₁ − ψ) + d sin ψ = 0`, so `sin(θ₁ + θ) = (r/d) sin θ`, two
/// crank angles, `θ₁ = asin((r/d) sin θ) − θ` and `π − asin(…) − θ`
/// (`guide`, the line carried across the given R2).
#[test]
fn inverted_slider_crank_block_driven_by_hand() {
    let (model, solve) = load("inverted_slider_crank_block_driven");
    let at = |name: &str| model.joints.iter().position(|j| j.name == name).unwrap();
    let (r1, r3) = (at("R1"), at("R3"));
    // Into the solver's (−π, π]; the difference below modulo 2π.
    let wrap = |a: f64| PI - (PI - a).rem_euclid(2.0 * PI);
    for theta in [0.0, 0.3, 1.0, PI / 2.0, 2.5, -0.7, -PI / 2.0, 3.0] {
        let s = (50.0 / 120.0 * f64::sin(theta)).asin();
        let solved = roots_by_hand(&model, &solve, "R1", theta, &[wrap(s - theta), wrap(PI - s - theta)]);
        for q in &solved {
            assert!(wrap(q[r3] - q[r1] - theta).abs() < 1e-12, "θ = {theta}: ψ ≠ θ₁ + θ");
        }
    }
}

/// A crank with a driven slide on it (R-P*-P-R): with the slide P2 given
/// (value s), crank and block are one body, turned about R1 until the
/// block's line (P1, along the rocker's y through its pivot R3 = (d, 0))
/// passes the pivot: the block keeps the crank's angle θ, so
/// `(s cos θ − d) cos θ + s sin² θ = 0`, `cos θ = s/d`, θ = ±acos(s/d)
/// (`guide`, the line carried across the given slide). Against Newton too.
const CRANK_WITH_A_DRIVEN_SLIDE: &str = "mechanism rppr {
    capabilities fk;
    planar;
    base R1 [crank] ⊥ P2* [block] ⊥ P1 [rocker] ⊥ R3 base;
    parameters { d = 120; }
    geometry {
        base   { R1 = (0, 0); R3 = (d, 0); }
        crank  { R1 = (0, 0); P2 = through (0, 0) along x; }
        block  { P2 = (0, 0); P1 = (0, 0); }
        rocker { P1 = through (0, 0) along y; R3 = (0, 0); }
    }
}";

#[test]
fn guide_carried_across_a_given_slide() {
    let (model, solve) = load_text(CRANK_WITH_A_DRIVEN_SLIDE);
    for s in [0.0, 30.0, 50.0, 100.0, -80.0, 119.0] {
        let want = f64::acos(s / 120.0);
        roots_by_hand(&model, &solve, "R1", s, &[-want, want]);
    }
    // Beyond d the line cannot reach the pivot.
    assert!(solve(&model, &[130.0]).is_empty());
    check_solver("rppr", &model, &solve, &[(-110.0, 110.0)], 100);
}

/// The RPP dyad's other placements (`slide_to_line`, the line on the new
/// link): the slot on the block (the yoke's slider point 20 off its
/// origin), and the yoke's slot tilted 30° with the base's guide at 10°;
/// and the PRP dyad (the point on the new link, the line known): a
/// tangent mechanism, a block sliding in the crank's slot pinned to a
/// slider on a guide h above the crank's pivot. Each against Newton as the
/// examples are.
#[test]
fn slide_to_line_other_forms() {
    let (text, _) = common::example_text("scotch_yoke");
    let block = "block { R2 = (0, 0); P1 = (0, 0); }";
    let yoke = "yoke  { P1 = through (0, 0) along y; P2 = (0, 0); }";
    let base = "base  { R1 = (0, 0); P2 = through (0, 0) along x; }";
    assert!(text.contains(block) && text.contains(yoke) && text.contains(base));
    let on_block = text
        .replace(block, "block { R2 = (0, 0); P1 = through (3, 4) along y; }")
        .replace(yoke, "yoke  { P1 = (20, 0); P2 = (0, 0); }");
    let tilted = text
        .replace(
            yoke,
            "yoke  { P1 = through (5, 0) along (-sin(deg(30)), cos(deg(30))); P2 = (0, 0); }",
        )
        .replace(
            base,
            "base  { R1 = (0, 0); P2 = through (0, -15) along (cos(deg(10)), sin(deg(10))); }",
        )
        .replace("⊥ P1 [yoke] ⊥ P2 base", "⊥ P1 [yoke] - P2 base")
        .replace("x ∥ P2;", "");
    let tangent = common::TANGENT_MECHANISM;
    for (name, text, range) in [
        ("slot on the block", on_block, (-PI, PI)),
        ("tilted yoke", tilted, (-PI, PI)),
        ("tangent mechanism", tangent.to_string(), (0.2, PI - 0.2)),
    ] {
        let (model, solve) = load_text(&text);
        check_solver(name, &model, &solve, &[range], 200);
    }
}

/// By hand, the tangent mechanism of [`slide_to_line_other_forms`]: the
/// crank's slot at angle θ meets the guide y = h at x = h/tan θ, h/sin θ
/// along the slot.
#[test]
fn tangent_mechanism_by_hand() {
    let text = common::TANGENT_MECHANISM;
    let (model, solve) = load_text(text);
    let at = |name: &str| model.joints.iter().position(|j| j.name == name).unwrap();
    let (p1, p2, h) = (at("P1"), at("P2"), 80.0f64);
    for theta in [0.3, 1.0, PI / 2.0, 2.5, -0.7, -2.0] {
        let solved = solve(&model, &[theta]);
        assert_eq!(solved.len(), 1, "θ = {theta}");
        let q = &solved[0].1;
        let (s, t) = (h / theta.tan(), h / theta.sin());
        assert!(
            (q[p2] - s).abs() <= 1e-12 * s.abs().max(h),
            "θ = {theta}: s {} vs {s}",
            q[p2]
        );
        assert!(
            (q[p1] - t).abs() <= 1e-12 * t.abs(),
            "θ = {theta}: slot {} vs {t}",
            q[p1]
        );
    }
    // Along the guide (θ = 0): the two lines are parallel, a typed error.
    assert!(solve(&model, &[0.0]).is_empty());
}

#[test]
fn four_bar_coupler_driven() {
    check("four_bar_coupler_driven", &[(-PI, PI)], 200);
}

/// By hand: with the coupler joint at φ, |R1R3|² = l1² + l2² + 2·l1·l2·cos φ
/// (φ = 0: the coupler continues the crank), and the rocker at ψ puts R3 at
/// (l4 + l3 cos ψ, l3 sin ψ): |R1R3|² = l4² + l3² + 2·l4·l3·cos ψ, so
/// ψ = ±acos((|R1R3|² − l4² − l3²)/(2·l4·l3)), two assemblies.
#[test]
fn four_bar_coupler_driven_by_hand() {
    let (model, solve) = load("four_bar_coupler_driven");
    let (l1, l2, l3, l4) = (100.0f64, 250.0f64, 200.0f64, 300.0f64);
    for phi in [0.0, 0.4, 1.5, PI / 2.0, 2.9, -1.0, -2.5] {
        let d2 = l1 * l1 + l2 * l2 + 2.0 * l1 * l2 * phi.cos();
        let psi = ((d2 - l4 * l4 - l3 * l3) / (2.0 * l4 * l3)).acos();
        roots_by_hand(&model, &solve, "R4", phi, &[-psi, psi]);
    }
}

/// A slider-crank (r = 50, l = 180, the guide on the x axis through R1)
/// declared by `chain` (which names the driven joint), with `fk` alone.
fn driven_slider_crank(chain: &str) -> String {
    format!(
        "mechanism driven {{
            capabilities fk;
            planar;
            {chain}
            x ∥ P1;
            geometry {{
                base   {{ R1 = (0, 0); P1 = through (0, 0) along x; }}
                crank  {{ R1 = (0, 0); R2 = (50, 0); }}
                rod    {{ R2 = (0, 0); R3 = (180, 0); }}
                slider {{ R3 = (0, 0); P1 = (0, 0); }}
            }}
        }}"
    )
}

/// `beyond`'s other loci and slides, each against Newton and by
/// hand. A slider-crank driven at the crank–rod joint R2 (v: the rod's turn
/// from the crank's line): crank and rod turn as one body until the rod's
/// pin R3 is on the guide (a slider's plane), |R1R3|² = r² + l² + 2rl·cos v,
/// s = ±|R1R3|. Driven at the rod–slider joint R3: the rod translates with
/// the slider, turned −v, and the slide puts the crank pin
/// R2 = (s − l·cos v, l·sin v) on the circle |R2| = r (a line meets a
/// cylinder): s = l·cos v ± √(r² − l²·sin²v). A Scotch yoke (r = 60) driven
/// at the block's slide v in the slot: the yoke slides until the pin
/// (s, v) is on the crank's circle, s = ±√(r² − v²).
#[test]
fn beyond_given_slides_and_sliders() {
    let (yoke, _) = common::example_text("scotch_yoke");
    assert!(yoke.contains("R1* [crank]") && yoke.contains("P1 [yoke]"));
    let yoke = yoke
        .replace("R1* [crank]", "R1 [crank]")
        .replace("P1 [yoke]", "P1* [yoke]")
        .replace("capabilities fk, ik;", "capabilities fk;");
    type Hand = fn(f64) -> Vec<f64>;
    let cases: [(&str, String, (f64, f64), Hand); 3] = [
        (
            "slider-crank driven at R2",
            driven_slider_crank("base R1 [crank] ∥ R2* [rod] ∥ R3 [slider] ⊥ P1 base;"),
            (-PI, PI),
            |v| {
                let d = (50.0f64 * 50.0 + 180.0 * 180.0 + 2.0 * 50.0 * 180.0 * v.cos()).sqrt();
                vec![-d, d]
            },
        ),
        (
            "slider-crank driven at R3",
            driven_slider_crank("base R1 [crank] ∥ R2 [rod] ∥ R3* [slider] ⊥ P1 base;"),
            (-0.27, 0.27),
            |v| {
                let h = (50.0f64 * 50.0 - (180.0 * v.sin()).powi(2)).sqrt();
                vec![180.0 * v.cos() - h, 180.0 * v.cos() + h]
            },
        ),
        ("Scotch yoke driven at P1", yoke, (-55.0, 55.0), |v| {
            let h = (60.0f64 * 60.0 - v * v).sqrt();
            vec![-h, h]
        }),
    ];
    for (name, text, range, hand) in cases {
        let (model, solve) = load_text(&text);
        check_solver(name, &model, &solve, &[range], 200);
        let s = model
            .joints
            .iter()
            .position(|j| j.name == if name.contains("yoke") { "P2" } else { "P1" })
            .unwrap();
        for k in 0..9 {
            let v = range.0 + (range.1 - range.0) * (k as f64 + 0.5) / 9.0;
            let mut got: Vec<f64> = solve(&model, &[v]).iter().map(|(_, q, _)| q[s]).collect();
            got.sort_by(f64::total_cmp);
            let want = hand(v);
            assert_eq!(got.len(), 2, "{name} at {v}");
            for (g, w) in got.iter().zip(&want) {
                assert!((g - w).abs() <= 1e-12 * 300.0, "{name} at {v}: s {g} vs {w}");
            }
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
            .filter(|s| matches!(s, plan::Step::Cone { .. }))
            .count();
        assert_eq!(cones, usize::from(text == example), "{}", a.mechanism.name);
        spherical_freudenstein(&model, &plan);
    }
}

fn spherical_freudenstein(model: &Model, plan: &plan::Plan) {
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
        let world = |s: &plan::Solution, n: usize| plan::at(&s.poses[model.points[n].link], model.points[n].at);
        let mut got: Vec<(f64, f64)> = plan::run_all(model, plan, &[theta])
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
        for s in plan::run_all(&model, &plan, &q).into_iter().filter_map(|(_, r)| r.ok()) {
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
        for (signs, s) in plan::run_all(&model, &plan, &[theta]) {
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

/// The R-S-U-R: every joint point and every revolute's value (the U's two
/// angles included: the coupler's points all lie on its S1–U1 line, which
/// the U's two branches share) agree with Newton's from a start 1e-3 away.
#[test]
fn rsur() {
    let (model, solve) = load("rsur");
    let scale = kinematics::model_scale(&model);
    let (offsets, _) = model.value_offsets();
    let mut rng = SplitMix::new(0x5eed);
    let (mut solved, mut worst_point, mut worst_angle) = (0, 0.0f64, 0.0f64);
    for _ in 0..200 {
        let q = [uniform(&mut rng, -PI, PI)];
        for (signs, values, points) in solve(&model, &q) {
            let guess: Vec<f64> = values.iter().map(|v| v + uniform(&mut rng, -1e-3, 1e-3)).collect();
            let reference = newton::solve_fk(&model, &q, &guess, &NewtonOptions::default())
                .unwrap_or_else(|e| panic!("rsur {q:?} {signs:?}: Newton failed: {e}"));
            for (j, joint) in model.joints.iter().enumerate() {
                let b = kinematics::joint_point(&model, &reference.poses, j);
                let a = points[j];
                let err = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
                assert!(err <= 1e-9 * scale, "rsur {q:?} {signs:?} joint {}: {err}", joint.name);
                worst_point = worst_point.max(err / scale);
                if joint.kind == pkm::runtime::model::JointType::R {
                    let (a, b) = (values[offsets[j]], reference.values[offsets[j]]);
                    let e = pkm::runtime::solution::wrap_angle(a - b).abs();
                    assert!(e <= 1e-9, "rsur {q:?} {signs:?} {}: {a} vs Newton's {b}", joint.name);
                    worst_angle = worst_angle.max(e);
                }
            }
            solved += 1;
        }
    }
    eprintln!("rsur: {solved} branches, worst point {worst_point:e} of the size, angle {worst_angle:e} rad");
    assert!(solved >= 800, "rsur: only {solved} solved branches");
}

/// By hand: ψ as the RSSR's (the rocker's U centre at l from the crank's S
/// centre, `rssr_by_hand`), and the U: its axis on the coupler (the
/// coupler's z, drawn normal to its S1–U1 line) must stay normal to the
/// rocker's axis x (the cross's two axes are normal) and to the S1–U1 line,
/// so it is `±(x × (U − S))/|x × (U − S)|`: each ψ twice, once per sign.
#[test]
fn rsur_by_hand() {
    let (analysis, model) = common::example("rsur");
    let (a, b, l, d, e, h) = (40.0f64, 120.0f64, 160.0f64, 100.0f64, 40.0f64, 60.0f64);
    let plan = pkm::dsl::planner::forward_plan(&analysis).unwrap();
    let coupler = model.links.iter().position(|l| l == "coupler").unwrap();
    let (r2, s1, u) = (
        model.joints.iter().position(|j| j.name == "R2").unwrap(),
        model.joints.iter().position(|j| j.name == "S1").unwrap(),
        model.joints.iter().position(|j| j.name == "U1.a").unwrap(),
    );
    let (offsets, _) = model.value_offsets();
    for theta in [-3.0, -1.5, -0.4, 0.0, 0.9, 2.0, PI] {
        let (s, c) = theta.sin_cos();
        let (aa, bb) = (2.0 * b * (e - a * s), 2.0 * b * h);
        let cc = l * l - (d - a * c).powi(2) - (e - a * s).powi(2) - h * h - b * b;
        let (base, half) = (bb.atan2(aa), (cc / aa.hypot(bb)).acos());
        let want = [base + half, base - half];
        let branches = plan::run_all(&model, &plan, &[theta]);
        assert_eq!(branches.len(), 4, "θ = {theta}");
        let mut seen = [[0usize; 2]; 2];
        for (signs, r) in branches {
            let sol = r.unwrap_or_else(|err| panic!("θ = {theta} {signs:?}: {err}"));
            let psi = sol.model_values(&model)[offsets[r2]];
            let root = want
                .iter()
                .position(|w| pkm::runtime::solution::wrap_angle(psi - w).abs() < 1e-13)
                .unwrap_or_else(|| panic!("θ = {theta} {signs:?}: ψ {psi} vs {want:?}"));
            let [sp, up] = [s1, u].map(|j| kinematics::joint_point(&model, &sol.poses, j));
            let line = [up[0] - sp[0], up[1] - sp[1], up[2] - sp[2]];
            // x × line, normalised.
            let n = [0.0, -line[2], line[1]];
            let len = n[1].hypot(n[2]);
            let z = sol.poses[coupler].rotation * pkm::runtime::nalgebra::Vector3::z();
            let plus = (z.x).abs() < 1e-13 && (z.y - n[1] / len).abs() < 1e-13 && (z.z - n[2] / len).abs() < 1e-13;
            let minus = (z.x).abs() < 1e-13 && (z.y + n[1] / len).abs() < 1e-13 && (z.z + n[2] / len).abs() < 1e-13;
            assert!(
                plus || minus,
                "θ = {theta} {signs:?}: the coupler's z {z:?} vs ±{n:?}/{len}"
            );
            seen[root][usize::from(minus)] += 1;
        }
        assert_eq!(seen, [[1, 1], [1, 1]], "θ = {theta}: each ψ once with each U sense");
    }
}

/// How [`every_assembly`] draws the given values of one sample (`None`:
/// none this time).
type Draw<'a> = &'a dyn Fn(&mut SplitMix) -> Option<Vec<f64>>;

/// Issue 29, item 3: every real assembly is listed. At `samples` given
/// values of `file` (inputs for the forward plan, outputs for the inverse),
/// Newton (the runtime's reference, which knows nothing of the plan) runs
/// from `starts` random configurations (every angle in (−π, π), every
/// slide within twice the mechanism's size, every ball's rotation vector
/// in a cube of ±1.8 rad); each configuration it converges to must be one
/// of the branches the plan lists: every joint point within 1e-6 of the
/// size and every R, P and Pa value within 1e-6 (rad, or of the size),
/// but the values `convention` names (by prefix) and the balls' rotations,
/// which the plan fixes by a documented convention (an S–S link's idle
/// spin; a U-P leg's cross, [`pkm::runtime::steps::plane_through`]).
/// Returns how many converged configurations it matched, and in how many
/// samples it found every listed branch.
fn every_assembly(
    file: &str,
    forward: bool,
    draw: Draw,
    samples: usize,
    starts: usize,
    convention: &[&str],
) -> (usize, usize) {
    use pkm::runtime::model::JointType;
    let (a, model) = common::example(file);
    let plan = if forward {
        pkm::dsl::planner::forward_plan(&a).unwrap()
    } else {
        pkm::dsl::planner::inverse_plan(&a).unwrap()
    };
    let outputs = pkm::dsl::numeric::newton_outputs(&a, &model, &HashMap::new()).unwrap();
    let scale = kinematics::model_scale(&model);
    let (offsets, len) = model.value_offsets();
    let compared: Vec<usize> = (0..model.joints.len())
        .filter(|&j| model.joints[j].kind != JointType::S)
        .filter(|&j| !convention.iter().any(|c| model.joints[j].name.starts_with(c)))
        .collect();
    let points = |poses: &[pkm::runtime::nalgebra::Isometry3<f64>]| -> Vec<[f64; 3]> {
        (0..model.joints.len())
            .map(|j| kinematics::joint_point(&model, poses, j))
            .collect()
    };
    let mut rng = SplitMix::new(0xa55e);
    let (mut matched, mut complete) = (0, 0);
    for _ in 0..samples {
        let Some(given) = draw(&mut rng) else { continue };
        let listed: Vec<(usize, Vec<f64>, Vec<[f64; 3]>)> = plan::run_all(&model, &plan, &given)
            .into_iter()
            .enumerate()
            .filter_map(|(i, (_, r))| r.ok().map(|s| (i, s.model_values(&model), points(&s.poses))))
            .collect();
        let mut found = vec![false; listed.len()];
        for _ in 0..starts {
            let mut guess = vec![0.0; len];
            for (j, joint) in model.joints.iter().enumerate() {
                let o = offsets[j];
                match joint.kind {
                    JointType::P => guess[o] = 2.0 * scale * rng.symmetric(),
                    JointType::S => guess[o..o + 3].iter_mut().for_each(|v| *v = 1.8 * rng.symmetric()),
                    _ => guess[o] = PI * rng.symmetric(),
                }
            }
            let options = NewtonOptions::default();
            let reference = if forward {
                newton::solve_fk(&model, &given, &guess, &options)
            } else {
                newton::solve_ik(&model, &outputs, &given, &guess, &options)
            };
            let Ok(reference) = reference else { continue };
            let at = points(&reference.poses);
            let off = |(_, values, pts): &(usize, Vec<f64>, Vec<[f64; 3]>)| {
                let value = compared
                    .iter()
                    .map(|&j| {
                        let (x, y) = (values[offsets[j]], reference.values[offsets[j]]);
                        match model.joints[j].kind {
                            JointType::P => (x - y).abs() / scale,
                            _ => pkm::runtime::solution::wrap_angle(x - y).abs(),
                        }
                    })
                    .fold(0.0, f64::max);
                let point = pts
                    .iter()
                    .zip(&at)
                    .map(|(p, q)| (0..3).map(|c| (p[c] - q[c]).abs()).fold(0.0, f64::max) / scale)
                    .fold(0.0, f64::max);
                value.max(point)
            };
            let nearest = listed
                .iter()
                .enumerate()
                .map(|(k, l)| (k, off(l)))
                .min_by(|a, b| a.1.total_cmp(&b.1));
            match nearest {
                Some((k, e)) if e <= 1e-6 => found[k] = true,
                _ => panic!(
                    "{file} ({}) at {given:?}: Newton closes the mechanism at {:?} (residual {:e}), \
                     none of the listed branches {:?}; nearest {nearest:?}",
                    if forward { "fk" } else { "ik" },
                    reference.values,
                    reference.residual,
                    listed.iter().map(|l| l.0).collect::<Vec<_>>()
                ),
            }
            matched += 1;
        }
        complete += usize::from(found.iter().all(|f| *f));
    }
    eprintln!(
        "{file} ({}): {matched} Newton solutions, each a listed branch; every branch found in {complete} of {samples} samples",
        if forward { "fk" } else { "ik" }
    );
    (matched, complete)
}

/// Inputs drawn uniformly in `ranges`.
fn within(ranges: &[(f64, f64)]) -> impl Fn(&mut SplitMix) -> Option<Vec<f64>> + '_ {
    move |rng| Some(ranges.iter().map(|&(lo, hi)| uniform(rng, lo, hi)).collect())
}

/// The outputs of a branch the forward plan of `file` solves at inputs
/// drawn in `ranges` (by the Newton reference's own output map).
fn reached(file: &str, ranges: &[(f64, f64)]) -> impl Fn(&mut SplitMix) -> Option<Vec<f64>> {
    let (a, model) = common::example(file);
    let plan = pkm::dsl::planner::forward_plan(&a).unwrap();
    let outputs = pkm::dsl::numeric::newton_outputs(&a, &model, &HashMap::new()).unwrap();
    let ranges = ranges.to_vec();
    move |rng| {
        let q: Vec<f64> = ranges.iter().map(|&(lo, hi)| uniform(rng, lo, hi)).collect();
        let solved: Vec<Vec<f64>> = plan::run_all(&model, &plan, &q)
            .into_iter()
            .filter_map(|(_, r)| r.ok().map(|s| s.model_values(&model)))
            .collect();
        let pick = solved.get((uniform(rng, 0.0, solved.len() as f64) as usize).min(solved.len().max(1) - 1))?;
        pkm::runtime::reference::output_values(&model, &outputs, pick).ok()
    }
}

/// The forward plans' inputs of the examples and the ranges drawn.
const FORWARD: [(&str, &[(f64, f64)]); 27] = [
    ("four_bar", &[(-PI, PI)]),
    ("slider_crank", &[(-PI, PI)]),
    ("inverted_slider_crank", &[(-PI, PI)]),
    ("crank_shaper", &[(-PI, PI)]),
    ("cylinder_rocker", &[(-60.0, 300.0)]),
    ("scotch_yoke", &[(-PI, PI)]),
    ("four_bar_coupler_driven", &[(-PI, PI)]),
    ("spherical_four_bar", &[(-PI, PI)]),
    ("five_bar", &[(1.2, 2.8), (0.3, 1.9)]),
    ("five_bar_tool", &[(1.2, 2.8), (0.3, 1.9)]),
    ("five_bar_slide", &[(-150.0, 150.0), (-PI, PI)]),
    ("rrrrp_tool", &[(-PI, PI), (-150.0, 250.0)]),
    ("trammel", &[(-PI, PI)]),
    ("inverted_slider_crank_block_driven", &[(-PI, PI)]),
    ("watt_six_bar", &[(-PI, PI)]),
    ("seed003_punch", &[(-PI, PI)]),
    ("seed000_a", &[(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)]),
    ("seed000_a_u", &[(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)]),
    ("seed000_b", &[(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)]),
    ("five_bar_pa", &[(-PI, PI), (-PI, PI), (-300.0, 300.0)]),
    ("rrrp_2t1r", &[(-250.0, 0.0), (0.0, 250.0), (0.0, 1.2)]),
    ("schoenflies_2limb", &SCHOENFLIES),
    ("translational_2limb", &[(-200.0, 200.0), (0.5, 2.5), (-100.0, 300.0)]),
    ("spherical_five_bar", &[(-PI, PI), (-PI, PI)]),
    ("rssr", &[(-PI, PI)]),
    ("rssp", &[(-PI, PI)]),
    ("rsur", &[(-PI, PI)]),
];

/// Every forward assembly Newton finds from random starts is listed
/// ([`every_assembly`]). Before the parallelogram plane's second root,
/// seed 000 A's four unlisted postures failed here.
#[test]
fn every_forward_assembly_is_listed() {
    for (file, ranges) in FORWARD {
        let (matched, _) = every_assembly(file, true, &within(ranges), 6, 40, &[]);
        assert!(matched >= 60, "{file}: Newton converged only {matched} times");
    }
}

/// Every inverse assembly Newton finds from random starts is listed, at
/// poses the forward plans reach and at the spatial platforms' own poses
/// (`common::poses`). A U-P leg's cross is taken on one side
/// (`plane_through`): the other turns the cross and the leg half a turn
/// about the leg's line, so the U's values are not compared there.
#[test]
fn every_inverse_assembly_is_listed() {
    for (file, ranges) in FORWARD.iter().filter(|(f, _)| *f != "seed003_punch") {
        let (matched, _) = every_assembly(file, false, &reached(file, ranges), 6, 40, &[]);
        assert!(matched >= 60, "{file}: Newton converged only {matched} times");
    }
    let planar = |rng: &mut SplitMix| {
        Some(vec![
            20.0 * rng.symmetric(),
            20.0 * rng.symmetric(),
            0.2 * rng.symmetric(),
        ])
    };
    let platforms: [(&str, Draw<'_>, &[&str]); 8] = [
        ("planar_3rpr", &planar, &[]),
        ("planar_3rrr", &planar, &[]),
        ("rps_3", &|rng| Some(common::poses::seed(rng).to_vec()), &[]),
        ("spr_3", &|rng| Some(common::poses::seed(rng).to_vec()), &[]),
        ("rps_3_tilt", &|rng| Some(common::poses::tilt(rng).to_vec()), &[]),
        ("prs_3", &|rng| Some(common::poses::tilt(rng).to_vec()), &[]),
        ("ups_6", &|rng| Some(common::poses::ups(rng).to_vec()), &["U"]),
        ("upu_3", &|rng| Some(common::poses::upu(rng).to_vec()), &["U"]),
    ];
    for (file, draw, convention) in platforms {
        let (matched, _) = every_assembly(file, false, draw, 6, 40, convention);
        assert!(matched >= 60, "{file}: Newton converged only {matched} times");
    }
}

/// The Bennett linkage (tests/fixtures/bennett_driven.pkm: a = 100, α =
/// 0.5, β = 1, b = a sin β / sin α), its mobility accepted by `mobility by
/// geometry`: F = 1 where generic instances give 0, R1 driven. Bennett's
/// relation (Bennett 1914; Baker 1979, with Denavit–Hartenberg angles from
/// the common normals): tan(θ₁/2)·tan(θ₂/2) = sin((β + α)/2) / sin((β − α)/2)
/// at the joints between the links of twists β, α (R1) and α, β (R2).
/// Here the base's x runs from R1 to R4, so the normal arriving at R1
/// points along −x: θ₁ = R1 + π, θ₂ = R2; the opposite joints turn as
/// θ₃ = θ₁ and θ₄ = θ₂ (R3 = π − R1 and R4 = R2 + π in these frames,
/// where l2's and l3's normals leave R3 and R4 the other way). Every input
/// has one assembly; the plan lists it and Newton agrees; the generated
/// fk equals the interpreter and its ik finds the input again.
#[test]
fn bennett_linkage() {
    let path = common::root().join("tests/fixtures/bennett_driven.pkm");
    let text = std::fs::read_to_string(&path).unwrap();
    let c = pkm::dsl::compile(&text).unwrap();
    let t = &c.analysis.topology;
    assert_eq!((t.dof, t.generic_dof, t.xi()), (1, Some(0), vec![3]));
    let model = c.model().unwrap().clone();
    let solve = solver(c.forward().unwrap().clone());
    check_solver("bennett_driven", &model, &solve, &[(-3.1, 3.1)], 200);
    let (alpha, beta) = (0.5f64, 1.0f64);
    let ratio = ((beta + alpha) / 2.0).sin() / ((beta - alpha) / 2.0).sin();
    let wrap = |x: f64| x.sin().atan2(x.cos());
    let generated = |q: f64| {
        crate::mechanisms::BennettDriven::fk(&Default::default(), &[q])
            .iter()
            .filter_map(|b| b.result.as_ref().ok().cloned())
            .collect::<Vec<_>>()
    };
    for r1 in [-3.0, -2.0, -1.0, -0.3, 0.0, 0.3, 1.0, 2.0, 3.0] {
        let solved = solve(&model, &[r1]);
        assert_eq!(solved.len(), 1, "R1 = {r1}");
        let q = &solved[0].1;
        let (t1, t2) = (r1 + PI, q[1]);
        // Multiplied out (θ₁ = π at R1 = 0, where the tangent is infinite).
        let miss = (t1 / 2.0).sin() * (t2 / 2.0).sin() - ratio * (t1 / 2.0).cos() * (t2 / 2.0).cos();
        assert!(
            miss.abs() <= 1e-12 * ratio,
            "R1 = {r1}: Bennett's relation misses by {miss}"
        );
        assert!(wrap(q[2] - (PI - r1)).abs() <= 1e-12, "R1 = {r1}: R3 = {}", q[2]);
        assert!(wrap(q[3] - (q[1] + PI)).abs() <= 1e-12, "R1 = {r1}: R4 = {}", q[3]);
        // Generated code: the same assembly, and its ik (given ψ = R4)
        // finds R1 again.
        let g = generated(r1);
        assert_eq!(g.len(), 1, "generated, R1 = {r1}");
        for (a, b) in g[0].q.iter().zip(q) {
            assert!(wrap(a - b).abs() <= 1e-12, "generated {:?} vs {q:?}", g[0].q);
        }
        let ik = crate::mechanisms::BennettDriven::ik(&Default::default(), &g[0].outputs);
        let back: Vec<f64> = ik
            .iter()
            .filter_map(|b| b.result.as_ref().ok())
            .map(|s| s.q[0])
            .collect();
        assert!(
            back.iter().any(|b| wrap(b - r1).abs() <= 1e-9),
            "R1 = {r1}: ik gives {back:?}"
        );
    }
}

/// The two-limb Schönflies robot's study ranges (P1, R1, R4, R5).
const SCHOENFLIES: [(f64, f64); 4] = [(-100.0, 200.0), (-0.5, 2.0), (-1.5, 1.5), (1.6, 2.8)];

#[test]
fn schoenflies_2limb() {
    check("schoenflies_2limb", &SCHOENFLIES, 200);
}

/// By hand, the two-limb Schönflies robot (d = 400, l1 = 250, l2 = 200,
/// l4 = 250, l5 = 200, l6 = 150) seen along z, at poses built first: the
/// arm puts R2 at A = l1·(cos θ1, sin θ1); R3 at B = A + l2·(cos β, sin β);
/// the platform turned φ has R6's axis at D = B + c·(cos φ, sin φ), where
/// c = e + l6 is how far the platform and the wrist, one body seen along z
/// across P2, keep R6 from R3; the SCARA arm reaches D by its two-link
/// inverse (|D − (d, 0)| = r: cos θ5 = (r² − l4² − l5²)/(2·l4·l5)). From
/// those inputs the forward plan must return B and φ among its branches,
/// the turn that aims P2's line at R6 (`steps::aim_along`) to within
/// 1e-15·400/c of φ (B and D hold a few units in the last place of the
/// robot's 400 mm, the turn divides them by c), as c shrinks from 270 mm
/// to 1 µm; at c = 0 (R6's image on R3's axis: every turn aims it) a typed
/// refusal, no number.
#[test]
fn schoenflies_2limb_by_hand_near_the_aims_degenerate_case() {
    let (d, l1, l2, l4, l5, l6) = (400.0f64, 250.0f64, 200.0, 250.0, 200.0, 150.0);
    let text = common::example_text("schoenflies_2limb").0;
    let (r3, p2) = (3, 7);
    for c in [270.0, 30.0, 1.0, 1e-3, 1e-6] {
        let (model, solve) = load_text(&text.replace("e = 120;", &format!("e = {};", c - l6)));
        assert_eq!(model.joints[r3].name, "R3");
        assert_eq!(model.joints[p2].name, "P2");
        for (theta1, beta, phi, z) in [
            (0.9, -0.6, 0.3, 50.0),
            (0.4, 0.8, -2.0, -80.0),
            (1.2, -0.9, -0.4, 150.0),
        ] {
            let a = [l1 * f64::cos(theta1), l1 * f64::sin(theta1)];
            let b = [a[0] + l2 * f64::cos(beta), a[1] + l2 * f64::sin(beta)];
            let dd = [b[0] + c * f64::cos(phi), b[1] + c * f64::sin(phi)];
            let (u, v) = (dd[0] - d, dd[1]);
            let theta5 = ((u * u + v * v - l4 * l4 - l5 * l5) / (2.0 * l4 * l5)).acos();
            let theta4 = v.atan2(u) - (l5 * theta5.sin()).atan2(l4 + l5 * theta5.cos());
            assert!(theta5.is_finite(), "c = {c}: D = {dd:?} out of the SCARA arm's reach");
            let got = solve(&model, &[z, theta1, theta4, theta5]);
            // The branch whose R3 is B (the other puts it at B's mirror in AD).
            let near = got
                .iter()
                .find(|(_, _, pts)| (pts[r3][0] - b[0]).hypot(pts[r3][1] - b[1]) < 1e-9 * 400.0);
            let Some((_, _, pts)) = near else {
                panic!(
                    "c = {c}: B = {b:?} missing from {:?}",
                    got.iter().map(|g| g.2[r3]).collect::<Vec<_>>()
                )
            };
            // P2's slider point on the wrist: D − l6·(cos φ, sin φ).
            let want = [dd[0] - l6 * phi.cos(), dd[1] - l6 * phi.sin()];
            let angle = (pts[p2][1] - dd[1]).atan2(pts[p2][0] - dd[0]) - (want[1] - dd[1]).atan2(want[0] - dd[0]);
            let angle = (angle + PI).rem_euclid(2.0 * PI) - PI;
            assert!(angle.abs() <= 1e-15 * 400.0 / c + 1e-13, "c = {c}: φ off by {angle:e}");
            assert!(
                (pts[r3][2] - z).abs() <= 1e-12 * 400.0,
                "c = {c}: height {}",
                pts[r3][2]
            );
        }
    }
    // At c = 0 (e = −l6: R6's image on R3's axis, every turn aims it; the
    // platform then spins freely about the common axis), the declared
    // plan run on that geometry, at inputs that put R6 where R3 can be:
    // no branch returns a number.
    let plan = pkm::dsl::planner::forward_plan(&pkm::dsl::analyze_source(&text).unwrap()).unwrap();
    let flat = pkm::dsl::analyze_source(&text.replace("e = 120;", "e = -150;")).unwrap();
    let model = pkm::dsl::numeric::model(&flat, &HashMap::new()).unwrap();
    let (theta1, beta) = (0.9f64, -0.6f64);
    let dd = [l1 * theta1.cos() + l2 * beta.cos(), l1 * theta1.sin() + l2 * beta.sin()];
    let (u, v) = (dd[0] - d, dd[1]);
    let theta5 = ((u * u + v * v - l4 * l4 - l5 * l5) / (2.0 * l4 * l5)).acos();
    let theta4 = v.atan2(u) - (l5 * theta5.sin()).atan2(l4 + l5 * theta5.cos());
    let results = plan::run_all(&model, &plan, &[0.0, theta1, theta4, theta5]);
    assert!(
        results.iter().all(|(_, r)| r.is_err()),
        "c = 0: {:?}",
        results
            .iter()
            .map(|(_, r)| r.as_ref().map(|s| s.values.clone()))
            .collect::<Vec<_>>()
    );
}

#[test]
fn translational_2limb() {
    check(
        "translational_2limb",
        &[(-200.0, 200.0), (0.5, 2.5), (-100.0, 300.0)],
        200,
    );
}

/// By hand, the two-limb 3T (d = 400, l1 = 250, l2 = 200, l4 = 250,
/// l5 = 200): the platform does not turn, so o = (P1, P2, z): limb I's
/// slide gives x and its arm, in the plane x = P1, puts R2 at
/// (l1 cos θ1, l1 sin θ1) in (y, z), so z = l1 sin θ1 ± √(l2² − (P2 −
/// l1 cos θ1)²); limb II's arm, in the plane y = P2, reaches R6 at
/// (P1 + d, z) from R4 at (d, 0) in two elbows where l4 − l5 ≤ √(P1² + z²)
/// ≤ l4 + l5. The assemblies are exactly those (o to 1e-9 mm), each z once
/// per elbow.
#[test]
fn translational_2limb_by_hand() {
    let (model, solve) = load("translational_2limb");
    let (l1, l2, l4, l5) = (250.0f64, 200.0f64, 250.0f64, 200.0f64);
    let r3 = model.joints.iter().position(|j| j.name == "R3").unwrap();
    for (p1, theta1, p2) in [
        (0.0, 1.0, 100.0),
        (-150.0, 2.0, 50.0),
        (120.0, 0.7, 250.0),
        (30.0, 1.6, -60.0),
    ] {
        let (cy, cz) = (l1 * f64::cos(theta1), l1 * f64::sin(theta1));
        let h = (l2 * l2 - (p2 - cy).powi(2)).sqrt();
        let mut want = Vec::new();
        for z in [cz + h, cz - h] {
            let r = (p1 * p1 + z * z).sqrt();
            if (l4 - l5..=l4 + l5).contains(&r) {
                want.extend([[p1, p2, z], [p1, p2, z]]);
            }
        }
        assert!(!want.is_empty(), "at ({p1}, {theta1}, {p2}): a sample that reaches");
        let mut got: Vec<[f64; 3]> = solve(&model, &[p1, theta1, p2])
            .iter()
            .map(|(_, _, pts)| pts[r3])
            .collect();
        assert_eq!(got.len(), want.len(), "at ({p1}, {theta1}, {p2}): {got:?} vs {want:?}");
        for w in &want {
            let i = got
                .iter()
                .position(|g| (0..3).all(|k| (g[k] - w[k]).abs() < 1e-9))
                .unwrap_or_else(|| panic!("at ({p1}, {theta1}, {p2}): {w:?} missing from {got:?}"));
            got.remove(i);
        }
    }
}

#[test]
fn spherical_five_bar() {
    check("spherical_five_bar", &[(-PI, PI), (-PI, PI)], 200);
}

/// The two unit directions at angle `a` from unit `w` and `b` from unit
/// `u` (two cones through the centre): `α·w + β·u ± γ·(w × u)` with
/// `[1 c; c 1]·(α, β) = (cos a, cos b)`, `c = w·u`,
/// `γ² = (1 − α cos a − β cos b)/|w × u|²`.
fn two_cones(
    w: pkm::runtime::nalgebra::Vector3<f64>,
    a: f64,
    u: pkm::runtime::nalgebra::Vector3<f64>,
    b: f64,
) -> [pkm::runtime::nalgebra::Vector3<f64>; 2] {
    let c = w.dot(&u);
    let det = 1.0 - c * c;
    let (alpha, beta) = ((a.cos() - c * b.cos()) / det, (b.cos() - c * a.cos()) / det);
    let n = w.cross(&u);
    let g = ((1.0 - alpha * a.cos() - beta * b.cos()) / n.norm_squared()).sqrt();
    [alpha * w + beta * u + g * n, alpha * w + beta * u - g * n]
}

/// Whether the two cones of [`two_cones`] nearly touch (γ below 1e-5:
/// their meeting is a double root, found to about √ε, not to 1e-12).
fn cones_touch(
    w: pkm::runtime::nalgebra::Vector3<f64>,
    a: f64,
    u: pkm::runtime::nalgebra::Vector3<f64>,
    b: f64,
) -> bool {
    let [p, m] = two_cones(w, a, u, b);
    // NaN (just past the tangency by rounding) counts as touching.
    let gap = (p - m).norm();
    gap.is_nan() || gap <= 2e-5
}

/// By hand, the spherical five-bar's distal dyad (a2 = a3 = 60°, r = 100):
/// with the unit axes w = R2/r and u = R4/r of a solution (the proximal
/// links, given by the inputs alone), R3's axis v keeps 60° from both:
/// v = α·w + β·u ± γ·(w × u), [1 c; c 1]·(α, β) = (cos a2, cos a3),
/// c = w·u, γ² = (1 − α cos a2 − β cos a3)/|w × u|². The two branches'
/// P/r are exactly v₊ and v₋ (1e-12), over a grid of both cranks. The
/// inverse plan, P given, returns the four arms' postures from the same
/// two cones about each base axis (1e-12; an arm whose cones touch, where
/// the grid puts P in the base axes' plane, is a double root found to
/// about √ε and not compared), the cranks' q among them.
#[test]
fn spherical_five_bar_by_hand() {
    let (a, model) = common::example("spherical_five_bar");
    let plan = pkm::dsl::planner::forward_plan(&a).unwrap();
    let r = 100.0;
    let inverse = pkm::dsl::planner::inverse_plan(&a).unwrap();
    let (a0, a1) = (PI / 6.0, PI / 4.0);
    let u1 = pkm::runtime::nalgebra::Vector3::new(-a0.sin(), 0.0, a0.cos());
    let u5 = pkm::runtime::nalgebra::Vector3::new(a0.sin(), 0.0, a0.cos());
    let mut touching = 0;
    let named = |n: &str| model.joints.iter().position(|j| j.name == n).unwrap();
    let (r2, r4) = (named("R2"), named("R4"));
    let unit = |v: [f64; 3]| pkm::runtime::nalgebra::Vector3::from(v) / r;
    let mut seen = 0;
    for i in 0..12 {
        for k in 0..12 {
            let q = [
                -PI + 2.0 * PI * f64::from(i) / 12.0,
                -PI + 2.0 * PI * f64::from(k) / 12.0,
            ];
            let got: Vec<_> = plan::run_all(&model, &plan, &q)
                .into_iter()
                .filter_map(|(_, r)| r.ok())
                .collect();
            let Some(first) = got.first() else { continue };
            let (w, u) = (
                unit(kinematics::joint_point(&model, &first.poses, r2)),
                unit(kinematics::joint_point(&model, &first.poses, r4)),
            );
            let want = two_cones(w, PI / 3.0, u, PI / 3.0);
            assert_eq!(got.len(), 2, "at {q:?}: {} branches", got.len());
            for s in &got {
                let at = unit(kinematics::point(&model, &s.poses, "P").unwrap());
                assert!(
                    want.iter().any(|v| (v - at).norm() < 1e-12),
                    "at {q:?}: P/r = {at:?}, not one of {want:?}"
                );
            }
            assert!(
                (unit(kinematics::point(&model, &got[0].poses, "P").unwrap())
                    - unit(kinematics::point(&model, &got[1].poses, "P").unwrap()))
                .norm()
                    > 1e-6,
                "at {q:?}: both branches at one P"
            );
            // Inverse: each P gives each arm's R2 (R4) axis at a1 (a4 = a1)
            // from its base axis and a2 (a3) from P, two each: 4 branches,
            // one of them the cranks' q.
            for s in &got {
                let p = kinematics::point(&model, &s.poses, "P").unwrap();
                let back: Vec<_> = plan::run_all(&model, &inverse, &p)
                    .into_iter()
                    .filter_map(|(_, r)| r.ok())
                    .collect();
                let v = unit(p);
                let (left, right) = (two_cones(u1, a1, v, PI / 3.0), two_cones(u5, a1, v, PI / 3.0));
                let touch = [cones_touch(u1, a1, v, PI / 3.0), cones_touch(u5, a1, v, PI / 3.0)];
                // At a tangency a branch is the other's double root, listed once.
                let want = if touch[0] || touch[1] { 2..=4 } else { 4..=4 };
                assert!(
                    want.contains(&back.len()),
                    "at P = {p:?}: {} inverse branches",
                    back.len()
                );
                touching += usize::from(touch[0] || touch[1]);
                for b in &back {
                    let w = unit(kinematics::joint_point(&model, &b.poses, r2));
                    let u = unit(kinematics::joint_point(&model, &b.poses, r4));
                    assert!(
                        touch[0] || left.iter().any(|x| (x - w).norm() < 1e-12),
                        "at P = {p:?}: R2/r = {w:?}, not one of {left:?}"
                    );
                    assert!(
                        touch[1] || right.iter().any(|x| (x - u).norm() < 1e-12),
                        "at P = {p:?}: R4/r = {u:?}, not one of {right:?}"
                    );
                }
                let values: Vec<Vec<f64>> = back.iter().map(|b| b.model_values(&model)).collect();
                let wrap = |x: f64| (x + PI).rem_euclid(2.0 * PI) - PI;
                let tol = if touch[0] || touch[1] { 1e-7 } else { 1e-9 };
                assert!(
                    values
                        .iter()
                        .any(|v| wrap(v[0] - q[0]).abs() < tol && wrap(v[4] - q[1]).abs() < tol),
                    "at P = {p:?}: the cranks {q:?} not among {values:?}"
                );
            }
            seen += 1;
        }
    }
    assert!(seen >= 100, "only {seen} of 144 grid nodes assemble");
    assert!(touching <= 12, "{touching} poses with an arm at its cones' tangency");
}

#[test]
fn rrrp_2t1r() {
    check("rrrp_2t1r", &[(-250.0, 0.0), (0.0, 250.0), (0.0, 1.2)], 200);
}

/// By hand, the 2T1R with an R-R-R-P branch (a = 300, l1 = 100, l2 = 200,
/// l3 = 450, l4 = 320, l5 = 250), in the yz plane seen along x: the
/// five-bar puts R4 (o) at y = −a, z = l1 ± √(l2² − ((P2 − P1)/2)²); R5 at
/// (a, l1) turns R6 to (a − l4 sin θ, l1 + l4 cos θ); R7 is where the circle
/// of radius l5 about R6 meets that of radius l3 about o (P3 slides along
/// x, so the platform keeps R7's axis l3 from R4's). Every assembly is one
/// of these (up to 2 × 2, where the circles meet), R7's point in y and z
/// to 1e-9 mm, and each appears.
#[test]
fn rrrp_2t1r_by_hand() {
    let (model, solve) = load("rrrp_2t1r");
    let (a, l1, l2, l3, l4, l5) = (300.0f64, 100.0f64, 200.0f64, 450.0f64, 320.0f64, 250.0f64);
    let r7 = model.joints.iter().position(|j| j.name == "R7").unwrap();
    // Circle–circle in the plane, both roots.
    let meet = |c0: [f64; 2], r0: f64, c1: [f64; 2], r1: f64| {
        let (dy, dz) = (c1[0] - c0[0], c1[1] - c0[1]);
        let d = dy.hypot(dz);
        let along = (r0 * r0 - r1 * r1 + d * d) / (2.0 * d);
        let h = (r0 * r0 - along * along).sqrt();
        let (uy, uz) = (dy / d, dz / d);
        let m = [c0[0] + along * uy, c0[1] + along * uz];
        [[m[0] - h * uz, m[1] + h * uy], [m[0] + h * uz, m[1] - h * uy]]
    };
    for (p1, p2, theta) in [
        (-150.0, 100.0, 0.5f64),
        (-200.0, 50.0, 0.8),
        (-100.0, 120.0, 0.2),
        (-60.0, 30.0, 1.0),
    ] {
        let half = (l2 * l2 - ((p2 - p1) / 2.0f64).powi(2)).sqrt();
        let r6 = [a - l4 * theta.sin(), l1 + l4 * theta.cos()];
        let mut want = Vec::new();
        for z in [l1 + half, l1 - half] {
            // Where the two circles meet (the other five-bar posture may not reach).
            want.extend(meet(r6, l5, [-a, z], l3).into_iter().filter(|p| p[0].is_finite()));
        }
        let got: Vec<[f64; 2]> = solve(&model, &[p1, p2, theta])
            .iter()
            .map(|(_, _, pts)| [pts[r7][1], pts[r7][2]])
            .collect();
        assert_eq!(got.len(), want.len(), "at ({p1}, {p2}, {theta}): {got:?} vs {want:?}");
        assert!(want.len() >= 2, "at ({p1}, {p2}, {theta}): a sample that reaches");
        let near = |u: [f64; 2], v: [f64; 2]| (u[0] - v[0]).abs().max((u[1] - v[1]).abs()) < 1e-9;
        for g in &got {
            assert!(
                want.iter().any(|w| near(*g, *w)),
                "at ({p1}, {p2}, {theta}): R7 at {g:?}, none of {want:?}"
            );
        }
        for w in &want {
            assert!(
                got.iter().any(|g| near(*g, *w)),
                "at ({p1}, {p2}, {theta}): {w:?} missing from {got:?}"
            );
        }
    }
}
