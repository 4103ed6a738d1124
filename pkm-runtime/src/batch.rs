//! What generated batch solvers (`fk_batch`, `ik_batch`, `fk_point_batch`)
//! share: the check of their slices' lengths, and running their loop with
//! the widest vectors the processor has ([`wide`]).
//!
//! A batch solver takes its given values and writes its results as
//! structure of arrays: one slice per given value, one per result, and
//! `ok`, one flag per lane. Every slice must have `ok.len()` entries (any
//! number, 0 included); anything else is [`SolveError::BadInput`] before a
//! lane is solved.

use crate::solution::SolveError;
use std::borrow::Cow;

/// `Ok` when every given and result slice has `lanes` entries (`ok.len()`),
/// else `BadInput` naming the first slice that does not, in `function`.
///
/// ```
/// use pkm_runtime::batch::check_lanes;
/// assert!(check_lanes("fk_batch", 4, &[4, 4], &[4]).is_ok());
/// let e = check_lanes("fk_batch", 4, &[4, 3], &[4]).unwrap_err();
/// assert_eq!(e.to_string(), "bad input: fk_batch: given[1] has 3 values, ok has 4");
/// ```
pub fn check_lanes(function: &str, lanes: usize, given: &[usize], out: &[usize]) -> Result<(), SolveError> {
    let given = given.iter().enumerate().map(|(i, n)| ("given", i, *n));
    let out = out.iter().enumerate().map(|(i, n)| ("out", i, *n));
    match given.chain(out).find(|(_, _, n)| *n != lanes) {
        None => Ok(()),
        Some((what, i, n)) => Err(SolveError::BadInput {
            what: Cow::Owned(format!("{function}: {what}[{i}] has {n} values, ok has {lanes}")),
        }),
    }
}

/// A batch loop that [`wide`] runs: a generated solver's loop over its
/// lanes, its slices inside. Implementations mark `run` (and what it
/// calls) `#[inline(always)]`, so that the loop is compiled inside
/// `wide`'s instruction-set choice.
pub trait Loop {
    /// Runs the loop over every lane.
    fn run(self);
}

/// Runs `lanes` compiled for AVX2 (four f64 lanes per instruction) where
/// the processor has it, detected at run time on x86-64; as built (SSE2's
/// two lanes) everywhere else. The results are the same bits either way:
/// Rust fuses no multiply-add, and AVX2's divisions and square roots are
/// IEEE 754's, as SSE2's are.
#[inline]
pub fn wide(lanes: impl Loop) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: `run_avx2` needs AVX2, which the processor has: detected
        // just above.
        unsafe { run_avx2(lanes) };
        return;
    }
    lanes.run();
}

/// `lanes.run()` compiled with AVX2 enabled.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn run_avx2(lanes: impl Loop) {
    lanes.run();
}
