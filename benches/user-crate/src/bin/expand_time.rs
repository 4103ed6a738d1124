//! Times `pkm::dsl::expand` — the whole body of `pkm::mechanism!` — for each
//! example mechanism, in this crate's profile. Built with plain
//! `cargo run --features compiler --bin expand_time`, pkm-dsl and its dependencies are compiled
//! at opt-level 0, as the proc-macro is in a user's debug build.
//!
//! Usage: `expand_time [RUNS] [NAME…]` (default 5 runs, every example; a
//! NAME ending in `.pkm` is a file's path).
//! Prints the minimum and median wall time per mechanism in milliseconds.

use std::time::Instant;

const EXAMPLES: [&str; 12] = [
    "five_bar",
    "five_bar_pa",
    "four_bar",
    "planar_3rrr",
    "rps_3",
    "seed000_a",
    "seed000_b",
    "seed003_punch",
    "seed003_punch_original",
    "slider_crank",
    "spr_3",
    "watt_six_bar",
];

fn main() {
    let mut args = std::env::args().skip(1);
    let runs: usize = args
        .next()
        .map_or(5, |a| a.parse().expect("RUNS is a positive integer"));
    let names: Vec<String> = args.collect();
    let names: Vec<&str> = if names.is_empty() {
        EXAMPLES.to_vec()
    } else {
        names.iter().map(String::as_str).collect()
    };
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/mechanisms");
    println!("{:<24} {:>9} {:>9}", "mechanism", "min ms", "median ms");
    for name in names {
        // A name ending in `.pkm` is a path; otherwise an example's name.
        let path = if name.ends_with(".pkm") {
            name.to_string()
        } else {
            format!("{dir}/{name}.pkm")
        };
        let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("cannot read {path}: {e}"));
        // The same input the macro gets for an inline description.
        let input = format!("pub M, {text:?}");
        let mut times = Vec::with_capacity(runs);
        for _ in 0..runs.max(1) {
            let tokens = input.parse().expect("the macro input tokenises");
            let start = Instant::now();
            let out = pkm::dsl::expand(tokens);
            times.push(start.elapsed().as_secs_f64() * 1e3);
            if let Err(e) = out {
                eprintln!("{name}: expansion failed: {e}");
                std::process::exit(1);
            }
        }
        times.sort_by(f64::total_cmp);
        println!("{:<24} {:>9.1} {:>9.1}", name, times[0], times[times.len() / 2]);
    }
}
