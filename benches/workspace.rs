//! Seed 000 §2.2's workspace sweep: 10⁶ actuator samples (100 per input over
//! −250 ≤ x1 ≤ 0, 0 ≤ x2 ≤ 250, −300 ≤ x3 ≤ 300 mm) through the generated
//! forward solution of the paper's assembly, on all cores, keeping the
//! platform midpoint G: one iteration is one whole sweep.

use criterion::{criterion_group, criterion_main, Criterion};
use pkm::runtime::primitives::Sign;
use pkm::runtime::spatial::at;
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
    let (ja, na) = (
        SeedA::joints(&Default::default()),
        SeedA::named_points(&Default::default()),
    );
    let ga = na[SeedA::POINTS[11..].iter().position(|p| *p == "G").unwrap()];
    group.bench_function("seed000_a", |b| {
        b.iter(|| {
            sweep_nodes::<3>(black_box(&grid), |q| {
                SeedA::fk_poses(&ja, &na, q, [Sign::Minus, Sign::Plus])
                    .ok()
                    .map(|t| at(&t[5], ga))
            })
        })
    });
    let (jb, nb) = (
        SeedB::joints(&Default::default()),
        SeedB::named_points(&Default::default()),
    );
    let gb = nb[SeedB::POINTS[11..].iter().position(|p| *p == "G").unwrap()];
    group.bench_function("seed000_b", |b| {
        b.iter(|| {
            sweep_nodes::<3>(black_box(&grid), |q| {
                SeedB::fk_poses(&jb, &nb, q, [Sign::Minus, Sign::Minus, Sign::Plus])
                    .ok()
                    .map(|t| at(&t[5], gb))
            })
        })
    });
    group.finish();
}

criterion_group!(benches, workspace);
criterion_main!(benches);
