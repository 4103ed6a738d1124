//! Inverse dynamics per sample (issue 12): the generated Newton–Euler
//! (capability `dynamics`, every reaction, prepared once) against the
//! runtime's three paths, Newton–Euler over the ordered SKCs with every
//! reaction, virtual work and Lagrange, on seed 003's punch (Table 1's
//! data, φ = 0.5 rad, ω = 1 rad/s) and on seed 000's mechanism A (Table
//! 1's inputs, made-up masses on every link, a payload).

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{criterion_group, criterion_main, Criterion};
use pkm::runtime::primitives::Sign::{self, Minus, Plus};
use pkm::runtime::{lagrange, newton_euler, virtual_work};
use std::hint::black_box;

/// Seed 000's mechanism A with masses on every link and a payload.
fn seed000_a() -> String {
    let extra = "
    units { length = mm; mass = kg; }
    masses {
        s1 { mass = 0.057; centroid = (0, 0, 40); } s2 { mass = 0.057; centroid = (0, 0, 50); }
        s3 { mass = 0.067; centroid = (0, 0, 30); }
        c1 { mass = 0.072; centroid = (100, 0, 0); inertia = (117, 291, 181); }
        c2 { mass = 0.070; centroid = (100, 0, 0); inertia = (113, 276, 173); }
        cross { mass = 0.02; centroid = (0, 0, 0); inertia = (1, 1, 1); }
        platform { mass = 0.494; centroid = (0, l3 / 2, 0); inertia = (7162, 1188, 7106); }
        pc { mass = 0.106; centroid = (0, 0, 0); inertia = (913, 706, 358); }
        r5 { mass = 0.03; centroid = (0, 0, 0); inertia = (2, 2, 1); }
    }
    loads { payload = force (0, 0, -50) on platform at G; }";
    common::example_with("seed000_a", extra)
}

pkm::mechanism!(Punch, file = "examples/mechanisms/seed003_punch.pkm");

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
    bench_one(
        c,
        "seed000_a",
        &seed000_a(),
        &[-106.09, 181.67, -70.29],
        &[Minus, Plus],
        &[1.0, -0.5, 0.25],
        &[-2.0, 0.75, 1.5],
        None,
    );
}

criterion_group!(benches, dynamics);
criterion_main!(benches);
