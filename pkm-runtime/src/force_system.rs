//! One SKC's reaction equations solved from the singular value
//! decomposition of its (padded, square) matrix: the minimum-norm solution,
//! the conditioning of the determined part, and the check that the
//! undetermined part does not move an actuator's force; the SKC's
//! reduction to its cut joints' reactions ([`tree`]), whose passive rows are
//! the transpose of its passive velocity equations and whose conditioning
//! is the kinematic conditioning that decides whether an answer keeps six
//! digits ([`near_change_point`]). Newton–Euler ([`crate::newton_euler`])
//! and the generated inverse dynamics both read it; they differ only in
//! where the matrix lives (heap or stack).

use crate::newton_euler::{DynamicsError, FORCE_SINGULAR};
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim, OMatrix, SMatrix};

/// The relative accuracy an answer of inverse dynamics keeps: 6 significant
/// digits of each force and moment against the largest of its kind.
pub const ACCURACY: f64 = 1e-6;

/// Below this kinematic conditioning c (an SKC's σ_r/σ_1, see [`tree`]) a
/// state with motion keeps fewer than [`ACCURACY`]: next to a change point
/// the position carries ε/c, the rates ε/c², the accelerations and so the
/// forces ε/c³ (docs/dynamics.md), and ε/c³ ≤ 1e-6 needs
/// c ≥ (ε/1e-6)^(1/3) = 6.06e-4.
pub const LEAST_IN_MOTION: f64 = 6.06e-4;

/// The same at rest (every input rate and acceleration zero): the forces
/// carry ε/c², and ε/c² ≤ 1e-6 needs c ≥ (ε/1e-6)^(1/2) = 1.49e-5, 1.5e-5
/// rounded up.
pub const LEAST_AT_REST: f64 = 1.5e-5;

/// The least kinematic conditioning that keeps [`ACCURACY`]: in motion (a
/// rate or an acceleration of an input not zero) or at rest.
#[inline]
pub fn least_conditioning(moving: bool) -> f64 {
    if moving {
        LEAST_IN_MOTION
    } else {
        LEAST_AT_REST
    }
}

/// [`DynamicsError::NearChangePoint`] where SKC `skc` (joints `joints`)
/// has a kinematic conditioning below the least that keeps six digits
/// ([`least_conditioning`]); a conditioning that is not a number counts as 0.
#[inline]
pub fn near_change_point(conditioning: f64, moving: bool, skc: usize, joints: &[usize]) -> Result<(), DynamicsError> {
    let least = least_conditioning(moving);
    if conditioning >= least {
        return Ok(());
    }
    Err(DynamicsError::NearChangePoint {
        skc,
        joints: joints.to_vec(),
        conditioning: if conditioning.is_nan() { 0.0 } else { conditioning },
        least,
        moving,
    })
}

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
    /// A itself, column-major: the solve is refined against it
    /// ([`pseudo_solve`]), so that its answer does not carry the
    /// decomposition's own error.
    pub matrix: &'a [f64],
}

/// How many refinement steps [`pseudo_solve`] takes at most.
const REFINEMENTS: usize = 4;

/// `x = A⁺ b` over the singular values above `tol`, refined against `A`
/// itself: `x ← x + A⁺ (b − A x)` while the residual falls (at most
/// [`REFINEMENTS`] steps). nalgebra's SVD does not always reproduce its
/// matrix to rounding (dimforge/nalgebra#1172): on the 3-UPU's 90 × 90
/// reaction system at one pose `U Σ Vᵀ` is 4.6e-7 of `‖A‖` off `A` (3e-12 a
/// nanometre away), and the forces from it alone were 2.8e-8 off; each
/// step gains that factor over the conditioning, and the answer keeps the
/// digits the matrix allows. `x` and `b` have `d.n` entries.
pub fn pseudo_solve(d: &Decomposition, b: &[f64], tol: f64, x: &mut [f64]) {
    let n = d.n;
    if n <= MAX_UNKNOWNS {
        let (mut r, mut dx) = ([0.0f64; MAX_UNKNOWNS], [0.0f64; MAX_UNKNOWNS]);
        pseudo_solve_in(d, b, tol, x, &mut r[..n], &mut dx[..n]);
    } else {
        let (mut r, mut dx) = (vec![0.0; n], vec![0.0; n]);
        pseudo_solve_in(d, b, tol, x, &mut r, &mut dx);
    }
}

/// [`pseudo_solve`] with its scratch given: `r` and `dx`, `d.n` entries each.
fn pseudo_solve_in(d: &Decomposition, b: &[f64], tol: f64, x: &mut [f64], r: &mut [f64], dx: &mut [f64]) {
    let n = d.n;
    let apply = |b: &[f64], x: &mut [f64]| {
        x[..n].iter_mut().for_each(|v| *v = 0.0);
        for (i, &sv) in d.singular_values.iter().enumerate() {
            if sv > tol {
                // x += v_i (u_iᵀ b) / σ_i.
                let k = (0..n).map(|r| d.u[i * n + r] * b[r]).sum::<f64>() / sv;
                for (c, xc) in x[..n].iter_mut().enumerate() {
                    *xc += d.v_t[c * n + i] * k;
                }
            }
        }
    };
    apply(b, x);
    if d.matrix.len() != n * n {
        return;
    }
    let residual = |x: &[f64], r: &mut [f64]| {
        r.copy_from_slice(&b[..n]);
        for (c, &xc) in x[..n].iter().enumerate() {
            let column = &d.matrix[c * n..(c + 1) * n];
            r.iter_mut().zip(column).for_each(|(ri, a)| *ri -= a * xc);
        }
        r.iter().map(|v| v * v).sum::<f64>()
    };
    let mut last = residual(x, r);
    for _ in 0..REFINEMENTS {
        if last.is_nan() || last <= 0.0 {
            return;
        }
        apply(r, dx);
        x[..n].iter_mut().zip(dx.iter()).for_each(|(x, d)| *x += d);
        let now = residual(x, r);
        if now.is_nan() || now >= last {
            x[..n].iter_mut().zip(dx.iter()).for_each(|(x, d)| *x -= d);
            return;
        }
        last = now;
    }
}

/// Above this bound of the conditioning of a determined SKC's reduced
/// system `G` ([`conditioning_bound`], from its inverse), the system is far
/// from a change point and the solution `G⁻¹ q` stands; at or below it
/// (or without an inverse) the whole system is decomposed by SVD for the
/// exact conditioning and the minimum-norm solve. The same bound gates the
/// minimum-norm solve of an overconstrained SKC's reduction
/// ([`reduced_min_norm`]) on its σ_r/σ_1.
pub const LU_TRUSTED: f64 = 1e-6;

/// The kinematic conditioning of an SKC whose passive rows are
/// independent, from `bound`, a lower bound of their σ_r/σ_1 (rows unit,
/// [`unit_rows`]; 0 where there is none): for a determined SKC the
/// [`conditioning_bound`] of its square `G`, for an overconstrained one
/// the [`triangular_bound`] of its rows' `R` ([`row_space`]). The bound
/// where it is [`LEAST_IN_MOTION`] or more (six digits kept however it
/// moves, no refusal either way), else `exact()`, σ_r/σ_1 from the
/// singular values, which only then are computed. The runtime's
/// Newton–Euler and the generated inverse dynamics both report this.
#[inline]
pub fn conditioning_from_bound(bound: f64, exact: impl FnOnce() -> f64) -> f64 {
    if bound >= LEAST_IN_MOTION {
        bound
    } else {
        exact()
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
#[inline]
pub fn conditioning_of(s: &[f64], rank_expected: usize) -> f64 {
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
/// decomposition, SKC `skc` (joints `joints`, for errors) of `unknowns`
/// reaction components (A's columns past them are zero padding), of which
/// the topology leaves `undetermined` free: A's expected rank is
/// `unknowns − undetermined` (rows past it, as an S–S link's moment about
/// its line, are consistency conditions the right-hand side meets). `actuated` holds one row
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
    unknowns: usize,
    undetermined: usize,
    actuated: &[f64],
    size: f64,
    x: &mut [f64],
) -> Result<Solved, DynamicsError> {
    let n = d.n;
    let s = d.singular_values;
    let smax = s.iter().fold(0.0f64, |a, &v| a.max(v));
    let conditioning = conditioning_of(s, unknowns.min(n).saturating_sub(undetermined));
    if conditioning.is_nan() || conditioning < FORCE_SINGULAR {
        return Err(DynamicsError::ForceSingular {
            skc,
            joints: joints.to_vec(),
            conditioning,
        });
    }
    // The rank: singular values above the overconstraint's zeros.
    let tol = smax * 1e-12 * n as f64;
    pseudo_solve(d, b, tol, x);
    let mut rank = 0;
    for (i, &sv) in s.iter().enumerate() {
        let v_row = |c: usize| d.v_t[c * n + i];
        if sv > tol {
            rank += 1;
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
        undetermined: unknowns.min(n).saturating_sub(rank),
    })
}

/// The most unknowns [`pseudo_solve`] refines on the stack.
pub const MAX_UNKNOWNS: usize = 127;

/// How an SKC's reactions reduce to its cut joints' ([`tree`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Tree {
    /// Per joint (its position in the SKC): for a tree joint, its sign on
    /// its subtree and the subtree's links (their positions in the SKC);
    /// `None` for a cut joint.
    pub tree: Vec<Option<(f64, Vec<usize>)>>,
    /// `C` per joint and cut joint (the cut joints' order): a joint's
    /// reaction is its `x0` plus `Σ C·y` over the cut joints' reactions `y`.
    pub coef: Vec<Vec<f64>>,
    /// The cut joints' positions.
    pub cuts: Vec<usize>,
}

/// The reduction of an SKC's reaction system to its cut joints'
/// reactions: a spanning tree of its links from the links it hangs on,
/// breadth first. `ends` gives each joint's two links as positions in the
/// SKC's `links` links, `links` standing for any link outside the SKC; a
/// tree joint carries the signed sum of its subtree's demands plus the cut
/// joints' reactions that cross into the subtree. `None` where the tree
/// does not reach every link, or where the `passive` rows (one per unit
/// twist of a passive joint) outnumber the cut joints' `d` unknowns each.
///
/// The passive rows acting on the cut joints' reactions (`G = P C`) are
/// then the transpose of the SKC's passive velocity equations with the
/// links it hangs on held: their conditioning is the SKC's kinematic
/// conditioning (0 where two assemblies meet, a change point).
pub fn tree(ends: &[[usize; 2]], links: usize, d: usize, passive: usize) -> Option<Tree> {
    let outside = links;
    let mut parent: Vec<Option<usize>> = vec![None; links];
    let mut reached = vec![false; links + 1];
    reached[outside] = true;
    let mut order = vec![outside];
    let mut tree_joint = vec![false; ends.len()];
    let mut at = 0;
    while at < order.len() {
        let here = order[at];
        at += 1;
        for (i, e) in ends.iter().enumerate() {
            let other = if e[0] == here {
                e[1]
            } else if e[1] == here {
                e[0]
            } else {
                continue;
            };
            if !reached[other] && !tree_joint[i] {
                reached[other] = true;
                parent[other] = Some(i);
                tree_joint[i] = true;
                order.push(other);
            }
        }
    }
    if reached.iter().any(|r| !r) {
        return None;
    }
    let cuts: Vec<usize> = (0..ends.len()).filter(|&i| !tree_joint[i]).collect();
    if passive > cuts.len() * d {
        return None;
    }
    // How joint i acts on node e: +1 on its second link, −1 on its first.
    let sign = |i: usize, e: usize| if ends[i][1] == e { 1.0 } else { -1.0 };
    let mut tree = vec![None; ends.len()];
    let mut coef = vec![vec![0.0; cuts.len()]; ends.len()];
    for (i, &is_tree) in tree_joint.iter().enumerate() {
        if !is_tree {
            if let Some(k) = cuts.iter().position(|&c| c == i) {
                coef[i][k] = 1.0;
            }
            continue;
        }
        // The child end and its subtree.
        let child = if parent.get(ends[i][1]).copied().flatten() == Some(i) {
            ends[i][1]
        } else {
            ends[i][0]
        };
        // A link is in the subtree if the way up from it passes the child.
        let up = |l: usize| parent[l].map(|p| if ends[p][0] == l { ends[p][1] } else { ends[p][0] });
        let subtree: Vec<usize> = (0..links)
            .filter(|&l| {
                let mut at = Some(l);
                while let Some(here) = at.filter(|&h| h < links) {
                    if here == child {
                        return true;
                    }
                    at = up(here);
                }
                false
            })
            .collect();
        let s = sign(i, child);
        // s·x_i = Σ b over the subtree − Σ sign(c, end in it)·x_c over the cuts crossing it.
        for (k, &c) in cuts.iter().enumerate() {
            let inside = ends[c].map(|e| subtree.contains(&e));
            if inside[0] != inside[1] {
                let end = if inside[0] { ends[c][0] } else { ends[c][1] };
                coef[i][k] = -s * sign(c, end);
            }
        }
        tree[i] = Some((s, subtree));
    }
    Some(Tree { tree, coef, cuts })
}

/// `1/(‖G‖_F ‖G⁻¹‖_F)` of a square `G` and its inverse (any layout): a
/// lower bound of σ_m/σ_1 within a factor m (`σ_1 ≤ ‖G‖_F ≤ √m σ_1`, and
/// likewise for `G⁻¹`), found from the inverse where the exact one needs an SVD.
/// A determined SKC whose bound is [`LEAST_IN_MOTION`] or more keeps six
/// digits however it moves: its kinematic conditioning is reported as this
/// bound, in both paths; below it, as σ_m/σ_1.
#[inline]
pub fn conditioning_bound(g: &[f64], inverse: &[f64]) -> f64 {
    let squares = |x: &[f64]| x.iter().map(|v| v * v).sum::<f64>();
    bound_of_squares(squares(g), squares(inverse))
}

/// `1/(‖A‖_F ‖A⁻¹‖_F)` from the two sums of squares; 0 where it is not finite.
#[inline]
fn bound_of_squares(a: f64, inverse: f64) -> f64 {
    let bound = 1.0 / (a.sqrt() * inverse.sqrt());
    if bound.is_finite() {
        bound
    } else {
        0.0
    }
}

/// The [`conditioning_bound`] of an upper triangular `R` (what lies below
/// its diagonal is not read), its inverse by back substitution; 0 where a
/// diagonal entry is 0. `R` of a QR of an SKC's independent passive rows
/// (`G_pᵀ = Q R`, [`row_space`]) has the rows' singular values, so this is
/// a lower bound of their σ_P/σ_1 within a factor P, without them.
#[inline]
pub fn triangular_bound<D: Dim>(r: &OMatrix<f64, D, D>) -> f64
where
    DefaultAllocator: Allocator<D, D>,
{
    let (rows, columns) = r.shape_generic();
    let p = r.nrows();
    // Column j of R⁻¹ solves R z = e_j: z is 0 below j, and from j up
    // z_i = (δ_ij − Σ_{k>i} r_ik z_k) / r_ii.
    let mut inverse = OMatrix::<f64, D, D>::zeros_generic(rows, columns);
    let (mut squares, mut inverse_squares) = (0.0f64, 0.0f64);
    for j in 0..p {
        for i in (0..=j).rev() {
            squares += r[(i, j)] * r[(i, j)];
            let mut z = if i == j { 1.0 } else { 0.0 };
            for k in i + 1..=j {
                z -= r[(i, k)] * inverse[(k, j)];
            }
            let z = z / r[(i, i)];
            inverse[(i, j)] = z;
            inverse_squares += z * z;
        }
    }
    bound_of_squares(squares, inverse_squares)
}

/// Scales each row of the `m × m` matrix `g` (column-major, as nalgebra
/// stores it) to unit length, and the same entry of `rhs` (if it has `m`)
/// by the same factor; a zero row stays zero. The kinematic conditioning
/// is that of the rows as directions, whatever the units of each passive
/// joint's twist (a parallelogram's is per radian of its arm, in lengths),
/// and the solutions of `g y = rhs` do not change.
#[inline]
pub fn unit_rows(g: &mut [f64], m: usize, rhs: &mut [f64]) {
    for r in 0..m {
        let norm = (0..m).map(|c| g[c * m + r] * g[c * m + r]).sum::<f64>().sqrt();
        if norm > 0.0 {
            (0..m).for_each(|c| g[c * m + r] /= norm);
            if let Some(b) = rhs.get_mut(r) {
                *b /= norm;
            }
        }
    }
}

impl Tree {
    /// The number of the cut joints' unknowns, `G`'s size: `d` each.
    pub fn unknowns(&self, d: usize) -> usize {
        self.cuts.len() * d
    }

    /// The entries of `G = P C` for the passive rows, given by the joint
    /// (position in the SKC) each row belongs to: `(row, column,
    /// component, factor)`, `G[row, column] = factor · coefficient[component]`
    /// of that row's `d` coefficients (columns `cut · d + component`).
    pub fn g_entries<'a>(
        &'a self,
        rows: &'a [usize],
        d: usize,
    ) -> impl Iterator<Item = (usize, usize, usize, f64)> + 'a {
        rows.iter().enumerate().flat_map(move |(r, &i)| {
            self.coef[i]
                .iter()
                .enumerate()
                .filter(|(_, f)| **f != 0.0)
                .flat_map(move |(k, &f)| (0..d).map(move |c| (r, k * d + c, c, f)))
        })
    }
}

/// The minimum-norm solution `x` (`N` reaction components) of an SKC's
/// system from its reduction to its cut joints' reactions (the spanning
/// tree of its links carries the rest): every solution of its links'
/// balances is `x = x0 + C y`, `C` (`N × M`) fixed by the topology (given
/// as the product `c(y)`, which the generated code writes out sparse) and
/// `x0` by the demands, and the passive joints' rows are `G y = q`, `g`
/// the SVD of `G` (`M × M`, rows past the passive ones zero). The same `x`
/// as [`min_norm`] on the whole system, at the size of its loops, on the
/// stack: `K` is the most null directions of `G` it keeps (the SKC's
/// undetermined components: where the conditioning passed
/// [`near_change_point`], `G` has no more). `None` where `G`'s conditioning
/// is `LU_TRUSTED` or below (near a change point, where the caller
/// decomposes the whole system for the exact conditioning) or its null
/// space is larger than `K`.
#[allow(clippy::too_many_arguments)]
pub fn reduced_min_norm<const N: usize, const M: usize, const K: usize>(
    g: &Decomposition,
    q: &[f64; M],
    x0: &[f64; N],
    c: impl Fn(&[f64; M]) -> [f64; N],
    skc: usize,
    undetermined: usize,
    actuated: &[f64],
    size: f64,
    x: &mut [f64; N],
) -> Result<Option<Solved>, DynamicsError> {
    if g.n != M {
        return Ok(None);
    }
    let s = g.singular_values;
    let smax = s.iter().fold(0.0f64, |a, &v| a.max(v));
    let conditioning = conditioning_of(s, M.saturating_sub(undetermined));
    if conditioning.is_nan() || conditioning <= LU_TRUSTED {
        return Ok(None);
    }
    let tol = smax * 1e-12 * M as f64;
    // y_p, the minimum-norm solution of G y = q, and G's null directions.
    let mut y = [0.0f64; M];
    let (mut r, mut dy) = ([0.0f64; M], [0.0f64; M]);
    pseudo_solve_in(g, q, tol, &mut y, &mut r, &mut dy);
    let mut null = [[0.0f64; N]; K];
    let mut k_null = 0;
    for (i, &sv) in s.iter().enumerate() {
        if sv > tol {
            continue;
        }
        if k_null == K {
            return Ok(None);
        }
        // The direction in x: C v.
        let v: [f64; M] = std::array::from_fn(|c| g.v_t[c * M + i]);
        null[k_null] = c(&v);
        k_null += 1;
    }
    // z0 = x0 + C y_p.
    *x = c(&y);
    x.iter_mut().zip(x0).for_each(|(x, x0)| *x += x0);
    Ok(
        shortest(x, &mut null[..k_null], actuated, size, skc)?.then_some(Solved {
            conditioning,
            undetermined: k_null,
        }),
    )
}

/// The shortest of the solutions `x + Σ a_i n_i` of an SKC's system, `x`
/// one of them and `null` the null directions of its matrix in `x`'s
/// space, orthonormalised here (Gram–Schmidt): `x − Σ (x·b̂) b̂`. `false`
/// where a direction vanishes (the caller decomposes the whole system);
/// [`DynamicsError::Undetermined`] where an actuator (a row of `actuated`,
/// its power coefficients) reads one.
fn shortest<const N: usize>(
    x: &mut [f64; N],
    null: &mut [[f64; N]],
    actuated: &[f64],
    size: f64,
    skc: usize,
) -> Result<bool, DynamicsError> {
    for i in 0..null.len() {
        let (done, rest) = null.split_at_mut(i);
        let b = &mut rest[0];
        for prior in done.iter() {
            let dot: f64 = b.iter().zip(prior).map(|(p, q)| p * q).sum();
            b.iter_mut().zip(prior).for_each(|(p, q)| *p -= dot * q);
        }
        let norm = b.iter().map(|p| p * p).sum::<f64>().sqrt();
        if norm.is_nan() || norm <= 0.0 {
            return Ok(false);
        }
        b.iter_mut().for_each(|p| *p /= norm);
        let along: f64 = x.iter().zip(b.iter()).map(|(p, q)| p * q).sum();
        x.iter_mut().zip(b.iter()).for_each(|(p, q)| *p -= along * q);
        for a in actuated.chunks_exact(N) {
            let moved: f64 = a.iter().zip(b.iter()).map(|(p, q)| p * q).sum();
            if moved.abs() > 1e-9 * size {
                return Err(DynamicsError::Undetermined { skc });
            }
        }
    }
    Ok(true)
}

/// The rows of an SKC's reduced matrix `G` that are not zero, its `P`
/// passive rows (`M` numbers each, `P ≤ M`), as `G_pᵀ = Q R` by Householder
/// reflections: `Q` (`M × M`, orthogonal, [`Reflections`]), whose first
/// `P` columns span the rows and whose others span `G`'s null space, and
/// `R` (`P × P`, upper triangular), whose singular values are `G`'s
/// nonzero ones. A zero column leaves its reflection out (and `R` singular).
pub fn row_space<const M: usize, const P: usize>(rows: &[[f64; M]; P]) -> (Reflections<M, P>, SMatrix<f64, P, P>) {
    let mut a = *rows;
    let mut q = Reflections {
        axes: [[0.0f64; M]; P],
        scales: [0.0f64; P],
    };
    for k in 0..P {
        let norm = a[k][k..].iter().map(|v| v * v).sum::<f64>().sqrt();
        let alpha = if a[k][k] > 0.0 { -norm } else { norm };
        let v = &mut q.axes[k];
        v[k..].copy_from_slice(&a[k][k..]);
        v[k] -= alpha;
        let vv = v[k..].iter().map(|x| x * x).sum::<f64>();
        if vv.is_nan() || vv <= 0.0 {
            continue;
        }
        let scale = 2.0 / vv;
        q.scales[k] = scale;
        // a_j ← a_j − 2 v (v·a_j)/(v·v) for the columns from k on.
        for column in a[k..].iter_mut() {
            let f = scale * (k..M).map(|i| v[i] * column[i]).sum::<f64>();
            (k..M).for_each(|i| column[i] -= f * v[i]);
        }
    }
    let r = SMatrix::<f64, P, P>::from_fn(|i, j| if i <= j { a[j][i] } else { 0.0 });
    (q, r)
}

/// `Q = H_0 H_1 ⋯ H_{P−1}` of [`row_space`], kept as its reflections:
/// `Q x` costs `P` of them, where forming `Q` costs `M`.
#[derive(Debug, Clone, Copy)]
pub struct Reflections<const M: usize, const P: usize> {
    /// Per reflection `k`, its axis `v` (zero before `k`).
    axes: [[f64; M]; P],
    /// Per reflection, `2/(v·v)`; 0 for one left out.
    scales: [f64; P],
}

impl<const M: usize, const P: usize> Reflections<M, P> {
    /// `x ← Q x`: the last reflection first.
    pub fn apply(&self, x: &mut [f64; M]) {
        self.apply_together::<0>(x, &mut []);
    }

    /// Column `j` of `Q`.
    pub fn column(&self, j: usize) -> [f64; M] {
        let mut e = [0.0f64; M];
        e[j] = 1.0;
        self.apply(&mut e);
        e
    }

    /// `x ← Q x` and each of `more` likewise ([`apply`] is this with no
    /// `more`): the vectors go through each reflection together, so that
    /// their dot products are independent chains, not one after another.
    ///
    /// [`apply`]: Self::apply
    pub fn apply_together<const V: usize>(&self, x: &mut [f64; M], more: &mut [[f64; M]; V]) {
        for k in (0..P).rev() {
            let (v, scale) = (&self.axes[k], self.scales[k]);
            if scale == 0.0 {
                continue;
            }
            let (mut f, mut g) = (0.0f64, [0.0f64; V]);
            for i in k..M {
                f += v[i] * x[i];
                g.iter_mut().zip(more.iter()).for_each(|(g, y)| *g += v[i] * y[i]);
            }
            let f = scale * f;
            g.iter_mut().for_each(|g| *g *= scale);
            for i in k..M {
                x[i] -= f * v[i];
                g.iter().zip(more.iter_mut()).for_each(|(g, y)| y[i] -= g * v[i]);
            }
        }
    }
}

/// [`reduced_min_norm`] where `G`'s `P` passive rows have full rank (the
/// SKC leaves `M − P = K` components undetermined), from their
/// [`row_space`] `(q, r)` and the kinematic conditioning σ_P/σ_1 of `r`:
/// `y_p = Q₁ R⁻ᵀ q` (`Q₁` the first `P` columns), the null directions
/// `C` times `Q`'s others. The same `x` and checks as [`reduced_min_norm`],
/// without a decomposition of the whole `G`, and without leaving `y`'s
/// space until the end: `ct` is `Cᵀ` and `gram` is `CᵀC` (both fixed by
/// the topology, written out sparse by the generated code), so that the
/// null directions are orthonormalised in `x`'s metric on `M` numbers
/// ([`shortest_in_loops`]) and `x = x0 + C y` is formed once. `None` where
/// the conditioning is `LU_TRUSTED` or below.
#[allow(clippy::too_many_arguments)]
pub fn reduced_min_norm_qr<const N: usize, const M: usize, const P: usize, const K: usize>(
    basis: &Reflections<M, P>,
    r: &SMatrix<f64, P, P>,
    conditioning: f64,
    q: &[f64; M],
    x0: &[f64; N],
    c: impl Fn(&[f64; M]) -> [f64; N],
    ct: impl Fn(&[f64; N]) -> [f64; M],
    gram: impl Fn(&[f64; M]) -> [f64; M],
    skc: usize,
    actuated: &[f64],
    size: f64,
    x: &mut [f64; N],
) -> Result<Option<Solved>, DynamicsError> {
    if P + K != M || conditioning.is_nan() || conditioning <= LU_TRUSTED {
        return Ok(None);
    }
    // Rᵀ z = q_p, forward.
    let mut z = [0.0f64; P];
    for i in 0..P {
        let known: f64 = (0..i).map(|k| r[(k, i)] * z[k]).sum();
        z[i] = (q[i] - known) / r[(i, i)];
    }
    // y = Q₁ z = Q (z, 0), and the null directions Q e_{P+i}, together.
    let mut y = [0.0f64; M];
    y[..P].copy_from_slice(&z);
    let mut null: [[f64; M]; K] = std::array::from_fn(|i| {
        let mut e = [0.0f64; M];
        e[P + i] = 1.0;
        e
    });
    basis.apply_together(&mut y, &mut null);
    if !shortest_in_loops(&mut y, x0, null, &ct, &gram, actuated, size, skc)? {
        return Ok(None);
    }
    *x = c(&y);
    x.iter_mut().zip(x0).for_each(|(x, x0)| *x += x0);
    Ok(Some(Solved {
        conditioning,
        undetermined: K,
    }))
}

/// [`shortest`] of the solutions `x0 + C (y + Σ a_i u_i)`, in `y`'s space:
/// the null directions `C u_i` are orthonormalised (Gram–Schmidt) in the
/// inner product `⟨u, v⟩ = (C u)·(C v) = uᵀ (CᵀC) v` (`gram` is `CᵀC`),
/// `x`'s component along each is read as `Cᵀ(x0 + C y)·u`, and an
/// actuator's (a row `a` of `actuated`) as `(Cᵀ a)·u` (`ct` is `Cᵀ`): the
/// same numbers as on `x`'s `N`, on `M`. `y` comes back the shortest's;
/// `false` where a direction vanishes, [`DynamicsError::Undetermined`]
/// where an actuator reads one, in the same order as [`shortest`].
#[allow(clippy::too_many_arguments)]
fn shortest_in_loops<const N: usize, const M: usize, const K: usize>(
    y: &mut [f64; M],
    x0: &[f64; N],
    mut null: [[f64; M]; K],
    ct: &impl Fn(&[f64; N]) -> [f64; M],
    gram: &impl Fn(&[f64; M]) -> [f64; M],
    actuated: &[f64],
    size: f64,
    skc: usize,
) -> Result<bool, DynamicsError> {
    let dot = |a: &[f64; M], b: &[f64; M]| a.iter().zip(b).map(|(p, q)| p * q).sum::<f64>();
    // Cᵀ x with x = x0 + C y, kept as y moves.
    let mut along_x = ct(x0);
    along_x.iter_mut().zip(gram(y)).for_each(|(g, w)| *g += w);
    // CᵀC of each direction done.
    let mut weighted = [[0.0f64; M]; K];
    for i in 0..K {
        let (done, rest) = null.split_at_mut(i);
        let b = &mut rest[0];
        for (prior, w) in done.iter().zip(&weighted) {
            let along = dot(b, w);
            b.iter_mut().zip(prior).for_each(|(p, q)| *p -= along * q);
        }
        let mut w = gram(b);
        let norm = dot(b, &w).sqrt();
        if norm.is_nan() || norm <= 0.0 {
            return Ok(false);
        }
        b.iter_mut().for_each(|p| *p /= norm);
        w.iter_mut().for_each(|p| *p /= norm);
        let along = dot(&along_x, b);
        y.iter_mut().zip(b.iter()).for_each(|(p, q)| *p -= along * q);
        along_x.iter_mut().zip(&w).for_each(|(p, q)| *p -= along * q);
        for a in actuated.chunks_exact(N) {
            let a: &[f64; N] = a.try_into().expect("N numbers a row");
            if dot(&ct(a), b).abs() > 1e-9 * size {
                return Err(DynamicsError::Undetermined { skc });
            }
        }
        weighted[i] = w;
    }
    Ok(true)
}

/// The residual of one link's balance relative to its largest term: the
/// terms of each component (the demand's, negated, and the reactions'),
/// summed; 0 for a link with no terms.
#[inline]
pub fn relative_residual<C: AsRef<[f64]>>(components: &[C]) -> f64 {
    let mut largest = 0.0f64;
    let mut worst = 0.0f64;
    // No term is NaN past the sum's check: plain comparisons serve as max.
    let larger = |a: f64, b: f64| if b > a { b } else { a };
    for terms in components {
        let terms = terms.as_ref();
        let sum: f64 = terms.iter().sum();
        if sum.is_nan() {
            return f64::NAN;
        }
        worst = larger(worst, sum.abs());
        largest = terms.iter().fold(largest, |a, t| larger(a, t.abs()));
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
        let svd = a.clone().svd(true, true);
        let (u, v_t) = (svd.u.unwrap(), svd.v_t.unwrap());
        let d = Decomposition {
            n,
            singular_values: svd.singular_values.as_slice(),
            u: u.as_slice(),
            v_t: v_t.as_slice(),
            matrix: a.as_slice(),
        };
        let mut x = vec![0.0; n];
        let s = min_norm(&d, b, 0, &[0, 1], n, undetermined, actuated, 1.0, &mut x)?;
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

    /// A decomposition 1e-6 off its matrix (that of A + E, as nalgebra's
    /// SVD can be off A) still gives A's own solution to rounding once
    /// refined against A: 2x + y = 3, x + 3y = 5 by hand, x = 4/5, y = 7/5;
    /// unrefined (no matrix given) it is about 1e-6 off.
    #[test]
    fn a_decomposition_off_its_matrix_is_refined_against_it() {
        let a = DMatrix::from_row_slice(2, 2, &[2.0, 1.0, 1.0, 3.0]);
        let off = DMatrix::from_row_slice(2, 2, &[2.0 + 1e-6, 1.0, 1.0 - 1e-6, 3.0]);
        let svd = off.svd(true, true);
        let (u, v_t) = (svd.u.unwrap(), svd.v_t.unwrap());
        let solve = |matrix: &[f64]| {
            let d = Decomposition {
                n: 2,
                singular_values: svd.singular_values.as_slice(),
                u: u.as_slice(),
                v_t: v_t.as_slice(),
                matrix,
            };
            let mut x = [0.0; 2];
            pseudo_solve(&d, &[3.0, 5.0], 1e-12, &mut x);
            (x[0] - 0.8).abs().max((x[1] - 1.4).abs())
        };
        assert!(solve(&[]) > 1e-7, "{}", solve(&[]));
        assert!(solve(a.as_slice()) < 1e-15, "{}", solve(a.as_slice()));
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
        let svd = g.clone().svd(true, true);
        let (u, v_t) = (svd.u.unwrap(), svd.v_t.unwrap());
        let d = Decomposition {
            n: 1,
            singular_values: svd.singular_values.as_slice(),
            u: u.as_slice(),
            v_t: v_t.as_slice(),
            matrix: g.as_slice(),
        };
        let c = |y: &[f64; 1]| [-y[0], y[0], y[0]];
        let x0 = [1.0, 2.0, 0.0];
        let mut x = [0.0; 3];
        let solved = reduced_min_norm::<3, 1, 1>(&d, &[0.0], &x0, c, 0, 1, &[], 1.0, &mut x)
            .unwrap()
            .unwrap();
        let y = -1.0 / 3.0;
        for (a, b) in x.iter().zip([1.0 - y, 2.0 + y, y]) {
            assert!((a - b).abs() < 1e-15, "{x:?}");
        }
        assert_eq!(solved.undetermined, 1);
        // An actuator reading x1 + x2 is blind to y; one reading x1 is not.
        assert!(reduced_min_norm::<3, 1, 1>(&d, &[0.0], &x0, c, 0, 1, &[1.0, 1.0, 0.0], 1.0, &mut x).is_ok());
        assert!(reduced_min_norm::<3, 1, 1>(&d, &[0.0], &x0, c, 0, 1, &[1.0, 0.0, 0.0], 1.0, &mut x).is_err());
        // The same from the row space of G's passive rows (none): Cᵀ and CᵀC by hand.
        let ct = |x: &[f64; 3]| [x[1] + x[2] - x[0]];
        let gram = |y: &[f64; 1]| [3.0 * y[0]];
        let (basis, r) = row_space::<1, 0>(&[]);
        let mut x = [0.0; 3];
        let solved = reduced_min_norm_qr::<3, 1, 0, 1>(&basis, &r, 1.0, &[0.0], &x0, c, ct, gram, 0, &[], 1.0, &mut x)
            .unwrap()
            .unwrap();
        for (a, b) in x.iter().zip([1.0 - y, 2.0 + y, y]) {
            assert!((a - b).abs() < 1e-15, "{x:?}");
        }
        assert_eq!(solved.undetermined, 1);
        assert!(reduced_min_norm_qr::<3, 1, 0, 1>(
            &basis,
            &r,
            1.0,
            &[0.0],
            &x0,
            c,
            ct,
            gram,
            0,
            &[1.0, 0.0, 0.0],
            1.0,
            &mut x
        )
        .is_err());
    }

    /// One passive row (3, 4) of two unknowns: by hand, |R| = 5, Q's first
    /// column ±(0.6, 0.8), its second ±(−0.8, 0.6) (the row's null space).
    /// With a second unknown in x = y (C = I) and y's right-hand side 10:
    /// the shortest y on 3a + 4b = 10 is (1.2, 1.6).
    #[test]
    fn a_row_space_by_householder() {
        let (reflections, r) = row_space::<2, 1>(&[[3.0, 4.0]]);
        let q = [reflections.column(0), reflections.column(1)];
        assert!((r[(0, 0)].abs() - 5.0).abs() < 1e-15, "{r}");
        let s = q[0][0].signum();
        assert!(
            (q[0][0] - 0.6 * s).abs() < 1e-15 && (q[0][1] - 0.8 * s).abs() < 1e-15,
            "{q:?}"
        );
        let t = q[1][1].signum();
        assert!(
            (q[1][0] + 0.8 * t).abs() < 1e-15 && (q[1][1] - 0.6 * t).abs() < 1e-15,
            "{q:?}"
        );
        let mut x = [0.0; 2];
        let solved = reduced_min_norm_qr::<2, 2, 1, 1>(
            &reflections,
            &r,
            1.0,
            &[10.0, 0.0],
            &[0.0; 2],
            |y| *y,
            |x| *x,
            |y| *y,
            0,
            &[],
            1.0,
            &mut x,
        )
        .unwrap()
        .unwrap();
        assert!((x[0] - 1.2).abs() < 1e-14 && (x[1] - 1.6).abs() < 1e-14, "{x:?}");
        assert_eq!(solved.undetermined, 1);
    }

    /// The least conditionings are the error model's: ε/c³ = 1e-6 in
    /// motion, ε/c² = 1e-6 at rest (rounded up).
    #[test]
    fn least_conditionings_keep_six_digits() {
        let (motion, rest) = ((f64::EPSILON / ACCURACY).cbrt(), (f64::EPSILON / ACCURACY).sqrt());
        assert!(LEAST_IN_MOTION >= motion && LEAST_IN_MOTION < 1.01 * motion, "{motion}");
        assert!(LEAST_AT_REST >= rest && LEAST_AT_REST < 1.01 * rest, "{rest}");
        assert!(near_change_point(LEAST_AT_REST, false, 0, &[]).is_ok());
        assert!(near_change_point(LEAST_AT_REST, true, 0, &[]).is_err());
        match near_change_point(f64::NAN, true, 2, &[6, 7, 8]) {
            Err(DynamicsError::NearChangePoint {
                skc: 2,
                conditioning,
                least,
                moving: true,
                ..
            }) => assert!(conditioning == 0.0 && least == LEAST_IN_MOTION),
            other => panic!("{other:?}"),
        }
    }

    /// A four-bar's SKC (links 0, 1, 2 in a row, joints A base–0, B 0–1,
    /// C 1–2, D 2–base; 3 stands for the base): the tree from the base
    /// takes A, D, then B, and cuts C. By hand, from the links' balances
    /// (a reaction acts + on its second link, − on its first): link 1
    /// gives x_B − x_C = b₁, so x_B = b₁ + x_C; links 0 and 1 give
    /// x_A = b₀ + b₁ + x_C; link 2 gives x_C − x_D = b₂, so x_D = x_C − b₂.
    #[test]
    fn a_four_bar_reduces_to_its_cut_joint() {
        let ends = [[3, 0], [0, 1], [1, 2], [2, 3]];
        let t = tree(&ends, 3, 3, 3).unwrap();
        assert_eq!(t.cuts, [2]);
        assert_eq!(t.coef, [[1.0], [1.0], [1.0], [1.0]]);
        assert_eq!(
            t.tree,
            [
                Some((1.0, vec![0, 1])),
                Some((1.0, vec![1])),
                None,
                Some((-1.0, vec![2]))
            ]
        );
        // The passive rows of B, C and D (a planar reaction: 3 numbers)
        // each read the cut's reaction once.
        let entries: Vec<_> = t.g_entries(&[1, 2, 3], 3).collect();
        let by_hand: Vec<_> = (0..3).flat_map(|r| (0..3).map(move |c| (r, c, c, 1.0))).collect();
        assert_eq!(entries, by_hand);
        // More passive rows than the cut's unknowns: no reduction.
        assert!(tree(&ends, 3, 3, 4).is_none());
        // A link the tree does not reach: none either.
        assert!(tree(&[[3, 0], [0, 0]], 2, 1, 0).is_none());
    }

    #[test]
    fn unit_rows_keep_the_solutions() {
        // [[3, 4], [0, 2]] column-major, right-hand side (5, 2).
        let mut g = [3.0, 0.0, 4.0, 2.0];
        let mut rhs = [5.0, 2.0];
        unit_rows(&mut g, 2, &mut rhs);
        assert_eq!(g, [0.6, 0.0, 0.8, 1.0]);
        assert_eq!(rhs, [1.0, 1.0]);
        let mut zero = [0.0; 4];
        unit_rows(&mut zero, 2, &mut []);
        assert_eq!(zero, [0.0; 4]);
    }

    /// diag(2, 1): σ_2/σ_1 = 1/2; the bound 1/(√5 · √(5/4)) = 2/5.
    #[test]
    fn a_bound_of_the_conditioning() {
        let bound = conditioning_bound(&[2.0, 0.0, 0.0, 1.0], &[0.5, 0.0, 0.0, 1.0]);
        assert!((bound - 0.4).abs() < 1e-15, "{bound}");
        assert_eq!(conditioning_bound(&[1.0], &[f64::INFINITY]), 0.0);
    }

    /// R = [[1, 1], [0, 1]]: ‖R‖_F = √3, R⁻¹ = [[1, −1], [0, 1]], ‖R⁻¹‖_F
    /// = √3, the bound 1/3, below σ_2/σ_1 = (3 − √5)/2 (σ_1σ_2 = 1, σ_1² +
    /// σ_2² = 3); what lies below the diagonal is not read; a zero on the
    /// diagonal gives 0.
    #[test]
    fn a_bound_from_a_triangular_factor() {
        let r = nalgebra::Matrix2::new(1.0, 1.0, 7.0, 1.0);
        let bound = triangular_bound(&r);
        assert!((bound - 1.0 / 3.0).abs() < 1e-15, "{bound}");
        assert!(bound <= (3.0 - 5f64.sqrt()) / 2.0);
        assert_eq!(triangular_bound(&nalgebra::Matrix2::new(1.0, 1.0, 0.0, 0.0)), 0.0);
        let dynamic = nalgebra::DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 0.0, 1.0]);
        assert!((triangular_bound(&dynamic) - 1.0 / 3.0).abs() < 1e-15);
    }

    #[test]
    fn residuals_relative_to_the_largest_term() {
        assert_eq!(relative_residual(&[[1.0, -1.0], [2.0, -2.0]]), 0.0);
        assert_eq!(relative_residual(&[[4.0, -3.0]]), 0.25);
        assert_eq!(relative_residual::<[f64; 2]>(&[]), 0.0);
        assert!(relative_residual(&[[f64::NAN, 1.0]]).is_nan());
    }
}
