//! Two paths that must agree, inverse direction: every branch of the
//! generated ik against Newton's inverse solution (the model with its
//! outputs as inputs), started 1e-3 away from that branch, at poses the
//! generated fk reaches from random inputs.

use crate::common;
use crate::mechanisms::{
    AgileEye, BlockDriven, CouplerDriven, Cylinder, FiveBar, FiveBarPa, FiveBarSlide, FiveBarTool, FourBar, Inverted,
    Rrrp2t1r, RrrrpTool, Rssp, Rssr, Rsur, Schoenflies, SeedA, SeedAU, SeedB, Shaper, SliderCrank, Spherical,
    SphericalFive, Trammel, Translational, Watt, Yoke,
};

use common::max_error;
use pkm::dsl::screw::SplitMix;
use pkm::runtime::kinematics;
use pkm::runtime::newton::{self, NewtonOptions};
use std::collections::HashMap;
use std::f64::consts::PI;

macro_rules! check {
    ($ty:ident, $file:expr, $ranges:expr) => {{
        let (a, model) = common::example($file);
        let outputs = pkm::dsl::numeric::newton_outputs(&a, &model, &HashMap::new()).unwrap();
        let scale = kinematics::model_scale(&model);
        let params = Default::default();
        let ranges: [(f64, f64); $ty::INPUTS.len()] = $ranges;
        let mut rng = SplitMix::new(7);
        let options = NewtonOptions {
            tolerance: 1e-14,
            ..NewtonOptions::default()
        };
        let (mut compared, mut same_branch) = (0, 0);
        for _ in 0..100 {
            let q = ranges.map(|(lo, hi)| lo + (hi - lo) * (rng.symmetric() + 1.0) / 2.0);
            for f in $ty::fk(&params, &q).iter().filter_map(|b| b.result.as_ref().ok()) {
                let ik = $ty::ik(&params, &f.outputs);
                let solved: Vec<_> = ik.iter().filter_map(|b| b.result.as_ref().ok()).collect();
                for (i, s) in solved.iter().enumerate() {
                    let guess: Vec<f64> = s.q.iter().map(|v| v + 1e-3 * rng.symmetric()).collect();
                    let reference = newton::solve_ik(&model, &outputs, &f.outputs, &guess, &options)
                        .unwrap_or_else(|e| panic!("{}: Newton ik failed at {:?}: {e}", $file, f.outputs));
                    // Newton lands on the started branch, or, next to a
                    // singularity, on a neighbour: it must be one of them.
                    let (best, e) = solved
                        .iter()
                        .map(|t| max_error(&t.q, &reference.values, &$ty::REVOLUTE, scale))
                        .enumerate()
                        .fold((0, f64::INFINITY), |b, (k, e)| if e < b.1 { (k, e) } else { b });
                    assert!(
                        e <= 1e-9,
                        "{}: at {:?} Newton is {e:e} from every ik branch",
                        $file,
                        f.outputs
                    );
                    compared += 1;
                    same_branch += usize::from(best == i);
                }
            }
        }
        eprintln!(
            "{}: {compared} ik branches, Newton on the same one {same_branch} times",
            $file
        );
        assert!(
            same_branch * 100 >= compared * 99,
            "{}: Newton changed branch too often",
            $file
        );
        assert!(compared >= 100, "{}: only {compared} ik branches compared", $file);
        compared
    }};
}

#[test]
fn planar() {
    check!(FourBar, "four_bar", [(-PI, PI)]);
    check!(SliderCrank, "slider_crank", [(-PI, PI)]);
    check!(Inverted, "inverted_slider_crank", [(-PI, PI)]);
    check!(Shaper, "crank_shaper", [(-PI, PI)]);
    check!(Cylinder, "cylinder_rocker", [(-60.0, 300.0)]);
    check!(Yoke, "scotch_yoke", [(-PI, PI)]);
    check!(CouplerDriven, "four_bar_coupler_driven", [(-PI, PI)]);
    check!(FiveBar, "five_bar", [(1.2, 2.8), (0.3, 1.9)]);
    check!(FiveBarTool, "five_bar_tool", [(1.2, 2.8), (0.3, 1.9)]);
    check!(FiveBarSlide, "five_bar_slide", [(-150.0, 150.0), (-PI, PI)]);
    check!(RrrrpTool, "rrrrp_tool", [(-PI, PI), (-150.0, 250.0)]);
    check!(Trammel, "trammel", [(-PI, PI)]);
    check!(BlockDriven, "inverted_slider_crank_block_driven", [(-PI, PI)]);
    check!(Watt, "watt_six_bar", [(-PI, PI)]);
}

#[test]
fn spherical() {
    check!(Spherical, "spherical_four_bar", [(-PI, PI)]);
    check!(SphericalFive, "spherical_five_bar", [(-PI, PI), (-PI, PI)]);
}

#[test]
fn spatial() {
    check!(FiveBarPa, "five_bar_pa", [(-PI, PI), (-PI, PI), (-300.0, 300.0)]);
    check!(SeedA, "seed000_a", [(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)]);
    check!(SeedAU, "seed000_a_u", [(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)]);
    check!(SeedB, "seed000_b", [(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)]);
    check!(Rrrp2t1r, "rrrp_2t1r", [(-250.0, 0.0), (0.0, 250.0), (0.0, 1.2)]);
    check!(Schoenflies, "schoenflies_2limb", SCHOENFLIES);
    check!(
        Translational,
        "translational_2limb",
        [(-200.0, 200.0), (0.5, 2.5), (-100.0, 300.0)]
    );
}

/// The two-limb Schönflies robot's study ranges (P1, R1, R4, R5).
const SCHOENFLIES: [(f64, f64); 4] = [(-100.0, 200.0), (-0.5, 2.0), (-1.5, 1.5), (1.6, 2.8)];

/// The agile eye (κ = 1, no forward solver; the example with an output,
/// tests/fixtures/agile_eye_ik.pkm) at the platform turned φ about
/// (1, 1, 1) from home: every generated ik branch against the interpreter,
/// against Newton started 1e-3 away, and against the hand solution. By
/// hand: limb i's base axis u = e_i, its platform axis v = Q·e_(i+1) (Q the
/// turn), and the proximal axis w, a right angle from both, is
/// ±(u × v)/|u × v|; the base joint turns w from its home e_(i+2) about u:
/// θ = atan2((e_(i+2) × w)·u, e_(i+2)·w), two values per limb, 2³ branches.
/// At φ = −2π/3, Q·e2 = e1 (u ∥ v for limb 1): the samples stay inside (−2, 2).
#[test]
fn agile_eye() {
    use pkm::runtime::nalgebra::{Rotation3, Unit, Vector3};
    let text = std::fs::read_to_string(common::root().join("tests/fixtures/agile_eye_ik.pkm")).unwrap();
    let a = pkm::dsl::analyze_source(&text).unwrap();
    let model = pkm::dsl::numeric::model(&a, &HashMap::new()).unwrap();
    let outputs = pkm::dsl::numeric::newton_outputs(&a, &model, &HashMap::new()).unwrap();
    let plan = pkm::dsl::planner::inverse_plan(&a).unwrap();
    let scale = kinematics::model_scale(&model).max(1.0);
    let params = Default::default();
    let options = NewtonOptions {
        tolerance: 1e-14,
        ..NewtonOptions::default()
    };
    let e = [Vector3::x(), Vector3::y(), Vector3::z()];
    let mut rng = SplitMix::new(11);
    let mut compared = 0;
    for _ in 0..100 {
        let phi = 2.0 * rng.symmetric();
        let given = [0.0, 0.0, 0.0, phi];
        let q_turn = Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::new(1.0, 1.0, 1.0)), phi);
        let hand: Vec<[f64; 2]> = (0..3)
            .map(|i| {
                let (u, home) = (e[i], e[(i + 2) % 3]);
                let w = u.cross(&(q_turn * e[(i + 1) % 3])).normalize();
                [w, -w].map(|w| home.cross(&w).dot(&u).atan2(home.dot(&w)))
            })
            .collect();
        let generated = AgileEye::ik(&params, &given);
        let interpreted = pkm::runtime::plan::run_all(&model, &plan, &given);
        assert_eq!(generated.len(), 8);
        for (g, (_, s)) in generated.iter().zip(&interpreted) {
            let (g, s) = (g.result.as_ref().unwrap(), s.as_ref().unwrap());
            for (x, y) in g.q.iter().zip(&s.values) {
                assert!((x - y).abs() <= 1e-12, "φ = {phi}: generated {x} vs interpreted {y}");
            }
            for (i, want) in hand.iter().enumerate() {
                let got = g.q[3 * i];
                let off = want
                    .iter()
                    .map(|w| ((got - w).sin().atan2((got - w).cos())).abs())
                    .fold(f64::INFINITY, f64::min);
                assert!(off < 1e-12, "φ = {phi}: limb {i}: {got} vs {want:?}");
            }
            let guess: Vec<f64> = g.q.iter().map(|v| v + 1e-3 * rng.symmetric()).collect();
            let reference = newton::solve_ik(&model, &outputs, &given, &guess, &options)
                .unwrap_or_else(|e| panic!("agile_eye: Newton ik failed at φ = {phi}: {e}"));
            let err = max_error(&g.q, &reference.values, &AgileEye::REVOLUTE, scale);
            assert!(err <= 1e-9, "φ = {phi}: Newton is {err:e} from the branch");
            compared += 1;
        }
        // The eight branches are the eight choices of the three limbs.
        let mut firsts: Vec<[i64; 3]> = generated
            .iter()
            .map(|b| {
                let q = &b.result.as_ref().unwrap().q;
                [0, 3, 6].map(|k| (q[k].sin().atan2(q[k].cos()) * 1e6).round() as i64)
            })
            .collect();
        firsts.sort_unstable();
        firsts.dedup();
        assert_eq!(firsts.len(), 8, "φ = {phi}");
    }
    eprintln!("agile_eye: {compared} ik branches, each on Newton's and the hand solution");
}

/// A mechanism with an S–S link (the RSSR, the R-S-S-P): its S joints have no one value in a solution, so
/// Newton starts from the model's values of each ik branch
/// (`Solution::model_values`, the rotation vectors from the interpreted
/// poses, 1e-3 off) and the revolutes and every joint point are compared.
macro_rules! with_spheres {
    ($ty:ident, $file:expr) => {{
        use pkm::runtime::plan;
        let (a, model) = common::example($file);
        let outputs = pkm::dsl::numeric::newton_outputs(&a, &model, &HashMap::new()).unwrap();
        let plan = pkm::dsl::planner::inverse_plan(&a).unwrap();
        let scale = kinematics::model_scale(&model);
        let (offsets, _) = model.value_offsets();
        let options = NewtonOptions {
            tolerance: 1e-14,
            ..NewtonOptions::default()
        };
        let mut rng = SplitMix::new(7);
        let mut compared = 0;
        for _ in 0..100 {
            let q = [PI * rng.symmetric()];
            for f in $ty::fk(&Default::default(), &q)
                .iter()
                .filter_map(|b| b.result.as_ref().ok())
            {
                for (_, s) in plan::run_all(&model, &plan, &f.outputs) {
                    let s = s.unwrap_or_else(|e| panic!("{}: ik at {:?}: {e}", $file, f.outputs));
                    let values = s.model_values(&model);
                    let guess: Vec<f64> = values.iter().map(|v| v + 1e-3 * rng.symmetric()).collect();
                    let reference = newton::solve_ik(&model, &outputs, &f.outputs, &guess, &options)
                        .unwrap_or_else(|e| panic!("{}: Newton ik failed at {:?}: {e}", $file, f.outputs));
                    for (j, joint) in model.joints.iter().enumerate() {
                        if joint.kind == pkm::runtime::model::JointType::R {
                            let e = max_error(&[values[offsets[j]]], &[reference.values[offsets[j]]], &[true], scale);
                            assert!(e <= 1e-9, "{} {}: {e:e} at {:?}", $file, joint.name, f.outputs);
                        }
                        let (p, r) = (
                            kinematics::joint_point(&model, &s.poses, j),
                            kinematics::joint_point(&model, &reference.poses, j),
                        );
                        let e = max_error(&p, &r, &[false; 3], scale);
                        assert!(e <= 1e-9, "{} point {}: {e:e} at {:?}", $file, joint.name, f.outputs);
                    }
                    compared += 1;
                }
            }
        }
        eprintln!("{}: {compared} ik branches", $file);
        assert!(compared >= 100, "{}: only {compared} ik branches compared", $file);
    }};
}

#[test]
fn rssr() {
    with_spheres!(Rssr, "rssr");
}

#[test]
fn rssp() {
    with_spheres!(Rssp, "rssp");
}

/// The R-S-U-R: every revolute's value (the U's two angles too) and every
/// joint point of each of the four ik branches.
#[test]
fn rsur() {
    with_spheres!(Rsur, "rsur");
}
