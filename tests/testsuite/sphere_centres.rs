//! The sphere a rigid link keeps about its known spherical (or universal)
//! centre, met by a point of the new link that reaches the link without
//! moving (rod's generalised match): the R-S-U-R four-bar's rocker
//! from its crank (the U centre at l from the S centre) and its crank from
//! its rocker (the S centre at l from the U centre), against the RSSR-style
//! closed form by hand. The steps the planner finds (the sphere, then the
//! U's two turns, `two_turns` and an aim) are run one by one, the sphere's
//! root chosen, the U's the `+` one.

use crate::common;

use pkm::runtime::frame::Frame;
use pkm::runtime::plan::{Constraint, Radius, Step};
use pkm::runtime::primitives::Sign;
use pkm::runtime::solution::PointRef;
use pkm::runtime::steps::search::Search;
use pkm::runtime::steps::{self, Geometry, Given, Solved};
use std::borrow::Cow;

const A: f64 = 40.0;
const B: f64 = 120.0;
const L: f64 = 160.0;
const D: f64 = 100.0;
const E: f64 = 40.0;
const H: f64 = 60.0;

/// The example's model and its steps with joint `given` given (value 0):
/// every step the planner finds.
fn steps_given(given: &str) -> (pkm::runtime::model::Model, Vec<Step>) {
    let text = common::example_text("rsur").0;
    let a = pkm::dsl::analyze_source(&text).unwrap_or_else(|d| panic!("{}", d.render(&text, "rsur.pkm")));
    let model = pkm::dsl::numeric::model(&a, &Default::default()).unwrap();
    let mut g = vec![None; model.joints.len()];
    g[joint(&model, given)] = Some(0);
    let mut known = vec![false; model.links.len()];
    known[0] = true;
    let mut search = Search::new(&model, g, known, vec![None; model.links.len()], vec![]);
    while search.step() {}
    let plan = search.into_plan(1, vec![]);
    (model, plan.steps)
}

fn joint(model: &pkm::runtime::model::Model, name: &str) -> usize {
    model.joints.iter().position(|j| j.name == name).unwrap()
}

fn link(model: &pkm::runtime::model::Model, name: &str) -> usize {
    model.links.iter().position(|l| l == name).unwrap()
}

/// The world poses after running `steps` at given value `v` and sign `sign`.
fn run(model: &pkm::runtime::model::Model, steps: &[Step], v: f64, sign: Sign) -> Vec<Frame<f64>> {
    let geometry = Geometry::of(model);
    let mut state = Solved {
        poses: vec![Frame::identity(); model.links.len()],
        values: vec![None; model.joints.len()],
    };
    let name = |_: usize| Cow::Borrowed("");
    let signs = [sign, Sign::Plus];
    let given = Given {
        values: &[v],
        signs: &signs,
        name: &name,
        sites: 0,
    };
    for (k, s) in steps.iter().enumerate() {
        steps::execute(k, s, &geometry, &mut state, &given).unwrap();
    }
    state.poses
}

/// The two roots ψ of `p cosψ + q sinψ = c`, by hand.
fn roots(p: f64, q: f64, c: f64) -> [f64; 2] {
    let (phi, r) = (q.atan2(p), p.hypot(q));
    let w = (c / r).acos();
    [phi + w, phi - w]
}

fn same_angle(x: f64, y: f64) -> bool {
    pkm::runtime::solution::wrap_angle(x - y).abs() < 1e-12
}

/// Given the crank's θ, the rocker's U centre (d, e + b cosψ, h + b sinψ)
/// keeps |U − S| = l from the crank's S centre (a cosθ, a sinθ, 0):
/// 2b(e − a sinθ) cosψ + 2bh sinψ = l² − (d − a cosθ)² − (e − a sinθ)² − b² − h².
#[test]
fn the_rocker_meets_the_sphere_about_the_s_centre() {
    let (model, steps) = steps_given("R1");
    let (r2, s1, ua) = (joint(&model, "R2"), joint(&model, "S1"), joint(&model, "U1.a"));
    let (crank, coupler, rocker) = (link(&model, "crank"), link(&model, "coupler"), link(&model, "rocker"));
    let sphere = steps.iter().find_map(|s| match s {
        Step::Locus {
            joint,
            constraint: Constraint::Sphere { centre, radius },
            ..
        } if *joint == r2 => Some((centre.clone(), *radius)),
        _ => None,
    });
    let (centre, radius) = sphere.expect("the rocker by the sphere about S1");
    assert_eq!((centre.link, centre.point), (crank, PointRef::Joint(s1)));
    assert_eq!(
        radius,
        Radius::Rod {
            link: coupler,
            point: PointRef::Joint(ua),
            joint: s1
        }
    );
    let mut checked = 0;
    for i in 0..64 {
        let theta = -3.0 + 6.0 * f64::from(i) / 63.0;
        let (s, c) = theta.sin_cos();
        let rhs = L * L - (D - A * c).powi(2) - (E - A * s).powi(2) - B * B - H * H;
        let want = roots(2.0 * B * (E - A * s), 2.0 * B * H, rhs);
        let got = [Sign::Plus, Sign::Minus].map(|sign| {
            let poses = run(&model, &steps, theta, sign);
            // The rocker's turn about +x: its +y axis at (0, cosψ, sinψ).
            let r = poses[rocker].r;
            r[2][1].atan2(r[1][1])
        });
        assert!(
            (same_angle(got[0], want[0]) && same_angle(got[1], want[1]))
                || (same_angle(got[0], want[1]) && same_angle(got[1], want[0])),
            "θ = {theta}: {got:?} vs {want:?}"
        );
        checked += 1;
    }
    assert_eq!(checked, 64);
}

/// Given the rocker's ψ, the crank's S centre keeps |S − U| = l from the
/// rocker's U centre, known through the U's two axes:
/// 2a(d cosθ + (e + b cosψ) sinθ) = a² + d² + (e + b cosψ)² + (h + b sinψ)² − l².
#[test]
fn the_crank_meets_the_sphere_about_the_u_centre() {
    let (model, steps) = steps_given("R2");
    let (r1, s1, ua) = (joint(&model, "R1"), joint(&model, "S1"), joint(&model, "U1.a"));
    let (crank, coupler, rocker) = (link(&model, "crank"), link(&model, "coupler"), link(&model, "rocker"));
    let sphere = steps.iter().find_map(|s| match s {
        Step::Locus {
            joint,
            constraint: Constraint::Sphere { centre, radius },
            ..
        } if *joint == r1 => Some((centre.clone(), *radius)),
        _ => None,
    });
    let (centre, radius) = sphere.expect("the crank by the sphere about U1");
    assert_eq!((centre.link, centre.point), (rocker, PointRef::Joint(ua)));
    assert_eq!(centre.hops.len(), 2, "across U1.b and U1.a");
    assert_eq!(
        radius,
        Radius::Rod {
            link: coupler,
            point: PointRef::Joint(s1),
            joint: ua
        }
    );
    let (mut met, mut refused) = (0, 0);
    for i in 0..64 {
        let psi = -3.0 + 6.0 * f64::from(i) / 63.0;
        let (y, z) = (E + B * psi.cos(), H + B * psi.sin());
        let rhs = A * A + D * D + y * y + z * z - L * L;
        let (p, q) = (2.0 * A * D, 2.0 * A * y);
        if rhs.abs() > p.hypot(q) {
            // Out of the crank's reach by hand: the step refuses it.
            let geometry = Geometry::of(&model);
            let mut state = Solved {
                poses: vec![Frame::identity(); model.links.len()],
                values: vec![None; model.joints.len()],
            };
            let name = |_: usize| Cow::Borrowed("");
            let given = Given {
                values: &[psi],
                signs: &[Sign::Plus, Sign::Plus],
                name: &name,
                sites: 0,
            };
            let out: Result<Vec<()>, _> = steps
                .iter()
                .enumerate()
                .map(|(k, s)| steps::execute(k, s, &geometry, &mut state, &given))
                .collect();
            assert!(out.is_err(), "ψ = {psi}: out of reach by hand");
            refused += 1;
            continue;
        }
        met += 1;
        let want = roots(p, q, rhs);
        let got = [Sign::Plus, Sign::Minus].map(|sign| {
            let r = run(&model, &steps, psi, sign)[crank].r;
            r[1][0].atan2(r[0][0])
        });
        assert!(
            (same_angle(got[0], want[0]) && same_angle(got[1], want[1]))
                || (same_angle(got[0], want[1]) && same_angle(got[1], want[0])),
            "ψ = {psi}: {got:?} vs {want:?}"
        );
    }
    eprintln!("rsur ik: {met} ψ met by hand, {refused} refused out of reach");
    assert!(met >= 20 && refused >= 5, "{met} met, {refused} refused");
}
