//! Newton–Euler's joint reactions (`pkm::runtime::newton_euler`) against a
//! statics worked by hand: a slider-crank whose slider alone has mass,
//! pushed along its guide. The sign convention: a joint's reaction is what
//! its first link exerts on its second, and a joint on the base has the
//! base first.

use pkm::runtime::primitives::Sign;

use crate::common;

/// The slider-crank of `examples/mechanisms/slider_crank.pkm` (r = 50,
/// l = 180, e = 0), its slider alone with mass, pushed back along its guide.
const PUSHED: &str = "
    units { length = mm; mass = kg; }
    masses { slider { mass = 2; centroid = (0, 0); } massless crank, rod; }
    gravity (0, -9.81);
    loads { push = force (-30, 0) on slider at R3; }";

/// At rest, with the crank at θ: the massless rod is a two-force member,
/// so it pushes the slider along itself (direction u from R2 to R3) with
/// the force N that balances the 30 N push: N u_x = 30. The guide then
/// holds the slider up against its weight and the rod's vertical part:
/// (0, 2·9.81 − N u_y). The crank torque is the moment about R1 of the
/// rod's force on the crank, −N u at R2: τ = −(R2 × (−N u))_z.
#[test]
fn a_pushed_slider_by_hand() {
    let text = common::example_with("slider_crank", PUSHED);
    let c = pkm::dsl::compile(&text).unwrap_or_else(|d| panic!("{}", d.render(&text, "test")));
    let a = &c.analysis;
    let model = pkm::dsl::numeric::model(a, &Default::default()).unwrap();
    let loading = pkm::dsl::numeric::loading(a, &model, &Default::default()).unwrap();
    let skcs = pkm::dsl::numeric::skc_parts(a);
    let plan = c.forward().unwrap();
    let joint = |n: &str| model.joints.iter().position(|j| j.name == n).unwrap();
    for theta in [0.3f64, 1.2, 2.5, -0.8, -2.2] {
        let (st, ct) = theta.sin_cos();
        let b = [50.0 * ct, 50.0 * st];
        let x = b[0] + (180.0f64 * 180.0 - b[1] * b[1]).sqrt();
        let values = [Sign::Plus, Sign::Minus]
            .into_iter()
            .filter_map(|s| plan.solve(&model, &[theta], &[s]).ok())
            .find(|v| (v[joint("P1")] - x).abs() < 1e-9)
            .expect("the slider right of the crank pin");
        let r = pkm::runtime::newton_euler::inverse_dynamics(&model, &loading, &skcs, &values, &[0.0], &[0.0]).unwrap();
        let u = [(x - b[0]) / 180.0, -b[1] / 180.0];
        let n = 30.0 / u[0];
        let close = |got: f64, want: f64| (got - want).abs() < 1e-11 * want.abs().max(1.0);
        // The rod (first link of R3) on the slider: N u.
        let r3 = r.joints[joint("R3")].force;
        assert!(
            close(r3[0], n * u[0]) && close(r3[1], n * u[1]),
            "θ = {theta}: R3 {r3:?}"
        );
        // The base (first link of P1) on the slider.
        let p1 = r.joints[joint("P1")].force;
        assert!(
            close(p1[0], 0.0) && close(p1[1], 2.0 * 9.81 - n * u[1]),
            "θ = {theta}: P1 {p1:?}"
        );
        let tau = -(b[0] * (-n * u[1]) - b[1] * (-n * u[0]));
        assert!(
            close(r.actuators[0], tau),
            "θ = {theta}: crank torque {} against {tau}",
            r.actuators[0]
        );
        assert_eq!(r.undetermined, vec![0]);
    }
}

/// Dynamics needs every moving link described: a mass, or `massless`.
#[test]
fn a_link_without_mass_is_named() {
    let text = common::example_with(
        "slider_crank",
        &PUSHED.replace("massless crank, rod;", "massless crank;"),
    );
    let c = pkm::dsl::compile(&text).unwrap();
    let model = pkm::dsl::numeric::model(&c.analysis, &Default::default()).unwrap();
    let e = pkm::dsl::numeric::loading(&c.analysis, &model, &Default::default()).unwrap_err();
    let message = &e.0[0].message;
    assert!(message.contains("rod has none"), "{message}");
}
