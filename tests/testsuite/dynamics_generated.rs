//! The generated inverse dynamics (capability `dynamics`) against the
//! runtime's Newton–Euler (`pkm_runtime::newton_euler`, which solves the
//! loop-closure velocity equations where the generated code differentiates
//! the forward solution): the actuators' forces and every joint's reaction
//! agree to 1e-9 of the largest.

use crate::common;
use crate::mechanisms::{
    FiveBarPaDynamics, FiveBarPaDynamicsParams, Punch, Rssr, Rsur, SeedA, SeedB, SliderCrankDynamics,
    SliderCrankDynamicsParams,
};

use pkm::dsl::screw::SplitMix;
use pkm::runtime::newton_euler::{inverse_dynamics, DynamicsError, JointReaction, Reactions};
use pkm::runtime::primitives::Sign::{self, Minus, Plus};
use std::collections::HashMap;
use std::f64::consts::PI;

/// The runtime's pieces for one example file.
struct Runtime {
    model: pkm::runtime::model::Model,
    loading: pkm::runtime::mass_properties::Loading,
    skcs: Vec<pkm::runtime::newton_euler::SkcParts>,
    plan: pkm::runtime::plan::Plan,
}

fn runtime(stem: &str) -> Runtime {
    let (text, path) = common::example_text(stem);
    runtime_of(&text, &path, &Default::default())
}

fn runtime_of(text: &str, path: &str, values: &HashMap<String, f64>) -> Runtime {
    let c = pkm::dsl::compile(text).unwrap_or_else(|d| panic!("{}", d.render(text, path)));
    let model = pkm::dsl::numeric::model(&c.analysis, values).unwrap();
    let loading = pkm::dsl::numeric::loading(&c.analysis, &model, values).unwrap();
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
fn difference(actuators: &[f64], joints: &[JointReaction], reference: &Reactions, size: f64) -> f64 {
    let mut largest = 0.0f64;
    let mut worst = 0.0f64;
    let mut compare = |a: f64, b: f64, scale: f64| {
        largest = largest.max(b.abs() / scale);
        worst = worst.max((a - b).abs() / scale);
    };
    assert_eq!(actuators.len(), reference.actuators.len());
    assert_eq!(joints.len(), reference.joints.len());
    for (a, b) in actuators.iter().zip(&reference.actuators) {
        compare(*a, *b, size);
    }
    for (a, b) in joints.iter().zip(&reference.joints) {
        for c in 0..3 {
            compare(a.force[c], b.force[c], 1.0);
            compare(a.moment[c], b.moment[c], size);
        }
    }
    worst / largest
}

/// The punch's joint values and signs at crank angle `phi` on the paper's
/// branch: C below B, G by the + arccos (signs − −), and F the
/// intersection other than H (the larger |X_F|).
fn punch_branch(r: &Runtime, phi: f64) -> (Vec<f64>, [Sign; 3]) {
    let p2 = r.model.joints.iter().position(|j| j.name == "P2").unwrap();
    [Plus, Minus]
        .into_iter()
        .filter_map(|s| {
            let signs = [Minus, Minus, s];
            r.plan.solve(&r.model, &[phi], &signs).ok().map(|v| (v, signs))
        })
        .max_by(|a, b| a.0[p2].abs().total_cmp(&b.0[p2].abs()))
        .unwrap()
}

/// The punch over a turn at ω = 1 rad/s and a crank acceleration of
/// 0.5 rad/s², on the paper's branch (signs − − and the F other than H):
/// generated and runtime agree to 1e-9, their kinematic conditioning too;
/// next to a change point both refuse (fewer than six digits there:
/// tests/testsuite/seed003_dynamics.rs holds both to a 60-digit reference).
#[test]
fn punch_over_a_turn() {
    let r = runtime("seed003_punch");
    let size = pkm::runtime::kinematics::model_scale(&r.model);
    let prepared = Punch::prepare(&Default::default());
    let mut worst = 0.0f64;
    let mut refused = 0;
    for k in 0..360 {
        let phi = (k as f64 + 0.25).to_radians();
        let (values, signs) = punch_branch(&r, phi);
        let reference = inverse_dynamics(&r.model, &r.loading, &r.skcs, &values, &[1.0], &[0.5]);
        let generated = prepared.inverse_dynamics(&[phi], signs, &[1.0], &[0.5]);
        match (generated, reference) {
            (Ok(g), Ok(n)) => {
                worst = worst.max(difference(&g.actuators, &g.joints, &n, size));
                assert!(g.balance < 1e-12, "φ = {k}°: balance {:e}", g.balance);
                assert_eq!(g.undetermined, [0, 0, 0]);
                for (a, b) in g.conditioning.iter().zip(&n.conditioning) {
                    assert!((a - b).abs() < 1e-9 * b, "φ = {k}°: conditioning {a:e} against {b:e}");
                }
            }
            (
                Err(DynamicsError::NearChangePoint { skc: a, .. }),
                Err(DynamicsError::NearChangePoint { skc: b, .. }),
            ) => {
                assert_eq!(a, b, "φ = {k}°");
                refused += 1;
            }
            (g, n) => panic!("φ = {k}°: generated {g:?}, runtime {n:?}"),
        }
    }
    assert!(worst < 1e-9, "worst relative difference {worst:e}");
    // 153.25°–155.25° and 233.25°–236.25°: within 1.4° and 1.7° of them.
    assert_eq!(refused, 7, "{refused} refused angles");
    eprintln!("punch: worst {worst:e}, {refused} refused");
}

/// A generated inverse dynamics at parameter values, inputs, signs, rates
/// and accelerations: its actuators' forces and joints' reactions.
type Generated = dyn Fn(
    &HashMap<String, f64>,
    &[f64],
    &[Sign],
    &[f64],
    &[f64],
) -> Result<(Vec<f64>, Vec<JointReaction>), DynamicsError>;

/// Next to the punch's change point near 154.5189° both report the same
/// kinematic conditioning (the reduced system's σ_r/σ_1) and refuse at the
/// same angles, at rest as in motion (tests/testsuite/seed003_dynamics.rs finds the
/// angle where the refusal begins by bisection).
#[test]
fn punch_change_point() {
    let r = runtime("seed003_punch");
    let prepared = Punch::prepare(&Default::default());
    let (mut lowest, mut refused) = (1.0f64, 0);
    for rates in [0.0, 1.0] {
        for k in -40..=40 {
            let phi = (154.5189 + k as f64 * 1e-3).to_radians();
            let (values, signs) = punch_branch(&r, phi);
            let reference = inverse_dynamics(&r.model, &r.loading, &r.skcs, &values, &[rates], &[0.0]);
            let generated = prepared.inverse_dynamics(&[phi], signs, &[rates], &[0.0]);
            match (&generated, &reference) {
                (Ok(g), Ok(n)) => {
                    let (a, b) = (g.conditioning[2], n.conditioning[2]);
                    assert!((a - b).abs() < 1e-9 * b, "φ = {phi}: conditioning {a:e} against {b:e}");
                    lowest = lowest.min(b);
                }
                (
                    Err(DynamicsError::NearChangePoint {
                        skc: 2,
                        conditioning: a,
                        ..
                    }),
                    Err(DynamicsError::NearChangePoint {
                        skc: 2,
                        conditioning: b,
                        ..
                    }),
                ) => {
                    assert!((a - b).abs() < 1e-6 * b, "φ = {phi}: conditioning {a:e} against {b:e}");
                    refused += 1
                }
                // At φ* itself F's two assembly branches meet: the motion has
                // no rates, which the runtime finds in its velocity equations
                // and the generated code as derivatives that are not numbers.
                (Err(DynamicsError::NotFinite), Err(DynamicsError::Velocity(_))) => refused += 1,
                _ => panic!("φ = {phi}: generated {generated:?}, runtime {reference:?}"),
            }
        }
    }
    eprintln!("punch near 154.5189°: lowest conditioning answered {lowest:e}, {refused} refused");
    // In motion all 81 angles are refused; at rest those within 0.035°.
    assert!(lowest < 2e-5, "lowest conditioning answered {lowest:e}");
    assert!((81 + 60..=81 + 75).contains(&refused), "{refused} refused");
}

/// Seed 000's A and B with §3.4's masses, the parallelogram's bar (on the
/// first link in A, the second in B) and the payload, along §3.1's inputs
/// over 0–5 s on every branch that assembles: generated and runtime agree,
/// their kinematic conditioning too (both SKCs overconstrained), and where
/// B does not assemble both say so.
#[test]
fn seed000_along_the_papers_inputs() {
    type Answer = (Vec<f64>, Vec<JointReaction>, Vec<f64>);
    type Generated<'a> = dyn Fn(&[f64; 3], &[Sign], &[f64; 3], &[f64; 3]) -> Result<Answer, DynamicsError> + 'a;
    let a = SeedA::prepare(&Default::default());
    let b = SeedB::prepare(&Default::default());
    let seed_a: &Generated = &|q, s, v, acc| {
        let d = a.inverse_dynamics(q, s.try_into().expect("A's two choices"), v, acc)?;
        Ok((d.actuators.to_vec(), d.joints.to_vec(), d.conditioning.to_vec()))
    };
    let seed_b: &Generated = &|q, s, v, acc| {
        let d = b.inverse_dynamics(q, s.try_into().expect("B's three choices"), v, acc)?;
        Ok((d.actuators.to_vec(), d.joints.to_vec(), d.conditioning.to_vec()))
    };
    for (stem, generated) in [("seed000_a", seed_a), ("seed000_b", seed_b)] {
        let r = runtime(stem);
        let size = pkm::runtime::kinematics::model_scale(&r.model);
        let (mut worst, mut compared, mut missing) = (0.0f64, 0, 0);
        for k in 0..=500 {
            let t = k as f64 * 0.01;
            let w = PI;
            let start = [-131.07, 181.55, -57.74];
            let amplitude = [20.0, -10.0, 20.0];
            let q: [f64; 3] = std::array::from_fn(|i| start[i] + amplitude[i] * (w * t).sin());
            let v: [f64; 3] = std::array::from_fn(|i| amplitude[i] * w * (w * t).cos());
            let acc: [f64; 3] = std::array::from_fn(|i| -amplitude[i] * w * w * (w * t).sin());
            for bits in 0..1usize << r.plan.choices() {
                let signs: Vec<Sign> = (0..r.plan.choices())
                    .map(|i| if bits >> i & 1 == 0 { Plus } else { Minus })
                    .collect();
                let Ok(values) = r.plan.solve(&r.model, &q, &signs) else {
                    assert!(
                        matches!(generated(&q, &signs, &v, &acc), Err(DynamicsError::Position(_))),
                        "{stem} t = {t}"
                    );
                    missing += 1;
                    continue;
                };
                let reference = inverse_dynamics(&r.model, &r.loading, &r.skcs, &values, &v, &acc)
                    .unwrap_or_else(|e| panic!("{stem} t = {t}: runtime {e}"));
                let (actuators, joints, conditioning) =
                    generated(&q, &signs, &v, &acc).unwrap_or_else(|e| panic!("{stem} t = {t}: generated {e}"));
                worst = worst.max(difference(&actuators, &joints, &reference, size));
                for (a, b) in conditioning.iter().zip(&reference.conditioning) {
                    assert!(
                        (a - b).abs() < 1e-9 * b,
                        "{stem} t = {t}: conditioning {a:e} against {b:e}"
                    );
                }
                compared += 1;
            }
        }
        assert!(worst < 1e-9, "{stem}: worst relative difference {worst:e}");
        eprintln!("{stem}: {compared} (time, branch) pairs, worst relative difference {worst:e}; {missing} without an assembly");
    }
}

/// The S-joint four-bars over a turn on every branch, with a crank rate
/// and acceleration: the generated inverse dynamics (the pose's own
/// derivatives through the plan, the coupler's spin as the position's
/// convention turns it) against the runtime's (the velocity equations'
/// minimum-norm spin). The RSSR's S–S coupler, symmetric about its line,
/// has its moment about the line dropped in both; each S joint's reaction
/// is a force, its moment zero.
#[test]
fn s_joint_four_bars_over_a_turn() {
    type Generated<'a> = dyn Fn(f64, &[Sign]) -> Result<(Vec<f64>, Vec<JointReaction>), DynamicsError> + 'a;
    let (rssr, rsur) = (Rssr::prepare(&Default::default()), Rsur::prepare(&Default::default()));
    let (rate, accel) = (1.5, -4.0);
    let rssr_fn: &Generated = &|q, s| {
        let d = rssr.inverse_dynamics(&[q], s.try_into().expect("one choice"), &[rate], &[accel])?;
        Ok((d.actuators.to_vec(), d.joints.to_vec()))
    };
    let rsur_fn: &Generated = &|q, s| {
        let d = rsur.inverse_dynamics(&[q], s.try_into().expect("two choices"), &[rate], &[accel])?;
        Ok((d.actuators.to_vec(), d.joints.to_vec()))
    };
    for (stem, generated) in [("rssr", rssr_fn), ("rsur", rsur_fn)] {
        let r = runtime(stem);
        let size = pkm::runtime::kinematics::model_scale(&r.model);
        let (mut worst, mut compared) = (0.0f64, 0);
        for k in 0..360 {
            let q = (k as f64 + 0.5).to_radians();
            for bits in 0..1usize << r.plan.choices() {
                let signs: Vec<Sign> = (0..r.plan.choices())
                    .map(|i| if bits >> i & 1 == 0 { Plus } else { Minus })
                    .collect();
                let values = r
                    .plan
                    .solve(&r.model, &[q], &signs)
                    .unwrap_or_else(|e| panic!("{stem} {k}°: {e}"));
                let reference = inverse_dynamics(&r.model, &r.loading, &r.skcs, &values, &[rate], &[accel])
                    .unwrap_or_else(|e| panic!("{stem} {k}°: runtime {e}"));
                let (actuators, joints) = generated(q, &signs).unwrap_or_else(|e| panic!("{stem} {k}°: generated {e}"));
                worst = worst.max(difference(&actuators, &joints, &reference, size));
                for (j, joint) in r.model.joints.iter().enumerate() {
                    if joint.kind == pkm::runtime::model::JointType::S {
                        let m = joints[j].moment.iter().fold(0.0f64, |a, x| a.max(x.abs()));
                        let f = joints[j].force.iter().fold(0.0f64, |a, x| a.max(x.abs()));
                        assert!(m < 1e-9 * f * size, "{stem} {k}°: {}'s moment {m}", joint.name);
                    }
                }
                compared += 1;
            }
        }
        assert!(worst < 1e-9, "{stem}: worst relative difference {worst:e}");
        eprintln!("{stem}: {compared} (angle, branch) pairs, worst relative difference {worst:e}");
    }
}

/// Random draws of the fixtures' parameters: masses ×0.5–2, inertias
/// ×0.2–3, gravity up to 20 m/s² in any direction, a load up to 50 N and
/// 50 N·m; `spatial` for a z component.
fn draw(rng: &mut SplitMix, spatial: bool) -> HashMap<String, f64> {
    let mut u = |lo: f64, hi: f64| lo + (hi - lo) * (rng.symmetric() + 1.0) / 2.0;
    let mut v: HashMap<String, f64> = HashMap::new();
    v.insert("mu".into(), u(0.5, 2.0));
    v.insert("k".into(), u(0.2, 3.0));
    let axes: &[&str] = if spatial { &["x", "y", "z"] } else { &["x", "y"] };
    for a in axes {
        v.insert(format!("g{a}"), u(-20.0, 20.0));
        v.insert(format!("f{a}"), u(-50.0, 50.0));
    }
    let moments: &[&str] = if spatial { &["mx", "my", "mz"] } else { &["mz"] };
    for m in moments {
        v.insert(m.to_string(), u(-5e4, 5e4));
    }
    v
}

/// `states` random reachable states (inputs in `ranges`, random branch,
/// rates and accelerations, parameters by [`draw`]): the generated inverse
/// dynamics `generated` against the runtime's on the fixture `file`.
fn agree(file: &str, ranges: &[(f64, f64)], states: usize, generated: &Generated) -> f64 {
    let path = common::root().join(file).display().to_string();
    let text = std::fs::read_to_string(&path).unwrap();
    let mut rng = SplitMix::new(0x9e4);
    let (mut done, mut drawn, mut worst) = (0, 0, 0.0f64);
    while done < states {
        drawn += 1;
        assert!(drawn < 100 * states, "{file}: too few reachable draws");
        let values = draw(&mut rng, !text.contains("planar;"));
        let r = runtime_of(&text, &path, &values);
        let q: Vec<f64> = ranges
            .iter()
            .map(|(lo, hi)| lo + (hi - lo) * (rng.symmetric() + 1.0) / 2.0)
            .collect();
        let signs: Vec<Sign> = (0..r.plan.choices())
            .map(|_| if rng.next_u64().is_multiple_of(2) { Plus } else { Minus })
            .collect();
        let Ok(joint_values) = r.plan.solve(&r.model, &q, &signs) else {
            continue;
        };
        let rates: Vec<f64> = q.iter().map(|_| rng.symmetric()).collect();
        let accels: Vec<f64> = q.iter().map(|_| 2.0 * rng.symmetric()).collect();
        // Next to an output singularity the runtime's velocity solve refuses: drawn again.
        let reference = match inverse_dynamics(&r.model, &r.loading, &r.skcs, &joint_values, &rates, &accels) {
            Ok(n) => n,
            Err(DynamicsError::Velocity(_)) => continue,
            Err(e) => panic!("{file} at q = {q:?}: runtime {e}"),
        };
        let (actuators, joints) = generated(&values, &q, &signs, &rates, &accels)
            .unwrap_or_else(|e| panic!("{file} at q = {q:?}: generated {e}"));
        let size = pkm::runtime::kinematics::model_scale(&r.model);
        let e = difference(&actuators, &joints, &reference, size);
        assert!(
            e < 1e-9,
            "{file} at q = {q:?}, q̇ = {rates:?}, q̈ = {accels:?}: relative difference {e:e}"
        );
        worst = worst.max(e);
        done += 1;
    }
    eprintln!("{file}: {states} states, worst relative difference {worst:e}");
    worst
}

#[test]
fn slider_crank_with_parameters() {
    agree(
        "tests/fixtures/slider_crank_dynamics.pkm",
        &[(-PI, PI)],
        300,
        &|v, q, signs, rates, accels| {
            let p = SliderCrankDynamicsParams {
                mu: v["mu"],
                k: v["k"],
                gx: v["gx"],
                gy: v["gy"],
                fx: v["fx"],
                fy: v["fy"],
                mz: v["mz"],
                ..Default::default()
            };
            let d = SliderCrankDynamics::inverse_dynamics(&p, &[q[0]], [signs[0]], &[rates[0]], &[accels[0]])?;
            Ok((d.actuators.to_vec(), d.joints.to_vec()))
        },
    );
}

#[test]
fn five_bar_pa_with_parameters() {
    let ranges = [(-PI, PI), (-PI, PI), (-300.0, 300.0)];
    agree(
        "tests/fixtures/five_bar_pa_dynamics.pkm",
        &ranges,
        300,
        &|v, q, signs, rates, accels| {
            let p = FiveBarPaDynamicsParams {
                mu: v["mu"],
                k: v["k"],
                gx: v["gx"],
                gy: v["gy"],
                gz: v["gz"],
                fx: v["fx"],
                fy: v["fy"],
                fz: v["fz"],
                mx: v["mx"],
                my: v["my"],
                mz: v["mz"],
                ..Default::default()
            };
            let signs: [Sign; 3] = signs.try_into().expect("three choices");
            let at = |x: &[f64]| [x[0], x[1], x[2]];
            let d = FiveBarPaDynamics::inverse_dynamics(&p, &at(q), signs, &at(rates), &at(accels))?;
            Ok((d.actuators.to_vec(), d.joints.to_vec()))
        },
    );
}

/// A negative mass or an inertia that is no rigid body's, given through
/// the parameters, is a typed error naming the link; so is a position
/// the mechanism cannot reach.
#[test]
fn bad_parameters_and_unreachable_positions() {
    let negative = SliderCrankDynamicsParams {
        mu: -1.0,
        ..Default::default()
    };
    let e = SliderCrankDynamics::inverse_dynamics(&negative, &[0.3], [Plus], &[1.0], &[0.0]).unwrap_err();
    assert!(
        matches!(&e, DynamicsError::MassProperties { body, problem } if body == "crank" && problem.contains("mass")),
        "{e:?}"
    );
    let flat = SliderCrankDynamicsParams {
        k: -1.0,
        ..Default::default()
    };
    let e = SliderCrankDynamics::inverse_dynamics(&flat, &[0.3], [Plus], &[1.0], &[0.0]).unwrap_err();
    assert!(
        matches!(&e, DynamicsError::MassProperties { body, .. } if body == "crank"),
        "{e:?}"
    );
    let short = SliderCrankDynamicsParams {
        l: 20.0,
        e: 40.0,
        ..Default::default()
    };
    let e = SliderCrankDynamics::inverse_dynamics(&short, &[-1.5], [Plus], &[1.0], &[0.0]).unwrap_err();
    assert!(matches!(e, DynamicsError::Position(_)), "{e:?}");
    let e =
        SliderCrankDynamics::inverse_dynamics(&Default::default(), &[0.3], [Plus], &[f64::NAN], &[0.0]).unwrap_err();
    assert_eq!(e, DynamicsError::NotFinite);
}
