//! What a solver returns: its error type ([`SolveError`]), one branch of a
//! generated solver ([`Branch`]) and the branch order ([`signs_of`]), and
//! following a branch along a trajectory ([`nearest_branch`],
//! [`extrapolate`]). Shared by the interpreter ([`crate::plan`]) and
//! generated code.

use crate::primitives::{Error as GeomError, Sign};
use core::fmt;
use std::borrow::Cow;

/// A point of a link: a joint's place on it, or one of the model's named points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PointRef {
    /// The place of joint `j` on the link.
    Joint(usize),
    /// Named point number `k` of the model.
    Named(usize),
}

/// Why a branch has no solution.
#[derive(Debug, Clone, PartialEq)]
pub enum SolveError {
    /// A step's existence condition fails by `by` (a length).
    Unreachable {
        /// The step's index.
        step: usize,
        /// The joint whose position cannot be reached, or a dyad's three
        /// joints (`R2–R3–R4`): the loop that cannot close.
        joint: Cow<'static, str>,
        /// The condition, e.g. `centre distance <= r1 + r2`.
        constraint: &'static str,
        /// By how much.
        by: f64,
    },
    /// A step's data are degenerate (coincident centres, a zero-length link, …).
    Degenerate {
        /// The step's index.
        step: usize,
        /// What is degenerate.
        what: &'static str,
    },
    /// The inputs are wrong (count, non-finite values) or the plan does not fit the model.
    BadInput {
        /// What is wrong.
        what: Cow<'static, str>,
    },
    /// The steps ran, but a joint the plan did not solve (or a given point
    /// it moved) does not close: the given values over-determine the
    /// mechanism and disagree (see [`crate::consistency`]).
    Inconsistent {
        /// What does not close, e.g. `joint R11`.
        owner: Cow<'static, str>,
        /// By how much (a length).
        gap: f64,
        /// The given value the others contradict, where the projection onto
        /// consistent values found it.
        contradicted: Option<Box<Contradicted>>,
    },
    /// This branch is the same solution as branch number `twin`: a double
    /// root (tangency) of one step, where its two signs meet.
    DoubleRoot {
        /// The branch (index in `signs_of` order) that keeps the solution.
        twin: usize,
    },
}

impl fmt::Display for SolveError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SolveError::Unreachable {
                joint, constraint, by, ..
            } => {
                write!(
                    f,
                    "the loop through {joint} cannot close: `{constraint}` fails by {}",
                    short(*by)
                )
            }
            SolveError::Degenerate { what, step } => write!(f, "degenerate configuration at step {step}: {what}"),
            SolveError::BadInput { what } => write!(f, "bad input: {what}"),
            SolveError::Inconsistent {
                owner,
                gap,
                contradicted: Some(c),
            } => write!(
                f,
                "the given values are inconsistent: {} = {} cannot be reached with the others, \
                 the nearest reachable value is {} (off by {:.6e}); as given, {owner} misses by {gap:.6e}",
                c.name,
                c.given,
                short(c.nearest),
                c.given - c.nearest
            ),
            SolveError::Inconsistent { owner, gap, .. } => {
                write!(f, "the given values are inconsistent: {owner} misses by {gap:.6e}")
            }
            SolveError::DoubleRoot { twin } => write!(
                f,
                "a double root (tangency): this branch is the same solution as branch {twin}"
            ),
        }
    }
}

impl std::error::Error for SolveError {}

/// The shortest decimal of `v` within 1e-12 of it (relative; a projection's
/// last digits are noise): −299.99999999999994 prints as −300; from 1e16
/// on in exponent form (1e308, not its 309 digits).
fn short(v: f64) -> String {
    if v.abs() >= 1e16 {
        return format!("{v:e}");
    }
    let tol = 1e-12 * v.abs().max(1.0);
    (0..17)
        .map(|p| format!("{v:.p$}"))
        .find(|t| t.parse::<f64>().is_ok_and(|x| (x - v).abs() <= tol))
        .unwrap_or_else(|| v.to_string())
}

/// An angle wrapped into (−π, π].
///
/// ```
/// use pkm_runtime::solution::wrap_angle;
/// use std::f64::consts::PI;
/// assert_eq!(wrap_angle(0.5), 0.5);
/// assert!((wrap_angle(0.5 + 4.0 * PI) - 0.5).abs() < 1e-12);
/// assert_eq!(wrap_angle(-PI), PI);
/// ```
#[inline]
pub fn wrap_angle(x: f64) -> f64 {
    use core::f64::consts::{PI, TAU};
    if x > -PI && x <= PI {
        return x;
    }
    // One turn off, as the difference of two wrapped angles is: the turn
    // subtracted is exact there (Sterbenz), so this equals the remainder
    // below, which costs a `fmod` call.
    let y = if x > 0.0 { x - TAU } else { x + TAU };
    if y > -PI && y <= PI {
        return y;
    }
    // Farther: the angle of its sine and cosine, which libm reduces by the
    // exact π (a remainder by the double TAU carries its rounding once per
    // turn: 1e11 rad would end 4.5e-6 off).
    crate::scalar::angle(x.sin(), x.cos())
}

/// A step kernel's error as the error of plan step `step`, at `joint`.
pub fn step_error(step: usize, joint: impl Into<Cow<'static, str>>, e: GeomError<f64>) -> SolveError {
    match e {
        GeomError::Unreachable { constraint, by } => SolveError::Unreachable {
            step,
            joint: joint.into(),
            constraint,
            by,
        },
        GeomError::Degenerate { what } => SolveError::Degenerate { step, what },
    }
}

/// `solve` for each of the 2^`choices` sign vectors, in [`signs_of`] order
/// (bit k set: choice k is `Minus`), with its signs.
pub fn every_branch<S>(choices: usize, mut solve: impl FnMut(&[Sign]) -> S) -> Vec<(Vec<Sign>, S)> {
    (0..1usize << choices)
        .map(|bits| {
            let signs: Vec<Sign> = (0..choices)
                .map(|k| if bits >> k & 1 == 0 { Sign::Plus } else { Sign::Minus })
                .collect();
            let result = solve(&signs);
            (signs, result)
        })
        .collect()
}

/// One branch of a generated solver: its ± choices and its solution, or why it has none.
#[derive(Debug, Clone, PartialEq)]
pub struct Branch<S, const D: usize> {
    /// The sign of each ± choice of the plan, in plan order.
    pub signs: [Sign; D],
    /// The solution, or why this branch has none.
    pub result: Result<S, SolveError>,
    /// Whether a step met a double root here (tangency): another branch
    /// that would be the same solution says [`SolveError::DoubleRoot`].
    pub tangent: bool,
}

/// The sign vector of branch number `index` (bit k set: choice k is `Minus`),
/// the order in which generated solvers and [`crate::plan::run_all`] list branches.
pub const fn signs_of<const D: usize>(index: usize) -> [Sign; D] {
    let mut signs = [Sign::Plus; D];
    let mut k = 0;
    while k < D {
        if index >> k & 1 == 1 {
            signs[k] = Sign::Minus;
        }
        k += 1;
    }
    signs
}

/// The distance between two joint-value vectors, with the differences of
/// revolute joints wrapped to (−π, π] (so 3.1 and −3.1 rad are close).
pub fn joint_distance(a: &[f64], b: &[f64], revolute: &[bool]) -> f64 {
    a.iter()
        .zip(b)
        .zip(revolute)
        .map(|((x, y), r)| if *r { wrap_angle(x - y) } else { x - y })
        .fold(0.0, |acc, d| d.mul_add(d, acc))
        .sqrt()
}

/// The index of the solved branch nearest `previous` (by [`joint_distance`]
/// of the values `values` reads from a solution), if any branch is solved.
pub fn nearest_branch<S, const D: usize>(
    branches: &[Branch<S, D>],
    previous: &[f64],
    revolute: &[bool],
    values: impl Fn(&S) -> &[f64],
) -> Option<usize> {
    let mut best: Option<(usize, f64)> = None;
    for (i, b) in branches.iter().enumerate() {
        if let Ok(s) = &b.result {
            let d = joint_distance(values(s), previous, revolute);
            if best.is_none_or(|(_, bd)| d < bd) {
                best = Some((i, d));
            }
        }
    }
    best.map(|(i, _)| i)
}

/// The joint values a smooth trajectory reaches next: `previous` plus the
/// last step `previous − before` (revolute steps wrapped), a linear
/// predictor. Near a tangency, where two branches meet, the branch nearest
/// this prediction is the one that continues; the nearest to `previous` may not be.
pub fn extrapolate<const J: usize>(previous: &[f64; J], before: &[f64; J], revolute: &[bool; J]) -> [f64; J] {
    let mut out = *previous;
    for k in 0..J {
        let step = previous[k] - before[k];
        out[k] += if revolute[k] { wrap_angle(step) } else { step };
    }
    out
}

/// A given value that the others contradict (see [`SolveError::Inconsistent`], found by
/// [`crate::consistency::inconsistent`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Contradicted {
    /// Its index among the given values.
    pub index: usize,
    /// Its name (an output's or an input's), or `#k` (1-based) where the
    /// solver does not know it.
    pub name: Cow<'static, str>,
    /// The value given.
    pub given: f64,
    /// The nearest value consistent with the other given values.
    pub nearest: f64,
}

#[cfg(test)]
mod tests {
    use super::wrap_angle;
    use core::f64::consts::{PI, TAU};

    /// The remainder by a whole turn, as `wrap_angle` computed it for
    /// every angle before it took the one-turn shortcut.
    fn by_remainder(x: f64) -> f64 {
        let w = x.rem_euclid(TAU);
        if w > PI {
            w - TAU
        } else {
            w
        }
    }

    /// One turn off, the shortcut gives the remainder's value exactly (at
    /// −2π it gives +0 where the remainder gives −0): at the ends of its
    /// range, next to them, and across it.
    #[test]
    fn one_turn_off_equals_the_remainder() {
        let mut xs = vec![];
        for edge in [PI, 2.0 * PI, 3.0 * PI, TAU + PI] {
            for e in [edge, -edge] {
                xs.extend([e, e.next_up(), e.next_down()]);
            }
        }
        let n = 100_000;
        xs.extend((0..=n).map(|i| -3.0 * PI + 6.0 * PI * i as f64 / n as f64));
        for x in xs.into_iter().filter(|x| x.abs() > PI && x.abs() < 3.0 * PI) {
            assert_eq!(wrap_angle(x), by_remainder(x), "at {x:e}");
        }
    }

    /// Farther, the angle reduced by the exact π: against 400-digit
    /// reductions (mpmath) of the doubles nearest 1e11, 1e15, ±1e308 and
    /// 10π + 0.1, within 2 ulps of π.
    #[test]
    fn far_angles_are_reduced_exactly() {
        for (x, want) in [
            (1e11, 1.1908745855222387),
            (1e15, 2.1096981170701126),
            (1e308, 2.6710203145624654),
            (-1e308, -2.6710203145624654),
            (10.0 * PI + 0.1, 0.1),
        ] {
            assert!(
                (wrap_angle(x) - want).abs() <= 2.0 * PI * f64::EPSILON,
                "{x:e}: {}",
                wrap_angle(x)
            );
        }
    }
}
