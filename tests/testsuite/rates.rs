//! The generated straight-line rates and Jacobians (`fk_rates`,
//! `fk_jacobian`, the solver's recorded operations differentiated in order)
//! against two independent paths: central finite differences of the
//! generated position solver, and the runtime's velocity model (the loop
//! equations differentiated through link twists, `Name::jacobian`).

use crate::mechanisms::SeedA;
use pkm::runtime::solution::signs_of;

/// Central differences of `f` at `x`, step `h` in each given value.
fn differences<const N: usize, const R: usize>(
    f: impl Fn(&[f64; N]) -> [f64; R],
    x: &[f64; N],
    h: f64,
) -> [[f64; N]; R] {
    let mut j = [[0.0; N]; R];
    for k in 0..N {
        let (mut a, mut b) = (*x, *x);
        a[k] += h;
        b[k] -= h;
        let (fa, fb) = (f(&a), f(&b));
        for r in 0..R {
            j[r][k] = (fa[r] - fb[r]) / (2.0 * h);
        }
    }
    j
}

fn check<const N: usize, const R: usize>(got: &[[f64; N]; R], want: &[[f64; N]; R], tol: f64, what: &str) {
    for r in 0..R {
        for k in 0..N {
            let (g, w) = (got[r][k], want[r][k]);
            assert!(
                (g - w).abs() <= tol * (1.0 + w.abs()),
                "{what}: J[{r}][{k}] = {g} vs {w}"
            );
        }
    }
}

#[test]
fn seed000_a_jacobian_and_rates() {
    let params = Default::default();
    let solver = SeedA::prepare(&params);
    let signs = signs_of::<3>(0b001);
    // Seed 000 Table 1's inputs and a few around them.
    for q in [[-106.09, 181.67, -70.29], [-60.0, 120.0, 40.0], [-150.0, 90.0, -200.0]] {
        let j = solver.fk_jacobian(&q, signs).unwrap();
        let fd = differences(|g| solver.fk_branch(g, signs).unwrap(), &q, 1e-4);
        check(&j, &fd, 1e-6, "against central differences");
        // The velocity model's forward map at the same solution.
        let all = SeedA::fk_branch(&params, &q, signs).unwrap().q;
        let model = SeedA::jacobian(&params, &all).unwrap().forward.unwrap();
        let model: [[f64; 3]; 4] = std::array::from_fn(|r| std::array::from_fn(|k| model[(r, k)]));
        check(&j, &model, 1e-9, "against the velocity model");
        // Rates along a direction are the Jacobian times it.
        let rates = [1.0, -0.5, 0.25];
        let (out, dout) = solver.fk_rates(&q, signs, &rates).unwrap();
        assert_eq!(out, solver.fk_branch(&q, signs).unwrap());
        for r in 0..4 {
            let want: f64 = (0..3).map(|k| j[r][k] * rates[k]).sum();
            assert!(
                (dout[r] - want).abs() <= 1e-12 * (1.0 + want.abs()),
                "rate {r}: {} vs {want}",
                dout[r]
            );
        }
    }
}

/// `ik_jacobian` and `ik_rates` (ik's steps, a line meeting a sphere
/// among them, are traced like fk's): the inverse solution's Jacobian is
/// the inverse of the forward one on the platform's motions, J_ik·J_fk = I
/// (the chain rule through ik∘fk = id), and ∂x_i/∂x = 1 by hand (each
/// slider moves with the platform's x).
#[test]
#[allow(clippy::needless_range_loop)] // Matrix products read best by index.
fn seed000_a_inverse_jacobian() {
    let solver = SeedA::prepare(&Default::default());
    let signs = signs_of::<3>(0b001);
    for q in [[-106.09, 181.67, -70.29], [-60.0, 120.0, 40.0], [-150.0, 90.0, -200.0]] {
        let pose = solver.fk_branch(&q, signs).unwrap();
        let jf = solver.fk_jacobian(&q, signs).unwrap();
        let ik = (0..16)
            .map(signs_of::<4>)
            .find(|&s| {
                solver
                    .ik_branch(&pose, s)
                    .is_ok_and(|back| back.iter().zip(&q).all(|(a, b)| (a - b).abs() < 1e-9))
            })
            .expect("an ik branch gives the inputs back");
        let ji = solver.ik_jacobian(&pose, ik).unwrap();
        for r in 0..3 {
            for c in 0..3 {
                let product: f64 = (0..4).map(|k| ji[r][k] * jf[k][c]).sum();
                let want = if r == c { 1.0 } else { 0.0 };
                assert!((product - want).abs() < 1e-9, "(J_ik J_fk)[{r}][{c}] = {product}");
            }
            assert!((ji[r][0] - 1.0).abs() < 1e-12, "∂x{r}/∂x = {}", ji[r][0]);
        }
        let rates = [0.5, 0.0, -1.0, 0.01];
        let (out, dout) = solver.ik_rates(&pose, ik, &rates).unwrap();
        assert_eq!(out, solver.ik_branch(&pose, ik).unwrap());
        for r in 0..3 {
            let want: f64 = (0..4).map(|k| ji[r][k] * rates[k]).sum();
            assert!((dout[r] - want).abs() <= 1e-12 * (1.0 + want.abs()), "rate {r}");
        }
    }
}

/// `fk_accelerations` (the rates differentiated again, straight-line)
/// against central differences of `fk_rates` along the trajectory
/// q(t) = q + q̇t + ½q̈t² (whose rate is q̇ + q̈t), and against the runtime's
/// acceleration model (twist derivatives through the loop equations): the
/// base point o's acceleration and the platform's angular acceleration
/// about x, which is α̈ (the platform turns about x alone).
#[test]
fn seed000_a_accelerations() {
    let params = Default::default();
    let solver = SeedA::prepare(&params);
    let signs = signs_of::<3>(0b001);
    let model = SeedA::model(&params);
    let platform = model.links.iter().position(|l| l == "platform").unwrap();
    let o = SeedA::POINTS.iter().position(|p| *p == "o").unwrap();
    let (rates, accelerations) = ([1.0, -0.5, 0.25], [-2.0, 0.75, 1.5]);
    for q in [[-106.09, 181.67, -70.29], [-60.0, 120.0, 40.0], [-150.0, 90.0, -200.0]] {
        let (out, dout, ddout) = solver.fk_accelerations(&q, signs, &rates, &accelerations).unwrap();
        // By hand: o is midway between the sliders, x = (x1 + x2)/2, y = −a.
        assert!((ddout[0] - 0.5 * (accelerations[0] + accelerations[1])).abs() < 1e-12);
        assert_eq!(ddout[1], 0.0);
        assert_eq!(out, solver.fk_branch(&q, signs).unwrap());
        assert_eq!(dout, solver.fk_rates(&q, signs, &rates).unwrap().1);

        // Central differences of the rates along the trajectory, h = 1e-4 s:
        // truncation ~h²·(third derivative), rounding ~ε·|rate|/h, both < 1e-7.
        let h = 1e-4;
        let at = |t: f64| {
            let q: [f64; 3] = std::array::from_fn(|k| q[k] + rates[k] * t + 0.5 * accelerations[k] * t * t);
            let qd: [f64; 3] = std::array::from_fn(|k| rates[k] + accelerations[k] * t);
            solver.fk_rates(&q, signs, &qd).unwrap().1
        };
        let (ahead, behind) = (at(h), at(-h));
        for r in 0..4 {
            let fd = (ahead[r] - behind[r]) / (2.0 * h);
            assert!(
                (ddout[r] - fd).abs() <= 1e-6 * (1.0 + fd.abs()),
                "output {r} at {q:?}: {} vs central differences {fd}",
                ddout[r]
            );
        }

        // The runtime's acceleration model at the same solution.
        let all = SeedA::fk_branch(&params, &q, signs).unwrap().q;
        let a = SeedA::acceleration(&params, &all, &rates, &accelerations).unwrap();
        let points = SeedA::point_accelerations(&params, &all, &a).unwrap();
        let want = [points[o][0], points[o][1], points[o][2], a.twists[platform].w[0]];
        for r in 0..4 {
            assert!(
                (ddout[r] - want[r]).abs() <= 1e-9 * (1.0 + want[r].abs()),
                "output {r} at {q:?}: {} vs the acceleration model {}",
                ddout[r],
                want[r]
            );
        }
    }
}
