//! Why SeedB's worst ik∘fk round trip in `round_trips.rs` is 5.3e-11: the
//! conditioning of ik at that draw, not a solver's error.
//!
//! The draws below are that test's (same seed, same fk branch). At each,
//! the generated fk's pose and the generated ik of that pose are compared
//! with the 70-digit reference (`pkm_runtime::reference`, Newton on the
//! loop residual, no closed-form step involved), and ik's sensitivity to z
//! with a hand derivation: branch II holds E at the parallelogram's arm
//! length l5 from B3 = (P3, a, l1) in the plane y = a, so
//! `(x − P3)² + (z − l1)² = l5²` and `|∂P3/∂z| = |z − l1| / √(l5² − (z − l1)²)`,
//! which grows without bound as the arm turns upright (z → l1 ± l5). There
//! the round trip multiplies fk's last-bit rounding of z by that factor.

use crate::common;
use crate::mechanisms::{SeedB, SeedBSolution};

use common::max_error;
use pkm::runtime::newton::{self, NewtonOptions, Output};
use pkm::runtime::reference::{self, f256, to_f64};
use std::collections::HashMap;

/// The round trips' scale for SeedB's lengths.
const SCALE: f64 = 300.0;
/// Seed 000's l1 and l5 (the slider's hinge height and the parallelogram's arm).
const L1: f64 = 100.0;
const L5: f64 = 320.0;
/// The actuators' places in a solution's `q`.
const INPUTS: [usize; 3] = [0, 4, 8];

struct Mechanism {
    model: pkm::runtime::model::Model,
    outputs: Vec<Output>,
}

fn mechanism() -> Mechanism {
    let (text, path) = common::example_text("seed000_b");
    let a = pkm::dsl::analyze_source(&text).unwrap_or_else(|d| panic!("{path}: {}", d.render(&text, &path)));
    let model = pkm::dsl::numeric::model(&a, &HashMap::new()).unwrap();
    let outputs = pkm::dsl::numeric::newton_outputs(&a, &model, &HashMap::new()).unwrap();
    Mechanism { model, outputs }
}

/// At the draw `q` on fk branch `branch`: fk's pose is within 2e-15 of the
/// scale of the reference; ik returns the reference ik of that same pose to
/// 1e-14; the exact ik's ∂P3/∂z (central difference of the reference) is
/// the hand derivation's to 1e-6 and at least `steep`; and the round trip's
/// error is that derivative times fk's rounding of z, to 1e-14.
fn check(m: &Mechanism, q: [f64; 3], branch: usize, steep: f64) {
    let tight = NewtonOptions {
        tolerance: 1e-13,
        max_iterations: 100,
    };
    let params = Default::default();
    let at = format!("q = {q:?}");
    let fk = SeedB::fk(&params, &q)[branch].result.clone().expect(&at);
    let start = newton::solve_fk(&m.model, &q, &fk.q, &tight).expect(&at);
    let exact = reference::fk(&m.model, &q, &start.values).expect(&at);
    let exact_pose = reference::output_values(&m.model, &m.outputs, &exact.values).unwrap();
    let angles = reference::output_is_angle(&m.model, &m.outputs);
    let fk_error = reference::max_error(&fk.outputs, &exact_pose, &angles, SCALE);
    assert!(fk_error < 2e-15, "{at}: fk's pose off by {fk_error:e}");

    // The generated ik of fk's pose, on the branch that returns to q.
    let pose = fk.outputs;
    let back = SeedB::ik(&params, &pose)
        .iter()
        .filter_map(|b| b.result.clone().ok())
        .min_by(|a, b| {
            let e = |s: &SeedBSolution| max_error(&INPUTS.map(|j| s.q[j]), &q, &[false; 3], SCALE);
            e(a).total_cmp(&e(b))
        })
        .expect(&at);
    let ik_start = newton::solve_ik(&m.model, &m.outputs, &pose, &back.q, &tight).expect(&at);
    let exact_ik = |given: [f64; 4]| {
        let r = reference::ik(&m.model, &m.outputs, &given, &ik_start.values).expect(&at);
        INPUTS.map(|j| r.values[j])
    };
    let ik_exact = exact_ik(pose);
    let own = INPUTS
        .iter()
        .zip(&ik_exact)
        .map(|(&j, r)| to_f64(f256::from(back.q[j]) - *r).abs() / SCALE)
        .fold(0.0, f64::max);
    assert!(own < 1e-14, "{at}: ik off the exact ik of its pose by {own:e}");

    // ∂P3/∂z of the exact ik at the pose, by a central difference of 2⁻⁴⁰
    // (16 ulps of z: its third-order term is below 1e-8 of it), and by hand.
    let h = 2f64.powi(-40);
    let (mut up, mut down) = (pose, pose);
    up[2] += h;
    down[2] -= h;
    let dp3_dz = to_f64((exact_ik(up)[2] - exact_ik(down)[2]) / f256::from(up[2] - down[2]));
    let arm = f256::from(pose[2]) - f256::from(L1);
    let l5 = f256::from(L5);
    let by_hand = to_f64(arm.abs() / ((l5 - arm.abs()) * (l5 + arm.abs())).sqrt());
    assert!(
        (dp3_dz.abs() - by_hand).abs() < 1e-6 * by_hand,
        "{at}: ∂P3/∂z {dp3_dz:e}, by hand {by_hand:e}"
    );
    assert!(by_hand >= steep, "{at}: ∂P3/∂z only {by_hand:e}");

    // The round trip: P3 moved by ∂P3/∂z times fk's rounding of z (the other
    // outputs' roundings move the inputs by less than 1e-15 of the scale).
    let round_trip = max_error(&INPUTS.map(|j| back.q[j]), &q, &[false; 3], SCALE);
    let z_rounding = to_f64(f256::from(pose[2]) - exact_pose[2]);
    let explained = (by_hand * z_rounding / SCALE).abs();
    assert!(
        (round_trip - explained).abs() < 1e-14,
        "{at}: round trip {round_trip:e}, ∂P3/∂z · δz = {explained:e}"
    );
}

#[test]
fn seed000_b_worst_round_trips_are_the_upright_arm() {
    let m = mechanism();
    // round_trips.rs's worst ik∘fk draw (reachable draw 98177): the arm
    // 4.6e-6 rad from upright, z − l1 short of l5 by 3.4e-9; |∂P3/∂z| = 2.16e5.
    check(&m, [-172.3409297635638, 98.39482133419996, -36.97157222451273], 3, 2e5);
    // Reachable draw 3543, the next nearest to upright: |∂P3/∂z| = 2.6e4.
    check(
        &m,
        [-186.61414328559707, 110.46761859637353, -38.08545197269393],
        7,
        2e4,
    );
}
