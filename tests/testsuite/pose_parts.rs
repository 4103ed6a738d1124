//! Poses given in part (`pose (z, rx, ry) of platform at o`): the 3-RPS's
//! inverse solution from its height and tilt, its parasitic x, y and rz
//! found from the planes its legs hold its ball joints on. Checked against
//! the mechanism's definition by hand (each ball on its leg's plane, each
//! leg as long as its slide, the platform rigid and at the given height
//! and tilt) and against Newton's inverse solution.

use crate::common;
use crate::mechanisms::{Prs, RpsTilt};

use pkm::dsl::screw::SplitMix;
use pkm::runtime::plan;

const A: f64 = 200.0;
const B: f64 = 100.0;

/// A random pose: z in 120..220 mm, rx and ry in ±0.35 rad.
fn pose(rng: &mut SplitMix) -> [f64; 3] {
    [
        170.0 + 50.0 * rng.symmetric(),
        0.35 * rng.symmetric(),
        0.35 * rng.symmetric(),
    ]
}

/// Every branch of the generated inverse solution against the mechanism's
/// definition, written out here: base revolute i at angle θᵢ = 120°·i on
/// the circle of radius 200, its axis tangent (−sin θᵢ, cos θᵢ, 0); ball i
/// at 100 from o on the platform, 120° apart; leg i along the line from
/// revolute i to ball i, normal to its axis.
#[test]
fn parasitic_motion_meets_the_definition() {
    let mut rng = SplitMix::new(11);
    let o = RpsTilt::POINTS.iter().position(|p| *p == "o").unwrap();
    let ball = |k: usize| {
        RpsTilt::POINTS
            .iter()
            .position(|p| *p == format!("S{}", k + 1))
            .unwrap()
    };
    let slide = |k: usize| {
        RpsTilt::JOINTS
            .iter()
            .position(|p| *p == format!("P{}", k + 1))
            .unwrap()
    };
    let (mut solved, mut worst) = (0usize, 0.0f64);
    for _ in 0..100_000 {
        let given = pose(&mut rng);
        for branch in RpsTilt::ik(&Default::default(), &given) {
            let Ok(s) = branch.result else { continue };
            solved += 1;
            let p = |i: usize| pkm::runtime::nalgebra::Vector3::from(s.points[i]);
            let centre = p(o);
            // The platform's axes from its balls: x towards ball 1, y from ball 2.
            let (c, si) = (120f64.to_radians().cos(), 120f64.to_radians().sin());
            let ex = (p(ball(0)) - centre) / B;
            let ey = ((p(ball(1)) - centre) / B - c * ex) / si;
            let ez = ex.cross(&ey);
            let mut e = vec![(ex.norm() - 1.0).abs(), (ey.norm() - 1.0).abs(), ex.dot(&ey).abs()];
            // Ball 3 where the rigid platform puts it.
            e.push(((p(ball(2)) - centre) / B - (c * ex - si * ey)).norm());
            // Height and tilt: R = [ex ey ez], rx = atan2(r21, r22), ry = atan2(−r20, √(r00² + r10²)).
            e.push((centre.z - given[0]).abs() / A);
            e.push(pkm::runtime::solution::wrap_angle(ey.z.atan2(ez.z) - given[1]).abs());
            e.push(pkm::runtime::solution::wrap_angle((-ex.z).atan2(ex.x.hypot(ex.y)) - given[2]).abs());
            for k in 0..3 {
                let t = (120.0 * k as f64).to_radians();
                let base = pkm::runtime::nalgebra::Vector3::new(A * t.cos(), A * t.sin(), 0.0);
                let axis = pkm::runtime::nalgebra::Vector3::new(-t.sin(), t.cos(), 0.0);
                let leg = p(ball(k)) - base;
                // On the leg's plane, as long as its slide.
                e.push(axis.dot(&leg).abs() / A);
                e.push((leg.norm() - s.q[slide(k)].abs()).abs() / A);
            }
            worst = e.into_iter().fold(worst, f64::max);
        }
    }
    eprintln!("rps_3_tilt: {solved} branches over 10⁵ poses, worst {worst:e}");
    assert!(worst < 1e-12, "worst {worst:e}");
    // Two platform poses (the parasitic turn's two roots), each leg's line
    // in two senses: 16 branches, every one real in this range.
    assert_eq!(solved, 16 * 100_000);
}

/// Every branch of the generated 3-PRS inverse solution against the
/// mechanism's definition, written out here: slide i vertical through
/// (200 cos θᵢ, 200 sin θᵢ, 0), θᵢ = 120°·i, its value the height of
/// revolute i's point on it, that revolute's axis tangent
/// (−sin θᵢ, cos θᵢ, 0); the leg from it to ball i normal to the axis
/// and of length l = √(100² + 240²) = 260; ball i at 100 from o on the
/// platform, 120° apart; the platform rigid at the given height and tilt.
#[test]
fn prs_slides_meet_the_definition() {
    use pkm::runtime::nalgebra::Vector3;
    const L: f64 = 260.0;
    let mut rng = SplitMix::new(17);
    let point = |name: String| Prs::POINTS.iter().position(|p| *p == name).unwrap();
    let joint = |name: String| Prs::JOINTS.iter().position(|p| *p == name).unwrap();
    let o = point("o".into());
    let balls: Vec<usize> = (1..=3).map(|k| point(format!("S{k}"))).collect();
    let hinges: Vec<usize> = (1..=3).map(|k| point(format!("R{k}"))).collect();
    let slides: Vec<usize> = (1..=3).map(|k| joint(format!("P{k}"))).collect();
    let (mut solved, mut worst) = (0usize, 0.0f64);
    for _ in 0..100_000 {
        let given = pose(&mut rng);
        for branch in Prs::ik(&Default::default(), &given) {
            let Ok(s) = branch.result else { continue };
            solved += 1;
            let p = |i: usize| Vector3::from(s.points[i]);
            let centre = p(o);
            let (c, si) = (120f64.to_radians().cos(), 120f64.to_radians().sin());
            let ex = (p(balls[0]) - centre) / B;
            let ey = ((p(balls[1]) - centre) / B - c * ex) / si;
            let ez = ex.cross(&ey);
            let mut e = vec![(ex.norm() - 1.0).abs(), (ey.norm() - 1.0).abs(), ex.dot(&ey).abs()];
            e.push(((p(balls[2]) - centre) / B - (c * ex - si * ey)).norm());
            e.push((centre.z - given[0]).abs() / A);
            e.push(pkm::runtime::solution::wrap_angle(ey.z.atan2(ez.z) - given[1]).abs());
            e.push(pkm::runtime::solution::wrap_angle((-ex.z).atan2(ex.x.hypot(ex.y)) - given[2]).abs());
            for k in 0..3 {
                let t = (120.0 * k as f64).to_radians();
                let axis = Vector3::new(-t.sin(), t.cos(), 0.0);
                let slide = s.q[slides[k]];
                let hinge = Vector3::new(A * t.cos(), A * t.sin(), slide);
                // The revolute's point where its slide puts it.
                e.push((p(hinges[k]) - hinge).norm() / A);
                let leg = p(balls[k]) - hinge;
                // The ball on the leg's plane, the leg as long as it is.
                e.push(axis.dot(&leg).abs() / A);
                e.push((leg.norm() - L).abs() / A);
            }
            worst = e.into_iter().fold(worst, f64::max);
        }
    }
    eprintln!("prs_3: {solved} branches over 10⁵ poses, worst {worst:e}");
    assert!(worst < 1e-12, "worst {worst:e}");
    // The parasitic root near the home pose puts each ball about 100 from
    // its slide's line, well within l: each leg meets it twice (its
    // revolute below or above the ball), 8 branches at every pose.
    assert!(solved >= 8 * 100_000, "{solved}");
}

/// Generated = interpreted, and every branch against Newton's inverse
/// solution (the platform hung from the base by x, y, z and the three
/// angles, x, y and rz free) started 1e-3 away from it.
#[test]
fn parasitic_inverse_agrees_with_newton() {
    common::inverse_agrees_with_newton("rps_3_tilt", 3000, pose, |given| {
        RpsTilt::ik(&Default::default(), given)
            .into_iter()
            .map(|b| b.result.map(|s| s.q.to_vec()).map_err(|_| ()))
            .collect()
    });
}

/// The same for the 3-PRS, whose slides meet the spheres its R–S legs keep
/// about the balls.
#[test]
fn prs_inverse_agrees_with_newton() {
    common::inverse_agrees_with_newton("prs_3", 1500, pose, |given| {
        Prs::ik(&Default::default(), given)
            .into_iter()
            .map(|b| b.result.map(|s| s.q.to_vec()).map_err(|_| ()))
            .collect()
    });
}

/// All six given (`pose (x, y, z, rx, ry, rz)`): the platform is placed
/// outright and each leg aimed at its ball. Given each branch's full pose
/// from the height-and-tilt solution, it finds the same legs, and a pose
/// off the parasitic motion (x moved 1 mm) is refused by the closure check.
#[test]
fn all_six_given_place_the_platform() {
    let (a, model) = common::example("rps_3_tilt");
    let plan = pkm::dsl::planner::inverse_plan(&a).unwrap();
    let (text, path) = common::example_text("rps_3_tilt");
    let six = text.replace(
        "outputs { z, rx, ry = pose (z, rx, ry) of platform at o; }",
        "outputs { x, y, z, rx, ry, rz = pose (x, y, z, rx, ry, rz) of platform at o; }",
    );
    assert_ne!(six, text, "{path}: the outputs line moved");
    let a6 = pkm::dsl::analyze_source(&six).unwrap();
    let plan6 = pkm::dsl::planner::inverse_plan(&a6).unwrap();
    assert_eq!(plan6.branches, 3, "one sense per leg");
    let o = model.points.iter().position(|p| p.name == "o").unwrap();
    let platform = model.points[o].link;
    let local = model.points[o].at;
    let slides: Vec<usize> = model.inputs();
    let mut rng = SplitMix::new(3);
    let (mut matched, mut refused) = (0, 0);
    for _ in 0..100 {
        let given = pose(&mut rng);
        for (_, r) in plan::run_all(&model, &plan, &given) {
            let Ok(s) = r else { continue };
            let frame = plan::frame_of(&s.poses[platform]);
            let mut full = pkm::runtime::steps::place::pose_values(&frame, local);
            let legs: Vec<f64> = slides.iter().map(|&j| s.values[j]).collect();
            let found = plan::run_all(&model, &plan6, &full)
                .into_iter()
                .filter_map(|(_, r)| r.ok())
                .any(|t| {
                    slides
                        .iter()
                        .zip(&legs)
                        .all(|(&j, l)| (t.values[j] - l).abs() < 1e-9 * A)
                });
            assert!(found, "{full:?}: no branch with legs {legs:?}");
            matched += 1;
            full[0] += 1.0;
            refused += usize::from(plan::run_all(&model, &plan6, &full).iter().all(|(_, r)| r.is_err()));
        }
    }
    assert_eq!(refused, matched, "a pose off the parasitic motion must not assemble");
    assert!(matched >= 1500);
}
