//! Inverse dynamics by virtual work (`pkm::runtime::virtual_work`) against
//! two independent sources: a slider-crank's crank torque derived by hand
//! in this file, and pure statics (no motion) from finite differences of
//! the positions the solver gives, on seed 000's mechanism A.

use crate::common;

use pkm::runtime::mass_properties::{Carrier, Loading};
use pkm::runtime::model::Model;
use pkm::runtime::nalgebra;
use pkm::runtime::plan::Plan;
use pkm::runtime::primitives::Sign;
use pkm::runtime::virtual_work::actuator_forces;

/// A mechanism text compiled at the parameters `params` (the others as
/// declared): its model, loading and forward plan.
fn compiled(text: &str, params: &[(&str, f64)]) -> (Model, Loading, Plan) {
    let c = pkm::dsl::compile(text).unwrap_or_else(|d| panic!("{}", d.render(text, "test")));
    let a = &c.analysis;
    let values = params.iter().map(|(k, v)| (k.to_string(), *v)).collect();
    let model = pkm::dsl::numeric::model(a, &values).expect("a model");
    let loading = pkm::dsl::numeric::loading(a, &model, &values).expect("a loading");
    let plan = c.forward().expect("a forward plan").clone();
    (model, loading, plan)
}

/// The slider-crank of `examples/mechanisms/slider_crank.pkm` (r = 50,
/// l = 180) with its guide offset to e = 12, masses on all three links (the
/// crank's centroid off its axis), gravity along −y, a cutting force on the
/// slider and a braking moment on the rod.
const SLIDER_CRANK: &str = "
    units { length = mm; mass = kg; }
    masses {
        crank  { mass = 0.3; centroid = (r / 2, 5); inertia = 70; }
        rod    { mass = 0.8; centroid = (l / 2, 0); inertia = 2160; }
        slider { mass = 1.2; centroid = (0, 0); }
    }
    gravity (0, -9.81);
    loads { cut = force (-40, 0) on slider at R3; brake = moment 3000 on rod; }";

/// The crank torque (N·mm) by hand. With s = sin φ = (e − r sin θ)/l the
/// rod's angle and c = cos φ > 0 (the slider right of the crank pin), each
/// centroid G(θ) and the rod's angle φ(θ) are differentiated in θ by the
/// chain rule: s' = −r cos θ/l, s'' = r sin θ/l, c' = −s s'/c,
/// c'' = −(s'² + s s'' + c'²)/c, φ' = s'/c, φ'' = (s'' c − s' c')/c².
/// A centroid's acceleration is G'' ω² + G' α, the rod's angular one
/// φ'' ω² + φ' α, and the power balance τ ω = Σ m (a − g)·Ġ + I φ̈ φ̇ − loads
/// gives τ = Σ m (a − g)·G' + I₁ α + I₂ φ̈ φ' − F·C' − M φ'. Masses in kg and
/// lengths in mm make kg·mm²/s² = 10⁻³ N·mm.
fn crank_torque_by_hand(theta: f64, omega: f64, alpha: f64) -> (f64, f64) {
    let (r, l, e) = (50.0, 180.0, 12.0);
    let (m1, m2, m3, i1, i2) = (0.3, 0.8, 1.2, 70.0, 2160.0);
    let g = [0.0, -9810.0];
    let (st, ct) = theta.sin_cos();
    let s = (e - r * st) / l;
    let c = (1.0 - s * s).sqrt();
    let (s1, s2) = (-r * ct / l, r * st / l);
    let c1 = -s * s1 / c;
    let c2 = -(s1 * s1 + s * s2 + c1 * c1) / c;
    let (phi1, phi2) = (s1 / c, (s2 * c - s1 * c1) / (c * c));
    // Centroids and their first and second derivatives in θ.
    let crank = (
        [0.5 * r * ct - 5.0 * st, 0.5 * r * st + 5.0 * ct],
        [-0.5 * r * st - 5.0 * ct, 0.5 * r * ct - 5.0 * st],
        [-0.5 * r * ct + 5.0 * st, -0.5 * r * st - 5.0 * ct],
    );
    let rod = (
        [r * ct + 0.5 * l * c, r * st + 0.5 * l * s],
        [-r * st + 0.5 * l * c1, r * ct + 0.5 * l * s1],
        [-r * ct + 0.5 * l * c2, -r * st + 0.5 * l * s2],
    );
    let slider = ([r * ct + l * c, e], [-r * st + l * c1, 0.0], [-r * ct + l * c2, 0.0]);
    let term = |m: f64, (_, d1, d2): ([f64; 2], [f64; 2], [f64; 2])| -> f64 {
        (0..2)
            .map(|k| m * (d2[k] * omega * omega + d1[k] * alpha - g[k]) * d1[k])
            .sum()
    };
    let inertial = term(m1, crank)
        + term(m2, rod)
        + term(m3, slider)
        + i1 * alpha
        + i2 * (phi2 * omega * omega + phi1 * alpha) * phi1;
    let loads = -40.0 * slider.1[0] + 3000.0 * phi1;
    (1e-3 * inertial - loads, slider.0[0])
}

#[test]
fn slider_crank_crank_torque_equals_the_hand_derivation() {
    let (model, loading, plan) = compiled(&common::example_with("slider_crank", SLIDER_CRANK), &[("e", 12.0)]);
    let p1 = model.joints.iter().position(|j| j.name == "P1").expect("P1");
    let mut worst = 0.0f64;
    for k in 0..72 {
        let theta = -3.1 + 6.2 * k as f64 / 71.0;
        for (omega, alpha) in [(1.0, 0.0), (2.0, -3.0), (-0.5, 4.0)] {
            let (want, x) = crank_torque_by_hand(theta, omega, alpha);
            // The branch whose slider is right of the crank pin, as by hand.
            let values = [Sign::Plus, Sign::Minus]
                .into_iter()
                .filter_map(|s| plan.solve(&model, &[theta], &[s]).ok())
                .find(|v| (v[p1] - x).abs() < 1e-9 * 180.0)
                .expect("the hand's branch");
            let got = actuator_forces(&model, &loading, &values, &[omega], &[alpha]).expect("forces")[0];
            let scale = want.abs().max(1.0);
            worst = worst.max((got - want).abs() / scale);
        }
    }
    // Measured 1.1e-14: the two differ by rounding alone.
    assert!(worst < 1e-12, "worst relative difference {worst:e}");
}

/// Seed 000's mechanism A with made-up masses on every link (centroids off
/// their links' axes), a payload force and moment on the platform.
fn seed000_a_with_masses() -> String {
    let extra = "
    units { length = mm; mass = kg; }
    masses {
        s1 { mass = 0.057; centroid = (0, 0, 40); inertia = (10, 12, 5); }
        c1 { mass = 0.072; centroid = (90, 3, 1); inertia = (117, 291, 181); }
        c2 { mass = 0.070; centroid = (100, -2, 0); inertia = (113, 276, 173, 4, -2, 1); }
        s2 { mass = 0.057; centroid = (0, 0, 50); inertia = (10, 12, 5); }
        cross { mass = 0.02; centroid = (0, 0, 0); inertia = (1, 1, 1); }
        platform { mass = 0.494; centroid = (0, l3 / 2, 4); inertia = (7162, 1188, 7106); }
        pc { mass = 0.106; centroid = (0, 0, 5); inertia = (913, 706, 358); }
        r5 { mass = 0.03; centroid = (0, 0, 10); inertia = (2, 2, 1); }
        s3 { mass = 0.067; centroid = (0, 0, 30); inertia = (10, 12, 5); }
    }
    loads { payload = force (0, 0, -50) moment (100, -200, 300) on platform at G; }";
    common::example_with("seed000_a", extra)
}

/// Statics (q̇ = q̈ = 0): the principle of virtual work says
/// τ_k = −Σ m g·∂c/∂q_k − F·∂p/∂q_k − M·∂θ/∂q_k, where the last term's
/// rotation derivative is the axial vector of (∂R/∂q_k) Rᵀ. Every
/// derivative here is a central difference of the positions the solver
/// gives at q ± h e_k (the one place differences are fine), h = 1e-4 mm,
/// which leaves an error of order h² times the third derivatives (about
/// 1e-9 of the largest force here): held to 1e-7.
#[test]
fn seed000_a_statics_balance_gravity_and_the_payload() {
    let (model, loading, plan) = compiled(&seed000_a_with_masses(), &[]);
    let q = [-106.09, 181.67, -70.29];
    let signs = [Sign::Minus, Sign::Plus, Sign::Plus];
    let values = plan.solve(&model, &q, &signs).expect("the paper's assembly");
    let got = actuator_forces(&model, &loading, &values, &[0.0; 3], &[0.0; 3]).expect("forces");
    let h = 1e-4;
    let g = loading.gravity;
    for k in 0..3 {
        let poses_at = |d: f64| {
            let mut qk = q;
            qk[k] += d;
            let v = plan.solve(&model, &qk, &signs).expect("nearby, same branch");
            pkm::runtime::kinematics::link_poses(&model, &v).expect("poses")
        };
        let (plus, minus) = (poses_at(h), poses_at(-h));
        let world = |poses: &[nalgebra::Isometry3<f64>], link: usize, p: &nalgebra::Vector3<f64>| {
            (poses[link] * nalgebra::Point3::from(*p)).coords
        };
        let mut want = 0.0;
        for b in &loading.bodies {
            let Carrier::Link(link) = b.carrier else {
                panic!("this fixture's bodies are links")
            };
            let dc = (world(&plus, link, &b.centroid) - world(&minus, link, &b.centroid)) / (2.0 * h);
            want -= b.mass * g.dot(&dc);
        }
        for l in &loading.loads {
            let dp = (world(&plus, l.link, &l.at) - world(&minus, l.link, &l.at)) / (2.0 * h);
            let (rp, rm) = (plus[l.link].rotation, minus[l.link].rotation);
            // ∂R/∂q Rᵀ ≈ the small rotation from R(q − h) to R(q + h), over 2h.
            let dtheta = (rp * rm.inverse()).scaled_axis() / (2.0 * h);
            want -= l.force.dot(&dp) + l.moment.dot(&dtheta);
        }
        let want = loading.to_newtons(want);
        let scale = got.iter().fold(1.0f64, |a, x| a.max(x.abs()));
        assert!(
            (got[k] - want).abs() < 1e-7 * scale,
            "input {k}: virtual work {} against differences {want}",
            got[k]
        );
    }
}
