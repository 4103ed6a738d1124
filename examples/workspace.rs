//! Seed 000 §2.2: the workspaces of mechanisms A and B swept through their
//! generated forward solutions over x1 ∈ [−250, 0], x2 ∈ [0, 250],
//! x3 ∈ [−300, 300] mm, for the platform's midpoint G (its centroid), on
//! the paper's assembly (the five-bar above the sliders), each root of the
//! platform's angle, through the batch path (`sweep_batch` handing chunks
//! of nodes to the generated `fk_point_batch`). Prints the volume (the
//! image of the input grid, `image_volume`) and the sweep's time.
//!
//! `cargo run --release --example workspace [nodes per input]` (default 100).

use pkm::runtime::primitives::Sign;
use pkm::runtime::solution::SolveError;
use pkm::runtime::workspace::{bounds, image_volume, sweep_batch, Grid, Lanes, Sample};
use std::time::Instant;

pkm::mechanism!(SeedA, file = "examples/mechanisms/seed000_a.pkm");
pkm::mechanism!(SeedB, file = "examples/mechanisms/seed000_b.pkm");

fn main() {
    let n: usize = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(100);
    let grid = Grid {
        ranges: vec![(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)],
        counts: vec![n; 3],
    };
    // Prepared once; per node only the steps.
    let (sa, sb) = (SeedA::prepare(&Default::default()), SeedB::prepare(&Default::default()));
    // G's index among each mechanism's points (a constant: the batch
    // solver's point is a compile-time choice).
    const GA: usize = index(&SeedA::POINTS, "G");
    const GB: usize = index(&SeedB::POINTS, "G");
    // The paper's assembly: the five-bar above the sliders (its first sign
    // Minus in both), each root of the platform's angle.
    let (m, p) = (Sign::Minus, Sign::Plus);
    type Solve = Box<dyn Fn(Lanes<3>) -> Result<(), SolveError> + Sync>;
    let a = move |signs| -> Solve { Box::new(move |(g, out, ok)| sa.fk_point_batch::<GA>(g, signs, out, ok)) };
    let b = move |signs| -> Solve { Box::new(move |(g, out, ok)| sb.fk_point_batch::<GB>(g, signs, out, ok)) };
    let runs: [(&str, Solve); 4] = [
        ("A (−, +, +)", a([m, p, p])),
        ("A (−, −, +)", a([m, m, p])),
        ("B (−, −, +)", b([m, m, p])),
        ("B (−, −, −)", b([m, m, m])),
    ];
    for (name, solve) in runs {
        let start = Instant::now();
        let nodes = match sweep_batch::<3, _>(&grid, |lanes| solve(lanes)) {
            Ok(points) => points.nodes(),
            Err(e) => {
                eprintln!("{name}: {e}");
                std::process::exit(1);
            }
        };
        let took = start.elapsed();
        let reached: Vec<_> = nodes
            .iter()
            .flatten()
            .map(|&point| Sample { q: [0.0; 3], point })
            .collect();
        let volume = image_volume(&grid, &nodes);
        let (lo, hi) = bounds(&reached).unwrap_or(([0.0; 3], [0.0; 3]));
        println!(
            "{name}: {} of {} nodes reachable in {:.2} s; volume {:.4e} mm³ (image of the input grid); x {:.0}..{:.0}, y {:.0}..{:.0}, z {:.0}..{:.0}",
            reached.len(),
            grid.len(),
            took.as_secs_f64(),
            volume,
            lo[0],
            hi[0],
            lo[1],
            hi[1],
            lo[2],
            hi[2]
        );
    }
}

/// The index of `name` in `names` (a compile-time error if absent).
const fn index(names: &[&str], name: &str) -> usize {
    let mut i = 0;
    while i < names.len() {
        let (a, b) = (names[i].as_bytes(), name.as_bytes());
        if a.len() == b.len() {
            let mut k = 0;
            while k < a.len() && a[k] == b[k] {
                k += 1;
            }
            if k == a.len() {
                return i;
            }
        }
        i += 1;
    }
    panic!("no such point")
}
