//! Position solvers per call, for every example with a closed form: the
//! generated fk and ik (one branch, and every branch), the plan interpreter
//! (one branch), and the Newton reference solved to the same residual
//! (1e-12, scaled) from the solution at inputs (or outputs) 0.05 away.

use criterion::{criterion_group, criterion_main, Criterion};
use pkm::runtime::newton::{self, NewtonOptions};
use pkm::runtime::plan;
use pkm::runtime::solution::signs_of;
use std::hint::black_box;

pkm::mechanism!(FourBar, file = "examples/mechanisms/four_bar.pkm");
pkm::mechanism!(SliderCrank, file = "examples/mechanisms/slider_crank.pkm");
pkm::mechanism!(FiveBar, file = "examples/mechanisms/five_bar.pkm");
pkm::mechanism!(Punch, file = "examples/mechanisms/seed003_punch.pkm");
pkm::mechanism!(Watt, file = "examples/mechanisms/watt_six_bar.pkm");
pkm::mechanism!(FiveBarPa, file = "examples/mechanisms/five_bar_pa.pkm");
pkm::mechanism!(SeedA, file = "examples/mechanisms/seed000_a.pkm");
pkm::mechanism!(SeedB, file = "examples/mechanisms/seed000_b.pkm");

/// The plan interpreter of one direction.
fn interpreter(
    c: &pkm::dsl::Compiled,
    inverse: bool,
) -> impl Fn(&pkm::runtime::model::Model, &[f64], &[pkm::runtime::primitives::Sign]) {
    let p = if inverse { c.inverse() } else { c.forward() }.unwrap().clone();
    move |model, given, signs| {
        black_box(plan::run(model, &p, given, signs).unwrap());
    }
}

const NEWTON: NewtonOptions = NewtonOptions {
    tolerance: 1e-12,
    max_iterations: 100,
};

macro_rules! bench_fk {
    ($c:expr, $ty:ident, $file:expr, $q:expr, $signs:expr) => {{
        let path = format!("{}/examples/mechanisms/{}.pkm", env!("CARGO_MANIFEST_DIR"), $file);
        let a = pkm::dsl::compile(&std::fs::read_to_string(path).unwrap()).unwrap();
        let model = a.model().unwrap().clone();
        let params = Default::default();
        let q = $q;
        let signs = signs_of($signs);
        let run = interpreter(&a, false);
        let mut group = $c.benchmark_group(concat!($file, "/fk"));
        group.bench_function("generated_branch", |b| {
            b.iter(|| $ty::fk_branch(black_box(&params), black_box(&q), signs))
        });
        group.bench_function("generated_all", |b| {
            b.iter(|| $ty::fk(black_box(&params), black_box(&q)))
        });
        group.bench_function("interpreter_branch", |b| b.iter(|| run(&model, black_box(&q), &signs)));
        let mut near = q;
        near[0] -= 0.05;
        let guess = $ty::fk_branch(&params, &near, signs).unwrap().q;
        group.bench_function("newton", |b| {
            b.iter(|| newton::solve_fk(&model, black_box(&q), &guess, &NEWTON).unwrap())
        });
        group.finish();
        (a, model, $ty::fk_branch(&params, &q, signs).unwrap().outputs)
    }};
}

macro_rules! bench_ik {
    ($c:expr, $ty:ident, $file:expr, $setup:expr, $signs:expr) => {{
        let (a, model, x) = $setup;
        let params = Default::default();
        let signs = signs_of($signs);
        let run = interpreter(&a, true);
        let outputs = a.outputs().unwrap().to_vec();
        let mut group = $c.benchmark_group(concat!($file, "/ik"));
        group.bench_function("generated_branch", |b| {
            b.iter(|| $ty::ik_branch(black_box(&params), black_box(&x), signs))
        });
        group.bench_function("generated_all", |b| {
            b.iter(|| $ty::ik(black_box(&params), black_box(&x)))
        });
        group.bench_function("interpreter_branch", |b| b.iter(|| run(&model, black_box(&x), &signs)));
        // From the solution 0.05 away in the first output, on whichever side is reachable.
        let guess = [-0.05, 0.05]
            .iter()
            .find_map(|d| {
                let mut near = x;
                near[0] += d;
                $ty::ik_branch(&params, &near, signs).ok()
            })
            .unwrap()
            .q;
        group.bench_function("newton", |b| {
            b.iter(|| newton::solve_ik(&model, &outputs, black_box(&x), &guess, &NEWTON).unwrap())
        });
        group.finish();
    }};
}

fn solvers(c: &mut Criterion) {
    let s = bench_fk!(c, FourBar, "four_bar", [0.7], 0);
    bench_ik!(c, FourBar, "four_bar", s, 0);
    let s = bench_fk!(c, SliderCrank, "slider_crank", [0.7], 0);
    bench_ik!(c, SliderCrank, "slider_crank", s, 0);
    let s = bench_fk!(c, FiveBar, "five_bar", [2.0, 1.0], 0);
    bench_ik!(c, FiveBar, "five_bar", s, 0);
    bench_fk!(c, Punch, "seed003_punch", [0.5], 0b011);
    let s = bench_fk!(c, Watt, "watt_six_bar", [0.7], 0);
    bench_ik!(c, Watt, "watt_six_bar", s, 0);
    let s = bench_fk!(c, FiveBarPa, "five_bar_pa", [-2.0, -1.1, -40.0], 0b01);
    bench_ik!(c, FiveBarPa, "five_bar_pa", s, 0b010);
    // Seed 000 Table 1's inputs; the paper's assembly (the five-bar above the sliders).
    let s = bench_fk!(c, SeedA, "seed000_a", [-106.09, 181.67, -70.29], 0b01);
    bench_ik!(c, SeedA, "seed000_a", s, 0b001);
    let s = bench_fk!(c, SeedB, "seed000_b", [-106.09, 181.67, -70.29], 0b011);
    bench_ik!(c, SeedB, "seed000_b", s, 0b001);
}

criterion_group!(benches, solvers);
criterion_main!(benches);
