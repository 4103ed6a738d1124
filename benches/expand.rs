//! What `pkm::mechanism!` costs at compile time: parse, analyse and
//! generate each example mechanism (the macro's whole expansion).

use criterion::{criterion_group, criterion_main, Criterion};

const EXAMPLES: [&str; 10] = [
    "seed000_a",
    "seed000_b",
    "seed003_punch_original",
    "seed003_punch",
    "four_bar",
    "slider_crank",
    "five_bar",
    "planar_3rrr",
    "rps_3",
    "spr_3",
];

fn expand(c: &mut Criterion) {
    let mut group = c.benchmark_group("expand");
    for name in EXAMPLES {
        let path = format!("{}/examples/mechanisms/{name}.pkm", env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(path).unwrap();
        // κ ≠ 0 examples request only ik, so every one expands without error.
        let input = format!("pub M, {text:?}");
        group.bench_function(name, |b| {
            b.iter(|| pkm::dsl::expand(input.parse().unwrap()).unwrap());
        });
    }
    group.finish();
}

criterion_group!(benches, expand);
criterion_main!(benches);
