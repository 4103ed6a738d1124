//! Singularity measures (pkm-runtime's `velocity::jacobians`) on the
//! conditions seed 000 §2.3 derives by hand for mechanisms A (§2.3.1) and B
//! (§2.3.2): placed exactly on each condition the measure vanishes
//! (relative σ below 1e-9), and a little off it does not; and the factor
//! pkm names for it (`singular`: the plan step whose derivative vanishes,
//! with its joint points) is the paper's condition read geometrically,
//! derived by hand in each test's comment. B's conditions the
//! paper rules out (x_E = x1 or x2, x1 = x2, z_E = l1: "not reachable") are
//! not placed.

use crate::common;
use crate::mechanisms::{SeedA, SeedB, SeedBSolution};

use pkm::runtime::primitives::Sign;
use pkm::runtime::velocity::{self, Singularity};
use pkm::runtime::{kinematics, plan, singular};
use std::collections::HashMap;

struct Setup {
    model: pkm::runtime::model::Model,
    outputs: Vec<pkm::runtime::newton::Output>,
    forward: plan::Plan,
    inverse: plan::Plan,
}

fn setup_file(name: &str) -> Setup {
    let (a, model) = common::example(name);
    let outputs = pkm::dsl::numeric::newton_outputs(&a, &model, &HashMap::new()).unwrap();
    Setup {
        model,
        outputs,
        forward: pkm::dsl::planner::forward_plan(&a).unwrap(),
        inverse: pkm::dsl::planner::inverse_plan(&a).unwrap(),
    }
}

fn setup() -> Setup {
    setup_file("seed000_a")
}

/// The smallest factor of the forward plan (`det J_o`) or of the inverse
/// plan (`det J_i`) at `q`, and what it says.
fn smallest(s: &Setup, q: &[f64], input: bool) -> (f64, String) {
    let poses = kinematics::link_poses(&s.model, q).unwrap();
    let plan = if input { &s.inverse } else { &s.forward };
    let f = singular::spatial_factors(&s.model, plan, &poses)
        .into_iter()
        .min_by(|a, b| a.value.total_cmp(&b.value))
        .unwrap();
    (f.value, f.describe(&s.model, &poses))
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
    let q = SeedA::fk_branch(&Default::default(), &[-106.09, 181.67, -70.29], [Sign::Plus; 3])
        .unwrap()
        .q;
    let (i, o, class) = measure(&s, &q);
    assert_eq!(class, Singularity::None, "{i:e} {o:e}");
    assert!(i > 1e-5 && o > 1e-3, "{i:e} {o:e}");
    for input in [false, true] {
        let (v, what) = smallest(&s, &q, input);
        assert!(v > 1e-2, "{what}: {v:e}");
    }
}

// The factors, read from the paper's conditions by hand. The five-bar's
// second circle: C1 turns about B1 at l2 and must stay l2 from B2; the
// circles touch (or coincide) when B1, C1, B2 are collinear (z_C1 = l1, the
// B's at height l1) or when B1 = B2 (x1 = x2).
const FIVE_BAR: &str = "the path of R12 (C1, o) moved by R11 (B1) touches the cylinder about R13 (B2)'s axis";
// D turns about R4 (the x axis through C3) and must stay l4 from B3: the
// circle touches the sphere when C3, D, B3 line up in the yz plane, the
// platform along C3B3: α = arctan((z_C3 − l1)/(y_C3 − a)), f33 = 0.
// With x1 = x2 the circles coincide: B1 and B2 are one point.
const FIVE_BAR_MET: &str =
    "the path of R12 (C1, o) moved by R11 (B1, B2) touches the cylinder about R13 (B1, B2)'s axis";
const PLATFORM: &str = "the path of R6 (D) moved by R4 (C1, o) touches the sphere about Pa (B3)";
// B3 slides along x and must stay l4 from D: tangent when B3D ⟂ x, x3 = x_D,
// and x_D = x_C3 since the platform turns about x.
const SLIDER_3: &str = "the path of R5 (B3) moved by P3 (A3) touches the sphere about Pa (D)";

#[test]
fn input_singularity_when_x3_equals_x_c3() {
    let s = setup();
    let p = Default::default();
    let x_c3 = SeedA::fk_branch(&p, &[-106.09, 181.67, -70.29], [Sign::Plus; 3])
        .unwrap()
        .points[SeedA::POINTS.iter().position(|n| *n == "o").unwrap()][0];

    for (dx, singular) in [(0.0, true), (2.0, false), (-2.0, false)] {
        let q = SeedA::fk(&p, &[-106.09, 181.67, x_c3 + dx]);
        for b in q.iter().filter_map(|b| b.result.as_ref().ok()) {
            assert!((b.q[P3] - (x_c3 + dx)).abs() < 1e-12);
            let (i, o, class) = measure(&s, &b.q);
            let (v, what) = smallest(&s, &b.q, true);
            if singular {
                assert!(
                    i < 1e-9 && matches!(class, Singularity::Input),
                    "x3 = x_C3: {i:e} {o:e}"
                );
                assert!(v < 1e-9 && what == SLIDER_3, "{what}: {v:e}");
            } else {
                assert!(v > 1e-4, "{what}: {v:e}");
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
fn check_output(s: &Setup, pose: [f64; 4], on: bool, what: &str, factor: &str) -> usize {
    let mut n = 0;
    // Solutions with x1 = x2 are on another output condition (tested below).
    for q in ik(pose).into_iter().filter(|q| (q[0] - q[4]).abs() > 1e-9) {
        let (_, o, _) = measure(s, &q);
        let (v, named) = smallest(s, &q, false);
        if on {
            assert!(o < 1e-9, "{what}: output σ {o:e} at {pose:?}");
            assert!(v < 1e-9 && named == factor, "{what}: {named}: {v:e}");
        } else {
            assert!(o > 1e-5, "{what}, off: output σ {o:e} at {pose:?}");
            assert!(v > 1e-4, "{what}, off: {named}: {v:e}");
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
            let (v, what) = smallest(&s, &q, false);
            assert!(v < 1e-9 && what == FIVE_BAR_MET, "{what}: {v:e}");
            met += 1;
        } else {
            assert!(o > 1e-3, "x1 ≠ x2: output σ {o:e}");
        }
    }
    // Four, each with the R5–parallelogram leg in either posture.
    assert_eq!(met, 8);
}

#[test]
fn output_singularity_when_c3_is_at_the_sliders_height() {
    // z_C3 = l1 = 100: the five-bar's distal links line up.
    let s = setup();
    assert!(check_output(&s, pose(100.0, -0.3), true, "z = l1", FIVE_BAR) > 0);
    assert!(check_output(&s, pose(110.0, -0.3), false, "z = l1 + 10", FIVE_BAR) > 0);
}

#[test]
fn output_singularity_on_f33() {
    // α = arctan((z_C3 − l1)/(y_C3 − a)) with y_C3 = −a: the platform lies
    // along C3B3, which the parallelogram's arm cannot turn.
    let s = setup();
    let z: f64 = 238.9192;
    let alpha = ((z - 100.0) / (-300.0 - 300.0)).atan();
    assert!(check_output(&s, pose(z, alpha), true, "f33 = 0", PLATFORM) > 0);
    assert!(check_output(&s, pose(z, alpha + 0.05), false, "f33 = 0, α + 0.05", PLATFORM) > 0);
}

// Mechanism B, §2.3.2. With x1, x2 fixed (x_E depends on them alone), x3 is
// moved until a condition holds, by bisection on one fk branch; there the
// measure vanishes and 2 mm of x3 away it does not.

fn setup_b() -> Setup {
    setup_file("seed000_b")
}

fn b_point(s: &SeedBSolution, name: &str) -> [f64; 3] {
    s.points[SeedB::POINTS.iter().position(|n| *n == name).unwrap()]
}

/// An x3 in [lo, hi] where `condition` changes sign on branch `signs`:
/// a scan for a sign change between reachable neighbours, then bisection.
fn root_in_x3(x12: [f64; 2], signs: [Sign; 3], lo: f64, hi: f64, condition: impl Fn(&SeedBSolution) -> f64) -> f64 {
    let p = Default::default();
    let f = |x3: f64| {
        SeedB::fk_branch(&p, &[x12[0], x12[1], x3], signs)
            .ok()
            .map(|s| condition(&s))
    };
    let steps = 600;
    let at = |k: usize| lo + (hi - lo) * k as f64 / steps as f64;
    let k = (0..steps)
        .find(|&k| matches!((f(at(k)), f(at(k + 1))), (Some(a), Some(b)) if a * b < 0.0))
        .expect("the condition changes sign somewhere in the reachable range");
    let (mut a, mut b) = (at(k), at(k + 1));
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if f(a).unwrap() * f(m).unwrap() <= 0.0 {
            b = m;
        } else {
            a = m;
        }
    }
    0.5 * (a + b)
}

fn b_measure(s: &Setup, x: [f64; 3], signs: [Sign; 3]) -> (f64, f64) {
    let q = SeedB::fk_branch(&Default::default(), &x, signs).unwrap().q;
    let (i, o, _) = measure(s, &q);
    (i, o)
}

/// The smallest input factor at an fk configuration of B.
fn b_input_factor(s: &Setup, x: [f64; 3], signs: [Sign; 3]) -> (f64, String) {
    smallest(s, &SeedB::fk_branch(&Default::default(), &x, signs).unwrap().q, true)
}

const X12: [f64; 2] = [-106.09, 181.67];

// B3 slides along x and must stay l5 from E: tangent when B3E ⟂ x, x3 = x_E.
const B_SLIDER_3: &str = "the path of Pa (B3) moved by P3 (A3) touches the sphere about Pa (E)";
// The rod's end C1 turns about R5 (the x axis through D) and must stay in
// the five-bar's plane y = −a: tangent when DC1 is along y, z_C1 = z_D.
const B_ROD: &str = "the path of R4 (C1) moved by R5 (D) touches the plane through R4 (C1)";
// D turns about R4 (the x axis through C1) at l3 and must stay l4 from R6's
// axis (the x axis through E): the circles touch when C1, D, E line up, f13 = 0.
const B_STRETCHED: &str = "the path of R5 (D) moved by R4 (C1) touches the cylinder about R6 (E)'s axis";
const UP: [Sign; 3] = [Sign::Minus, Sign::Minus, Sign::Plus];

#[test]
fn b_input_singularity_when_x3_equals_x_e() {
    let s = setup_b();
    let x_e = b_point(
        &SeedB::fk_branch(&Default::default(), &[X12[0], X12[1], 0.0], UP).unwrap(),
        "E",
    )[0];
    let (i, _) = b_measure(&s, [X12[0], X12[1], x_e], UP);
    assert!(i < 1e-9, "x3 = x_E: {i:e}");
    let (v, what) = b_input_factor(&s, [X12[0], X12[1], x_e], UP);
    assert!(v < 1e-9 && what == B_SLIDER_3, "{what}: {v:e}");
    let (i, _) = b_measure(&s, [X12[0], X12[1], x_e + 2.0], UP);
    assert!(i > 1e-7, "x3 = x_E + 2: {i:e}");
    assert!(b_input_factor(&s, [X12[0], X12[1], x_e + 2.0], UP).0 > 1e-4);
}

#[test]
fn b_input_singularity_when_c1_and_d_are_level() {
    // ④ z_C1 = z_D: the rod C1D horizontal.
    let s = setup_b();
    let level = |b: &SeedBSolution| b_point(b, "C1")[2] - b_point(b, "D")[2];
    // On the assembly with E below the five-bar, the rod passes level as x3 moves.
    let low = [Sign::Plus; 3];
    let x3 = root_in_x3(X12, low, -300.0, 300.0, level);
    let (i, o) = b_measure(&s, [X12[0], X12[1], x3], low);
    assert!(i < 1e-9, "z_C1 = z_D at x3 = {x3}: σ_in {i:e} (σ_out {o:e})");
    let (v, what) = b_input_factor(&s, [X12[0], X12[1], x3], low);
    assert!(v < 1e-9 && what == B_ROD, "{what}: {v:e}");
    for d in [-2.0, 2.0] {
        let (i, _) = b_measure(&s, [X12[0], X12[1], x3 + d], low);
        assert!(i > 1e-7, "x3 {d:+} from z_C1 = z_D: {i:e}");
        assert!(b_input_factor(&s, [X12[0], X12[1], x3 + d], low).0 > 1e-4);
    }
}

#[test]
fn b_output_singularity_when_rod_and_platform_line_up() {
    // ③ f13 = ∂|C1D|²/∂α = 0: C1, D and E in one line, the rod and the
    // platform stretched (|C1E| = l3 + l4 = 630). Paper typo: its f13 has the
    // factor −2l3; differentiating D = E − l4 (0, sin α, cos α) gives −2l4
    // (the zero set is the same). Its g33 reads 2(x_c3 − x3) in the matrix
    // and 2(x_E − x3) in the text; x_E is right for B (tested above). Built exactly: C1 from the
    // five-bar at Table 1's x1, x2; E on y = a at 630 from C1; α along C1E.
    let s = setup_b();
    let c1 = b_point(
        &SeedB::fk_branch(&Default::default(), &[X12[0], X12[1], 0.0], UP).unwrap(),
        "C1",
    );
    let (l1, l3, l4, l5, a) = (100.0, 180.0, 450.0, 320.0, 300.0);
    let dy = a - c1[1];
    let mut poses = 0;
    for sign in [1.0, -1.0] {
        let dz = sign * ((l3 + l4) * (l3 + l4) - dy * dy).sqrt();
        let e = [c1[0], a, c1[2] + dz];
        if (e[2] - l1).abs() > l5 {
            continue; // E out of reach of B3's arm
        }
        poses += 1;
        // D = E − l4 (0, sin α, cos α) = C1 + l3 û with û = (C1E)/|C1E|.
        let alpha = dy.atan2(dz);
        let mut found = 0;
        for b in SeedB::ik(&Default::default(), &[e[0], e[1], e[2], alpha]) {
            let Ok(sol) = b.result else { continue };
            if (sol.q[0] - X12[0]).abs() > 1e-6 || (b_point(&sol, "C1")[2] - c1[2]).abs() > 1e-6 {
                continue; // another five-bar assembly
            }
            if (sol.q[0] - sol.q[4]).abs() < 1e-9 {
                continue; // x1 = x2: singular by the five-bar, tested on A
            }
            let (_, o, _) = measure(&s, &sol.q);
            assert!(o < 1e-9, "f13 = 0 (C1E {sign:+}): σ_out {o:e}");
            let (v, what) = smallest(&s, &sol.q, false);
            assert!(v < 1e-9 && what == B_STRETCHED, "{what}: {v:e}");
            found += 1;
        }
        // Turned 0.05 rad off the line, the same E is regular.
        for b in SeedB::ik(&Default::default(), &[e[0], e[1], e[2] + 5.0, alpha + 0.05]) {
            let Ok(sol) = b.result else { continue };
            if (sol.q[0] - X12[0]).abs() > 1.0 {
                continue;
            }
            let (_, o, _) = measure(&s, &sol.q);
            assert!(o > 1e-5, "off f13 = 0: σ_out {o:e}");
            assert!(smallest(&s, &sol.q, false).0 > 1e-4);
        }
        assert!(found > 0, "no ik solution through C1 for the stretched pose {e:?}");
    }
    assert_eq!(poses, 1);
}

#[test]
fn combined_singularities_only_on_the_five_bars_reach() {
    // §2.3.1 says A has no combined singularity inside §2.2's ranges. Over a
    // grid of those ranges (both α roots of the paper's assembly) the input
    // and output measures never vanish together.
    let s = setup();
    let p = Default::default();
    let (mut nodes, mut closest) = (0, f64::INFINITY);
    for (k, m, n) in (0..13).flat_map(|k| (0..13).flat_map(move |m| (0..13).map(move |n| (k, m, n)))) {
        let q = [
            -250.0 + 250.0 * k as f64 / 12.0,
            250.0 * m as f64 / 12.0,
            -300.0 + 50.0 * n as f64,
        ];
        for signs in [
            [Sign::Minus, Sign::Plus, Sign::Plus],
            [Sign::Minus, Sign::Minus, Sign::Plus],
        ] {
            let Ok(b) = SeedA::fk_branch(&p, &q, signs) else {
                continue;
            };
            let (i, o, _) = measure(&s, &b.q);
            closest = closest.min(i.max(o));
            nodes += 1;
        }
    }
    eprintln!("{nodes} regular nodes: the smallest max(σ_in, σ_out) is {closest:e}");
    assert!(nodes > 2000 && closest > 1e-4, "{nodes} nodes, closest {closest:e}");
    // Arithmetic against the paper: on the edge of the five-bar's reach,
    // x2 − x1 = 2·l2 = 400 (in the ranges: x1 = −200, x2 = 200), the
    // five-bar lies flat (z_C3 = l1, output singular), and with x3 = x_C3 = 0
    // the slider is input-singular at once. The combined set is that line on
    // the boundary of the reachable inputs (and the corner x1 = x2 = 0), so
    // the paper's statement holds for the interior only.
    for signs in [
        [Sign::Minus, Sign::Plus, Sign::Plus],
        [Sign::Minus, Sign::Minus, Sign::Plus],
    ] {
        let b = SeedA::fk_branch(&p, &[-200.0, 200.0, 0.0], signs).unwrap();
        let (i, o, class) = measure(&s, &b.q);
        assert_eq!(class, Singularity::Combined, "{i:e} {o:e}");
        assert_eq!(smallest(&s, &b.q, false).1, FIVE_BAR);
        assert_eq!(smallest(&s, &b.q, true).1, SLIDER_3);
        // 1 mm inside the reach, regular again.
        let b = SeedA::fk_branch(&p, &[-199.0, 200.0, 0.0], signs).unwrap();
        assert_eq!(measure(&s, &b.q).2, Singularity::None);
    }
}

/// The RPR dyad's factor (`guide`): the inverted slider-crank with
/// the rocker's guide 70 = d − r off its pivot C (R3). At crank angle 0
/// the pin B (R2) is |CB| = 70 from C: the line through B at distance 70
/// from C is normal to CB, the two roots meet, and the forward plan's
/// factor, the cosine between the guide and the line from the turning
/// centre to the point it must pass, is 0; so is the forward solution's
/// output σ. At crank angle π/2, B = (0, 50), |CB| = 130 and the cosine is
/// √(130² − 70²)/130 on both branches, by hand.
#[test]
fn guide_through_factor_vanishes_where_the_guide_is_normal_to_cb() {
    let (text, _) = common::example_text("inverted_slider_crank");
    let guide = "P1 = through (0, 0) along x; R3 = (0, 0);";
    assert!(text.contains(guide));
    let text = text.replace(guide, "P1 = through (0, 70) along x; R3 = (0, 0);");
    let a = pkm::dsl::analyze_source(&text).unwrap();
    let model = pkm::dsl::numeric::model(&a, &HashMap::new()).unwrap();
    let outputs = pkm::dsl::numeric::newton_outputs(&a, &model, &HashMap::new()).unwrap();
    let plan = pkm::dsl::planner::forward_plan(&a).unwrap();
    let factor = |crank: f64| {
        let solved: Vec<_> = plan::run_all(&model, &plan, &[crank])
            .into_iter()
            .filter_map(|(_, r)| r.ok())
            .collect();
        // At the tangency the double root is listed once.
        assert_eq!(solved.len(), if crank == 0.0 { 1 } else { 2 }, "crank {crank}");
        solved
            .iter()
            .map(|s| {
                let f = singular::spatial_factors(&model, &plan, &s.poses)
                    .into_iter()
                    .min_by(|a, b| a.value.total_cmp(&b.value))
                    .unwrap();
                let o = velocity::jacobians(&model, &s.values, &outputs).unwrap().output_sigma;
                (f.value, f.describe(&model, &s.poses), o)
            })
            .collect::<Vec<_>>()
    };
    for (v, named, o) in factor(0.0) {
        assert!(v < 1e-7 && o < 1e-7, "{named}: {v:e}, output σ {o:e}");
        assert!(named.contains("is normal to the guide of P1"), "{named}");
    }
    let want = (130f64.powi(2) - 70f64.powi(2)).sqrt() / 130.0;
    for (v, named, o) in factor(std::f64::consts::FRAC_PI_2) {
        assert!(
            (v - want).abs() < 1e-12 && o > 1e-3,
            "{named}: {v} vs {want}, output σ {o:e}"
        );
    }
}

/// The factor of a point beyond a given slide (`beyond`), on the
/// cylinder rocker: the path of the rod pin R2 about R3 against the normal
/// of the circle about R1 (R2 − R1) is the sine of the triangle's angle at
/// R2. At s = 0, |R2R3| = 200, a = 150, |R1R3| = √(300² + 80²): by hand
/// cos = (150² + 200² − |R1R3|²)/(2·150·200), the factor √(1 − cos²) on both
/// branches. At full stroke, |R2R3| = |R1R3| + a, the triangle folds flat:
/// the factor and the output σ vanish.
#[test]
fn beyond_given_factor_is_the_sine_at_the_rod_pin() {
    let (a, model) = common::example("cylinder_rocker");
    let outputs = pkm::dsl::numeric::newton_outputs(&a, &model, &HashMap::new()).unwrap();
    let plan = pkm::dsl::planner::forward_plan(&a).unwrap();
    let factor = |s: f64| {
        plan::run_all(&model, &plan, &[s])
            .into_iter()
            .filter_map(|(_, r)| r.ok())
            .map(|sol| {
                let f = singular::spatial_factors(&model, &plan, &sol.poses)
                    .into_iter()
                    .find(|f| f.step == 0)
                    .unwrap();
                let o = velocity::jacobians(&model, &sol.values, &outputs).unwrap().output_sigma;
                (f.value, f.describe(&model, &sol.poses), o)
            })
            .collect::<Vec<_>>()
    };
    let r13 = 300f64.hypot(80.0);
    let cos = (150f64.powi(2) + 200f64.powi(2) - r13 * r13) / (2.0 * 150.0 * 200.0);
    let want = (1.0 - cos * cos).sqrt();
    let regular = factor(0.0);
    assert_eq!(regular.len(), 2);
    for (v, named, o) in regular {
        assert!(
            (v - want).abs() < 1e-12 && o > 1e-3,
            "{named}: {v} vs {want}, output σ {o:e}"
        );
        assert!(named.contains("touches the cylinder about R1"), "{named}");
    }
    let folded = factor(r13 + 150.0 - 200.0);
    assert!(!folded.is_empty());
    for (v, named, o) in folded {
        assert!(v < 1e-6 && o < 1e-6, "{named}: {v:e}, output σ {o:e}");
    }
}

/// The factor of a slide onto a line (`slide_to_line`): the sine between
/// the slide and the line. On a tangent mechanism (a block slides in the
/// crank's slot, pinned to a slider on the guide y = 80), the block's slide
/// along the slot at angle θ meets the slider's line along x: |sin θ| by
/// hand, vanishing as the slot turns onto the guide (θ → 0, where
/// s = 80/tan θ runs off). On the Scotch yoke the slot is normal to the
/// yoke's guide: 1 at every crank angle.
/// The factor of the forward plan's step that `is_step` picks, at each
/// input of `inputs`, on each of the `branches` branches that solve:
/// `want(input)` to 1e-12, its description containing `phrase`.
fn check_step_factor(
    a: &pkm::dsl::Analysis,
    is_step: fn(&plan::Step) -> bool,
    inputs: &[f64],
    branches: usize,
    want: impl Fn(f64) -> f64,
    phrase: &str,
) {
    let model = pkm::dsl::numeric::model(a, &HashMap::new()).unwrap();
    let plan = pkm::dsl::planner::forward_plan(a).unwrap();
    let k = plan.steps.iter().position(is_step).unwrap();
    for &q in inputs {
        let want = want(q);
        let solved: Vec<_> = plan::run_all(&model, &plan, &[q])
            .into_iter()
            .filter_map(|(_, r)| r.ok())
            .collect();
        assert_eq!(solved.len(), branches, "input {q}");
        for sol in solved {
            let f = singular::spatial_factors(&model, &plan, &sol.poses)
                .into_iter()
                .find(|f| f.step == k)
                .unwrap();
            let named = f.describe(&model, &sol.poses);
            assert!(
                (f.value - want).abs() < 1e-12,
                "input {q}: {named}: {} vs {want}",
                f.value
            );
            assert!(named.contains(phrase), "{named}");
        }
    }
}

#[test]
fn slide_to_line_factor_is_the_sine_between_slide_and_line() {
    let tangent = pkm::dsl::analyze_source(common::TANGENT_MECHANISM).unwrap();
    let (yoke, _) = common::example("scotch_yoke");
    let is_step = |s: &plan::Step| matches!(s, plan::Step::SlideToLine { .. });
    let inputs = [1.2, 0.5, -2.0, 1e-3, -1e-5];
    check_step_factor(
        &tangent,
        is_step,
        &inputs,
        1,
        |t| t.sin().abs(),
        "slides along the line",
    );
    check_step_factor(&yoke, is_step, &inputs, 1, |_| 1.0, "slides along the line");
}

/// `beyond` with a slide: a slider-crank (r = 50, l = 180) driven at
/// the rod–slider joint R3, the slider sliding the rod (turned −v) until
/// the crank pin R2 = (s − l·cos v, l·sin v) is on the circle |R2| = r. The
/// factor is the cosine between the slide (x) and the circle's normal R2:
/// |s − l·cos v|/r = √(r² − l²·sin²v)/r by hand, vanishing where
/// |sin v| = r/l (the two roots meet).
#[test]
fn beyond_given_slide_factor_by_hand() {
    let text = "mechanism driven {
        capabilities fk;
        planar;
        base R1 [crank] ∥ R2 [rod] ∥ R3* [slider] ⊥ P1 base;
        x ∥ P1;
        geometry {
            base   { R1 = (0, 0); P1 = through (0, 0) along x; }
            crank  { R1 = (0, 0); R2 = (50, 0); }
            rod    { R2 = (0, 0); R3 = (180, 0); }
            slider { R3 = (0, 0); P1 = (0, 0); }
        }
    }";
    let a = pkm::dsl::analyze_source(text).unwrap();
    check_step_factor(
        &a,
        |s| matches!(s, plan::Step::Beyond { .. }),
        &[0.0, 0.1, -0.2, 0.27],
        2,
        |v| (50.0f64 * 50.0 - (180.0 * f64::sin(v)).powi(2)).sqrt() / 50.0,
        "touches the cylinder about R1",
    );
}

/// The factor of a cone (`cone`), on the spherical four-bar's forward
/// plan: the path of the coupler's R3 axis about R2 against the normal of
/// the cone about R4, `|det[u2, u3, a4]|/(sin α2 sin α3)`, is the sine of
/// the spherical triangle R2–R3–R4's angle γ at R3 (the transmission
/// angle). By hand from the crank angle θ: the arc δ from R2 to R4 has
/// cos δ = sin α1 sin α4 cos θ + cos α1 cos α4, and the spherical law of
/// cosines gives cos γ = (cos δ − cos α2 cos α3)/(sin α2 sin α3), the same
/// on both branches.
#[test]
fn cone_factor_is_the_sine_of_the_transmission_angle() {
    let (a, _) = common::example("spherical_four_bar");
    let [a1, a2, a3, a4] = [30.0f64, 70.0, 60.0, 80.0].map(f64::to_radians);
    check_step_factor(
        &a,
        |s| matches!(s, plan::Step::Cone { .. }),
        &[-2.5, -1.0, 0.0, 0.7, 2.0, 3.1],
        2,
        |theta| {
            let cos_delta = a1.sin() * a4.sin() * f64::cos(theta) + a1.cos() * a4.cos();
            let cos_gamma = (cos_delta - a2.cos() * a3.cos()) / (a2.sin() * a3.sin());
            (1.0 - cos_gamma * cos_gamma).sqrt()
        },
        // R2 and R4 are placed where their axes cross the sphere, at B and D.
        "the axes of R2 (B), R3, R4 (D) lie in one plane",
    );
}

/// The factor of two turns about meeting axes (`two_turns`), on the
/// R-S-U-R's forward plan: the cosine between the normal of the U's two
/// axes (the rocker's x and the coupler's z) and the line from the U
/// centre to the crank's S centre. The coupler's z is normal to x and to
/// that line d, so `x × z = ∓d⊥/|x × d̂|` (d⊥ normal to x) and the factor
/// is `|d⊥|²/(|x × d̂|·l) = |x × d̂|`: the sine between the coupler and
/// the rocker's axis, `√(l² − (a cos θ − d)²)/l` by hand (the S centre at
/// x = a cos θ, the U centre at x = d), on all four branches; zero where
/// the coupler lies along the U's rocker axis (the cross's gimbal lock).
#[test]
fn two_turns_factor_is_the_sine_between_coupler_and_rocker_axis() {
    let (a, _) = common::example("rsur");
    let (crank, l, d) = (40.0f64, 160.0f64, 100.0f64);
    check_step_factor(
        &a,
        |s| matches!(s, plan::Step::TwoTurns { .. }),
        &[-2.5, -1.0, 0.0, 0.7, 2.0, 3.1],
        4,
        |theta| {
            let dx = crank * f64::cos(theta) - d;
            (l * l - dx * dx).sqrt() / l
        },
        "S1 lies in the plane of the axes of U1.b and U1.a",
    );
}
