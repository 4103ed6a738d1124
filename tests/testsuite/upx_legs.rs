//! Legs with a universal joint at the base and both ends known: the 6-UPS
//! Stewart–Gough platform (examples/mechanisms/ups_6.pkm, the platform's
//! full pose given) and the translational 3-UPU (upu_3.pkm, its position
//! given), whose base U's first half is the `plane_through` step. Checked
//! against the closed form written out here (a leg is as long as the
//! distance between its two centres, `|p + R·b_i − a_i|`), the U's two
//! angles against the leg's line by the documented conventions, the
//! generated solvers against the plan interpreter, and every branch against
//! Newton's inverse solution.

use crate::common;
use crate::mechanisms::{Ups, Upu};

use common::max_error;
use pkm::dsl::screw::SplitMix;
use pkm::runtime::kinematics;
use pkm::runtime::model::JointType;
use pkm::runtime::nalgebra::{Rotation3, Vector3};
use pkm::runtime::newton::{self, NewtonOptions};
use pkm::runtime::plan;
use std::collections::HashMap;

/// ups_6's base and platform joints: leg i from the base circle (radius
/// 200) at α_i to the platform circle (radius 100) at β_i, degrees.
const UPS_LEGS: [(f64, f64); 6] = [
    (20.0, 40.0),
    (100.0, 80.0),
    (140.0, 160.0),
    (220.0, 200.0),
    (260.0, 280.0),
    (340.0, 320.0),
];

fn on_circle(r: f64, deg: f64) -> Vector3<f64> {
    let t = deg.to_radians();
    Vector3::new(r * t.cos(), r * t.sin(), 0.0)
}

/// `R = R_z(rz)·R_y(ry)·R_x(rx)` (docs/language.md, outputs).
fn rotation(rx: f64, ry: f64, rz: f64) -> Rotation3<f64> {
    Rotation3::from_axis_angle(&Vector3::z_axis(), rz)
        * Rotation3::from_axis_angle(&Vector3::y_axis(), ry)
        * Rotation3::from_axis_angle(&Vector3::x_axis(), rx)
}

/// The direction a U with its first axis `a` (fixed in the base, unit)
/// gives its second link's z axis at angles `ta`, `tb`, by the documented
/// conventions (docs/language.md, U joints; the canonical frame of
/// `steps::canonical_frame`): the cross is the first axis's joint frame
/// (z = `a`, x = the world x made normal to `a`, the world y where `a` is
/// within about 25° of x) turned by `ta` about `a`, its x axis the second
/// axis `b`; at `tb = 0` the second link's joint frame of `b` has its y
/// axis along `a`, and the legs place `b` along the leg's x, so that frame's
/// y is the leg's z: turned by `tb` about `b`, `cos tb·a + sin tb·(b × a)`.
fn leg_direction(a: Vector3<f64>, ta: f64, tb: f64) -> Vector3<f64> {
    let e = if a.x.abs() < 0.9 { Vector3::x() } else { Vector3::y() };
    let xa = (e - a * a.dot(&e)).normalize();
    let b = xa * ta.cos() + a.cross(&xa) * ta.sin();
    a * tb.cos() + b.cross(&a) * tb.sin()
}

/// One leg of a UPS or UPU platform, its names looked up once: the slide's
/// and the base U's two joint values, the base U's centre and the leg's
/// far end (the S centre, or the platform U's) among the points, its base
/// joint `a` and platform joint `b` (at the platform's home pose), and its
/// base U's first axis.
struct Leg {
    slide: usize,
    ua: usize,
    ub: usize,
    u_point: usize,
    end_point: usize,
    a: Vector3<f64>,
    b: Vector3<f64>,
    axis: Vector3<f64>,
}

fn index(names: &[&str], name: &str) -> usize {
    names
        .iter()
        .position(|n| *n == name)
        .unwrap_or_else(|| panic!("no {name} in {names:?}"))
}

/// Every branch of the generated Stewart inverse solution at 10⁵ poses:
/// each leg's slide is ±|p + R·b_i − a_i|, the S centre is the platform's
/// b_i, and the U's angles send the leg from the U's centre along the
/// slide to the S centre. 2⁶ branches (each leg's two senses), all real.
#[test]
fn stewart_legs_by_hand() {
    let mut rng = SplitMix::new(17);
    let (mut solved, mut worst_length, mut worst_line) = (0usize, 0.0f64, 0.0f64);
    let params = Default::default();
    // Each leg's joints and points by name, its base and platform joints and
    // its U's first axis, found once (the same for every pose).
    let legs: Vec<_> = UPS_LEGS
        .iter()
        .enumerate()
        .map(|(i, &(alpha, beta))| {
            let n = i + 1;
            let q = |name: String| index(&Ups::JOINTS, &name);
            let at = |name: String| index(&Ups::POINTS, &name);
            let t = alpha.to_radians();
            Leg {
                slide: q(format!("P{n}")),
                ua: q(format!("U{n}.a")),
                ub: q(format!("U{n}.b")),
                u_point: at(format!("U{n}.a")),
                end_point: at(format!("S{n}")),
                a: on_circle(200.0, alpha),
                b: on_circle(100.0, beta),
                axis: Vector3::new(-t.sin(), t.cos(), 0.0),
            }
        })
        .collect();
    for _ in 0..100_000 {
        let g = common::poses::ups(&mut rng);
        let (p, r) = (Vector3::new(g[0], g[1], g[2]), rotation(g[3], g[4], g[5]));
        let branches = Ups::ik(&params, &g);
        assert_eq!(branches.len(), 64);
        let mut senses = Vec::new();
        for branch in &branches {
            let s = branch.result.as_ref().unwrap_or_else(|e| panic!("at {g:?}: {e}"));
            solved += 1;
            let mut sense = 0u32;
            for (i, leg) in legs.iter().enumerate() {
                let ai = leg.a;
                let ball = p + r * leg.b;
                let length = (ball - ai).norm();
                let slide = s.q[leg.slide];
                worst_length = worst_length.max((slide.abs() - length).abs() / length);
                sense |= u32::from(slide < 0.0) << i;
                // The U's centre and the ball where the solution puts them.
                let (u, sc) = (
                    Vector3::from(s.points[leg.u_point]),
                    Vector3::from(s.points[leg.end_point]),
                );
                worst_line = worst_line.max((u - ai).norm() / 200.0).max((sc - ball).norm() / 200.0);
                let d = leg_direction(leg.axis, s.q[leg.ua], s.q[leg.ub]);
                worst_line = worst_line.max((ai + d * slide - ball).norm() / 200.0);
            }
            senses.push(sense);
        }
        senses.sort_unstable();
        senses.dedup();
        assert_eq!(senses.len(), 64, "at {g:?}: every branch a different choice of senses");
    }
    eprintln!("ups_6: {solved} branches over 10⁵ poses, worst leg length {worst_length:e}, worst line {worst_line:e}");
    assert!(worst_length < 1e-12 && worst_line < 1e-12);
}

/// The same for the translational 3-UPU at 10⁵ positions: leg i is
/// ±|p + b_i − a_i| long (a_i on the base circle of radius 200, b_i on the
/// platform's of radius 100, both at 120°·i), its base U sends it there,
/// and the platform U's centres are at p + b_i (three points: the platform
/// translated, not turned). 2³ branches (each leg's two senses).
#[test]
fn translational_upu_legs_by_hand() {
    let mut rng = SplitMix::new(19);
    let (mut solved, mut worst) = (0usize, 0.0f64);
    let params = Default::default();
    let legs: Vec<_> = (0..3)
        .map(|i| {
            let n = i + 1;
            let deg = 120.0 * i as f64;
            let q = |name: String| index(&Upu::JOINTS, &name);
            let at = |name: String| index(&Upu::POINTS, &name);
            let t = deg.to_radians();
            Leg {
                slide: q(format!("P{n}")),
                ua: q(format!("U{n}1.a")),
                ub: q(format!("U{n}1.b")),
                u_point: at(format!("U{n}1.a")),
                end_point: at(format!("U{n}2.b")),
                a: on_circle(200.0, deg),
                b: on_circle(100.0, deg),
                axis: Vector3::new(-t.sin(), t.cos(), 0.0),
            }
        })
        .collect();
    for _ in 0..100_000 {
        let g = common::poses::upu(&mut rng);
        let p = Vector3::new(g[0], g[1], g[2]);
        let branches = Upu::ik(&params, &g);
        assert_eq!(branches.len(), 8);
        for branch in &branches {
            let s = branch.result.as_ref().unwrap_or_else(|e| panic!("at {g:?}: {e}"));
            solved += 1;
            for leg in &legs {
                let ai = leg.a;
                let top = p + leg.b;
                let length = (top - ai).norm();
                let slide = s.q[leg.slide];
                let d = leg_direction(leg.axis, s.q[leg.ua], s.q[leg.ub]);
                let e = [
                    (slide.abs() - length).abs() / length,
                    (Vector3::from(s.points[leg.u_point]) - ai).norm() / 200.0,
                    (Vector3::from(s.points[leg.end_point]) - top).norm() / 200.0,
                    (ai + d * slide - top).norm() / 200.0,
                ];
                worst = e.into_iter().fold(worst, f64::max);
            }
        }
    }
    eprintln!("upu_3: {solved} branches over 10⁵ positions, worst {worst:e}");
    assert!(worst < 1e-12, "worst {worst:e}");
}

/// Generated = interpreted, and every interpreted branch against Newton's
/// inverse solution started from its model values (S joints' rotation
/// vectors, [`plan::Solution::model_values`]) 1e-3 away: revolutes and
/// slides, and every joint's point, agree to 1e-9.
fn against_newton<const N: usize>(
    file: &str,
    poses: &[[f64; N]],
    generated: impl Fn(&[f64; N]) -> Vec<Option<Vec<f64>>>,
) {
    let (a, model) = common::example(file);
    let plan = pkm::dsl::planner::inverse_plan(&a).unwrap();
    let outputs = pkm::dsl::numeric::newton_outputs(&a, &model, &HashMap::new()).unwrap();
    let scale = kinematics::model_scale(&model);
    let (offsets, _) = model.value_offsets();
    let revolute: Vec<bool> = model.joints.iter().map(|j| j.kind == JointType::R).collect();
    let options = NewtonOptions {
        tolerance: 1e-14,
        ..NewtonOptions::default()
    };
    let mut rng = SplitMix::new(23);
    let (mut compared, mut worst_gen) = (0, 0.0f64);
    for given in poses {
        let interpreted = plan::run_all(&model, &plan, given);
        let gen = generated(given);
        assert_eq!(gen.len(), interpreted.len());
        for ((_, s), g) in interpreted.iter().zip(&gen) {
            let s = s.as_ref().unwrap_or_else(|e| panic!("{file} at {given:?}: {e}"));
            let g = g.as_ref().unwrap();
            worst_gen = worst_gen.max(max_error(g, &s.values, &revolute, scale));
            let values = s.model_values(&model);
            let guess: Vec<f64> = values.iter().map(|v| v + 1e-3 * rng.symmetric()).collect();
            let reference = newton::solve_ik(&model, &outputs, given, &guess, &options)
                .unwrap_or_else(|e| panic!("{file}: Newton ik failed at {given:?}: {e}"));
            for (j, joint) in model.joints.iter().enumerate() {
                if joint.kind != JointType::S {
                    let o = offsets[j];
                    let e = max_error(&[values[o]], &[reference.values[o]], &[revolute[j]], scale);
                    assert!(e <= 1e-9, "{file} {}: {e:e} at {given:?}", joint.name);
                }
                let (p, r) = (
                    kinematics::joint_point(&model, &s.poses, j),
                    kinematics::joint_point(&model, &reference.poses, j),
                );
                let e = max_error(&p, &r, &[false; 3], scale);
                assert!(e <= 1e-9, "{file} point {}: {e:e} at {given:?}", joint.name);
            }
            compared += 1;
        }
    }
    eprintln!("{file}: {compared} ik branches on Newton's, generated = interpreted to {worst_gen:e}");
    assert!(worst_gen <= 1e-12);
    assert!(compared >= 100);
}

#[test]
fn stewart_against_newton() {
    let mut rng = SplitMix::new(29);
    let poses: Vec<[f64; 6]> = (0..20).map(|_| common::poses::ups(&mut rng)).collect();
    against_newton("ups_6", &poses, |g| {
        Ups::ik(&Default::default(), g)
            .iter()
            .map(|b| b.result.as_ref().ok().map(|s| s.q.to_vec()))
            .collect()
    });
}

#[test]
fn translational_upu_against_newton() {
    let mut rng = SplitMix::new(31);
    let poses: Vec<[f64; 3]> = (0..100).map(|_| common::poses::upu(&mut rng)).collect();
    against_newton("upu_3", &poses, |g| {
        Upu::ik(&Default::default(), g)
            .iter()
            .map(|b| b.result.as_ref().ok().map(|s| s.q.to_vec()))
            .collect()
    });
}

/// The plans: each base U's first half is the plane step (no branch: the
/// leg's slide passes through the U's centre), its second half the guide.
#[test]
fn plans_use_the_plane_step() {
    for (file, legs, branches) in [("ups_6", 6, 6), ("upu_3", 3, 3)] {
        let (a, _) = common::example(file);
        let plan = pkm::dsl::planner::inverse_plan(&a).unwrap();
        let planes: Vec<_> = plan
            .steps
            .iter()
            .filter_map(|s| match s {
                plan::Step::PlaneThrough { branch, .. } => Some(*branch),
                _ => None,
            })
            .collect();
        assert_eq!(planes, vec![None; legs], "{file}: {:#?}", plan.steps);
        assert_eq!(plan.branches, branches, "{file}");
    }
}

/// The plane step's factor (`plane_through::factor`): the cosine between
/// the plane's motion at the ball, `u × n`, and the ball's offset from the
/// U's centre. With the U's axes normal and the ball in the plane, that is
/// the sine of the angle between the leg and the U's first axis, by hand
/// `|d × t|/|d|` (d = b-centre minus U centre, t the base axis): zero only
/// where the leg lies along the first axis.
#[test]
fn plane_factor_is_the_sine_between_leg_and_first_axis() {
    use pkm::runtime::singular;
    let (a, model) = common::example("ups_6");
    let plan = pkm::dsl::planner::inverse_plan(&a).unwrap();
    let mut rng = SplitMix::new(37);
    let mut checked = 0;
    for _ in 0..200 {
        let g = common::poses::ups(&mut rng);
        let (p, r) = (Vector3::new(g[0], g[1], g[2]), rotation(g[3], g[4], g[5]));
        for (_, s) in plan::run_all(&model, &plan, &g) {
            let s = s.unwrap();
            for f in singular::spatial_factors(&model, &plan, &s.poses) {
                if !matches!(plan.steps[f.step], plan::Step::PlaneThrough { .. }) {
                    continue;
                }
                let name = &model.joints[f.joint].name;
                let n: usize = name.trim_start_matches('U').trim_end_matches(".a").parse().unwrap();
                let (alpha, beta) = UPS_LEGS[n - 1];
                let d = p + r * on_circle(100.0, beta) - on_circle(200.0, alpha);
                let t = alpha.to_radians();
                let hand = d.cross(&Vector3::new(-t.sin(), t.cos(), 0.0)).norm() / d.norm();
                let named = f.describe(&model, &s.poses);
                assert!((f.value - hand).abs() < 1e-12, "{named}: {} vs {hand}", f.value);
                assert!(
                    named.contains(&format!("the plane of P{n} turned by {name}")),
                    "{named}"
                );
                checked += 1;
            }
        }
    }
    assert_eq!(checked, 200 * 64 * 6);
}
