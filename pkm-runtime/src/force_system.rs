//! One SKC's reaction equations solved from the singular value
//! decomposition of its (padded, square) matrix: the minimum-norm solution,
//! the conditioning of the determined part, and the check that the
//! undetermined part does not move an actuator's force. Newton–Euler
//! ([`crate::newton_euler`]) and the generated inverse dynamics both read
//! it; they differ only in where the matrix lives (heap or stack).

use crate::newton_euler::{DynamicsError, FORCE_SINGULAR};

/// An SVD `A = U Σ Vᵀ` of an `n × n` matrix, column-major slices of `U`
/// and `Vᵀ` (as nalgebra stores them) and the singular values, in any order.
#[derive(Debug, Clone, Copy)]
pub struct Decomposition<'a> {
    /// The size.
    pub n: usize,
    /// σ.
    pub singular_values: &'a [f64],
    /// U, column-major.
    pub u: &'a [f64],
    /// Vᵀ, column-major.
    pub v_t: &'a [f64],
}

/// Above this ratio of a full-pivoting LU's smallest to largest pivot, a
/// determined SKC's system is far from a change point and its LU solution
/// stands (the ratio, an estimate of σ_n/σ_1, is its conditioning); at or
/// below it the system is decomposed by SVD for the exact conditioning and
/// the minimum-norm solve. The SVD costs about ten LUs at these sizes.
pub const LU_TRUSTED: f64 = 1e-6;

/// The ratio of the smallest to the largest magnitude of a triangular
/// factor's diagonal (0 if it is all zero or not finite).
pub fn pivot_ratio(diagonal: &[f64]) -> f64 {
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for d in diagonal {
        let d = d.abs();
        if d.is_nan() {
            return 0.0;
        }
        lo = lo.min(d);
        hi = hi.max(d);
    }
    if hi > 0.0 && hi.is_finite() {
        lo / hi
    } else {
        0.0
    }
}

/// What one SKC's solve found besides the reactions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Solved {
    /// The conditioning of its determined part (σ_r/σ_1, r its expected rank).
    pub conditioning: f64,
    /// The reaction components left undetermined (n − rank).
    pub undetermined: usize,
}

/// σ_r/σ_1 of the singular values `s` (any order), r the rank expected
/// (1 if it is 0 or every value is 0): the conditioning of the determined part.
fn conditioning_of(s: &[f64], rank_expected: usize) -> f64 {
    let r = rank_expected.min(s.len());
    let smax = s.iter().fold(0.0f64, |a, &v| a.max(v));
    if r == 0 || smax <= 0.0 {
        return 1.0;
    }
    // The r-th largest, without sorting a copy.
    let kth = s
        .iter()
        .copied()
        .filter(|&v| s.iter().filter(|&&w| w > v).count() < r)
        .fold(f64::INFINITY, f64::min);
    kth / smax
}

/// The minimum-norm least-squares solution `x` of `A x = b` from `A`'s
/// decomposition, SKC `skc` (joints `joints`, for errors) of which the
/// topology leaves `undetermined` components free. `actuated` holds one row
/// of `n` numbers per actuator twist (its power coefficients against the
/// unknowns, zero elsewhere): a null-space direction that moves one by more
/// than `1e-9·size` means statics cannot tell the actuator's force.
///
/// Errors: [`DynamicsError::ForceSingular`] where the determined part's
/// conditioning is below [`FORCE_SINGULAR`] (a change point), and
/// [`DynamicsError::Undetermined`].
#[allow(clippy::too_many_arguments)]
pub fn min_norm(
    d: &Decomposition,
    b: &[f64],
    skc: usize,
    joints: &[usize],
    undetermined: usize,
    actuated: &[f64],
    size: f64,
    x: &mut [f64],
) -> Result<Solved, DynamicsError> {
    let n = d.n;
    let s = d.singular_values;
    let smax = s.iter().fold(0.0f64, |a, &v| a.max(v));
    let conditioning = conditioning_of(s, n.saturating_sub(undetermined));
    if conditioning.is_nan() || conditioning < FORCE_SINGULAR {
        return Err(DynamicsError::ForceSingular {
            skc,
            joints: joints.to_vec(),
            conditioning,
        });
    }
    // The rank: singular values above the overconstraint's zeros.
    let tol = smax * 1e-12 * n as f64;
    let mut rank = 0;
    x[..n].iter_mut().for_each(|v| *v = 0.0);
    for (i, &sv) in s.iter().enumerate() {
        let v_row = |c: usize| d.v_t[c * n + i];
        if sv > tol {
            rank += 1;
            // x += v_i (u_iᵀ b) / σ_i.
            let ub: f64 = (0..n).map(|r| d.u[i * n + r] * b[r]).sum();
            let k = ub / sv;
            for (c, xc) in x[..n].iter_mut().enumerate() {
                *xc += v_row(c) * k;
            }
        } else {
            // Null-space directions must not move an actuator's force.
            for row in actuated.chunks_exact(n) {
                let moved: f64 = (0..n).map(|c| row[c] * v_row(c)).sum();
                if moved.abs() > 1e-9 * size {
                    return Err(DynamicsError::Undetermined { skc });
                }
            }
        }
    }
    Ok(Solved {
        conditioning,
        undetermined: n - rank,
    })
}

/// The most null directions [`reduced_min_norm`] handles on the stack.
pub const MAX_NULL: usize = 12;

/// The most unknowns [`reduced_min_norm`] handles on the stack.
pub const MAX_UNKNOWNS: usize = 127;

/// An SKC's reactions reduced to its cut joints' (the spanning tree of its
/// links carries the rest): every solution of its links' balances is
/// `x = x0 + C y`, with `C` (`n × m`, row-major) fixed by the topology and
/// `x0` by the demands, and the passive joints' rows are `G y = q`.
#[derive(Debug, Clone, Copy)]
pub struct Reduced<'a> {
    /// Unknowns of the whole system.
    pub n: usize,
    /// The cut joints' unknowns.
    pub m: usize,
    /// `C`, row-major.
    pub c: &'a [f64],
    /// `x0`.
    pub x0: &'a [f64],
}

/// The minimum-norm solution `x` of an SKC's system from its reduction
/// `r` and the SVD `g` of `G` (`m × m`, rows past the passive ones zero):
/// the same `x` as [`min_norm`] on the whole system, at the size of its
/// loops. `None` where `G`'s conditioning is `LU_TRUSTED` or below (near a
/// change point, where the caller decomposes the whole system for the
/// exact conditioning) or its null space is too large for the stack.
#[allow(clippy::too_many_arguments)]
pub fn reduced_min_norm(
    g: &Decomposition,
    q: &[f64],
    r: &Reduced,
    skc: usize,
    undetermined: usize,
    actuated: &[f64],
    size: f64,
    x: &mut [f64],
) -> Result<Option<Solved>, DynamicsError> {
    let (n, m) = (r.n, r.m);
    if n > MAX_UNKNOWNS || g.n != m {
        return Ok(None);
    }
    let s = g.singular_values;
    let smax = s.iter().fold(0.0f64, |a, &v| a.max(v));
    let conditioning = conditioning_of(s, m.saturating_sub(undetermined));
    if conditioning.is_nan() || conditioning <= LU_TRUSTED {
        return Ok(None);
    }
    let tol = smax * 1e-12 * m as f64;
    // y_p, the minimum-norm solution of G y = q, and G's null directions.
    let mut y = [0.0f64; MAX_UNKNOWNS];
    let mut null = [[0.0f64; MAX_UNKNOWNS]; MAX_NULL];
    let mut k_null = 0;
    for (i, &sv) in s.iter().enumerate() {
        let v_row = |c: usize| g.v_t[c * m + i];
        if sv > tol {
            let uq: f64 = (0..m).map(|row| g.u[i * m + row] * q[row]).sum();
            for (c, yc) in y[..m].iter_mut().enumerate() {
                *yc += v_row(c) * uq / sv;
            }
        } else {
            if k_null == MAX_NULL {
                return Ok(None);
            }
            // The direction in x: C v.
            for (row, out) in null[k_null][..n].iter_mut().enumerate() {
                *out = (0..m).map(|c| r.c[row * m + c] * v_row(c)).sum();
            }
            k_null += 1;
        }
    }
    // z0 = x0 + C y_p.
    for (row, xr) in x[..n].iter_mut().enumerate() {
        *xr = r.x0[row] + (0..m).map(|c| r.c[row * m + c] * y[c]).sum::<f64>();
    }
    // Orthonormal null directions (Gram–Schmidt): then x − Σ (x·b̂) b̂ is
    // the shortest solution, and an actuator must not read any b̂.
    for i in 0..k_null {
        let (done, rest) = null.split_at_mut(i);
        let b = &mut rest[0][..n];
        for prior in done.iter() {
            let dot: f64 = b.iter().zip(&prior[..n]).map(|(p, q)| p * q).sum();
            b.iter_mut().zip(&prior[..n]).for_each(|(p, q)| *p -= dot * q);
        }
        let norm = b.iter().map(|p| p * p).sum::<f64>().sqrt();
        if norm.is_nan() || norm <= 0.0 {
            return Ok(None);
        }
        b.iter_mut().for_each(|p| *p /= norm);
        let along: f64 = x[..n].iter().zip(b.iter()).map(|(p, q)| p * q).sum();
        x[..n].iter_mut().zip(b.iter()).for_each(|(p, q)| *p -= along * q);
        for a in actuated.chunks_exact(n) {
            let moved: f64 = a.iter().zip(b.iter()).map(|(p, q)| p * q).sum();
            if moved.abs() > 1e-9 * size {
                return Err(DynamicsError::Undetermined { skc });
            }
        }
    }
    Ok(Some(Solved {
        conditioning,
        undetermined: k_null,
    }))
}

/// The residual of one link's balance relative to its largest term: the
/// terms of each component (the demand's, negated, and the reactions'),
/// summed; 0 for a link with no terms.
pub fn relative_residual<const K: usize>(components: &[[f64; K]]) -> f64 {
    let mut largest = 0.0f64;
    let mut worst = 0.0f64;
    for terms in components {
        let sum: f64 = terms.iter().sum();
        worst = worst.max(sum.abs());
        largest = terms.iter().fold(largest, |a, t| a.max(t.abs()));
        if sum.is_nan() {
            return f64::NAN;
        }
    }
    if largest > 0.0 {
        worst / largest
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;

    fn solve(
        a: DMatrix<f64>,
        b: &[f64],
        undetermined: usize,
        actuated: &[f64],
    ) -> Result<(Vec<f64>, Solved), DynamicsError> {
        let n = a.nrows();
        let svd = a.svd(true, true);
        let (u, v_t) = (svd.u.unwrap(), svd.v_t.unwrap());
        let d = Decomposition {
            n,
            singular_values: svd.singular_values.as_slice(),
            u: u.as_slice(),
            v_t: v_t.as_slice(),
        };
        let mut x = vec![0.0; n];
        let s = min_norm(&d, b, 0, &[0, 1], undetermined, actuated, 1.0, &mut x)?;
        Ok((x, s))
    }

    /// A regular system is solved exactly; a rank-deficient one gives the
    /// minimum-norm solution (the pseudo-inverse's), whose undetermined
    /// direction an actuator row may not read.
    #[test]
    fn minimum_norm_solutions() {
        let a = DMatrix::from_row_slice(2, 2, &[2.0, 1.0, 1.0, 3.0]);
        let (x, s) = solve(a, &[3.0, 5.0], 0, &[]).unwrap();
        // 2x + y = 3, x + 3y = 5: x = 4/5, y = 7/5.
        assert!((x[0] - 0.8).abs() < 1e-15 && (x[1] - 1.4).abs() < 1e-15, "{x:?}");
        assert_eq!(s.undetermined, 0);
        // x + y = 2 twice: the minimum-norm solution is (1, 1), one free direction (1, −1).
        let a = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 1.0, 1.0]);
        let (x, s) = solve(a.clone(), &[2.0, 2.0], 1, &[]).unwrap();
        assert!((x[0] - 1.0).abs() < 1e-15 && (x[1] - 1.0).abs() < 1e-15, "{x:?}");
        assert_eq!(s.undetermined, 1);
        assert_eq!(s.conditioning, 1.0);
        // An actuator reading x + y is blind to (1, −1); one reading x is not.
        assert!(solve(a.clone(), &[2.0, 2.0], 1, &[1.0, 1.0]).is_ok());
        assert_eq!(
            solve(a, &[2.0, 2.0], 1, &[1.0, 0.0]).unwrap_err(),
            DynamicsError::Undetermined { skc: 0 }
        );
    }

    /// A matrix losing rank beyond what the topology leaves free is a
    /// change point: an error with its conditioning.
    #[test]
    fn singular_beyond_the_overconstraint() {
        let a = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 1.0, 1.0 + 1e-12]);
        match solve(a, &[1.0, 1.0], 0, &[]) {
            Err(DynamicsError::ForceSingular { conditioning, .. }) => assert!(conditioning < 1e-11, "{conditioning}"),
            other => panic!("{other:?}"),
        }
    }

    /// The reduced solve finds the whole system's minimum-norm solution:
    /// x = (x1, x2, y) with x1 = 1 − y, x2 = 2 + y (two links' balances
    /// carried by a tree) and no passive row, so y is free. By hand:
    /// d/dy of (1 − y)² + (2 + y)² + y² is 0 at y = −1/3.
    #[test]
    fn reduced_minimum_norm() {
        let g = DMatrix::<f64>::zeros(1, 1);
        let svd = g.svd(true, true);
        let (u, v_t) = (svd.u.unwrap(), svd.v_t.unwrap());
        let d = Decomposition {
            n: 1,
            singular_values: svd.singular_values.as_slice(),
            u: u.as_slice(),
            v_t: v_t.as_slice(),
        };
        let r = Reduced {
            n: 3,
            m: 1,
            c: &[-1.0, 1.0, 1.0],
            x0: &[1.0, 2.0, 0.0],
        };
        let mut x = [0.0; 3];
        let solved = reduced_min_norm(&d, &[0.0], &r, 0, 1, &[], 1.0, &mut x)
            .unwrap()
            .unwrap();
        let y = -1.0 / 3.0;
        for (a, b) in x.iter().zip([1.0 - y, 2.0 + y, y]) {
            assert!((a - b).abs() < 1e-15, "{x:?}");
        }
        assert_eq!(solved.undetermined, 1);
        // An actuator reading x1 + x2 is blind to y; one reading x1 is not.
        assert!(reduced_min_norm(&d, &[0.0], &r, 0, 1, &[1.0, 1.0, 0.0], 1.0, &mut x).is_ok());
        assert!(reduced_min_norm(&d, &[0.0], &r, 0, 1, &[1.0, 0.0, 0.0], 1.0, &mut x).is_err());
    }

    #[test]
    fn pivot_ratios() {
        assert_eq!(pivot_ratio(&[2.0, -0.5, 1.0]), 0.25);
        assert_eq!(pivot_ratio(&[0.0, 0.0]), 0.0);
        assert_eq!(pivot_ratio(&[1.0, f64::NAN]), 0.0);
        assert_eq!(pivot_ratio(&[]), 0.0);
    }

    #[test]
    fn residuals_relative_to_the_largest_term() {
        assert_eq!(relative_residual(&[[1.0, -1.0], [2.0, -2.0]]), 0.0);
        assert_eq!(relative_residual(&[[4.0, -3.0]]), 0.25);
        assert_eq!(relative_residual::<2>(&[]), 0.0);
        assert!(relative_residual(&[[f64::NAN, 1.0]]).is_nan());
    }
}
