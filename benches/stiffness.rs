//! Static stiffness per pose (issue 30): the generated `stiffness` of the
//! 3-RPS (`examples/mechanisms/rps_3.pkm`, seed 004's legs; prepared once)
//! against the interpreter's path the CLI runs, the plan's inverse
//! solution, `wrench::analyse` on its link poses and
//! `stiffness::stiffness`, at the seed table's home pose (H = 75 mm) on
//! the branch with the legs nearest upright.

use criterion::{criterion_group, criterion_main, Criterion};
use pkm::runtime::{plan, stiffness, wrench};
use std::collections::HashMap;
use std::hint::black_box;

pkm::mechanism!(Rps, file = "examples/mechanisms/rps_3.pkm");

fn bench(c: &mut Criterion) {
    let given = [75.0, 0.0, 0.0];
    let params = RpsParams::default();
    let legs = |q: &[f64; 9]| q[1].abs() + q[4].abs() + q[7].abs();
    let signs = Rps::ik(&params, &given)
        .iter()
        .filter_map(|b| b.result.as_ref().ok().map(|s| (legs(&s.q), b.signs)))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, signs)| signs)
        .expect("an assembly at home");
    let prepared = Rps::prepare(&params);
    prepared.stiffness(&given, signs).expect("a stiffness at home");

    let text = std::fs::read_to_string("examples/mechanisms/rps_3.pkm").expect("the example");
    let a = pkm::dsl::analyze_source(&text).unwrap_or_else(|d| panic!("{}", d.render(&text, "rps_3")));
    let values = HashMap::new();
    let model = pkm::dsl::numeric::model(&a, &values).unwrap();
    let inverse = pkm::dsl::planner::inverse_plan(&a).unwrap();
    let outputs = pkm::dsl::numeric::newton_outputs(&a, &model, &values).unwrap();
    let (link, _) = outputs.iter().find_map(|o| o.point()).unwrap();
    let limbs = pkm::dsl::numeric::limb_properties(&a, &values).unwrap();
    let signs_vec = signs.to_vec();
    let interpreted = |g: &[f64]| {
        let s = plan::run(&model, &inverse, g, &signs_vec).expect("a solution");
        let analysis = wrench::analyse(&model, &s, link).expect("a wrench analysis");
        let declared = pkm::dsl::limb_properties::in_analysis_order(&limbs, &analysis.limbs).unwrap();
        let properties: Vec<_> = declared.iter().map(|d| d.properties()).collect();
        stiffness::stiffness(&analysis, &properties).expect("a stiffness")
    };
    interpreted(&given);

    let mut group = c.benchmark_group("rps_3/stiffness");
    group.bench_function("generated", |b| b.iter(|| prepared.stiffness(black_box(&given), signs)));
    group.bench_function("interpreted", |b| b.iter(|| interpreted(black_box(&given))));
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
