//! Velocities and accelerations from the differentiated loop equations
//! (pkm-runtime's `velocity`) against central finite differences of the
//! generated position solutions along q(t) = q + q̇ t + q̈ t²/2, on the same
//! branch: every joint rate and second derivative, every point's velocity
//! and acceleration, every output rate; the
//! forward velocity map reproduces the output rates and the inverse map
//! takes them back to the input rates.

use crate::common;
use crate::mechanisms::{
    CouplerDriven, Cylinder, FiveBar, FiveBarPa, FourBar, Inverted, Punch, Rssp, RsspSolution, Rssr, RssrSolution,
    Rsur, RsurSolution, SeedA, SeedASolution, SeedAU, SeedB, Shaper, SliderCrank, Spherical, Watt, Yoke,
};

use common::max_error;
use pkm::dsl::screw::SplitMix;
use pkm::runtime::primitives::Sign::{Minus, Plus};
use pkm::runtime::velocity;
use std::collections::HashMap;
use std::f64::consts::PI;

/// A five-point stencil's derivative (first or second, error O(h⁴)) from
/// samples at −2h, −h, 0, h, 2h.
fn stencil(f: [&[f64]; 5], second: bool, h: f64) -> Vec<f64> {
    (0..f[0].len())
        .map(|i| {
            let [a, b, c, d, e] = f.map(|x| x[i]);
            if second {
                (-e + 16.0 * d - 30.0 * c + 16.0 * b - a) / (12.0 * h * h)
            } else {
                (8.0 * (d - b) - (e - a)) / (12.0 * h)
            }
        })
        .collect()
}

/// The derivative from samples at −2h, −h, −h/2, 0, h/2, h, 2h: the
/// stencils at h and h/2, Richardson-extrapolated (error O(h⁶)), so that
/// configurations near a singularity, where higher derivatives are large,
/// are measured as well as the others.
fn derivative(v: &[Vec<f64>], second: bool, h: f64) -> Vec<f64> {
    let wide = stencil([&v[0], &v[1], &v[3], &v[5], &v[6]], second, h);
    let narrow = stencil([&v[1], &v[2], &v[3], &v[4], &v[5]], second, h / 2.0);
    narrow.iter().zip(&wide).map(|(n, w)| n + (n - w) / 15.0).collect()
}

fn first(v: &[Vec<f64>], h: f64) -> Vec<f64> {
    derivative(v, false, h)
}

fn second(v: &[Vec<f64>], h: f64) -> Vec<f64> {
    derivative(v, true, h)
}

macro_rules! check {
    ($ty:ident, $file:expr, $ranges:expr, $rate:expr) => {{
        let (a, model) = common::example($file);
        let outputs = pkm::dsl::numeric::newton_outputs(&a, &model, &HashMap::new()).unwrap();
        let scale = pkm::runtime::kinematics::model_scale(&model);
        let params = Default::default();
        let ranges: [(f64, f64); $ty::INPUTS.len()] = $ranges;
        let mut rng = SplitMix::new(11);
        let (mut checked, mut worst_v, mut worst_a) = (0, 0.0f64, 0.0f64);
        let (mut inverted, mut worst_inverse) = (0, 0.0f64);
        let input_angles: Vec<bool> = model
            .inputs()
            .iter()
            .map(|&j| model.joints[j].kind != pkm::runtime::model::JointType::P)
            .collect();
        while checked < 50 {
            let q = ranges.map(|(lo, hi)| lo + (hi - lo) * (rng.symmetric() + 1.0) / 2.0);
            let qd = ranges.map(|_| $rate * rng.symmetric());
            let qdd = ranges.map(|_| $rate * rng.symmetric());
            let fk = $ty::fk(&params, &q);
            let Some(b) = fk.iter().find(|b| b.result.is_ok()) else {
                continue;
            };
            let signs = b.signs;
            let at = |t: f64| {
                let qt: [f64; $ty::INPUTS.len()] = std::array::from_fn(|i| q[i] + qd[i] * t + qdd[i] * t * t / 2.0);
                $ty::fk_branch(&params, &qt, signs).ok()
            };
            // Five-point stencils (error O(h⁴)); h small against the branch's reach.
            let h = 2.5e-4;
            let Some(s) = [-2.0, -1.0, -0.5, 0.0, 0.5, 1.0, 2.0]
                .map(|k| at(k * h))
                .into_iter()
                .collect::<Option<Vec<_>>>()
            else {
                continue;
            };
            // Angles unwrapped against the centre so the stencils see a smooth curve.
            let unwrap = |x: &[f64], centre: &[f64], angle: &[bool]| -> Vec<f64> {
                x.iter()
                    .zip(centre)
                    .zip(angle)
                    .map(|((a, c), &r)| {
                        if r {
                            c + pkm::runtime::solution::wrap_angle(a - c)
                        } else {
                            *a
                        }
                    })
                    .collect()
            };
            let centre = s[3].q;
            let joints: Vec<Vec<f64>> = s.iter().map(|x| unwrap(&x.q, &centre, &$ty::REVOLUTE)).collect();
            let outs: Vec<Vec<f64>> = s
                .iter()
                .map(|x| unwrap(&x.outputs, &s[3].outputs, &$ty::OUTPUT_ANGLES))
                .collect();
            let acc = velocity::accelerations(&model, &centre, &qd, &qdd)
                .unwrap_or_else(|e| panic!("{}: {e} at {q:?}", $file));
            let v = &acc.velocities;
            // Every point's velocity and acceleration against the differenced positions.
            let poses = pkm::runtime::kinematics::link_poses(&model, &centre).unwrap();
            let points: Vec<Vec<f64>> = s.iter().map(|x| x.points.iter().flatten().copied().collect()).collect();
            let dim = s[3].points[0].len();
            let flat = |p: Vec<[f64; 3]>| p.iter().flat_map(|x| x[..dim].to_vec()).collect::<Vec<f64>>();
            let lengths = vec![false; points[0].len()];
            let pv = flat(velocity::point_velocities(&model, &poses, &v.twists));
            let e = max_error(&pv, &first(&points, h), &lengths, scale);
            assert!(e < 1e-6, "{}: point velocities off by {e:e} at {q:?}", $file);
            worst_v = worst_v.max(e);
            let pa = flat(velocity::point_accelerations(&model, &poses, &acc));
            let e = max_error(&pa, &second(&points, h), &lengths, scale);
            assert!(e < 1e-5, "{}: point accelerations off by {e:e} at {q:?}", $file);
            worst_a = worst_a.max(e);
            let e = max_error(&v.rates, &first(&joints, h), &$ty::REVOLUTE, scale);
            assert!(e < 1e-6, "{}: joint rates off by {e:e} at {q:?}", $file);
            worst_v = worst_v.max(e);
            let e = max_error(&acc.rates, &second(&joints, h), &$ty::REVOLUTE, scale);
            assert!(e < 1e-5, "{}: joint accelerations off by {e:e} at {q:?}", $file);
            worst_a = worst_a.max(e);
            if !outputs.is_empty() {
                let poses = pkm::runtime::kinematics::link_poses(&model, &centre).unwrap();
                let rates = velocity::output_rates(&model, &poses, &outputs, &v.rates, &v.twists);
                let e = max_error(&rates, &first(&outs, h), &$ty::OUTPUT_ANGLES, scale);
                assert!(e < 1e-6, "{}: output rates off by {e:e} at {q:?}", $file);
                // The forward Jacobian maps the input rates to the same output rates.
                let j = velocity::jacobians(&model, &centre, &outputs).unwrap();
                let jq = j.forward.expect("regular here") * pkm::runtime::nalgebra::DVector::from_column_slice(&qd);
                let e = max_error(jq.as_slice(), &rates, &$ty::OUTPUT_ANGLES, scale);
                assert!(e < 1e-12, "{}: forward Jacobian off by {e:e}", $file);
                // The inverse map sends those (differences-checked) output rates back to the input rates.
                if let Some(ji) = j.inverse {
                    let back = ji * pkm::runtime::nalgebra::DVector::from_column_slice(&rates);
                    let e = max_error(back.as_slice(), &qd, &input_angles, scale);
                    assert!(e < 1e-9, "{}: inverse Jacobian off by {e:e} at {q:?}", $file);
                    worst_inverse = worst_inverse.max(e);
                    inverted += 1;
                }
            }
            checked += 1;
        }
        eprintln!(
            "{}: worst joint-rate error {worst_v:e}, acceleration {worst_a:e}; inverse map checked {inverted} times, worst {worst_inverse:e}",
            $file
        );
        assert!(outputs.is_empty() || inverted > 0, "{}: the inverse map was never checked", $file);
    }};
}

#[test]
fn planar() {
    check!(FourBar, "four_bar", [(-PI, PI)], 1.0);
    check!(SliderCrank, "slider_crank", [(-PI, PI)], 1.0);
    check!(Inverted, "inverted_slider_crank", [(-PI, PI)], 1.0);
    check!(Shaper, "crank_shaper", [(-PI, PI)], 1.0);
    check!(Cylinder, "cylinder_rocker", [(-60.0, 300.0)], 1.0);
    check!(Yoke, "scotch_yoke", [(-PI, PI)], 1.0);
    check!(CouplerDriven, "four_bar_coupler_driven", [(-PI, PI)], 1.0);
    check!(FiveBar, "five_bar", [(1.2, 2.8), (0.3, 1.9)], 1.0);
    check!(Watt, "watt_six_bar", [(-PI, PI)], 1.0);
    check!(Punch, "seed003_punch", [(-PI, PI)], 1.0);
}

#[test]
fn spherical() {
    check!(Spherical, "spherical_four_bar", [(-PI, PI)], 1.0);
}

#[test]
fn spatial() {
    check!(FiveBarPa, "five_bar_pa", [(-PI, PI), (-PI, PI), (-300.0, 300.0)], 1.0);
    check!(SeedA, "seed000_a", [(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)], 20.0);
    check!(
        SeedAU,
        "seed000_a_u",
        [(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)],
        20.0
    );
    check!(SeedB, "seed000_b", [(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)], 20.0);
}

#[test]
fn generated_point_velocities_and_accelerations() {
    // Seed 000's A asks for `velocity` and `acceleration`: its generated
    // point functions (order `POINTS`) against differences of its fk points.
    use pkm::runtime::primitives::Sign;
    let p = Default::default();
    let signs = [Sign::Minus, Sign::Plus, Sign::Plus];
    let (q0, qd, qdd) = ([-106.09, 181.67, -70.29], [20.0, -10.0, 20.0], [-5.0, 8.0, 3.0]);
    let h = 2.5e-4;
    let s: Vec<SeedASolution> = [-2.0, -1.0, -0.5, 0.0, 0.5, 1.0, 2.0]
        .iter()
        .map(|k| {
            let t = k * h;
            let q: [f64; 3] = std::array::from_fn(|i| q0[i] + qd[i] * t + qdd[i] * t * t / 2.0);
            SeedA::fk_branch(&p, &q, signs).unwrap()
        })
        .collect();
    let q = s[3].q;
    let points: Vec<Vec<f64>> = s.iter().map(|x| x.points.iter().flatten().copied().collect()).collect();
    let v = SeedA::velocity(&p, &q, &qd).unwrap();
    let a = SeedA::acceleration(&p, &q, &qd, &qdd).unwrap();
    let pv: Vec<f64> = SeedA::point_velocities(&p, &q, &v).unwrap().concat();
    let pa: Vec<f64> = SeedA::point_accelerations(&p, &q, &a).unwrap().concat();
    let lengths = vec![false; pv.len()];
    let e = max_error(&pv, &first(&points, h), &lengths, 1.0);
    assert!(e < 1e-6, "point velocities off by {e:e} mm/s");
    let e = max_error(&pa, &second(&points, h), &lengths, 1.0);
    assert!(e < 1e-4, "point accelerations off by {e:e} mm/s²");
}

/// A mechanism with an S–S link (the RSSR, the R-S-S-P), both branches at 50 random crank angles, rates and
/// second derivatives: the velocity equations at the model's values of the
/// interpreted solution (`Solution::model_values`: the S joints' rotation
/// vectors, the coupler's spin by the plan's convention) against
/// differences of the generated fk along q(t): the revolutes' rates, every
/// point's velocity and acceleration (the joints' and the coupler's
/// midpoint M, on its S–S line, so the idle spin moves none of them), the
/// output's rate. The S joints' own rates carry the coupler's spin about
/// its S–S line, which no difference of positions sees: the velocity
/// analysis takes it as zero (the state the dynamics assume), checked as
/// `â·ω = 0` and `â·ω̇ = 0` with `â` from the generated fk's ball centres.
macro_rules! with_spheres {
    ($ty:ident, $sol:ident, $file:expr, $signs:expr) => {{
        use pkm::runtime::model::JointType;
        let (a, model) = common::example($file);
        let outputs = pkm::dsl::numeric::newton_outputs(&a, &model, &HashMap::new()).unwrap();
        let plan = pkm::dsl::planner::forward_plan(&a).unwrap();
        let scale = pkm::runtime::kinematics::model_scale(&model);
        let (offsets, _) = model.value_offsets();
        let params = Default::default();
        let mut rng = SplitMix::new(11);
        let h = 2.5e-4;
        let (mut checked, mut worst_v, mut worst_a, mut spins) = (0, 0.0f64, 0.0f64, 0);
        for _ in 0..50 {
            let (q, qd, qdd) = (PI * rng.symmetric(), rng.symmetric(), rng.symmetric());
            for signs in $signs {
                assert_eq!(plan.branches, signs.len());
                let s: Vec<$sol> = [-2.0, -1.0, -0.5, 0.0, 0.5, 1.0, 2.0]
                    .iter()
                    .map(|k| {
                        let t = k * h;
                        $ty::fk_branch(&params, &[q + qd * t + qdd * t * t / 2.0], signs).unwrap()
                    })
                    .collect();
                let centre = spatial_solution(&model, &plan, q, &signs);
                let values = centre.model_values(&model);
                let acc = velocity::accelerations(&model, &values, &[qd], &[qdd]).unwrap();
                let v = &acc.velocities;
                let poses = pkm::runtime::kinematics::link_poses(&model, &values).unwrap();
                let points: Vec<Vec<f64>> = s.iter().map(|x| x.points.iter().flatten().copied().collect()).collect();
                let lengths = vec![false; points[0].len()];
                let flat = |p: Vec<[f64; 3]>| p.concat();
                let pv = flat(velocity::point_velocities(&model, &poses, &v.twists));
                let e = max_error(&pv, &first(&points, h), &lengths, scale);
                assert!(e < 1e-6, "{}: point velocities off by {e:e} at {q}", $file);
                worst_v = worst_v.max(e);
                let pa = flat(velocity::point_accelerations(&model, &poses, &acc));
                let e = max_error(&pa, &second(&points, h), &lengths, scale);
                assert!(e < 1e-5, "{}: point accelerations off by {e:e} at {q}", $file);
                worst_a = worst_a.max(e);
                let centre_q = s[3].q;
                let unwrap = |x: &[f64]| -> Vec<f64> {
                    x.iter()
                        .zip(&centre_q)
                        .map(|(a, c)| c + pkm::runtime::solution::wrap_angle(a - c))
                        .collect()
                };
                let joints: Vec<Vec<f64>> = s.iter().map(|x| unwrap(&x.q)).collect();
                let (d1, d2) = (first(&joints, h), second(&joints, h));
                for (j, joint) in model.joints.iter().enumerate() {
                    if joint.kind == JointType::R {
                        let e = (v.rates[offsets[j]] - d1[j]).abs();
                        assert!(e < 1e-6, "{}: {} rate off by {e:e} at {q}", $file, joint.name);
                        worst_v = worst_v.max(e);
                        let e = (acc.rates[offsets[j]] - d2[j]).abs();
                        assert!(e < 1e-5, "{}: {} acceleration off by {e:e} at {q}", $file, joint.name);
                        worst_a = worst_a.max(e);
                    }
                }
                // Every link held by two S joints and nothing else: no spin about its line.
                for link in 0..model.links.len() {
                    let held: Vec<usize> = (0..model.joints.len())
                        .filter(|&j| model.joints[j].links.contains(&link))
                        .collect();
                    let balls = held.iter().all(|&j| model.joints[j].kind == JointType::S);
                    let [j1, j2] = held[..] else { continue };
                    if !balls {
                        continue;
                    }
                    let [p1, p2] = [s[3].points[j1], s[3].points[j2]];
                    let axis = pkm::runtime::nalgebra::Vector3::from(p2) - pkm::runtime::nalgebra::Vector3::from(p1);
                    let axis = axis / axis.norm();
                    let spin = v.twists[link].w.dot(&axis) / v.twists[link].w.norm().max(1.0);
                    assert!(spin.abs() < 1e-12, "{}: {} spins at {spin:e} about its S–S line", $file, model.links[link]);
                    let spin = acc.twists[link].w.dot(&axis) / acc.twists[link].w.norm().max(1.0);
                    assert!(spin.abs() < 1e-12, "{}: {}'s spin accelerates at {spin:e}", $file, model.links[link]);
                    spins += 1;
                }
                let outs: Vec<Vec<f64>> = s.iter().map(|x| unwrap(&x.outputs)).collect();
                let rates = velocity::output_rates(&model, &poses, &outputs, &v.rates, &v.twists);
                let e = max_error(&rates, &first(&outs, h), &$ty::OUTPUT_ANGLES, scale);
                assert!(e < 1e-6, "{}: output rate off by {e:e} at {q}", $file);
                checked += 1;
            }
        }
        eprintln!(
            "{}: {checked} branches, worst rate error {worst_v:e}, acceleration {worst_a:e}, {spins} couplers' spins zero",
            $file
        );
        assert!(checked >= 100, "{}: only {checked} branches checked", $file);
    }};
}

#[test]
fn rssr() {
    with_spheres!(Rssr, RssrSolution, "rssr", [[Plus], [Minus]]);
}

#[test]
fn rssp() {
    with_spheres!(Rssp, RsspSolution, "rssp", [[Plus], [Minus]]);
}

/// The R-S-U-R's four branches: the U's two angles' rates (the coupler's
/// spin, which no point on its S1–U1 line shows) against differences too.
#[test]
fn rsur() {
    with_spheres!(
        Rsur,
        RsurSolution,
        "rsur",
        [[Plus, Plus], [Minus, Plus], [Plus, Minus], [Minus, Minus]]
    );
}

/// The interpreted solution of `plan` at crank angle `q` on the branch `signs`.
fn spatial_solution(
    model: &pkm::runtime::model::Model,
    plan: &pkm::runtime::plan::Plan,
    q: f64,
    signs: &[pkm::runtime::primitives::Sign],
) -> pkm::runtime::plan::Solution {
    pkm::runtime::plan::run(model, plan, &[q], signs).unwrap()
}
