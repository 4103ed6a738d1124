//! Forward position per call: the generated closed form (one branch and every
//! branch), the plan interpreter, and the Newton reference solved to a
//! residual of 1e-12 from the solution at an input 0.05 away (rad).

use criterion::{criterion_group, criterion_main, Criterion};
use pkm::runtime::newton::{self, NewtonOptions};
use pkm::runtime::plan::{self, signs_of};
use std::collections::HashMap;
use std::hint::black_box;

pkm::mechanism!(FourBar, file = "examples/mechanisms/four_bar.pkm");
pkm::mechanism!(SliderCrank, file = "examples/mechanisms/slider_crank.pkm");
pkm::mechanism!(FiveBar, file = "examples/mechanisms/five_bar.pkm");
pkm::mechanism!(Punch, file = "examples/mechanisms/seed003_punch.pkm");
pkm::mechanism!(Watt, file = "examples/mechanisms/watt_six_bar.pkm");

macro_rules! bench_mechanism {
    ($c:expr, $ty:ident, $file:expr, $q:expr, $signs:expr) => {{
        let path = format!("{}/examples/mechanisms/{}.pkm", env!("CARGO_MANIFEST_DIR"), $file);
        let a = pkm::dsl::analyze_source(&std::fs::read_to_string(path).unwrap()).unwrap();
        let model = pkm::dsl::plan::model(&a, &HashMap::new()).unwrap();
        let p = pkm::dsl::plan::forward_plan(&a).unwrap();
        let params = Default::default();
        let q = $q;
        let signs = signs_of($signs);
        let mut group = $c.benchmark_group($file);
        group.bench_function("generated_branch", |b| {
            b.iter(|| $ty::fk_branch(black_box(&params), black_box(&q), signs))
        });
        group.bench_function("generated_all", |b| {
            b.iter(|| $ty::fk(black_box(&params), black_box(&q)))
        });
        group.bench_function("interpreter_branch", |b| {
            b.iter(|| plan::run(&model, &p, black_box(&q), &signs))
        });
        // Newton from the solution at an input 0.05 rad away, to residual 1e-12.
        let mut near = q;
        near[0] -= 0.05;
        let guess = plan::run(&model, &p, &near, &signs).unwrap().values;
        let options = NewtonOptions {
            tolerance: 1e-12,
            ..NewtonOptions::default()
        };
        group.bench_function("newton", |b| {
            b.iter(|| newton::solve_fk(&model, black_box(&q), &guess, &options).unwrap())
        });
        group.finish();
    }};
}

fn fk(c: &mut Criterion) {
    bench_mechanism!(c, FourBar, "four_bar", [0.7], 0);
    bench_mechanism!(c, SliderCrank, "slider_crank", [0.7], 0);
    bench_mechanism!(c, FiveBar, "five_bar", [2.0, 1.0], 0);
    bench_mechanism!(c, Punch, "seed003_punch", [0.5], 0b011);
    bench_mechanism!(c, Watt, "watt_six_bar", [0.7], 0);
}

criterion_group!(benches, fk);
criterion_main!(benches);
