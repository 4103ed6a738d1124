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
pkm::mechanism!(SeedAU, file = "examples/mechanisms/seed000_a_u.pkm");
pkm::mechanism!(SeedB, file = "examples/mechanisms/seed000_b.pkm");

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
    check!(SeedAU, "seed000_a_u", [(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)]);
    check!(SeedB, "seed000_b", [(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)]);
}
