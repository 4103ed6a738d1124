//! Seed 000 §2.2's workspace sweep: 10⁶ actuator samples (100 per input over
//! −250 ≤ x1 ≤ 0, 0 ≤ x2 ≤ 250, −300 ≤ x3 ≤ 300 mm) through the generated
//! forward solution of the paper's assembly, on all cores, keeping the
//! platform midpoint G: one iteration is one whole sweep.
//!
//! Mechanism A three ways in one run: node by node through `fk_solution`
//! (`sweep_nodes`), through the generated batch solver `fk_point_batch`
//! (`sweep_batch`), and through a hand-written structure-of-arrays loop of
//! G's closed form in the same `sweep_batch` (a baseline only: the library
//! has no mechanism-specific code). Both batch sweeps are checked against
//! the per-node one before timing. The `kernel` group times the two loops
//! alone on one core over the same 10⁶ prefilled lanes.

use criterion::{criterion_group, criterion_main, Criterion};
use pkm::runtime::batch::{wide, Loop};
use pkm::runtime::primitives::Sign;
use pkm::runtime::workspace::{sweep_batch, sweep_nodes, Grid, Lanes, Points};
use std::hint::black_box;

pkm::mechanism!(SeedA, file = "examples/mechanisms/seed000_a.pkm");
pkm::mechanism!(SeedB, file = "examples/mechanisms/seed000_b.pkm");

/// G's index in `SeedA::POINTS` (checked below).
const G: usize = 18;

/// Seed 000 A's G by hand (a = 300, l1 = 100, l2 = 200, l3 = 450,
/// l4 = 320; the closed form of benches/handwritten.rs): the five-bar puts
/// o midway between the sliders at height l1 + w, w = ±√(l2² − ((x2 −
/// x1)/2)²); D, l3 from o at α about x, is l4 from B3, which gives cos α
/// and sin α; G is l3/2 from o towards D. `up`, `plus`: the roots' signs.
/// Lane by lane with selects, no branch, so that it vectorises; run
/// through `batch::wide` as the generated loop is (AVX2 where present).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn hand_g(
    x1: &[f64],
    x2: &[f64],
    x3: &[f64],
    gx: &mut [f64],
    gy: &mut [f64],
    gz: &mut [f64],
    ok: &mut [bool],
    up: bool,
    plus: bool,
) {
    const A: f64 = 300.0;
    const L1: f64 = 100.0;
    const L2: f64 = 200.0;
    const L3: f64 = 450.0;
    const L4: f64 = 320.0;
    let n = ok.len();
    let (x1, x2, x3) = (&x1[..n], &x2[..n], &x3[..n]);
    let (gx, gy, gz) = (&mut gx[..n], &mut gy[..n], &mut gz[..n]);
    let (w_sign, s_sign) = (if up { 1.0 } else { -1.0 }, if plus { 1.0 } else { -1.0 });
    for i in 0..n {
        let half = 0.5 * (x2[i] - x1[i]);
        let h2 = L2 * L2 - half * half;
        let w = w_sign * h2.sqrt();
        let x = 0.5 * (x1[i] + x2[i]);
        let (u, dx) = (-2.0 * A, x - x3[i]);
        let r2 = u * u + w * w;
        let k = (L4 * L4 - dx * dx - r2 - L3 * L3) / (2.0 * L3);
        let s2 = r2 - k * k;
        let s = s_sign * s2.sqrt();
        let (cos, sin) = ((u * k - w * s) / r2, (w * k + u * s) / r2);
        // Coincident sliders (half = 0): the five-bar's two circles are one,
        // its position undetermined; the generated solver refuses it too.
        let reached =
            (half != 0.0) & (h2 >= 0.0) & (s2 >= 0.0) & x1[i].is_finite() & x2[i].is_finite() & x3[i].is_finite();
        gx[i] = if reached { x } else { 0.0 };
        gy[i] = if reached { -A + 0.5 * L3 * cos } else { 0.0 };
        gz[i] = if reached { L1 + w + 0.5 * L3 * sin } else { 0.0 };
        ok[i] = reached;
    }
}

/// `hand_g` as a loop for `batch::wide`.
struct HandLoop<'a> {
    given: [&'a [f64]; 3],
    out: [&'a mut [f64]; 3],
    ok: &'a mut [bool],
    up: bool,
    plus: bool,
}

impl Loop for HandLoop<'_> {
    #[inline(always)]
    fn run(self) {
        let ([x1, x2, x3], [gx, gy, gz]) = (self.given, self.out);
        hand_g(x1, x2, x3, gx, gy, gz, self.ok, self.up, self.plus);
    }
}

/// Hand-written G over lanes, on the widest vectors.
fn hand_lanes((given, out, ok): Lanes<3>, up: bool, plus: bool) {
    wide(HandLoop {
        given,
        out,
        ok,
        up,
        plus,
    });
}

/// Whether two sweeps reach the same nodes at the same points (to 1e-9 of
/// the 450 mm platform).
fn same(a: &Points, b: &[Option<[f64; 3]>]) -> bool {
    a.nodes().iter().zip(b).all(|(p, q)| match (p, q) {
        (Some(p), Some(q)) => (0..3).all(|c| (p[c] - q[c]).abs() <= 1e-9 * 450.0),
        (None, None) => true,
        _ => false,
    }) && a.ok.len() == b.len()
}

fn workspace(c: &mut Criterion) {
    let grid = Grid {
        ranges: vec![(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)],
        counts: vec![100; 3],
    };
    let sa = SeedA::prepare(&Default::default());
    assert_eq!(SeedA::POINTS[G], "G");
    let signs = [Sign::Minus, Sign::Plus, Sign::Plus];
    let per_node = |grid: &Grid| sweep_nodes::<3>(grid, |q| sa.fk_solution(q, signs).ok().map(|s| s.points[G]));
    let batch = |grid: &Grid| {
        sweep_batch::<3, _>(grid, |(given, out, ok): Lanes<3>| {
            sa.fk_point_batch::<G>(given, signs, out, ok)
        })
    };
    // The hand-written branch that is the generated one: the one that agrees.
    let nodes = per_node(&grid);
    let hand = |grid: &Grid, up: bool, plus: bool| {
        sweep_batch::<3, ()>(grid, |lanes: Lanes<3>| {
            hand_lanes(lanes, up, plus);
            Ok(())
        })
        .unwrap()
    };
    let (up, plus) = [(true, true), (true, false), (false, true), (false, false)]
        .into_iter()
        .find(|&(u, p)| same(&hand(&grid, u, p), &nodes))
        .expect("a hand-written branch sweeps what the generated one does");
    assert!(
        same(&batch(&grid).unwrap(), &nodes),
        "the batch sweep is the per-node sweep"
    );
    let reached = nodes.iter().filter(|n| n.is_some()).count();
    println!("seed000_a: {reached} of {} nodes reached", nodes.len());

    let mut group = c.benchmark_group("sweep_1e6");
    group.sample_size(10);
    group.bench_function("seed000_a", |b| b.iter(|| per_node(black_box(&grid))));
    group.bench_function("seed000_a_batch", |b| b.iter(|| batch(black_box(&grid))));
    group.bench_function("seed000_a_hand_soa", |b| b.iter(|| hand(black_box(&grid), up, plus)));
    group.bench_function("overhead", |b| {
        b.iter(|| {
            sweep_batch::<3, ()>(black_box(&grid), |(_, _, ok): Lanes<3>| {
                ok[0] = true;
                Ok(())
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

    // The two loops alone, one core, the same prefilled lanes.
    let n = grid.len();
    let inputs: Vec<[f64; 3]> = (0..n)
        .map(|i| {
            let mut q = [0.0; 3];
            grid.node(i, &mut q);
            q
        })
        .collect();
    let given: [Vec<f64>; 3] = std::array::from_fn(|k| inputs.iter().map(|q| q[k]).collect());
    let (mut gx, mut gy, mut gz, mut ok) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![false; n]);
    let mut group = c.benchmark_group("kernel_1e6_one_core");
    group.sample_size(20);
    group.bench_function("seed000_a_batch", |b| {
        b.iter(|| {
            let g = black_box([&given[0][..], &given[1][..], &given[2][..]]);
            sa.fk_point_batch::<G>(g, signs, [&mut gx, &mut gy, &mut gz], &mut ok)
        })
    });
    group.bench_function("seed000_a_hand_soa", |b| {
        b.iter(|| {
            let g = black_box([&given[0][..], &given[1][..], &given[2][..]]);
            hand_lanes((g, [&mut gx, &mut gy, &mut gz], &mut ok), up, plus)
        })
    });
    group.finish();
}

criterion_group!(benches, workspace);
criterion_main!(benches);
