//! Generated forward solvers against the plan interpreter (two paths that
//! must agree), branch by branch, at many inputs.

use crate::common;
use crate::mechanisms::{
    CouplerDriven, Cylinder, FiveBar, FourBar, Inverted, Punch, PunchParams, Shaper, SliderCrank, Spherical, Watt, Yoke,
};

use pkm::runtime::plan;
use pkm::runtime::solution::signs_of;

fn interpreter(file: &str) -> (pkm::runtime::model::Model, plan::Plan) {
    let (a, model) = common::example(file);
    (model, pkm::dsl::planner::forward_plan(&a).unwrap())
}

/// The generated branch and the interpreted one give the same joint values
/// and the same points (to rounding), or both fail.
macro_rules! agree {
    ($ty:ident, $file:expr, $q:expr) => {{
        let (model, plan) = interpreter($file);
        let generated = $ty::fk(&Default::default(), &$q);
        assert_eq!(generated.len(), 1 << plan.branches);
        for (i, branch) in generated.iter().enumerate() {
            assert_eq!(branch.signs.to_vec(), signs_of::<16>(i)[..plan.branches].to_vec());
            let interpreted = plan::run(&model, &plan, &$q, &branch.signs);
            match (&branch.result, &interpreted) {
                (Ok(g), Ok(s)) => {
                    for (k, (a, b)) in g.q.iter().zip(&s.values).enumerate() {
                        assert!(
                            (a - b).abs() <= 1e-12 * b.abs().max(1.0),
                            "{} q[{k}]: {a} vs {b}",
                            $file
                        );
                    }
                    for (k, name) in $ty::POINTS.iter().enumerate().take(model.joints.len()) {
                        let p = pkm::runtime::newton::joint_point(&model, &s.poses, k);
                        let d = (g.points[k][0] - p[0]).hypot(g.points[k][1] - p[1]);
                        assert!(d <= 1e-12 * p[0].hypot(p[1]).max(1.0), "{} {name}: {d}", $file);
                    }
                }
                (Err(a), Err(b)) => assert_eq!(a, b, "{}", $file),
                (g, s) => panic!("{}: generated {g:?}, interpreted {s:?}", $file),
            }
        }
    }};
}

#[test]
fn generated_equals_interpreted() {
    for k in 0..720 {
        let t = -3.2 + k as f64 * 0.01;
        agree!(FourBar, "four_bar", [t]);
        agree!(SliderCrank, "slider_crank", [t]);
        agree!(Inverted, "inverted_slider_crank", [t]);
        agree!(Shaper, "crank_shaper", [t]);
        // The stroke from −60 to 300: out of reach at both ends.
        agree!(Cylinder, "cylinder_rocker", [100.0 + 50.0 * t]);
        agree!(Yoke, "scotch_yoke", [t]);
        agree!(CouplerDriven, "four_bar_coupler_driven", [t]);
        agree!(Punch, "seed003_punch", [t]);
        agree!(Watt, "watt_six_bar", [t]);
        agree!(Spherical, "spherical_four_bar", [t]);
        agree!(
            FiveBar,
            "five_bar",
            [1.2 + (k % 40) as f64 * 0.04, 0.3 + (k / 40) as f64 * 0.09]
        );
    }
}

#[test]
fn generated_names_and_nominal_parameters() {
    assert_eq!(FourBar::INPUTS, ["R1"]);
    assert_eq!(Punch::JOINTS, ["A", "B", "C", "P1", "D", "G", "G.2", "F", "P2", "H"]);
    assert_eq!(FourBar::POINTS[4], "E");
    assert_eq!(PunchParams::default().l2, 117.0);
    // The seed 003 branch of the paper at φ = 30°: C below B, G by + arccos, F ≠ H.
    let sol = Punch::fk_branch(&PunchParams::default(), &[0.5], signs_of(0b011)).unwrap();
    assert!((sol.points[2][1] - 112.567).abs() < 1e-3, "{:?}", sol.points[2]);
}

/// Following the branch nearest the linear prediction over a whole crank turn
/// (720 steps) reproduces seed 003's description (F the intersection other
/// than H) even where the SOC3 dyad is tangent and its ± branches exchange
/// (near φ = 150°), which no fixed sign does.
#[test]
fn following_the_punch_through_a_crank_turn() {
    let p = PunchParams::default();
    let mut before = Punch::fk_branch(&p, &[-std::f64::consts::PI / 360.0], signs_of(0b011)).unwrap();
    let mut sol = Punch::fk_branch(&p, &[0.0], signs_of(0b011)).unwrap();
    let l7 = p.l7;
    for k in 1..=720 {
        let phi = k as f64 * std::f64::consts::PI / 360.0;
        let next = Punch::fk_follow(&p, &[phi], &sol, Some(&before)).unwrap();
        (before, sol) = (sol, next);
        // F = (2 l7 cos φ3, 0) with G = l7 (cos φ3, sin φ3): X_F = 2 X_G, never H unless X_G = 0.
        let (g, f) = (sol.points[5], sol.points[7]);
        assert!((f[0] - 2.0 * g[0]).abs() < 1e-9 * l7, "φ = {phi}: F = {f:?}, G = {g:?}");
        assert!((g[0].hypot(g[1]) - l7).abs() < 1e-9 * l7);
        assert!(sol.points[2][1] < sol.points[1][1], "C below B at φ = {phi}");
    }
}
