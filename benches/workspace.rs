//! Seed 000 §2.2's workspace sweep: 10⁶ actuator samples (100 per input over
//! −250 ≤ x1 ≤ 0, 0 ≤ x2 ≤ 250, −300 ≤ x3 ≤ 300 mm) through the generated
//! forward solution of the paper's assembly, on all cores, keeping the
//! platform midpoint G: one iteration is one whole sweep.

use criterion::{criterion_group, criterion_main, Criterion};
use pkm::runtime::primitives::Sign;
use pkm::runtime::workspace::{sweep_nodes, Grid};
use std::hint::black_box;

pkm::mechanism!(SeedA, file = "examples/mechanisms/seed000_a.pkm");
pkm::mechanism!(SeedB, file = "examples/mechanisms/seed000_b.pkm");

fn workspace(c: &mut Criterion) {
    let grid = Grid {
        ranges: vec![(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)],
        counts: vec![100; 3],
    };
    let mut group = c.benchmark_group("sweep_1e6");
    group.sample_size(10);
    let sa = SeedA::prepare(&Default::default());
    let ga = SeedA::POINTS.iter().position(|p| *p == "G").unwrap();
    group.bench_function("seed000_a", |b| {
        b.iter(|| {
            sweep_nodes::<3>(black_box(&grid), |q| {
                sa.fk_solution(q, [Sign::Minus, Sign::Plus]).ok().map(|s| s.points[ga])
            })
        })
    });
    let sb = SeedB::prepare(&Default::default());
    let gb = SeedB::POINTS.iter().position(|p| *p == "G").unwrap();
    group.bench_function("seed000_b", |b| {
        b.iter(|| {
            sweep_nodes::<3>(black_box(&grid), |q| {
                sb.fk_solution(q, [Sign::Minus, Sign::Minus, Sign::Plus])
                    .ok()
                    .map(|s| s.points[gb])
            })
        })
    });
    group.finish();
}

criterion_group!(benches, workspace);
criterion_main!(benches);
