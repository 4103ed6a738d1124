//! Verifying a solution, and naming the given value that contradicts it.
//!
//! A plan closes the joints its steps solve by construction. Every other
//! joint (a loop the plan never needed) and every given point the plan
//! placed and later moved is checked after the last step: its *residual*
//! (how far the two sides of the joint are apart, in lengths; rotations
//! times the solution's extent) must vanish to [`VERIFY_TOL`] of that
//! extent. When it does not, the given values over-determine the mechanism
//! and disagree (a pose with a translation the platform's POC set does not
//! have, for example), and [`nearest`] finds, by a Gauss–Newton projection
//! along the same plan, the nearest given values that are consistent: the
//! value that moved most is the one [`SolveError::Inconsistent`] names.
//!
//! Double roots: where a step's two roots coincide (tangency) the two
//! branches that differ only in that step's sign are one solution;
//! [`mark_double_roots`] keeps the first and turns the second into
//! [`SolveError::DoubleRoot`], naming its twin.

use crate::primitives::TANGENCY_TOL;
pub use crate::solution::Contradicted;
use crate::solution::{wrap_angle, Branch, SolveError};
use nalgebra::{DMatrix, DVector};
use std::borrow::Cow;

/// A solution is verified when every residual is at most `VERIFY_TOL`
/// times its extent (the largest coordinate of a joint point, at least 1).
/// A tenth of [`TANGENCY_TOL`]: a verified answer reproduces its given
/// values to 1e-9 of the extent even where the mechanism amplifies a
/// residual several times; a step clamped at a double root within the
/// tangency tolerance still verifies where its excess is rounding, as it
/// is at a true tangency.
pub const VERIFY_TOL: f64 = 0.1 * TANGENCY_TOL;

/// How many Gauss–Newton steps [`nearest`] takes at most.
pub const NEAREST_ITERATIONS: usize = 40;

/// The extent of a solution: the largest coordinate magnitude of its
/// points, at least 1 (the scale residuals are measured against).
pub fn extent<const N: usize>(points: &[[f64; N]]) -> f64 {
    // A fold of f64::max, which LLVM vectorises across the batch lanes: a
    // loop of selects here made the 10⁶-sample sweep 4.5× slower.
    points
        .iter()
        .flat_map(|p| p.iter())
        .map(|c| c.abs())
        .filter(|c| c.is_finite())
        .fold(1.0, f64::max)
}

/// Whether every residual component is within [`VERIFY_TOL`]` · extent`
/// (NaN is not): the fast path before [`worst`].
#[inline]
pub fn within(residual: &[f64], extent: f64) -> bool {
    let tol = VERIFY_TOL * extent;
    residual.iter().all(|r| r.abs() <= tol)
}

/// [`worst`] behind the fast path [`within`]: what generated solvers check.
#[inline]
pub fn beyond(residual: &[f64], extent: f64) -> Option<(usize, f64)> {
    if within(residual, extent) {
        None
    } else {
        worst(residual, extent)
    }
}

/// The largest residual component, if it exceeds [`VERIFY_TOL`]` · extent`
/// (or is not finite): its index and magnitude.
pub fn worst(residual: &[f64], extent: f64) -> Option<(usize, f64)> {
    let tol = VERIFY_TOL * extent;
    let mut bad: Option<(usize, f64)> = None;
    for (i, r) in residual.iter().enumerate() {
        let m = if r.is_finite() { r.abs() } else { f64::INFINITY };
        if m > tol && bad.is_none_or(|(_, b)| m > b) {
            bad = Some((i, m));
        }
    }
    bad
}

/// The given values nearest to `given` that the solver solves with a
/// vanishing residual, `residual` being the solver's residual as a
/// function of the given values. First each value alone is moved (a given
/// value the mechanism does not free, such as a translation its POC set
/// lacks, is found this way, and named cleanly) and the smallest such move
/// wins; failing that, all move together: Gauss–Newton with minimum-norm
/// steps (SVD). Jacobians by central differences (this is the failure
/// path, not a hot one). Angles (`angular`) are weighed as arcs of radius
/// `extent`. `None` if no projection reaches a residual within tolerance.
pub fn nearest(
    given: &[f64],
    angular: &[bool],
    extent: f64,
    mut residual: impl FnMut(&[f64]) -> Option<Vec<f64>>,
) -> Option<Vec<f64>> {
    // Angles projected from their value in (−π, π] (`wrap_angle`: reduced
    // by the exact π), the turns given added back after: an unreduced
    // angle (1e11 rad) would swallow the difference steps (its ulp is 1.5e-5).
    let reduced: Vec<f64> = given
        .iter()
        .enumerate()
        .map(|(i, &x)| {
            if angular.get(i).copied().unwrap_or(false) {
                wrap_angle(x)
            } else {
                x
            }
        })
        .collect();
    let turns = |x: Vec<f64>| -> Vec<f64> {
        x.iter()
            .zip(given)
            .zip(&reduced)
            .map(|((x, g), r)| g + (x - r))
            .collect()
    };
    nearest_reduced(&reduced, angular, extent, &mut residual).map(turns)
}

/// [`nearest`] from given values whose angles are in (−π, π].
fn nearest_reduced(
    given: &[f64],
    angular: &[bool],
    extent: f64,
    mut residual: impl FnMut(&[f64]) -> Option<Vec<f64>>,
) -> Option<Vec<f64>> {
    let n = given.len();
    let weight: Vec<f64> = (0..n)
        .map(|i| {
            if angular.get(i).copied().unwrap_or(false) {
                extent
            } else {
                1.0
            }
        })
        .collect();
    let alone = (0..n)
        .filter_map(|i| project(given, &weight, extent, &[i], &mut residual))
        .min_by(|a, b| moved(given, a, &weight).total_cmp(&moved(given, b, &weight)));
    alone.or_else(|| project(given, &weight, extent, &(0..n).collect::<Vec<_>>(), &mut residual))
}

/// The weighed distance between two vectors of given values.
fn moved(given: &[f64], x: &[f64], weight: &[f64]) -> f64 {
    given
        .iter()
        .zip(x)
        .zip(weight)
        .map(|((g, x), w)| ((x - g) * w).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// Gauss–Newton from `given` moving only the values `free`, in scaled
/// coordinates `s_i = w_i·x_i`, with a trust region.
fn project(
    given: &[f64],
    weight: &[f64],
    extent: f64,
    free: &[usize],
    residual: &mut impl FnMut(&[f64]) -> Option<Vec<f64>>,
) -> Option<Vec<f64>> {
    let norm = |r: &[f64]| r.iter().map(|x| x * x).sum::<f64>().sqrt();
    let mut x = given.to_vec();
    let mut r = residual(&x)?;
    for _ in 0..NEAREST_ITERATIONS {
        // Polished well past the tolerance, so the nearest value is printed right.
        if worst(&r, 1e-4 * extent).is_none() {
            return Some(x);
        }
        let mut jac = DMatrix::<f64>::zeros(r.len(), free.len());
        for (c, &i) in free.iter().enumerate() {
            let h = 1e-6 * extent / weight[i];
            let (mut xp, mut xm) = (x.clone(), x.clone());
            xp[i] += h;
            xm[i] -= h;
            let (rp, rm) = (residual(&xp)?, residual(&xm)?);
            if rp.len() != r.len() || rm.len() != r.len() {
                return None;
            }
            for k in 0..r.len() {
                jac[(k, c)] = (rp[k] - rm[k]) / (2.0 * h) / weight[i];
            }
        }
        // nalgebra's SVD does not return on a non-finite matrix: a
        // residual that is NaN beside the point ends the projection.
        if jac.iter().chain(&r).any(|v| !v.is_finite()) {
            return None;
        }
        let step = jac
            .svd(true, true)
            .solve(&-DVector::from_column_slice(&r), 1e-12)
            .ok()?;
        // A trust region: no step longer than twice the residual (a given
        // value that moves one of the solution's points one for one needs
        // no more), so the projection stays near the given values.
        let mut t = (2.0 * norm(&r) / step.norm()).min(1.0);
        loop {
            let mut trial = x.clone();
            for (c, &i) in free.iter().enumerate() {
                trial[i] += t * step[c] / weight[i];
            }
            if let Some(rt) = residual(&trial) {
                if norm(&rt) < norm(&r) {
                    x = trial;
                    r = rt;
                    break;
                }
            }
            t /= 2.0;
            if t < 1e-6 {
                return worst(&r, extent).is_none().then_some(x);
            }
        }
    }
    worst(&r, extent).is_none().then_some(x)
}

/// The given value that moved most (angles as arcs of radius `extent`)
/// from `given` to `nearest`, named `#k` (see [`Contradicted::name`]).
pub fn contradicted(given: &[f64], nearest: &[f64], angular: &[bool], extent: f64) -> Option<Contradicted> {
    let moved = |i: usize| {
        let d = nearest[i] - given[i];
        if angular.get(i).copied().unwrap_or(false) {
            wrap_angle(d).abs() * extent
        } else {
            d.abs()
        }
    };
    let index = (0..given.len()).max_by(|&a, &b| moved(a).total_cmp(&moved(b)))?;
    Some(Contradicted {
        index,
        name: Cow::Owned(format!("#{}", index + 1)),
        given: given[index],
        nearest: nearest[index],
    })
}

/// The error of a solution whose residual component `index` (owned by
/// `owner`, e.g. `joint R11`) is `gap`, with the contradicted given value
/// found by [`nearest`] where the projection succeeds.
pub fn inconsistent(
    owner: Cow<'static, str>,
    gap: f64,
    given: &[f64],
    angular: &[bool],
    extent: f64,
    residual: impl FnMut(&[f64]) -> Option<Vec<f64>>,
) -> SolveError {
    let contradicted = nearest(given, angular, extent, residual).and_then(|n| contradicted(given, &n, angular, extent));
    SolveError::Inconsistent {
        owner,
        gap,
        // Boxed: the failure path's detail, kept out of every result's size.
        contradicted: contradicted.map(Box::new),
    }
}

/// Verifies a solution by its residual rows (`owners[i]` names what row
/// `i` measures, e.g. `joint R3`): Ok when every row is within tolerance of
/// `extent`; otherwise the error names the given value the others
/// contradict, found through `rerun` (the same branch's rows at other given
/// values) and named from `names`.
pub fn verify_rows(
    rows: &[f64],
    extent: f64,
    owners: &[&str],
    given: &[f64],
    angular: &[bool],
    names: &[&str],
    rerun: impl FnMut(&[f64]) -> Option<Vec<f64>>,
) -> Result<(), SolveError> {
    let Some((row, gap)) = worst(rows, extent) else {
        return Ok(());
    };
    let owner = Cow::Owned(
        owners
            .get(row)
            .map_or_else(|| format!("row {row}"), |o| (*o).to_string()),
    );
    Err(name_given(
        inconsistent(owner, gap, given, angular, extent, rerun),
        names,
    ))
}

/// Names the contradicted value of an [`SolveError::Inconsistent`] from
/// `names` (the given values' names in order); other errors pass unchanged.
pub fn name_given(mut e: SolveError, names: &[&str]) -> SolveError {
    if let SolveError::Inconsistent {
        contradicted: Some(c), ..
    } = &mut e
    {
        if let Some(n) = names.get(c.index) {
            c.name = Cow::Owned((*n).to_string());
        }
    }
    e
}

/// Two solutions are one when their joint values (angles modulo 2π) agree
/// to [`VERIFY_TOL`] of the larger length among them (at least 1): the
/// lengths alone set the scale, never an angle, which a given input may
/// carry unreduced (1e11 rad is an angle of the mechanism like any other,
/// and would make every pair of branches "one").
#[inline]
pub fn same_solution(a: &[f64], b: &[f64], revolute: &[bool]) -> bool {
    same_within(
        a,
        b,
        revolute,
        VERIFY_TOL * magnitude(a, revolute).max(magnitude(b, revolute)),
    )
}

/// The largest magnitude of the lengths of `v` (the entries `revolute`
/// does not mark), at least 1 (NaN compares false).
#[inline]
fn magnitude(v: &[f64], revolute: &[bool]) -> f64 {
    let mut m = 1.0f64;
    for (x, r) in v.iter().zip(revolute) {
        if !r && x.abs() > m {
            m = x.abs();
        }
    }
    m
}

/// Whether every value of `a` is within `tol` of `b`'s (angles modulo 2π).
#[inline]
fn same_within(a: &[f64], b: &[f64], revolute: &[bool], tol: f64) -> bool {
    a.iter().zip(b).zip(revolute).all(|((x, y), &r)| {
        // S joints have no single value (NaN on both sides).
        if x.is_nan() && y.is_nan() {
            return true;
        }
        let d = if r { wrap_angle(x - y) } else { x - y };
        d.abs() <= tol
    })
}

/// The earliest branch before `i` whose solution branch `i` repeats (by
/// [`same_solution`]); `solution(k)` is branch `k`'s joint values, if it
/// solved, and `size(k, values)` their [`magnitude`] (which a caller may
/// keep rather than measure again for every pair).
#[inline]
fn twin_of<'a>(
    i: usize,
    revolute: &[bool],
    solution: impl Fn(usize) -> Option<&'a [f64]>,
    size: impl Fn(usize, &[f64]) -> f64,
) -> Option<usize> {
    let s = solution(i)?;
    (0..i).find(|&k| solution(k).is_some_and(|t| same_within(s, t, revolute, VERIFY_TOL * size(i, s).max(size(k, t)))))
}

/// Marks double roots in a list of branches: a branch whose solution is one
/// an earlier branch already has ([`same_solution`]) becomes
/// [`SolveError::DoubleRoot`] naming that twin, which is flagged `tangent`.
/// No allocation: generated `fk` and `ik` call this on every call, so each
/// solution's magnitude is measured once, on the stack (`N` of them).
pub fn mark_double_roots<S, const D: usize, const N: usize>(
    branches: &mut [Branch<S, D>; N],
    revolute: &[bool],
    values: impl Fn(&S) -> &[f64],
) {
    let size: [f64; N] = core::array::from_fn(|k| {
        branches[k]
            .result
            .as_ref()
            .map_or(0.0, |s| magnitude(values(s), revolute))
    });
    for i in 1..N {
        let all = &*branches;
        if let Some(k) = twin_of(
            i,
            revolute,
            |k| all[k].result.as_ref().ok().map(&values),
            |k, _| size[k],
        ) {
            branches[i].result = Err(SolveError::DoubleRoot { twin: k });
            branches[k].tangent = true;
        }
    }
}

/// [`mark_double_roots`] where the branches are told apart by `keys[i]`
/// (branch `i`'s [`crate::steps::choice_values`]: what its ± choices
/// solved) instead of their results: generated solvers that return the
/// outputs (or the actuators' values) alone, which two assemblies may
/// share. Keys are compared as [`same_solution`] compares lengths.
pub fn mark_double_roots_by<S, const D: usize, const N: usize, const K: usize>(
    branches: &mut [Branch<S, D>; N],
    keys: &[[f64; K]; N],
) {
    let plain = [false; K];
    let size: [f64; N] = core::array::from_fn(|k| magnitude(&keys[k], &plain));
    for i in 1..N {
        let all = &*branches;
        if let Some(k) = twin_of(
            i,
            &plain,
            |k| all[k].result.is_ok().then_some(&keys[k][..]),
            |k, _| size[k],
        ) {
            branches[i].result = Err(SolveError::DoubleRoot { twin: k });
            branches[k].tangent = true;
        }
    }
}

/// [`mark_double_roots`] for the interpreter's lists of (signs, result).
pub fn mark_double_roots_in<S>(
    branches: &mut [(Vec<crate::primitives::Sign>, Result<S, SolveError>)],
    revolute: &[bool],
    values: impl Fn(&S) -> &[f64],
) {
    for i in 1..branches.len() {
        let all = &*branches;
        if let Some(k) = twin_of(
            i,
            revolute,
            |k| all[k].1.as_ref().ok().map(&values),
            |_, v| magnitude(v, revolute),
        ) {
            branches[i].1 = Err(SolveError::DoubleRoot { twin: k });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The given values (x, y) must lie on the unit circle: the residual
    /// is x² + y² − 1. From (2, 0) the nearest consistent values are (1, 0),
    /// and x is the contradicted one.
    #[test]
    fn nearest_projects_onto_the_consistent_set() {
        let r = |v: &[f64]| Some(vec![v[0] * v[0] + v[1] * v[1] - 1.0]);
        let n = nearest(&[2.0, 0.0], &[false, false], 1.0, r).unwrap();
        assert!((n[0] - 1.0).abs() < 1e-9 && n[1].abs() < 1e-12, "{n:?}");
        let c = contradicted(&[2.0, 0.0], &n, &[false, false], 1.0).unwrap();
        assert_eq!((c.index, c.name.as_ref()), (0, "#1"));
    }

    /// An angle weighed by the extent: y = 3 is fixed, the angle is free,
    /// so the projection moves y alone.
    #[test]
    fn nearest_moves_only_what_is_constrained() {
        let r = |v: &[f64]| Some(vec![v[0] - 3.0]);
        let n = nearest(&[3.5, 0.2], &[false, true], 100.0, r).unwrap();
        // Polished to 1e-4 of the tolerance: 1e-4 · 1e-9 · 100.
        assert!((n[0] - 3.0).abs() <= 1e-11 && n[1] == 0.2, "{n:?}");
    }

    #[test]
    fn worst_finds_the_largest_excess_and_non_finite_values() {
        assert_eq!(worst(&[0.0, 1e-12, -1e-10], 10.0), None);
        assert_eq!(worst(&[0.0, 2e-8, -3e-8], 10.0), Some((2, 3e-8)));
        assert_eq!(worst(&[0.0, f64::NAN], 10.0), Some((1, f64::INFINITY)));
    }
}
