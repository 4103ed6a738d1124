//! Inverse dynamics per sample (issue 12): the generated Newton–Euler
//! (capability `dynamics`, every reaction, prepared once) against the
//! runtime's three paths, Newton–Euler over the ordered SKCs with every
//! reaction, virtual work and Lagrange, on seed 003's punch (Table 1's
//! data, φ = 0.5 rad, ω = 1 rad/s) and on seed 000's mechanism A (Table
//! 1's inputs, §3.4's masses, the parallelogram's bar and the payload, as
//! the example declares them).

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{criterion_group, criterion_main, Criterion};
use pkm::runtime::primitives::Sign::{self, Minus, Plus};
use pkm::runtime::{lagrange, newton_euler, virtual_work};
use std::hint::black_box;

pkm::mechanism!(Punch, file = "examples/mechanisms/seed003_punch.pkm");
pkm::mechanism!(SeedA, file = "examples/mechanisms/seed000_a.pkm");

/// A generated inverse dynamics at given inputs, its first actuator's force.
type Generated<'a> = dyn Fn(&[f64]) -> f64 + 'a;

#[allow(clippy::too_many_arguments)]
fn bench_one(
    c: &mut Criterion,
    name: &str,
    text: &str,
    q: &[f64],
    signs: &[Sign],
    rates: &[f64],
    accels: &[f64],
    generated: Option<&Generated<'_>>,
) {
    let compiled = pkm::dsl::compile(text).unwrap_or_else(|d| panic!("{}", d.render(text, name)));
    let a = &compiled.analysis;
    let model = pkm::dsl::numeric::model(a, &Default::default()).unwrap();
    let loading = pkm::dsl::numeric::loading(a, &model, &Default::default()).unwrap();
    let skcs = pkm::dsl::numeric::skc_parts(a);
    let plan = compiled.forward().unwrap();
    let values = plan.solve(&model, q, signs).unwrap();
    let mut group = c.benchmark_group(format!("{name}/inverse_dynamics"));
    if let Some(generated) = generated {
        group.bench_function("generated", |b| b.iter(|| generated(black_box(q))));
    }
    group.bench_function("newton_euler", |b| {
        b.iter(|| newton_euler::inverse_dynamics(&model, &loading, &skcs, black_box(&values), rates, accels))
    });
    group.bench_function("virtual_work", |b| {
        b.iter(|| virtual_work::actuator_forces(&model, &loading, black_box(&values), rates, accels))
    });
    group.bench_function("lagrange", |b| {
        b.iter(|| lagrange::actuator_forces(&model, plan, &loading, black_box(q), signs, rates, accels))
    });
    group.finish();
}

fn dynamics(c: &mut Criterion) {
    let punch = std::fs::read_to_string("examples/mechanisms/seed003_punch.pkm").expect("the example");
    let prepared = Punch::prepare(&Default::default());
    let generated = |q: &[f64]| {
        let d = prepared
            .inverse_dynamics(&[q[0]], [Minus, Minus, Plus], &[1.0], &[0.0])
            .expect("the paper's branch");
        d.actuators[0]
    };
    bench_one(
        c,
        "seed003_punch",
        &punch,
        &[0.5],
        &[Minus, Minus, Plus],
        &[1.0],
        &[0.0],
        Some(&generated),
    );
    let seed_a = std::fs::read_to_string("examples/mechanisms/seed000_a.pkm").expect("the example");
    let prepared = SeedA::prepare(&Default::default());
    let generated = |q: &[f64]| {
        let d = prepared
            .inverse_dynamics(
                &[q[0], q[1], q[2]],
                [Minus, Plus, Plus],
                &[1.0, -0.5, 0.25],
                &[-2.0, 0.75, 1.5],
            )
            .expect("an assembly");
        d.actuators[0]
    };
    bench_one(
        c,
        "seed000_a",
        &seed_a,
        &[-106.09, 181.67, -70.29],
        &[Minus, Plus, Plus],
        &[1.0, -0.5, 0.25],
        &[-2.0, 0.75, 1.5],
        Some(&generated),
    );
}

criterion_group!(benches, dynamics);
criterion_main!(benches);
