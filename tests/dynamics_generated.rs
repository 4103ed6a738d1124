//! The generated inverse dynamics (capability `dynamics`) against the
//! runtime's Newton–Euler (`pkm_runtime::newton_euler`, which solves the
//! loop-closure velocity equations where the generated code differentiates
//! the forward solution): the actuators' forces and every joint's reaction
//! agree to 1e-9 of the largest.

mod common;

use pkm::runtime::newton_euler::{inverse_dynamics, DynamicsError, Reactions};
use pkm::runtime::primitives::Sign::{self, Minus, Plus};

pkm::mechanism!(Punch, file = "examples/mechanisms/seed003_punch.pkm");

/// The runtime's pieces for one example file.
struct Runtime {
    model: pkm::runtime::model::Model,
    loading: pkm::runtime::mass_properties::Loading,
    skcs: Vec<pkm::runtime::newton_euler::SkcParts>,
    plan: pkm::runtime::spatial::Plan,
}

fn runtime(stem: &str) -> Runtime {
    let (text, path) = common::example_text(stem);
    let c = pkm::dsl::compile(&text).unwrap_or_else(|d| panic!("{}", d.render(&text, &path)));
    let model = pkm::dsl::numeric::model(&c.analysis, &Default::default()).unwrap();
    let loading = pkm::dsl::numeric::loading(&c.analysis, &model, &Default::default()).unwrap();
    Runtime {
        skcs: pkm::dsl::numeric::skc_parts(&c.analysis),
        plan: c.forward().unwrap().clone(),
        model,
        loading,
    }
}

/// The largest difference of two inverse dynamics relative to the largest
/// number of the runtime's (forces and moments over the mechanism's size
/// `size`, so that N and N·mm weigh alike).
fn difference(generated: &PunchDynamics, reference: &Reactions, size: f64) -> f64 {
    let mut largest = 0.0f64;
    let mut worst = 0.0f64;
    let mut compare = |a: f64, b: f64, scale: f64| {
        largest = largest.max(b.abs() / scale);
        worst = worst.max((a - b).abs() / scale);
    };
    for (a, b) in generated.actuators.iter().zip(&reference.actuators) {
        compare(*a, *b, size);
    }
    for (a, b) in generated.joints.iter().zip(&reference.joints) {
        for c in 0..3 {
            compare(a.force[c], b.force[c], 1.0);
            compare(a.moment[c], b.moment[c], size);
        }
    }
    worst / largest
}

/// The punch over a turn at ω = 1 rad/s and a crank acceleration of
/// 0.5 rad/s², on the paper's branch (signs − − and the F other than H):
/// generated and runtime agree to 1e-9; at a change point both say so.
#[test]
fn punch_over_a_turn() {
    let r = runtime("seed003_punch");
    let size = pkm::runtime::kinematics::model_scale(&r.model);
    let prepared = Punch::prepare(&Default::default());
    let p2 = r.model.joints.iter().position(|j| j.name == "P2").unwrap();
    let mut worst = 0.0f64;
    let mut singular = 0;
    for k in 0..360 {
        let phi = (k as f64 + 0.25).to_radians();
        let (values, signs): (Vec<f64>, [Sign; 3]) = [Plus, Minus]
            .into_iter()
            .filter_map(|s| {
                let signs = [Minus, Minus, s];
                r.plan.solve(&r.model, &[phi], &signs).ok().map(|v| (v, signs))
            })
            .max_by(|a, b| a.0[p2].abs().total_cmp(&b.0[p2].abs()))
            .unwrap();
        let reference = inverse_dynamics(&r.model, &r.loading, &r.skcs, &values, &[1.0], &[0.5]);
        let generated = prepared.inverse_dynamics(&[phi], signs, &[1.0], &[0.5]);
        match (generated, reference) {
            (Ok(g), Ok(n)) => {
                worst = worst.max(difference(&g, &n, size));
                assert!(g.balance < 1e-12, "φ = {k}°: balance {:e}", g.balance);
                assert_eq!(g.undetermined, [0, 0, 0]);
            }
            (Err(DynamicsError::ForceSingular { skc: a, .. }), Err(DynamicsError::ForceSingular { skc: b, .. })) => {
                assert_eq!(a, b, "φ = {k}°");
                singular += 1;
            }
            (g, n) => panic!("φ = {k}°: generated {g:?}, runtime {n:?}"),
        }
    }
    assert!(worst < 1e-9, "worst relative difference {worst:e}");
    assert!(singular <= 2, "{singular} singular angles");
    eprintln!("punch: worst {worst:e}, {singular} singular");
}
