//! The generated straight-line rates and Jacobians (`fk_rates`,
//! `fk_jacobian`, the solver's recorded operations differentiated in order)
//! against two independent paths: central finite differences of the
//! generated position solver, and the runtime's velocity model (the loop
//! equations differentiated through link twists, `Name::jacobian`).

use pkm::runtime::solution::signs_of;

pkm::mechanism!(SeedA, file = "examples/mechanisms/seed000_a.pkm");

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
    let signs = signs_of::<2>(0b01);
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
