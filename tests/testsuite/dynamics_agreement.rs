//! Inverse dynamics three independent ways on the example mechanisms:
//! Newton–Euler over the ordered SKCs with every joint's reaction
//! (`pkm::runtime::newton_euler`), virtual work over the loop-closure
//! velocity equations (`pkm::runtime::virtual_work`) and Lagrange's
//! equations with the link poses differentiated exactly through the
//! closed-form plan on hyper-dual numbers (`pkm::runtime::lagrange`). At
//! random states (q, q̇, q̈), with random masses, centroids, inertias,
//! gravity and a random load (and two massive swinging bars per
//! parallelogram), the three give the same actuator forces to
//! 1e-9 of the largest; every link's balance under the Newton–Euler
//! reactions holds to 1e-12 of its largest term (rounding over the SKCs'
//! conditioning where a draw lands near a change point); and the reaction
//! components each SKC leaves undetermined are as many as its loops'
//! Σ (6 − ξ_L) from the topology.

use crate::common;

use pkm::dsl::screw::SplitMix;
use pkm::runtime::mass_properties::{Body, Carrier, Loading, PointLoad};
use pkm::runtime::model::{JointType, Model};
use pkm::runtime::nalgebra::{Matrix3, Rotation3, Vector3};
use pkm::runtime::primitives::Sign;
use pkm::runtime::{lagrange, newton_euler, virtual_work};
use std::f64::consts::PI;

/// A random rigid body carried by `carrier`: mass 0.1–2, centroid within
/// `size` of its frame's origin, principal moments that satisfy the
/// triangle inequality, turned by a random rotation.
fn body(rng: &mut SplitMix, carrier: Carrier, size: f64, planar: bool) -> Body {
    let u = |rng: &mut SplitMix| (rng.symmetric() + 1.0) / 2.0;
    let mass = 0.1 + 1.9 * u(rng);
    let mut centroid = rng.vector() * size;
    if planar {
        centroid.z = 0.0;
    }
    // I₁ = a + b, I₂ = b + c, I₃ = a + c with a, b, c ≥ 0 meet the inequality.
    let [a, b, c] = [u(rng), u(rng), u(rng)].map(|x| x * mass * size * size);
    let principal = Matrix3::from_diagonal(&Vector3::new(a + b, b + c, a + c));
    let inertia = if planar {
        Matrix3::from_diagonal(&Vector3::new(0.0, 0.0, a + c))
    } else {
        let r = Rotation3::new(rng.vector() * PI);
        r.matrix() * principal * r.matrix().transpose()
    };
    Body {
        carrier,
        mass,
        centroid,
        inertia,
    }
}

/// A random body made symmetric about the line through `point` along
/// the unit `axis`: its centroid moved onto the line, its inertia the same
/// about every normal to it (an S–S link's, which turns freely about it:
/// `Loading::idle_spins_dropped`).
fn symmetric_about(mut b: Body, rng: &mut SplitMix, point: Vector3<f64>, axis: Vector3<f64>, size: f64) -> Body {
    let along = (b.centroid - point).dot(&axis);
    b.centroid = point + axis * along;
    // Axial ≤ twice the transverse moment (the triangle inequality).
    let transverse = b.mass * size * size * (0.1 + (rng.symmetric() + 1.0) / 2.0);
    let axial = 2.0 * transverse * (rng.symmetric() + 1.0) / 2.0;
    b.inertia = Matrix3::identity() * transverse + axis * axis.transpose() * (axial - transverse);
    b
}

fn random_loading(rng: &mut SplitMix, model: &Model, size: f64) -> Loading {
    let planar = model.planar;
    let spins: Vec<_> = (0..model.links.len())
        .map(|l| pkm::runtime::mass_properties::idle_spin_line(model, l))
        .collect();
    let mut bodies: Vec<Body> = (1..model.links.len())
        .map(|l| {
            let b = body(rng, Carrier::Link(l), size, planar);
            match spins[l] {
                Some((point, axis)) => symmetric_about(b, rng, point, axis, size),
                None => b,
            }
        })
        .collect();
    // Two swinging bars per parallelogram, hinged anywhere on the link that
    // holds its arm (a bar's hinge need not be the joint's own point).
    for (j, joint) in model.joints.iter().enumerate() {
        if joint.kind == JointType::Pa {
            for _ in 0..2 {
                let mut hinge = rng.vector() * size;
                if planar {
                    hinge.z = 0.0;
                }
                bodies.push(body(rng, Carrier::Bar { joint: j, hinge }, size, planar));
            }
        }
    }
    let flat = |v: Vector3<f64>| if planar { Vector3::new(v.x, v.y, 0.0) } else { v };
    let gravity = flat(rng.vector() * 9810.0);
    // A load on a link that does not turn freely (one on an S–S link would
    // spin it: refused, `a_load_that_would_spin_an_s_s_link_is_refused`).
    let free: Vec<usize> = (1..model.links.len()).filter(|&l| spins[l].is_none()).collect();
    let link = free[(rng.next_u64() as usize) % free.len()];
    let at = flat(rng.vector() * size);
    let force = flat(rng.vector() * 50.0);
    let moment = if planar {
        Vector3::new(0.0, 0.0, rng.symmetric() * 50.0 * size)
    } else {
        rng.vector() * 50.0 * size
    };
    Loading {
        bodies,
        gravity,
        loads: vec![PointLoad {
            link,
            at,
            force: force * 1e3,
            moment: moment * 1e3,
        }],
        metres_per_unit: 1e-3,
    }
}

/// `states` random reachable states of one example, both paths compared.
fn agree(stem: &str, ranges: &[(f64, f64)], size: f64, states: usize) {
    let (text, path) = common::example_text(stem);
    agree_on(stem, &text, &path, ranges, size, states);
}

/// [`agree`] on a mechanism's text.
fn agree_on(stem: &str, text: &str, path: &str, ranges: &[(f64, f64)], size: f64, states: usize) {
    let c = pkm::dsl::compile(text).unwrap_or_else(|d| panic!("{}", d.render(text, path)));
    let model = pkm::dsl::numeric::model(&c.analysis, &Default::default()).expect("a model");
    let plan = c.forward().expect("a forward plan");
    let skcs = pkm::dsl::numeric::skc_parts(&c.analysis);
    let expected: Vec<usize> = skcs.iter().map(|s| s.undetermined).collect();
    assert_eq!(
        plan.input_joints(&model),
        model.inputs(),
        "{stem}: one input order for both paths"
    );
    let mut rng = SplitMix::new(0xd1a9);
    let (mut done, mut drawn, mut worst, mut balance) = (0, 0, 0.0f64, 0.0f64);
    while done < states {
        drawn += 1;
        assert!(drawn < 100 * states, "{stem}: too few reachable draws");
        let q: Vec<f64> = ranges
            .iter()
            .map(|(lo, hi)| lo + (hi - lo) * (rng.symmetric() + 1.0) / 2.0)
            .collect();
        let signs: Vec<Sign> = (0..plan.choices())
            .map(|_| {
                if rng.next_u64().is_multiple_of(2) {
                    Sign::Plus
                } else {
                    Sign::Minus
                }
            })
            .collect();
        let Ok(values) = plan.solve(&model, &q, &signs) else {
            continue;
        };
        let rates: Vec<f64> = q.iter().map(|_| rng.symmetric()).collect();
        let accels: Vec<f64> = q.iter().map(|_| 2.0 * rng.symmetric()).collect();
        let loading = random_loading(&mut rng, &model, size);
        // Next to an output singularity the velocity solve refuses: drawn again.
        let Ok(by_work) = virtual_work::actuator_forces(&model, &loading, &values, &rates, &accels) else {
            continue;
        };
        let by_lagrange =
            lagrange::actuator_forces(&model, plan, &loading, &q, &signs, &rates, &accels).expect("Lagrange");
        let ne = newton_euler::inverse_dynamics(&model, &loading, &skcs, &values, &rates, &accels)
            .unwrap_or_else(|e| panic!("{stem} at q = {q:?}: {e}"));
        let scale = by_work.iter().fold(1e-12f64, |a, x| a.max(x.abs()));
        let e = by_work
            .iter()
            .zip(&by_lagrange)
            .zip(&ne.actuators)
            .map(|((a, b), c)| ((a - b).abs().max((a - c).abs())) / scale)
            .fold(0.0, f64::max);
        assert!(
            e < 1e-9,
            "{stem} at q = {q:?}, q̇ = {rates:?}, q̈ = {accels:?}: virtual work {by_work:?}, Lagrange {by_lagrange:?}, Newton–Euler {:?}",
            ne.actuators
        );
        // The balance holds to rounding over the SKC system's conditioning:
        // 1e-12 but on one draw of seed 000 B (2.3e-11), whose whole system
        // is far worse conditioned than its kinematics (0.05).
        assert!(
            ne.balance < 1e-10,
            "{stem} at q = {q:?}: a link's balance is off by {:e} (conditioning {:?})",
            ne.balance,
            ne.conditioning
        );
        assert_eq!(
            ne.undetermined, expected,
            "{stem} at q = {q:?}: undetermined reaction components"
        );
        balance = balance.max(ne.balance);
        worst = worst.max(e);
        done += 1;
    }
    eprintln!(
        "{stem}: {states} states, worst relative difference {worst:e}, worst balance {balance:e}, undetermined {expected:?}"
    );
}

#[test]
fn four_bar() {
    agree("four_bar", &[(-PI, PI)], 100.0, 1000);
}

#[test]
fn slider_crank() {
    agree("slider_crank", &[(-PI, PI)], 100.0, 1000);
}

#[test]
fn five_bar() {
    agree("five_bar", &[(-PI, PI), (-PI, PI)], 100.0, 1000);
}

#[test]
fn watt_six_bar() {
    agree("watt_six_bar", &[(-PI, PI)], 100.0, 1000);
}

#[test]
fn five_bar_with_parallelogram() {
    agree("five_bar_pa", &[(-PI, PI), (-PI, PI), (-300.0, 300.0)], 100.0, 1000);
}

/// The spatial RSSR with the S–S coupler's mass symmetric about its line
/// (its idle spin then does no work: each path's own convention for it,
/// the plan's for Lagrange, the velocity solve's minimum norm for virtual
/// work and Newton–Euler, gives the same forces).
#[test]
fn rssr() {
    agree("rssr", &[(-PI, PI)], 100.0, 1000);
}

/// The RSUR, whose U holds the coupler's spin: its inertia is general.
#[test]
fn rsur() {
    agree("rsur", &[(-PI, PI)], 100.0, 1000);
}

/// An S–S coupler whose centroid is off its line, whose inertia is not
/// symmetric about it, or that carries a load off the line would have
/// forces that depend on its idle spin: each path refuses, naming it.
#[test]
fn an_s_s_link_that_its_spin_would_move_is_refused() {
    let (text, path) = common::example_text("rssr");
    let c = pkm::dsl::compile(&text).unwrap_or_else(|d| panic!("{}", d.render(&text, &path)));
    let model = pkm::dsl::numeric::model(&c.analysis, &Default::default()).expect("a model");
    let plan = c.forward().expect("a forward plan");
    let skcs = pkm::dsl::numeric::skc_parts(&c.analysis);
    let coupler = model.links.iter().position(|l| l == "coupler").unwrap();
    let (point, axis) = pkm::runtime::mass_properties::idle_spin_line(&model, coupler).unwrap();
    // By hand: S1 at the coupler's origin, S2 at (l, 0, 0).
    assert!(
        (point.norm() < 1e-15) && (axis - Vector3::x()).norm() < 1e-15,
        "{point} {axis}"
    );
    let values = plan.solve(&model, &[0.5], &[Sign::Plus]).unwrap();
    let mut rng = SplitMix::new(7);
    let good = random_loading(&mut rng, &model, 100.0);
    let on_coupler = good
        .bodies
        .iter()
        .position(|b| b.carrier == Carrier::Link(coupler))
        .unwrap();
    let mut off_line = good.clone();
    off_line.bodies[on_coupler].centroid.y += 1.0;
    let mut lopsided = good.clone();
    lopsided.bodies[on_coupler].inertia[(1, 1)] *= 1.5;
    let mut pushed = good.clone();
    pushed.loads[0].link = coupler;
    pushed.loads[0].at = Vector3::new(40.0, 5.0, 0.0);
    pushed.loads[0].moment = Vector3::zeros();
    for (what, loading) in [("centroid", off_line), ("inertia", lopsided), ("load", pushed)] {
        let ne = newton_euler::inverse_dynamics(&model, &loading, &skcs, &values, &[1.0], &[0.0]);
        assert!(
            matches!(&ne, Err(newton_euler::DynamicsError::MassProperties { body, .. }) if body == "coupler"),
            "{what}: {ne:?}"
        );
        assert!(
            virtual_work::actuator_forces(&model, &loading, &values, &[1.0], &[0.0]).is_err(),
            "{what}"
        );
        assert!(lagrange::actuator_forces(&model, plan, &loading, &[0.5], &[Sign::Plus], &[1.0], &[0.0]).is_err());
    }
    // The symmetric coupler's moment about its line does no work: another
    // one gives the same forces.
    let mut axial = good.clone();
    axial.bodies[on_coupler].inertia += axis * axis.transpose() * 1e3;
    let a = newton_euler::inverse_dynamics(&model, &good, &skcs, &values, &[1.0], &[2.0]).unwrap();
    let b = newton_euler::inverse_dynamics(&model, &axial, &skcs, &values, &[1.0], &[2.0]).unwrap();
    assert_eq!(a.undetermined, [0]);
    assert!(
        (a.actuators[0] - b.actuators[0]).abs() < 1e-12 * a.actuators[0].abs(),
        "{a:?} {b:?}"
    );
}

#[test]
fn seed000_a() {
    agree(
        "seed000_a",
        &[(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)],
        200.0,
        1000,
    );
}

#[test]
fn seed000_b() {
    agree(
        "seed000_b",
        &[(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)],
        200.0,
        1000,
    );
}

#[test]
fn seed000_b_with_the_arm_on_the_parallelograms_second_link() {
    // The same parallelogram declared with its arm on `pc`, the joint's
    // second link, pointing back to B3: bars then hang on the second link
    // and their demand passes to the first (s3) through the far hinges.
    let (text, path) = common::example_text("seed000_b");
    let swap = [
        (
            "pc    { R6 = (0, 0, 0) along x; Pa = (0, 0, 0) along y; }",
            "pc    { R6 = (0, 0, 0) along x; Pa = (0, 0, 0) along y arm (0, 0, -l5); }",
        ),
        ("Pa = (0, 0, l1) along y arm (0, 0, l5);", "Pa = (0, 0, l1) along y;"),
    ];
    let mut mirrored = text.clone();
    for (from, to) in swap {
        assert!(mirrored.contains(from), "{path}: `{from}` not found");
        mirrored = mirrored.replace(from, to);
    }
    let c = pkm::dsl::compile(&mirrored).unwrap_or_else(|d| panic!("{}", d.render(&mirrored, &path)));
    let model = pkm::dsl::numeric::model(&c.analysis, &Default::default()).expect("a model");
    let pa = model
        .joints
        .iter()
        .find(|j| j.kind == JointType::Pa)
        .expect("a parallelogram");
    assert!(
        matches!(pa.places[1], pkm::runtime::model::Place::Arm { .. }),
        "the arm is on the second link"
    );
    agree_on(
        "seed000_b, arm on pc",
        &mirrored,
        &path,
        &[(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)],
        200.0,
        1000,
    );
}

/// The RSSR and RSUR with their own masses (examples/mechanisms), at rest:
/// the crank torque is the derivative of the weights' potential along the
/// crank, U = −Σ m g·c with every centroid c placed by the position
/// solution alone (no velocity, no dynamics code), by central differences
/// (h = 1e-5 rad), on every branch every 10°: to 1e-8 of the largest.
#[test]
fn s_joint_statics_is_the_gradient_of_the_potential() {
    for stem in ["rssr", "rsur"] {
        let (text, path) = common::example_text(stem);
        let c = pkm::dsl::compile(&text).unwrap_or_else(|d| panic!("{}", d.render(&text, &path)));
        let model = pkm::dsl::numeric::model(&c.analysis, &Default::default()).expect("a model");
        let loading = pkm::dsl::numeric::loading(&c.analysis, &model, &Default::default()).expect("its masses");
        let plan = c.forward().expect("a forward plan");
        let skcs = pkm::dsl::numeric::skc_parts(&c.analysis);
        let potential = |phi: f64, signs: &[Sign]| {
            let values = plan.solve(&model, &[phi], signs).unwrap();
            let poses = pkm::runtime::kinematics::link_poses(&model, &values).unwrap();
            loading
                .bodies
                .iter()
                .map(|b| {
                    let Carrier::Link(l) = b.carrier else { unreachable!() };
                    let centroid = poses[l] * pkm::runtime::nalgebra::Point3::from(b.centroid);
                    -b.mass * loading.gravity.dot(&centroid.coords)
                })
                .sum::<f64>()
        };
        let (mut worst, mut largest) = (0.0f64, 0.0f64);
        for k in 0..36 {
            let phi = (10.0 * k as f64 + 3.0).to_radians();
            for bits in 0..1usize << plan.choices() {
                let signs: Vec<Sign> = (0..plan.choices())
                    .map(|i| if bits >> i & 1 == 0 { Sign::Plus } else { Sign::Minus })
                    .collect();
                let values = plan.solve(&model, &[phi], &signs).unwrap();
                let ne = newton_euler::inverse_dynamics(&model, &loading, &skcs, &values, &[0.0], &[0.0])
                    .unwrap_or_else(|e| panic!("{stem} at {phi}: {e}"))
                    .actuators[0];
                let h = 1e-5;
                let by_differences =
                    loading.to_newtons((potential(phi + h, &signs) - potential(phi - h, &signs)) / (2.0 * h));
                worst = worst.max((ne - by_differences).abs());
                largest = largest.max(ne.abs());
            }
        }
        assert!(worst < 1e-8 * largest, "{stem}: {worst} N·mm off, largest {largest}");
        eprintln!(
            "{stem} at rest: Newton–Euler against the potential's differences within {:.1e}",
            worst / largest
        );
    }
}

/// The 3-UPU with the MuJoCo check's masses (tests/mujoco/test_mujoco.py's
/// `generic_masses` at its size 0.2 m: 0.1 kg per moving link 26 mm along
/// its x axis, inertias (160, 208, 256) kg·mm²), at rest on the inverse
/// solution's branch 0 at the pose where the check found Newton–Euler 2.8e-8
/// off MuJoCo (P1 2.27618378 N against 2.27618384), and 1e-9 mm on either
/// side in x: Newton–Euler against virtual work (which shares no code with
/// it) to 1e-10 of the largest force.
#[test]
fn upu_3_with_the_mujoco_checks_masses_at_rest() {
    let masses: String = ["A1", "A2", "B1", "B2", "C1", "C2", "platform"]
        .map(|l| format!("{l} {{ mass = 0.1; centroid = (26.0, 0, 0); inertia = (160.0, 208.0, 256.0); }}\n"))
        .concat();
    let text = common::example_with("upu_3", &format!("masses {{\n{masses}}}\n"));
    let c = pkm::dsl::compile(&text).unwrap_or_else(|d| panic!("{}", d.render(&text, "upu_3")));
    let model = pkm::dsl::numeric::model(&c.analysis, &Default::default()).expect("a model");
    let loading = pkm::dsl::numeric::loading(&c.analysis, &model, &Default::default()).expect("its masses");
    let plan = pkm::dsl::planner::inverse_plan(&c.analysis).expect("an inverse plan");
    let skcs = pkm::dsl::numeric::skc_parts(&c.analysis);
    let (x, y, z) = (1.200713418466638, 2.8079374345009525, 57.54539871295128);
    let mut worst = 0.0f64;
    for dx in [0.0, -1e-9, 1e-9] {
        let given = [x + dx, y, z];
        let (_, solution) = pkm::runtime::plan::run_all(&model, &plan, &given).remove(0);
        let values = solution.expect("branch 0 assembles").model_values(&model);
        let ne = newton_euler::inverse_dynamics(&model, &loading, &skcs, &values, &[0.0; 3], &[0.0; 3])
            .expect("Newton–Euler");
        let by_work =
            virtual_work::actuator_forces(&model, &loading, &values, &[0.0; 3], &[0.0; 3]).expect("virtual work");
        let scale = by_work.iter().fold(0.0f64, |a, f| a.max(f.abs()));
        let e = ne
            .actuators
            .iter()
            .zip(&by_work)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
            / scale;
        eprintln!(
            "upu_3 at x + {dx:e}: Newton–Euler {:?}, virtual work {by_work:?}: {e:.1e}",
            ne.actuators
        );
        worst = worst.max(e);
    }
    assert!(
        worst < 1e-10,
        "upu_3: Newton–Euler and virtual work differ by {worst:e} of the largest force"
    );
}
