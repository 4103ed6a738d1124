//! What generated batch solvers (`fk_batch`, `ik_batch`, `fk_point_batch`)
//! share: the check of their slices' lengths.
//!
//! A batch solver takes its given values and writes its results as
//! structure of arrays: one slice per given value, one per result, and
//! `ok`, one flag per lane. Every slice must have `ok.len()` entries (any
//! number, 0 included); anything else is [`SolveError::BadInput`] before a
//! lane is solved.

use crate::plan::SolveError;
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
