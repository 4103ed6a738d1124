//! A rank decision with a certificate, by a Householder QR with column
//! pivoting of a 6×n matrix: the fast path of the wrench analysis's null
//! spaces and of `J`'s rank, which fall back to the SVD where the
//! certificate does not hold.
//!
//! With `A P = Q R` and `R = [[R₁₁, R₁₂], [0, R₂₂]]`, `R₁₁` of size r:
//! - `σ_{r+1}(A) ≤ ‖R₂₂‖₂ ≤ ‖R₂₂‖_F` (`A` minus a rank-r matrix), and
//! - `σ_r(A) ≥ σ_min(R₁₁) ≥ 1/‖R₁₁⁻¹‖_F` (`R₁₁` is a block of `R`, whose
//!   singular values are `A`'s: interlacing).
//!
//! An SVD rule "a singular value counts as zero at most θ" (θ a tolerance
//! times σ_max, or an absolute one) therefore gives rank r when
//! `‖R₂₂‖_F ≤ θ` and `1/‖R₁₁⁻¹‖_F > θ`. [`PivotedQr::rank`] asks for
//! both with a factor [`MARGIN`] to spare on either side (so that the
//! rounding of either factorisation cannot tell them apart), and for
//! `‖R₂₂‖_F ≤ AGREE · σ_min(R₁₁)`, so that the spaces it gives (`Q`'s
//! columns) are the SVD's to `AGREE` (the angle between the two is at most
//! their ratio). Otherwise it answers `None` and the caller takes the SVD.

/// The factor kept between the certificate's bounds and the threshold.
pub(crate) const MARGIN: f64 = 1e3;
/// The largest `‖R₂₂‖_F / σ_min(R₁₁)` (the angle between `Q`'s spaces and
/// the SVD's) the certificate accepts.
pub(crate) const AGREE: f64 = 1e-12;

/// Householder QR with column pivoting of the 6×n matrix whose columns are
/// given (n ≤ N), held on the stack.
pub(crate) struct PivotedQr<const N: usize> {
    /// The columns as they are reduced: column `j < steps` holds `R`'s
    /// column `j` in its first `j + 1` entries; below row `steps`, the
    /// remaining block `R₂₂`.
    a: [[f64; 6]; N],
    /// The unit Householder vectors (`H_k = I − 2 v_k v_kᵀ`, zero above `k`).
    v: [[f64; 6]; 6],
    steps: usize,
    /// `‖R₂₂‖_F²` below row and right of column `k`, for `k ≤ steps`.
    trailing: [f64; 7],
}

fn dot(a: &[f64; 6], b: &[f64; 6], from: usize) -> f64 {
    let mut s = 0.0;
    for i in from..6 {
        s += a[i] * b[i];
    }
    s
}

impl<const N: usize> PivotedQr<N> {
    /// The factorisation of the columns `cols(0..n)` (n ≤ N).
    #[inline]
    pub(crate) fn new(n: usize, cols: impl Fn(usize) -> [f64; 6]) -> Self {
        let n = n.min(N);
        let mut a = [[0.0; 6]; N];
        for (j, col) in a.iter_mut().enumerate().take(n) {
            *col = cols(j);
        }
        let mut v = [[0.0; 6]; 6];
        let mut trailing = [0.0; 7];
        let mut norms = [0.0; N];
        let mut steps = 0;
        for k in 0..n.min(6) {
            // The column with the longest remaining part first.
            let (mut best, mut best_norm, mut total) = (k, -1.0, 0.0);
            for j in k..n {
                let norm = dot(&a[j], &a[j], k);
                norms[j] = norm;
                total += norm;
                if norm > best_norm {
                    (best, best_norm) = (j, norm);
                }
            }
            trailing[k] = total;
            if best_norm.is_nan() || best_norm <= 0.0 {
                // Nothing remains (or it is not finite): R₂₂ is what is left.
                break;
            }
            a.swap(k, best);
            let norm = best_norm.sqrt();
            let alpha = if a[k][k] >= 0.0 { -norm } else { norm };
            let mut h = [0.0; 6];
            // Element by element: a slice copy of a run-time length would
            // call memcpy.
            for (hi, ai) in h.iter_mut().zip(&a[k]).skip(k) {
                *hi = *ai;
            }
            h[k] -= alpha;
            // |h|² = 2 norm (norm + |x_k|).
            let scale = 1.0 / (2.0 * norm * (norm + a[k][k].abs())).sqrt();
            for e in h.iter_mut().skip(k) {
                *e *= scale;
            }
            for col in a[k + 1..n].iter_mut() {
                let d = 2.0 * dot(&h, col, k);
                for i in k..6 {
                    col[i] -= d * h[i];
                }
            }
            a[k][k] = alpha;
            for e in a[k].iter_mut().skip(k + 1) {
                *e = 0.0;
            }
            v[k] = h;
            steps = k + 1;
        }
        // The next step's pivot search summed the others; after the last
        // step nothing remains (no row below the sixth, or no column).
        if steps == n.min(6) {
            trailing[steps] = 0.0;
        }
        PivotedQr { a, v, steps, trailing }
    }

    /// The largest column norm, `|R₀₀|` (a lower bound of σ_max), and the
    /// Frobenius norm `‖A‖_F` (an upper bound).
    pub(crate) fn norm_bounds(&self) -> (f64, f64) {
        if self.steps == 0 {
            return (0.0, self.trailing[0].sqrt());
        }
        (self.a[0][0].abs(), self.trailing[0].sqrt())
    }

    /// `1/‖R₁₁⁻¹‖_F` for the leading r×r block (a lower bound of its least
    /// singular value), 0 if a pivot is zero.
    fn least_bound(&self, r: usize) -> f64 {
        let mut sum = 0.0;
        // Column c of R₁₁⁻¹ by back substitution.
        for c in 0..r {
            let mut x = [0.0; 6];
            x[c] = 1.0 / self.a[c][c];
            sum += x[c] * x[c];
            for i in (0..c).rev() {
                let mut s = 0.0;
                for (j, xj) in x.iter().enumerate().take(c + 1).skip(i + 1) {
                    s += self.a[j][i] * xj;
                }
                x[i] = -s / self.a[i][i];
                sum += x[i] * x[i];
            }
        }
        let bound = 1.0 / sum.sqrt();
        if bound.is_finite() {
            bound
        } else {
            0.0
        }
    }

    /// The rank an SVD would give counting a singular value as zero at or
    /// below θ, for any θ in `[lo, hi]`, where the certificate holds (see
    /// the module's header); `None` where it does not.
    #[inline]
    pub(crate) fn rank(&self, lo: f64, hi: f64) -> Option<usize> {
        let small = lo / MARGIN;
        let r = (0..=self.steps).find(|&r| self.trailing[r] <= small * small)?;
        if r == 0 {
            return Some(0);
        }
        let least = self.least_bound(r);
        let t = self.trailing[r].sqrt();
        (least > MARGIN * hi && t <= AGREE * least).then_some(r)
    }

    /// The factorisation of `cols(0..n)` and its rank under the rule "at
    /// most [`RANK_TOL`](super::RANK_TOL) times the largest singular
    /// value", where certified.
    #[inline]
    pub(crate) fn relative(n: usize, cols: impl Fn(usize) -> [f64; 6]) -> (Self, Option<usize>) {
        let qr = Self::new(n, cols);
        let (lo, hi) = qr.norm_bounds();
        let rank = qr.rank(super::RANK_TOL * lo, super::RANK_TOL * hi);
        (qr, rank)
    }

    /// `Q x`.
    pub(crate) fn q(&self, mut x: [f64; 6]) -> [f64; 6] {
        for k in (0..self.steps).rev() {
            let d = 2.0 * dot(&self.v[k], &x, k);
            for (xi, vi) in x.iter_mut().zip(&self.v[k]).skip(k) {
                *xi -= d * vi;
            }
        }
        x
    }

    /// `Qᵀ x`.
    pub(crate) fn qt(&self, mut x: [f64; 6]) -> [f64; 6] {
        for k in 0..self.steps {
            let d = 2.0 * dot(&self.v[k], &x, k);
            for (xi, vi) in x.iter_mut().zip(&self.v[k]).skip(k) {
                *xi -= d * vi;
            }
        }
        x
    }

    /// `Q`'s column `j`.
    pub(crate) fn column(&self, j: usize) -> [f64; 6] {
        let mut e = [0.0; 6];
        e[j] = 1.0;
        self.q(e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, Matrix6};

    /// The rank and `Q` against nalgebra's SVD and the identity `A P = Q R`,
    /// on matrices of known rank (products of random factors), and one
    /// whose least singular value is at the threshold.
    #[test]
    fn rank_and_spaces_against_the_svd() {
        let mut rng = crate::random::SplitMix::new(7);
        let mut rnd = || rng.symmetric();
        for n in 1..=12usize {
            for rank in 0..=n.min(6) {
                let b = DMatrix::from_fn(6, rank, |_, _| rnd());
                let c = DMatrix::from_fn(rank, n, |_, _| rnd());
                let a = &b * &c;
                let qr = PivotedQr::<12>::new(n, |j| std::array::from_fn(|i| a[(i, j)]));
                let svd = a.clone().svd(false, false);
                let smax = svd.singular_values.max();
                let svd_rank = svd.singular_values.iter().filter(|&&s| s > 1e-9 * smax).count();
                let (lo, hi) = qr.norm_bounds();
                assert!(lo <= smax * (1.0 + 1e-12) && smax <= hi * (1.0 + 1e-12));
                let got = qr.rank(1e-9 * lo, 1e-9 * hi);
                if let Some(r) = got {
                    assert_eq!(r, svd_rank, "n {n} rank {rank}");
                }
                // Generic products are far from the threshold: certified.
                assert_eq!(got, Some(rank), "n {n} rank {rank}");
                // Q orthogonal, its last 6 − r columns orthogonal to A's columns.
                let q = Matrix6::from_fn(|i, j| qr.column(j)[i]);
                assert!((q.transpose() * q - Matrix6::identity()).norm() < 1e-14);
                for j in rank..6 {
                    let qj = q.column(j);
                    for col in 0..n {
                        let d: f64 = (0..6).map(|i| qj[i] * a[(i, col)]).sum();
                        assert!(d.abs() <= 1e-13 * hi, "n {n} rank {rank}: {d}");
                    }
                }
                // Qᵀ then Q is the identity.
                let x = std::array::from_fn(|_| rnd());
                let back = qr.q(qr.qt(x));
                assert!((0..6).all(|i| (back[i] - x[i]).abs() < 1e-14));
            }
        }
        // Near the threshold the certificate declines: a rank-6 matrix whose
        // least singular value is 1e-9 of the largest.
        let u = DMatrix::from_fn(6, 6, |_, _| rnd()).qr().q();
        let v = DMatrix::from_fn(6, 6, |_, _| rnd()).qr().q();
        let s = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![1.0, 0.5, 0.3, 0.2, 0.1, 1e-9]));
        let a = &u * s * v.transpose();
        let qr = PivotedQr::<6>::new(6, |j| std::array::from_fn(|i| a[(i, j)]));
        let (lo, hi) = qr.norm_bounds();
        assert_eq!(qr.rank(1e-9 * lo, 1e-9 * hi), None);
        // The zero matrix has rank 0, the empty one too.
        assert_eq!(PivotedQr::<6>::new(3, |_| [0.0; 6]).rank(0.0, 0.0), Some(0));
        assert_eq!(PivotedQr::<6>::new(0, |_| [0.0; 6]).rank(0.0, 0.0), Some(0));
    }
}
