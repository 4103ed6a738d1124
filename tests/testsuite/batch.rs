//! The generated batch solvers (`fk_batch`, `ik_batch`, `fk_point_batch`)
//! against the one-branch solvers they are written from, lane by lane and
//! bit for bit: the same recorded graph, the same operations in the same
//! order, so rounding cannot differ. Lanes the scalar solver refuses (out of
//! reach, not finite, over-determined poses its verification rejects) must
//! be `ok = false` with zeros, and each kind is present in every case.
//! Seed 000 A's point G is also checked against its closed form (derived by
//! hand in benches/handwritten.rs).

use crate::mechanisms::{FiveBarPa, FourBarOver, SeedA, SeedB};
use pkm::runtime::solution::{signs_of, SolveError};
use std::f64::consts::PI;

/// How the lanes the scalar solver refused failed: (guard or kernel,
/// verification, not finite).
#[derive(Debug, Default)]
struct Refused {
    reached: usize,
    step: usize,
    verification: usize,
    not_finite: usize,
}

impl Refused {
    fn count(&mut self, r: &Result<impl Sized, SolveError>) {
        match r {
            Ok(_) => self.reached += 1,
            Err(SolveError::Inconsistent { .. }) => self.verification += 1,
            Err(SolveError::BadInput { .. }) => self.not_finite += 1,
            Err(_) => self.step += 1,
        }
    }
}

/// Lane i of a batch (`ok`, `out[r][i]`) against the scalar result.
fn check_lane<const R: usize>(scalar: &Result<[f64; R], SolveError>, ok: bool, out: [f64; R], what: &str) {
    match scalar {
        Ok(want) => {
            assert!(ok, "{what}: scalar ok {want:?}, batch refused");
            assert_eq!(
                want.map(f64::to_bits),
                out.map(f64::to_bits),
                "{what}: {want:?} != {out:?}"
            );
        }
        Err(e) => {
            assert!(!ok, "{what}: scalar {e}, batch ok {out:?}");
            assert_eq!(out, [0.0; R], "{what}: a refused lane writes zeros");
        }
    }
}

/// Given values: `n` uniform in `ranges` (wider than the mechanism
/// reaches), then a NaN and an infinity.
fn lanes<const N: usize>(ranges: [(f64, f64); N], n: usize, seed: u64) -> Vec<[f64; N]> {
    let mut rng = pkm::dsl::screw::SplitMix::new(seed);
    let mut v: Vec<[f64; N]> = (0..n)
        .map(|_| ranges.map(|(lo, hi)| lo + (hi - lo) * (rng.symmetric() + 1.0) / 2.0))
        .collect();
    let mut bad = v[0];
    bad[0] = f64::NAN;
    v.push(bad);
    bad[0] = f64::INFINITY;
    v.push(bad);
    v
}

/// Structure of arrays from lanes.
fn columns<const N: usize>(v: &[[f64; N]]) -> [Vec<f64>; N] {
    std::array::from_fn(|k| v.iter().map(|l| l[k]).collect())
}

/// Every branch of `fk_batch` and `fk_point_batch::<P>` (every point P)
/// against `fk_branch` and `fk_solution`; then `ik_batch` against
/// `ik_branch` on the poses the forward lanes reached, each also pushed off
/// (the verification's refusals).
macro_rules! agree {
    ($ty:ident, $choices_fk:literal, $choices_ik:literal, $ranges:expr, $seed:expr, [$($p:literal)*]) => {{
        let s = $ty::prepare(&Default::default());
        let q = lanes::<3>($ranges, 400, $seed);
        let n = q.len();
        let cols = columns(&q);
        let given: [&[f64]; 3] = std::array::from_fn(|k| &cols[k][..]);
        let mut refused = Refused::default();
        let mut poses = Vec::new();
        for b in 0..1usize << $choices_fk {
            let signs = signs_of::<$choices_fk>(b);
            let mut out = [vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]];
            let mut ok = vec![true; n];
            let [o0, o1, o2, o3] = &mut out;
            s.fk_batch(given, signs, [o0, o1, o2, o3], &mut ok).unwrap();
            for i in 0..n {
                let scalar = s.fk_branch(&q[i], signs);
                refused.count(&scalar);
                if let Ok(x) = scalar {
                    poses.push(x);
                }
                let lane = [out[0][i], out[1][i], out[2][i], out[3][i]];
                check_lane(&scalar, ok[i], lane, &format!("fk branch {b} lane {i} {:?}", q[i]));
            }
            // Every point of the solution, one instantiation each.
            $({
                let (mut x, mut y, mut z, mut ok) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![true; n]);
                s.fk_point_batch::<$p>(given, signs, [&mut x, &mut y, &mut z], &mut ok).unwrap();
                for i in 0..n {
                    let want = s.fk_solution(&q[i], signs).map(|sol| sol.points[$p]);
                    check_lane(&want, ok[i], [x[i], y[i], z[i]], &format!("point {} lane {i} branch {b}", $p));
                }
            })*
        }
        assert!(refused.reached > 0 && refused.step > 0 && refused.not_finite > 0, "fk {refused:?}");

        // Inverse: the reached poses, each also with y pushed off by 1 (a
        // translation the platform's POC set does not have: refused by the
        // verification), then a NaN and an infinity.
        let mut x: Vec<[f64; 4]> = Vec::new();
        for p in poses.iter().step_by(7) {
            x.push(*p);
            x.push([p[0], p[1] + 1.0, p[2], p[3]]);
        }
        x.push([f64::NAN, 0.0, 0.0, 0.0]);
        x.push([0.0, 0.0, f64::INFINITY, 0.0]);
        let n = x.len();
        let cols = columns(&x);
        let given: [&[f64]; 4] = std::array::from_fn(|k| &cols[k][..]);
        let mut refused = Refused::default();
        for b in 0..1usize << $choices_ik {
            let signs = signs_of::<$choices_ik>(b);
            let mut out = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
            let mut ok = vec![true; n];
            let [o0, o1, o2] = &mut out;
            s.ik_batch(given, signs, [o0, o1, o2], &mut ok).unwrap();
            for i in 0..n {
                let scalar = s.ik_branch(&x[i], signs);
                refused.count(&scalar);
                let lane = [out[0][i], out[1][i], out[2][i]];
                check_lane(&scalar, ok[i], lane, &format!("ik branch {b} lane {i} {:?}", x[i]));
            }
        }
        assert!(
            refused.reached > 0 && refused.verification > 0 && refused.not_finite > 0,
            "ik {refused:?}"
        );
    }};
}

#[test]
fn seed000_a_batch_equals_scalar() {
    agree!(
        SeedA, 3, 4,
        [(-400.0, 150.0), (-150.0, 400.0), (-500.0, 500.0)], 1,
        [0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20]
    );
}

#[test]
fn seed000_b_batch_equals_scalar() {
    agree!(
        SeedB, 3, 4,
        [(-400.0, 150.0), (-150.0, 400.0), (-500.0, 500.0)], 2,
        [0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20]
    );
}

#[test]
fn five_bar_pa_batch_equals_scalar() {
    agree!(
        FiveBarPa, 3, 4,
        [(-PI, PI), (-PI, PI), (-600.0, 600.0)], 3,
        [0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15]
    );
}

/// Seed 000 A's point G by hand (benches/handwritten.rs's closed form): the
/// five-bar puts o midway between the sliders at height l1 + w, w = ±√(l2² −
/// ((x2 − x1)/2)²); D, l3 from o at α about x, is l4 from B3, which gives
/// cos α and sin α; G is l3/2 from o towards D.
fn seed000_a_g(q: [f64; 3], up: bool, plus: bool) -> Option<[f64; 3]> {
    let (a, l1, l2, l3, l4) = (300.0, 100.0, 200.0, 450.0, 320.0);
    if !q.iter().all(|v| v.is_finite()) {
        return None;
    }
    let [x1, x2, x3] = q;
    let half = 0.5 * (x2 - x1);
    let h2 = l2 * l2 - half * half;
    if h2 < 0.0 {
        return None;
    }
    let w = if up { h2.sqrt() } else { -h2.sqrt() };
    let x = 0.5 * (x1 + x2);
    let (u, dx) = (-2.0 * a, x - x3);
    let r2 = u * u + w * w;
    let k = (l4 * l4 - dx * dx - r2 - l3 * l3) / (2.0 * l3);
    let s2 = r2 - k * k;
    if s2 < 0.0 {
        return None;
    }
    let s = if plus { s2.sqrt() } else { -s2.sqrt() };
    let (cos, sin) = ((u * k - w * s) / r2, (w * k + u * s) / r2);
    Some([x, -a + 0.5 * l3 * cos, l1 + w + 0.5 * l3 * sin])
}

#[test]
fn seed000_a_point_g_matches_its_closed_form() {
    let s = SeedA::prepare(&Default::default());
    const G: usize = 18;
    assert_eq!(SeedA::POINTS[G], "G");
    let q = lanes::<3>([(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)], 2000, 4);
    let n = q.len();
    let cols = columns(&q);
    let given: [&[f64]; 3] = std::array::from_fn(|k| &cols[k][..]);
    // Eight branches: four platforms, each with the R5–parallelogram leg
    // in either posture (the same G).
    for b in 0..8 {
        let signs = signs_of::<3>(b);
        let (mut x, mut y, mut z, mut ok) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![false; n]);
        s.fk_point_batch::<G>(given, signs, [&mut x, &mut y, &mut z], &mut ok)
            .unwrap();
        // The hand-written branch this one is: the one that agrees on most lanes.
        let hand = [(true, true), (true, false), (false, true), (false, false)]
            .into_iter()
            .max_by_key(|&(up, plus)| {
                (0..n)
                    .filter(|&i| {
                        ok[i]
                            && seed000_a_g(q[i], up, plus)
                                .is_some_and(|g| (g[0] - x[i]).abs() + (g[1] - y[i]).abs() + (g[2] - z[i]).abs() < 1e-6)
                    })
                    .count()
            })
            .unwrap();
        let mut reached = 0;
        for i in 0..n {
            let want = seed000_a_g(q[i], hand.0, hand.1);
            assert_eq!(ok[i], want.is_some(), "branch {b} lane {i} {:?}", q[i]);
            if let Some(g) = want {
                reached += 1;
                let got = [x[i], y[i], z[i]];
                assert!(
                    (0..3).all(|c| (g[c] - got[c]).abs() <= 1e-9 * 450.0),
                    "branch {b} lane {i}: {got:?} != {g:?}"
                );
            }
        }
        assert!(reached > n / 4, "branch {b}: {reached} of {n} reached");
    }
}

/// Slices of other lengths than `ok`: a typed error naming the slice, and
/// no lane touched.
#[test]
fn lengths_are_checked() {
    let s = SeedA::prepare(&Default::default());
    let check = |lens: [usize; 8], expect: &str| {
        let given: Vec<Vec<f64>> = (0..3).map(|k| vec![-100.0; lens[k]]).collect();
        let mut out: Vec<Vec<f64>> = (3..7).map(|k| vec![7.0; lens[k]]).collect();
        let mut ok = vec![true; lens[7]];
        let [o0, o1, o2, o3] = &mut out[..] else { unreachable!() };
        let r = s.fk_batch(
            [&given[0], &given[1], &given[2]],
            signs_of::<3>(0),
            [o0, o1, o2, o3],
            &mut ok,
        );
        assert_eq!(
            r.map_err(|e| e.to_string()),
            if expect.is_empty() {
                Ok(())
            } else {
                Err(expect.to_string())
            }
        );
        if !expect.is_empty() {
            assert!(
                ok.iter().all(|&o| o) && out.iter().flatten().all(|&v| v == 7.0),
                "a lane was touched"
            );
        }
    };
    check([2; 8], "");
    check([0; 8], "");
    check(
        [2, 2, 1, 2, 2, 2, 2, 2],
        "bad input: fk_batch: given[2] has 1 values, ok has 2",
    );
    check(
        [2, 2, 2, 2, 3, 2, 2, 2],
        "bad input: fk_batch: out[1] has 3 values, ok has 2",
    );
    check(
        [2, 2, 2, 2, 2, 2, 2, 5],
        "bad input: fk_batch: given[0] has 2 values, ok has 5",
    );
}

/// A pinned point is verified lane by lane: consistent outputs (from fk)
/// solve as `ik_branch` does, and the same with y moved by 1 are refused
/// on every branch, as `ik_branch` refuses them.
#[test]
fn pinned_points_are_verified_per_lane() {
    let s = FourBarOver::prepare(&Default::default());
    let mut poses = Vec::new();
    for k in 0..40 {
        let theta = -3.0 + 0.15 * k as f64;
        if let Some(out) = s.fk(&[theta]).iter().find_map(|b| b.result.as_ref().ok().copied()) {
            poses.push(out);
            poses.push([out[0], out[1] + 1.0, out[2]]);
        }
    }
    assert!(poses.len() >= 40);
    let cols = columns(&poses);
    let given: [&[f64]; 3] = std::array::from_fn(|k| &cols[k][..]);
    let mut refused = 0;
    for (b, branch) in s.ik(&poses[0]).iter().enumerate() {
        let signs = branch.signs;
        let n = poses.len();
        let mut out = vec![vec![0.0; n]; 1];
        let mut ok = vec![false; n];
        {
            let [o0] = &mut out[..] else { unreachable!() };
            s.ik_batch(given, signs, [&mut o0[..]], &mut ok).unwrap();
        }
        for i in 0..n {
            let scalar = s.ik_branch(&poses[i], signs);
            check_lane(&scalar, ok[i], [out[0][i]], &format!("lane {i} branch {b}"));
            if i % 2 == 1 {
                assert!(!ok[i], "lane {i} (y + 1) solved on branch {b}");
                refused += 1;
            }
        }
    }
    assert!(refused >= 40);
}
