//! Generated spatial solvers against the plan interpreter (the two paths
//! that must agree), for seed 000 mechanisms A and B and the five-bar with
//! a parallelogram branch: every branch of fk at random inputs, and of ik
//! at the poses fk finds; the balls' rotations of the S-joint mechanisms.

use crate::common;
use crate::mechanisms::{
    FiveBarPa, Rps, Rssp, RsspSolution, Rssr, RssrSolution, Rsur, RsurSolution, SeedA, SeedAU, SeedB, Spr, Ups, Upu,
};

use pkm::runtime::plan::{self, Solution};
use pkm::runtime::primitives::Sign;
use pkm::runtime::solution::{Branch, SolveError};

type Interpreted = Vec<(Vec<Sign>, Result<Solution, SolveError>)>;

fn compare<const D: usize>(generated: &[Branch<[f64; 11], D>], interpreted: &Interpreted) -> usize {
    assert_eq!(generated.len(), interpreted.len());
    let mut same = 0;
    for (g, (signs, i)) in generated.iter().zip(interpreted) {
        assert_eq!(&g.signs[..], &signs[..]);
        match (&g.result, i) {
            (Ok(g), Ok(i)) => {
                for (a, b) in g.iter().zip(&i.values) {
                    assert!((a - b).abs() < 1e-12 * 300.0, "{a} vs {b}");
                }
                same += 1;
            }
            (Err(_), Err(_)) => {}
            other => panic!("generated and interpreted differ: {other:?}"),
        }
    }
    same
}

/// At 200 random inputs in `ranges`: every fk branch, and every ik branch
/// at the poses the generated fk finds, generated = interpreted.
macro_rules! check {
    ($ty:ident, $file:expr, $ranges:expr) => {{
        let p = Default::default();
        let (a, model) = common::example($file);
        let (fk_plan, ik_plan) = (
            pkm::dsl::planner::forward_plan(&a).unwrap(),
            pkm::dsl::planner::inverse_plan(&a).unwrap(),
        );
        let ranges: [(f64, f64); 3] = $ranges;
        let mut rng = pkm::dsl::screw::SplitMix::new(99);
        let (mut n_fk, mut n_ik) = (0, 0);
        for _ in 0..200 {
            let q = ranges.map(|(lo, hi)| lo + (hi - lo) * (rng.symmetric() + 1.0) / 2.0);
            let generated = $ty::fk(&p, &q);
            n_fk += compare(&q_only(&generated, |s| s.q), &plan::run_all(&model, &fk_plan, &q));
            for s in generated.iter().filter_map(|b| b.result.as_ref().ok()) {
                let pose = s.outputs;
                n_ik += compare(
                    &q_only(&$ty::ik(&p, &pose), |s| s.q),
                    &plan::run_all(&model, &ik_plan, &pose),
                );
            }
        }
        assert!(
            n_fk > 200 && n_ik > 200,
            "{}: {n_fk} fk, {n_ik} ik solutions compared",
            $file
        );
    }};
}

fn q_only<S, const D: usize>(branches: &[Branch<S, D>], q: impl Fn(&S) -> [f64; 11]) -> Vec<Branch<[f64; 11], D>> {
    branches
        .iter()
        .map(|b| Branch {
            signs: b.signs,
            result: b.result.as_ref().map(&q).map_err(Clone::clone),
            tangent: b.tangent,
        })
        .collect()
}

#[test]
fn seed000_a_generated_equals_interpreted() {
    check!(SeedA, "seed000_a", [(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)]);
}

#[test]
fn seed000_a_u_generated_equals_interpreted() {
    check!(SeedAU, "seed000_a_u", [(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)]);
}

#[test]
fn seed000_b_generated_equals_interpreted() {
    check!(SeedB, "seed000_b", [(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)]);
}

#[test]
fn five_bar_pa_generated_equals_interpreted() {
    use std::f64::consts::PI;
    check!(FiveBarPa, "five_bar_pa", [(-PI, PI), (-PI, PI), (-300.0, 300.0)]);
}

/// The generated solution's joint values against the interpreter's, the
/// largest difference: an R, P or Pa joint's value; a ball's rotation
/// vector in `balls` against `Solution::model_values` (nalgebra's
/// quaternion logarithm of `R_uᵀ·R_v`, the runtime model's form) and its
/// angle in `q` against that vector's length.
fn joints_differ(model: &pkm::runtime::model::Model, q: &[f64], balls: &[[f64; 3]], i: &Solution) -> f64 {
    use pkm::runtime::model::JointType;
    let full = i.model_values(model);
    let (mut at, mut ball, mut worst) = (0, 0, 0.0f64);
    for (j, joint) in model.joints.iter().enumerate() {
        if joint.kind == JointType::S {
            let r = &full[at..at + 3];
            let g = balls[ball];
            let d = (0..3).map(|c| (g[c] - r[c]).abs()).fold(0.0, f64::max);
            let norm = r.iter().map(|x| x * x).sum::<f64>().sqrt();
            worst = worst.max(d).max((q[j] - norm).abs());
            assert!(q[j].is_finite(), "{}: {}", joint.name, q[j]);
            (at, ball) = (at + 3, ball + 1);
        } else {
            worst = worst.max((q[j] - i.values[j]).abs());
            at += 1;
        }
    }
    assert_eq!(ball, balls.len());
    worst
}

/// A mechanism with an S–S link (the RSSR, the R-S-S-P), fk over the crank's turn and ik at the angles fk
/// (crank) finds: the generated branch and the interpreted one give the same
/// joint values (a ball's rotation vector and angle: [`joints_differ`]) and the same points in
/// space, the S–S link's midpoint M among them, or the same error.
macro_rules! with_spheres {
    ($ty:ident, $sol:ident, $file:expr) => {{
        let p = Default::default();
        let (a, model) = common::example($file);
        let (fk_plan, ik_plan) = (
            pkm::dsl::planner::forward_plan(&a).unwrap(),
            pkm::dsl::planner::inverse_plan(&a).unwrap(),
        );
        let same = |g: &Result<$sol, SolveError>, i: &Result<Solution, SolveError>| match (g, i) {
            (Ok(g), Ok(i)) => {
                let d = joints_differ(&model, &g.q, &g.balls, i);
                assert!(d < 1e-12 * 300.0, "{:?} vs {:?}: {d:e}", g.q, i.values);
                let points = (0..model.joints.len())
                    .map(|j| pkm::runtime::kinematics::joint_point(&model, &i.poses, j))
                    .chain(std::iter::once(
                        pkm::runtime::kinematics::point(&model, &i.poses, "M").unwrap(),
                    ));
                for (k, q) in points.enumerate() {
                    let d = (0..3).map(|c| (g.points[k][c] - q[c]).abs()).fold(0.0, f64::max);
                    assert!(d < 1e-12 * 300.0, "{}: {:?} vs {q:?}", $ty::POINTS[k], g.points[k]);
                }
                1
            }
            (Err(a), Err(b)) => {
                assert_eq!(a, b);
                0
            }
            other => panic!("generated and interpreted differ: {other:?}"),
        };
        let (mut n_fk, mut n_ik) = (0, 0);
        for k in 0..720 {
            let q = [-3.2 + k as f64 * 0.01];
            let generated = $ty::fk(&p, &q);
            let interpreted = plan::run_all(&model, &fk_plan, &q);
            assert_eq!(generated.len(), interpreted.len());
            for (g, (signs, i)) in generated.iter().zip(&interpreted) {
                assert_eq!(&g.signs[..], &signs[..]);
                n_fk += same(&g.result, i);
                if let Ok(f) = &g.result {
                    let generated = $ty::ik(&p, &f.outputs);
                    let interpreted = plan::run_all(&model, &ik_plan, &f.outputs);
                    for (g, (_, i)) in generated.iter().zip(&interpreted) {
                        n_ik += same(&g.result, i);
                    }
                }
            }
        }
        assert!(n_fk >= 1440 && n_ik >= 2000, "{n_fk} fk, {n_ik} ik solutions compared");
    }};
}

#[test]
fn rssr_generated_equals_interpreted() {
    with_spheres!(Rssr, RssrSolution, "rssr");
}

#[test]
fn rssp_generated_equals_interpreted() {
    with_spheres!(Rssp, RsspSolution, "rssp");
}

#[test]
fn rsur_generated_equals_interpreted() {
    with_spheres!(Rsur, RsurSolution, "rsur");
}

/// Issue 29, item 4: a ball's value in generated `q` was NaN. The inverse
/// solutions of seed 004's 3-RPS and 3-SPR, the Stewart platform and the
/// 3-UPU at random poses: every branch's joint values, its balls' rotation
/// vectors and angles among them, are the interpreter's
/// ([`joints_differ`]), or both give the same error.
macro_rules! balls_of_ik {
    ($ty:ident, $file:expr, $pose:path, $n:expr) => {{
        let (a, model) = common::example($file);
        let plan = pkm::dsl::planner::inverse_plan(&a).unwrap();
        let mut rng = pkm::dsl::screw::SplitMix::new(29);
        let (mut compared, mut worst) = (0usize, 0.0f64);
        for _ in 0..$n {
            let g = $pose(&mut rng);
            let generated = $ty::ik(&Default::default(), &g);
            let interpreted = plan::run_all(&model, &plan, &g);
            assert_eq!(generated.len(), interpreted.len());
            for (g, (_, i)) in generated.iter().zip(&interpreted) {
                match (&g.result, i) {
                    (Ok(g), Ok(i)) => {
                        worst = worst.max(joints_differ(&model, &g.q, &g.balls, i));
                        compared += 1;
                    }
                    (Err(a), Err(b)) => assert_eq!(a, b),
                    other => panic!("{}: generated and interpreted differ: {other:?}", $file),
                }
            }
        }
        assert!(compared >= $n, "{}: {compared} solutions", $file);
        assert!(worst < 1e-12 * 300.0, "{}: {worst:e}", $file);
        (compared, worst)
    }};
}

#[test]
fn balls_of_generated_inverse_solutions_are_the_interpreters() {
    assert_eq!(
        (Rps::BALLS, Spr::BALLS.len(), Ups::BALLS.len(), Upu::BALLS.len()),
        (["S1", "S2", "S3"], 3, 6, 0)
    );
    let figures = [
        balls_of_ik!(Rps, "rps_3", common::poses::seed, 200),
        balls_of_ik!(Spr, "spr_3", common::poses::seed, 200),
        balls_of_ik!(Ups, "ups_6", common::poses::ups, 20),
        balls_of_ik!(Upu, "upu_3", common::poses::upu, 200),
    ];
    eprintln!("{figures:?}");
}
