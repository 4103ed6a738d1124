//! Generated prepared solvers against the same closed forms written by hand
//! in straight-line Rust (benchmark baselines only: the library has no
//! mechanism-specific code). Each hand-written solver is checked against the
//! generated one at the benchmark's point before timing, so both compute the
//! same thing: fk returns the declared outputs, ik the actuators' values.
//!
//! Ratios (generated / hand-written) are read off one run of
//! `cargo bench --bench handwritten`.

use criterion::{criterion_group, criterion_main, Criterion};
use pkm::runtime::solution::signs_of;
use std::hint::black_box;

pkm::mechanism!(SeedA, file = "examples/mechanisms/seed000_a.pkm");
pkm::mechanism!(FourBar, file = "examples/mechanisms/four_bar.pkm");
pkm::mechanism!(SliderCrank, file = "examples/mechanisms/slider_crank.pkm");

/// The planar four-bar (l1 = 100, l2 = 250, l3 = 200, l4 = 300): the
/// coupler's far hinge B is where the circles about the crank pin A (l2)
/// and the rocker pivot D (l3) meet; ψ is the rocker's angle at D.
mod four_bar {
    const L1: f64 = 100.0;
    const L2: f64 = 250.0;
    const L3: f64 = 200.0;
    const L4: f64 = 300.0;

    /// The two circles about `p` (radius `rp`) and `q` (radius `rq`) meet at
    /// `q + a·u ± h·u⊥`, `u` the unit vector from `q` to `p`.
    #[inline]
    fn meet(p: [f64; 2], rp: f64, q: [f64; 2], rq: f64, plus: bool) -> Option<[f64; 2]> {
        let (dx, dy) = (p[0] - q[0], p[1] - q[1]);
        let d = (dx * dx + dy * dy).sqrt();
        let a = (rq * rq - rp * rp + d * d) / (2.0 * d);
        let h2 = rq * rq - a * a;
        if h2 < 0.0 {
            return None;
        }
        let h = if plus { h2.sqrt() } else { -h2.sqrt() };
        let (ux, uy) = (dx / d, dy / d);
        Some([q[0] + a * ux - h * uy, q[1] + a * uy + h * ux])
    }

    /// ψ from the crank angle.
    #[inline]
    pub fn fk(theta: f64, plus: bool) -> Option<f64> {
        let (s, c) = theta.sin_cos();
        let b = meet([L1 * c, L1 * s], L2, [L4, 0.0], L3, plus)?;
        Some(b[1].atan2(b[0] - L4))
    }

    /// The crank angle from ψ.
    #[inline]
    pub fn ik(psi: f64, plus: bool) -> Option<f64> {
        let (s, c) = psi.sin_cos();
        let a = meet([L4 + L3 * c, L3 * s], L2, [0.0, 0.0], L1, plus)?;
        Some(a[1].atan2(a[0]))
    }
}

/// The planar slider-crank (r = 50, l = 180, e = 0): the slider on y = e
/// at l from the crank pin.
mod slider_crank {
    const R: f64 = 50.0;
    const L: f64 = 180.0;
    const E: f64 = 0.0;

    /// The slide from the crank angle.
    #[inline]
    pub fn fk(theta: f64, plus: bool) -> Option<f64> {
        let (s, c) = theta.sin_cos();
        let dy = E - R * s;
        let h2 = L * L - dy * dy;
        if h2 < 0.0 {
            return None;
        }
        Some(R * c + if plus { h2.sqrt() } else { -h2.sqrt() })
    }

    /// The crank angle from the slide: the crank pin where the circle of
    /// radius r about the pivot meets the circle of radius l about the slider.
    #[inline]
    pub fn ik(x: f64, plus: bool) -> Option<f64> {
        let d = (x * x + E * E).sqrt();
        let a = (R * R - L * L + d * d) / (2.0 * d);
        let h2 = R * R - a * a;
        if h2 < 0.0 {
            return None;
        }
        let h = if plus { h2.sqrt() } else { -h2.sqrt() };
        let (ux, uy) = (x / d, E / d);
        let p = [a * ux - h * uy, a * uy + h * ux];
        Some(p[1].atan2(p[0]))
    }
}

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

/// A planar mechanism's prepared fk and ik (the one pipeline's straight-line
/// code: the declared output, or the actuator) against the hand-written
/// closed form of its one output, one branch and both.
macro_rules! planar {
    ($c:expr, $ty:ident, $hand:ident, $name:expr, $q:expr) => {{
        let solver = $ty::prepare(&Default::default());
        let q = [$q];
        let signs = signs_of::<1>(0);
        let out = solver.fk_branch(&q, signs).unwrap()[0];
        let plus = [true, false]
            .into_iter()
            .find(|&p| $hand::fk(q[0], p).is_some_and(|h| (h - out).abs() < 1e-9))
            .expect("a hand-written fk branch equals the generated one");
        let mut group = $c.benchmark_group(concat!($name, "/fk"));
        group.bench_function("generated_branch", |b| {
            b.iter(|| solver.fk_branch(black_box(&q), signs))
        });
        group.bench_function("hand_branch", |b| b.iter(|| $hand::fk(black_box(q[0]), plus)));
        group.bench_function("generated_all", |b| b.iter(|| solver.fk(black_box(&q))));
        group.bench_function("hand_all", |b| {
            b.iter(|| [$hand::fk(black_box(q[0]), true), $hand::fk(black_box(q[0]), false)])
        });
        group.finish();
        let x = [out];
        let back = solver.ik_branch(&x, signs).unwrap()[0];
        let plus = [true, false]
            .into_iter()
            .find(|&p| $hand::ik(x[0], p).is_some_and(|h| (h - back).abs() < 1e-9))
            .expect("a hand-written ik branch equals the generated one");
        let mut group = $c.benchmark_group(concat!($name, "/ik"));
        group.bench_function("generated_branch", |b| {
            b.iter(|| solver.ik_branch(black_box(&x), signs))
        });
        group.bench_function("hand_branch", |b| b.iter(|| $hand::ik(black_box(x[0]), plus)));
        group.bench_function("generated_all", |b| b.iter(|| solver.ik(black_box(&x))));
        group.bench_function("hand_all", |b| {
            b.iter(|| [$hand::ik(black_box(x[0]), true), $hand::ik(black_box(x[0]), false)])
        });
        group.finish();
    }};
}

fn handwritten(c: &mut Criterion) {
    planar!(c, FourBar, four_bar, "four_bar", 0.7);
    planar!(c, SliderCrank, slider_crank, "slider_crank", 0.7);
    let solver = SeedA::prepare(&Default::default());
    // Seed 000 Table 1's inputs; the paper's assembly.
    let q = [-106.09, 181.67, -70.29];
    let signs = signs_of::<3>(0b001);
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

    let signs = signs_of::<4>(0b0001);
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
    // asks for at most 5×): the Jacobians, the velocities and the
    // accelerations at the solution.
    let params = Default::default();
    let all = SeedA::fk_branch(&params, &q, signs_of::<3>(0b001)).unwrap().q;
    let rates = [1.0, -0.5, 0.25];
    let mut group = c.benchmark_group("seed000_a/velocity");
    group.bench_function("fk_branch", |b| {
        b.iter(|| solver.fk_branch(black_box(&q), signs_of::<3>(0b001)))
    });
    group.bench_function("fk_rates", |b| {
        b.iter(|| solver.fk_rates(black_box(&q), signs_of::<3>(0b001), black_box(&rates)))
    });
    group.bench_function("fk_jacobian", |b| {
        b.iter(|| solver.fk_jacobian(black_box(&q), signs_of::<3>(0b001)))
    });
    let accelerations = [-2.0, 0.75, 1.5];
    group.bench_function("fk_accelerations", |b| {
        b.iter(|| solver.fk_accelerations(black_box(&q), signs_of::<3>(0b001), &rates, black_box(&accelerations)))
    });
    group.bench_function("jacobian", |b| b.iter(|| SeedA::jacobian(&params, black_box(&all))));
    group.bench_function("velocity", |b| {
        b.iter(|| SeedA::velocity(&params, black_box(&all), black_box(&rates)))
    });
    group.finish();
}

criterion_group!(benches, handwritten);
criterion_main!(benches);
