//! Generated spatial solvers against the plan interpreter (the two paths
//! that must agree), for seed 000 mechanisms A and B: every branch of fk
//! at random inputs, and of ik at the poses fk finds.

use pkm::runtime::plan::{Branch, SolveError};
use pkm::runtime::primitives::Sign;
use pkm::runtime::spatial::{self, Solution};
use std::collections::HashMap;

pkm::mechanism!(SeedA, file = "examples/mechanisms/seed000_a.pkm");
pkm::mechanism!(SeedB, file = "examples/mechanisms/seed000_b.pkm");

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

fn check<const DF: usize, const DI: usize>(
    file: &str,
    fk: impl Fn(&[f64; 3]) -> Vec<Branch<[f64; 11], DF>>,
    ik: impl Fn(&[f64; 4]) -> Vec<Branch<[f64; 11], DI>>,
    pose: impl Fn(&Solution) -> [f64; 4],
) {
    let path = format!("{}/examples/mechanisms/{file}.pkm", env!("CARGO_MANIFEST_DIR"));
    let a = pkm::dsl::analyze_source(&std::fs::read_to_string(path).unwrap()).unwrap();
    let model = pkm::dsl::plan::model(&a, &HashMap::new()).unwrap();
    let (fk_plan, ik_plan) = (
        pkm::dsl::plan3::forward_plan(&a).unwrap(),
        pkm::dsl::plan3::inverse_plan(&a).unwrap(),
    );
    let mut rng = pkm::dsl::screw::SplitMix::new(99);
    let (mut n_fk, mut n_ik) = (0, 0);
    for _ in 0..200 {
        let q = [
            -125.0 + 125.0 * rng.symmetric(),
            125.0 + 125.0 * rng.symmetric(),
            300.0 * rng.symmetric(),
        ];
        let interpreted = spatial::run_all(&model, &fk_plan, &q);
        n_fk += compare(&fk(&q), &interpreted);
        for s in interpreted.iter().filter_map(|(_, r)| r.as_ref().ok()) {
            let p = pose(s);
            n_ik += compare(&ik(&p), &spatial::run_all(&model, &ik_plan, &p));
        }
    }
    assert!(
        n_fk > 200 && n_ik > 200,
        "{file}: {n_fk} fk, {n_ik} ik solutions compared"
    );
}

fn platform_pose(link: usize, point: [f64; 3], about: [f64; 3]) -> impl Fn(&Solution) -> [f64; 4] {
    move |s| {
        let p = spatial::at(&s.poses[link], point);
        [p[0], p[1], p[2], spatial::angle_about(&s.poses[link], about)]
    }
}

fn q_only<S, const D: usize>(branches: &[Branch<S, D>], q: impl Fn(&S) -> [f64; 11]) -> Vec<Branch<[f64; 11], D>> {
    branches
        .iter()
        .map(|b| Branch {
            signs: b.signs,
            result: b.result.as_ref().map(&q).map_err(Clone::clone),
        })
        .collect()
}

#[test]
fn seed000_a_generated_equals_interpreted() {
    let p = SeedAParams::default();
    let platform = 5;
    check(
        "seed000_a",
        |q| q_only(&SeedA::fk(&p, q), |s| s.q),
        |x| q_only(&SeedA::ik(&p, x), |s| s.q),
        platform_pose(platform, [0.0; 3], [1.0, 0.0, 0.0]),
    );
}

#[test]
fn seed000_b_generated_equals_interpreted() {
    let p = SeedBParams::default();
    check(
        "seed000_b",
        |q| q_only(&SeedB::fk(&p, q), |s| s.q),
        |x| q_only(&SeedB::ik(&p, x), |s| s.q),
        platform_pose(5, [0.0; 3], [-1.0, 0.0, 0.0]),
    );
}
