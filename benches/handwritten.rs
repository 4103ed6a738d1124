//! Generated prepared solvers against the same closed forms written by hand
//! in straight-line Rust (benchmark baselines only: the library has no
//! mechanism-specific code). Each hand-written solver is checked against the
//! generated one at the benchmark's point before timing, so both compute the
//! same thing: fk returns the declared outputs, ik the actuators' values.
//!
//! Ratios (generated / hand-written) are read off one run of
//! `cargo bench --bench handwritten`.

use criterion::{criterion_group, criterion_main, Criterion};
use pkm::runtime::plan::signs_of;
use std::hint::black_box;

pkm::mechanism!(SeedA, file = "examples/mechanisms/seed000_a.pkm");

/// Seed 000 mechanism A (a = 300, l1 = 100, l2 = 200, l3 = 450, l4 = 320).
/// The five-bar puts C1 = o midway between the sliders, l2 from both
/// hinges; D, at l3 from o turned by α about x, is l4 from B3:
/// `u·cosα + w·sinα = K` with u = −2a, w = z − l1.
mod seed000_a {
    const A: f64 = 300.0;
    const L1: f64 = 100.0;
    const L2: f64 = 200.0;
    const L3: f64 = 450.0;
    const L4: f64 = 320.0;

    /// One branch: `up` picks the five-bar above the sliders, `plus` the
    /// root of the trig equation.
    #[inline]
    pub fn fk(q: &[f64; 3], up: bool, plus: bool) -> Option<[f64; 4]> {
        let [x1, x2, x3] = *q;
        let half = 0.5 * (x2 - x1);
        let h2 = L2 * L2 - half * half;
        if h2 < 0.0 {
            return None;
        }
        let h = h2.sqrt();
        let x = 0.5 * (x1 + x2);
        let w = if up { h } else { -h };
        platform(x, w, x - x3, plus)
    }

    #[inline]
    fn platform(x: f64, w: f64, dx: f64, plus: bool) -> Option<[f64; 4]> {
        let u = -2.0 * A;
        let r2 = u * u + w * w;
        let k = (L4 * L4 - dx * dx - r2 - L3 * L3) / (2.0 * L3);
        let s2 = r2 - k * k;
        if s2 < 0.0 {
            return None;
        }
        let s = if plus { s2.sqrt() } else { -s2.sqrt() };
        // cos α = (u k − w s)/r², sin α = (w k + u s)/r².
        let alpha = (w * k + u * s).atan2(u * k - w * s);
        Some([x, -A, L1 + w, alpha])
    }

    /// Every branch, the five-bar's root shared.
    #[inline]
    pub fn fk_all(q: &[f64; 3]) -> [Option<[f64; 4]>; 4] {
        let [x1, x2, x3] = *q;
        let half = 0.5 * (x2 - x1);
        let h2 = L2 * L2 - half * half;
        if h2 < 0.0 {
            return [None; 4];
        }
        let h = h2.sqrt();
        let x = 0.5 * (x1 + x2);
        [
            platform(x, h, x - x3, true),
            platform(x, h, x - x3, false),
            platform(x, -h, x - x3, true),
            platform(x, -h, x - x3, false),
        ]
    }

    /// One branch of ik: the sliders from the pose.
    #[inline]
    pub fn ik(p: &[f64; 4], s1: bool, s2: bool, s3: bool) -> Option<[f64; 3]> {
        let [x, y, z, alpha] = *p;
        if (y + A).abs() > 1e-9 * A {
            return None;
        }
        let dz = z - L1;
        let c2 = L2 * L2 - dz * dz;
        if c2 < 0.0 {
            return None;
        }
        let c = c2.sqrt();
        let (s, co) = alpha.sin_cos();
        let (dy, dz3) = (y + L3 * co - A, z + L3 * s - L1);
        let e2 = L4 * L4 - dy * dy - dz3 * dz3;
        if e2 < 0.0 {
            return None;
        }
        let e = e2.sqrt();
        let pick = |b: bool, v: f64| if b { v } else { -v };
        Some([x + pick(s1, c), x + pick(s2, c), x + pick(s3, e)])
    }

    /// Every branch of ik, the roots shared.
    #[inline]
    pub fn ik_all(p: &[f64; 4]) -> [Option<[f64; 3]>; 8] {
        let [x, y, z, alpha] = *p;
        if (y + A).abs() > 1e-9 * A {
            return [None; 8];
        }
        let dz = z - L1;
        let c2 = L2 * L2 - dz * dz;
        let (s, co) = alpha.sin_cos();
        let (dy, dz3) = (y + L3 * co - A, z + L3 * s - L1);
        let e2 = L4 * L4 - dy * dy - dz3 * dz3;
        if c2 < 0.0 || e2 < 0.0 {
            return [None; 8];
        }
        let (c, e) = (c2.sqrt(), e2.sqrt());
        core::array::from_fn(|i| {
            let pick = |bit: usize, v: f64| if (i >> bit) & 1 == 0 { v } else { -v };
            Some([x + pick(0, c), x + pick(1, c), x + pick(2, e)])
        })
    }
}

fn close(a: &[f64], b: &[f64]) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-9 * 300.0)
}

fn handwritten(c: &mut Criterion) {
    let solver = SeedA::prepare(&Default::default());
    // Seed 000 Table 1's inputs; the paper's assembly.
    let q = [-106.09, 181.67, -70.29];
    let signs = signs_of::<2>(0b01);
    let out = solver.fk_branch(&q, signs).unwrap();
    // The hand-written branch that is the generated one.
    let (up, plus) = [(true, true), (true, false), (false, true), (false, false)]
        .into_iter()
        .find(|&(u, p)| seed000_a::fk(&q, u, p).is_some_and(|h| close(&h, &out)))
        .expect("a hand-written fk branch equals the generated one");
    let mut group = c.benchmark_group("seed000_a/fk");
    group.bench_function("generated_branch", |b| {
        b.iter(|| solver.fk_branch(black_box(&q), signs))
    });
    group.bench_function("hand_branch", |b| b.iter(|| seed000_a::fk(black_box(&q), up, plus)));
    group.bench_function("generated_all", |b| b.iter(|| solver.fk(black_box(&q))));
    group.bench_function("hand_all", |b| b.iter(|| seed000_a::fk_all(black_box(&q))));
    group.finish();

    let signs = signs_of::<3>(0b001);
    let x = out;
    let inputs = solver.ik_branch(&x, signs).unwrap();
    let picks = (0..8)
        .map(|i| (i & 1 == 0, i & 2 == 0, i & 4 == 0))
        .find(|&(a, b, c)| seed000_a::ik(&x, a, b, c).is_some_and(|h| close(&h, &inputs)))
        .expect("a hand-written ik branch equals the generated one");
    let mut group = c.benchmark_group("seed000_a/ik");
    group.bench_function("generated_branch", |b| {
        b.iter(|| solver.ik_branch(black_box(&x), signs))
    });
    group.bench_function("hand_branch", |b| {
        b.iter(|| seed000_a::ik(black_box(&x), picks.0, picks.1, picks.2))
    });
    group.bench_function("generated_all", |b| b.iter(|| solver.ik(black_box(&x))));
    group.bench_function("hand_all", |b| b.iter(|| seed000_a::ik_all(black_box(&x))));
    group.finish();

    // What the velocity capabilities cost against one fk branch (issue 11
    // asks for at most 5×): the Jacobians and the velocities at the solution.
    let params = Default::default();
    let all = SeedA::fk_branch(&params, &q, signs_of::<2>(0b01)).unwrap().q;
    let rates = [1.0, -0.5, 0.25];
    let mut group = c.benchmark_group("seed000_a/velocity");
    group.bench_function("fk_branch", |b| {
        b.iter(|| solver.fk_branch(black_box(&q), signs_of::<2>(0b01)))
    });
    group.bench_function("fk_rates", |b| {
        b.iter(|| solver.fk_rates(black_box(&q), signs_of::<2>(0b01), black_box(&rates)))
    });
    group.bench_function("fk_jacobian", |b| {
        b.iter(|| solver.fk_jacobian(black_box(&q), signs_of::<2>(0b01)))
    });
    group.bench_function("jacobian", |b| b.iter(|| SeedA::jacobian(&params, black_box(&all))));
    group.bench_function("velocity", |b| {
        b.iter(|| SeedA::velocity(&params, black_box(&all), black_box(&rates)))
    });
    group.finish();
}

criterion_group!(benches, handwritten);
criterion_main!(benches);
