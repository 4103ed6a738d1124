//! Two paths that must agree, inverse direction: every branch of the
//! generated ik against Newton's inverse solution (the model with its
//! outputs as inputs), started 1e-3 away from that branch, at poses the
//! generated fk reaches from random inputs.

mod common;

use common::max_error;
use pkm::dsl::screw::SplitMix;
use pkm::runtime::kinematics;
use pkm::runtime::newton::{self, NewtonOptions};
use std::collections::HashMap;
use std::f64::consts::PI;

pkm::mechanism!(FourBar, file = "examples/mechanisms/four_bar.pkm");
pkm::mechanism!(SliderCrank, file = "examples/mechanisms/slider_crank.pkm");
pkm::mechanism!(Inverted, file = "examples/mechanisms/inverted_slider_crank.pkm");
pkm::mechanism!(Shaper, file = "examples/mechanisms/crank_shaper.pkm");
pkm::mechanism!(Cylinder, file = "examples/mechanisms/cylinder_rocker.pkm");
pkm::mechanism!(FiveBar, file = "examples/mechanisms/five_bar.pkm");
pkm::mechanism!(Watt, file = "examples/mechanisms/watt_six_bar.pkm");
pkm::mechanism!(FiveBarPa, file = "examples/mechanisms/five_bar_pa.pkm");
pkm::mechanism!(SeedA, file = "examples/mechanisms/seed000_a.pkm");
pkm::mechanism!(SeedB, file = "examples/mechanisms/seed000_b.pkm");
pkm::mechanism!(Rssr, file = "examples/mechanisms/rssr.pkm");
pkm::mechanism!(Rssp, file = "examples/mechanisms/rssp.pkm");

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
    check!(FiveBar, "five_bar", [(1.2, 2.8), (0.3, 1.9)]);
    check!(Watt, "watt_six_bar", [(-PI, PI)]);
}

#[test]
fn spatial() {
    check!(FiveBarPa, "five_bar_pa", [(-PI, PI), (-PI, PI), (-300.0, 300.0)]);
    check!(SeedA, "seed000_a", [(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)]);
    check!(SeedB, "seed000_b", [(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)]);
}

/// A mechanism with an S–S link (the RSSR, the R-S-S-P): its S joints have no one value in a solution, so
/// Newton starts from the model's values of each ik branch
/// (`Solution::model_values`, the rotation vectors from the interpreted
/// poses, 1e-3 off) and the revolutes and every joint point are compared.
macro_rules! with_spheres {
    ($ty:ident, $file:expr) => {{
        use pkm::runtime::spatial;
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
                for (_, s) in spatial::run_all(&model, &plan, &f.outputs) {
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
