//! A reference position solution to about 70 significant digits, for
//! measuring the error of the `f64` solvers (the work-precision benchmark).
//!
//! Newton's method on the loop residual of [`crate::kinematics`], evaluated in
//! the octuple-precision [`f256`] (237-bit significand, about 71 digits):
//! the Jacobian by central differences with step `1e-20` (truncation error
//! about `1e-40`, rounding error about `1e-51`), the Gauss–Newton step by
//! Gaussian elimination with partial pivoting on the normal equations, all in
//! `f256`; started from an `f64` solution on the wanted branch and iterated
//! until the step is below [`STEP_TOLERANCE`] (relative to the model's
//! scale for lengths, radians for angles). Only with the `high-precision`
//! feature, which benches and tests enable.

use crate::kinematics::{model_scale, Kinematics, ModelError, Pose};
use crate::model::{JointType, Model};
use crate::newton::{ik_problem, split_entries, NewtonError, Output};
use crate::primitives::{Error as GeomError, Sign};
use crate::scalar::{Failure, Real, Scalar};

/// The octuple-precision scalar, re-exported so that benches and tests name this version.
pub use ::f256::f256;

impl Scalar for f256 {
    type Choice = Sign;

    fn c(x: f64) -> Self {
        f256::from(x)
    }

    fn sqrt(self) -> Self {
        f256::sqrt(self)
    }

    fn abs(self) -> Self {
        f256::abs(&self)
    }

    fn sin(self) -> Self {
        f256::sin(&self)
    }

    fn cos(self) -> Self {
        f256::cos(&self)
    }

    fn atan2(self, x: Self) -> Self {
        // f256 0.11's own atan2 returns ±π/2 when |y| = |x| (atan2(1, 1) =
        // π/2): built on its atan instead, which is right there.
        let pi = ::f256::consts::PI;
        if x > f256::ZERO {
            (self / x).atan()
        } else if x < f256::ZERO {
            let t = (self / x).atan();
            if self.is_sign_negative() {
                t - pi
            } else {
                t + pi
            }
        } else if self == f256::ZERO {
            f256::ZERO
        } else {
            ::f256::consts::FRAC_PI_2.copysign(self)
        }
    }

    fn if_less(a: Self, b: Self, then: Self, otherwise: Self) -> Self {
        if a < b {
            then
        } else {
            otherwise
        }
    }

    fn require(a: Self, b: Self, failure: Failure<Self>, _site: [usize; 2]) -> Result<(), GeomError<f64>> {
        if a < b {
            Ok(())
        } else {
            Err(failure.map(to_f64).error())
        }
    }

    fn pick(choice: Sign, plus: Self, minus: Self) -> Self {
        choice.pick(plus, minus)
    }

    fn choice(signs: &[Sign], k: Option<usize>) -> Sign {
        Sign::nth(signs, k)
    }
}

impl Real for f256 {
    fn is_finite(self) -> bool {
        f256::is_finite(self)
    }
}

/// The nearest `f64` to `x` (up to one extra rounding; infinite beyond
/// `f64`'s range, zero below 2⁻¹⁰⁷⁴ or so). For reporting errors only.
pub fn to_f64(x: f256) -> f64 {
    if !x.is_finite() {
        return f64::NAN;
    }
    let (sign, exp, (hi, lo)) = x.as_sign_exp_signif();
    // The significand (below 2²³⁷, as hi·2¹²⁸ + lo) over 2²³⁶, then the
    // power of two in two halves so that neither factor underflows early.
    let significand = hi as f64 * 2f64.powi(-108) + lo as f64 * 2f64.powi(-236);
    let e = exp + 236;
    let magnitude = significand * 2f64.powi(e / 2) * 2f64.powi(e - e / 2);
    if sign == 1 {
        -magnitude
    } else {
        magnitude
    }
}

/// The step below which the iteration stops (see the module documentation).
pub const STEP_TOLERANCE: f64 = 1e-40;
/// The central-difference step, relative to each unknown's unit.
const DIFF_STEP: f64 = 1e-20;
/// At most this many Newton steps (from an `f64` solution, three suffice).
const MAX_ITERATIONS: usize = 12;

/// A reference solution.
#[derive(Debug, Clone, PartialEq)]
pub struct Reference {
    /// All joint values of the model (laid out as by [`Model::value_offsets`]).
    pub values: Vec<f256>,
    /// The largest entry of the loop residual, position rows relative to the
    /// model's scale ([`model_scale`]), at `values`.
    pub residual: f256,
    /// The last Newton step's largest entry (lengths relative to the scale).
    pub step: f256,
    /// The Newton steps taken.
    pub iterations: usize,
}

/// The largest absolute entry.
fn max_abs(xs: &[f256]) -> f256 {
    xs.iter().fold(f256::ZERO, |m, x| m.max(x.abs()))
}

/// Solves `a x = b` (square) by Gaussian elimination with partial pivoting;
/// `None` if a pivot is exactly zero.
fn solve(mut a: Vec<Vec<f256>>, mut b: Vec<f256>) -> Option<Vec<f256>> {
    let n = b.len();
    for col in 0..n {
        let pivot = (col..n).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[pivot][col] == f256::ZERO {
            return None;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        let (upper, lower) = a.split_at_mut(col + 1);
        let pivot_row = &upper[col];
        for (offset, row) in lower.iter_mut().enumerate() {
            let f = row[col] / pivot_row[col];
            for (x, p) in row[col..].iter_mut().zip(&pivot_row[col..]) {
                *x -= f * *p;
            }
            let sub = f * b[col];
            b[col + 1 + offset] -= sub;
        }
    }
    let mut x = vec![f256::ZERO; n];
    for row in (0..n).rev() {
        let tail = (row + 1..n).fold(f256::ZERO, |s, k| s + a[row][k] * x[k]);
        x[row] = (b[row] - tail) / a[row][row];
    }
    Some(x)
}

/// The reference forward solution: the joint values that close every loop
/// with the actuated joints at `inputs` (as for [`crate::newton::solve_fk`]),
/// refined from `start`, a full `f64` joint-value vector near it (e.g. an
/// `f64` Newton solution).
///
/// # Errors
/// [`NewtonError::BadInput`] for an unusable model, inputs or start;
/// [`NewtonError::Singular`] if the normal equations are singular;
/// [`NewtonError::NoConvergence`] if the step does not fall below
/// [`STEP_TOLERANCE`] within 12 iterations.
pub fn fk(model: &Model, inputs: &[f64], start: &[f64]) -> Result<Reference, NewtonError> {
    let k = Kinematics::<f256>::new(model)?;
    let mut values: Vec<f256> = start.iter().map(|&x| f256::from(x)).collect();
    k.check(&values)?;
    let (solved, actuated) = split_entries(model, &k.offsets, values.len(), inputs)?;
    for (&i, &x) in actuated.iter().zip(inputs) {
        values[i] = f256::from(x);
    }
    let scale_f64 = model_scale(model);
    let scale = f256::from(scale_f64);
    // Each unknown's unit: the scale for P joints (lengths), 1 for angles.
    let unit: Vec<f256> = model
        .length_values()
        .iter()
        .map(|&l| if l { scale } else { f256::ONE })
        .collect();
    let unknowns: Vec<usize> = (0..values.len()).filter(|&i| solved[i]).collect();
    let h = f256::from(DIFF_STEP);
    let two = f256::from(2.0);
    let mut step = f256::INFINITY;
    let mut iterations = 0;
    while step >= f256::from(STEP_TOLERANCE) {
        if iterations == MAX_ITERATIONS {
            let residual = to_f64(max_abs(&k.scaled_residual(&values, scale)?));
            return Err(NewtonError::NoConvergence { residual, iterations });
        }
        let r = k.scaled_residual(&values, scale)?;
        // Central-difference Jacobian, column by column.
        let mut columns = Vec::with_capacity(unknowns.len());
        let mut probe = values.clone();
        for &i in &unknowns {
            let d = h * unit[i];
            probe[i] = values[i] + d;
            let plus = k.scaled_residual(&probe, scale)?;
            probe[i] = values[i] - d;
            let minus = k.scaled_residual(&probe, scale)?;
            probe[i] = values[i];
            columns.push(
                plus.iter()
                    .zip(&minus)
                    .map(|(p, m)| (*p - *m) / (two * d))
                    .collect::<Vec<_>>(),
            );
        }
        // Normal equations JᵀJ δ = −Jᵀr: the residual has redundant rows.
        let dot = |a: &[f256], b: &[f256]| a.iter().zip(b).fold(f256::ZERO, |s, (x, y)| s + *x * *y);
        let jtj = columns
            .iter()
            .map(|a| columns.iter().map(|b| dot(a, b)).collect())
            .collect();
        let minus_jtr = columns.iter().map(|a| -dot(a, &r)).collect();
        let delta = solve(jtj, minus_jtr).ok_or(NewtonError::Singular)?;
        step = f256::ZERO;
        for (&i, d) in unknowns.iter().zip(&delta) {
            values[i] += *d;
            step = step.max(d.abs() / unit[i]);
        }
        iterations += 1;
    }
    let residual = max_abs(&k.scaled_residual(&values, scale)?);
    Ok(Reference {
        values,
        residual,
        step,
        iterations,
    })
}

/// The reference inverse solution: the joint values with the outputs at
/// `given` (as for [`crate::newton::solve_ik`]), refined from `start`, a
/// joint-value vector of `model` near it. The residual is that of the model
/// of [`crate::newton::with_outputs_as_inputs`].
///
/// # Errors
/// As [`fk`].
pub fn ik(model: &Model, outputs: &[Output], given: &[f64], start: &[f64]) -> Result<Reference, NewtonError> {
    let (m, inputs, extended) = ik_problem(model, outputs, given, start)?;
    let mut reference = fk(&m, &inputs, &extended)?;
    reference.values.truncate(start.len());
    Ok(reference)
}

/// The outputs (in the order of `outputs`, as [`crate::newton::solve_ik`]
/// takes them) at joint values `values`, in scalar `T`: a point's
/// coordinates (x, y, and z if spatial), a pose's angle about its axis in
/// (−π, π] (from the link's orientation), a joint's value.
///
/// # Errors
/// As [`Kinematics::poses`], and for values of the wrong length.
pub fn output_values<T: Real>(model: &Model, outputs: &[Output], values: &[T]) -> Result<Vec<T>, ModelError> {
    let k = Kinematics::<T>::new(model)?;
    k.check(values)?;
    let poses: Vec<Pose<T>> = k.poses(values)?;
    let n = if model.planar { 2 } else { 3 };
    let mut out = Vec::new();
    for o in outputs {
        match *o {
            Output::Joint(j) => out.push(values[k.offsets[j]]),
            Output::Parts { link, local, parts } => {
                let p = poses[link].transform_point(local.map(T::c));
                // R = R_z·R_y·R_x from q = (w, x, y, z): r₂₁ = 2(yz + wx),
                // r₂₂ = 1 − 2(x² + y²), −r₂₀ = 2(wy − xz), r₁₀ = 2(xy + wz),
                // r₀₀ = 1 − 2(y² + z²), √(r₀₀² + r₁₀²) = √(1 − r₂₀²).
                let [w, x, y, z] = poses[link].rotation;
                let (one, two) = (T::c(1.0), T::c(2.0));
                let sy = two * (w * y - x * z);
                let six = [
                    p[0],
                    p[1],
                    p[2],
                    (two * (y * z + w * x)).atan2(one - two * (x * x + y * y)),
                    sy.atan2((one - sy * sy).sqrt()),
                    (two * (x * y + w * z)).atan2(one - two * (y * y + z * z)),
                ];
                out.extend(parts.given().map(|i| six[i]));
            }
            Output::Point { link, local } | Output::Pose { link, local, .. } => {
                let p = poses[link].transform_point(local.map(T::c));
                out.extend_from_slice(&p[..n]);
                if let Output::Pose { about: Some(axis), .. } = *o {
                    // q = (cos α/2, sin α/2 · â) for a turn by α about â.
                    let [w, x, y, z] = poses[link].rotation;
                    let a = axis.map(T::c);
                    let norm = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
                    let s = (x * a[0] + y * a[1] + z * a[2]) / norm;
                    let (s, w) = if w < T::c(0.0) { (-s, -w) } else { (s, w) };
                    out.push(s.atan2(w) * T::c(2.0));
                }
            }
        }
    }
    Ok(out)
}

/// Which outputs are angles (compared modulo 2π) rather than lengths.
pub fn output_is_angle(model: &Model, outputs: &[Output]) -> Vec<bool> {
    let n = if model.planar { 2 } else { 3 };
    outputs
        .iter()
        .flat_map(|o| match *o {
            Output::Joint(j) => vec![model.joints[j].kind != JointType::P],
            Output::Point { .. } => vec![false; n],
            Output::Parts { parts, .. } => parts.given().map(|i| i >= 3).collect(),
            // A pose without `about` keeps the base's orientation: no angle.
            Output::Pose { about, .. } => {
                let mut v = vec![false; n];
                if about.is_some() {
                    v.push(true);
                }
                v
            }
        })
        .collect()
}

/// Which joint values are angles (R and Pa joints' values, S rotation
/// vectors' components) rather than lengths (P joints').
pub fn value_is_angle(model: &Model) -> Vec<bool> {
    model
        .joints
        .iter()
        .flat_map(|j| vec![j.kind != JointType::P; j.kind.dof()])
        .collect()
}

/// The largest difference of `got` from `reference`: angles (where `angle`
/// says so) modulo 2π, in radians; lengths divided by `scale`. Computed in
/// `f256`, reported in `f64`; infinite if the lengths differ.
pub fn max_error(got: &[f64], reference: &[f256], angle: &[bool], scale: f64) -> f64 {
    if got.len() != reference.len() || angle.len() != got.len() {
        return f64::INFINITY;
    }
    let turn = f256::from(2.0) * ::f256::consts::PI;
    let scale = f256::from(scale);
    let worst = got
        .iter()
        .zip(reference)
        .zip(angle)
        .map(|((&g, &r), &angle)| {
            let d = f256::from(g) - r;
            if angle {
                (d - (d / turn).round() * turn).abs()
            } else {
                d.abs() / scale
            }
        })
        .fold(f256::ZERO, f256::max);
    to_f64(worst)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One flag per output value, as `Output::len` counts them: a spatial
    /// pose without `about` is three lengths (it had a fourth flag, which
    /// shifted every later output's), with `about` three and an angle.
    #[test]
    fn output_angles_match_the_values() {
        use crate::model::{Joint, Place};
        let axis = |at| Place::Axis {
            at,
            axis: [0.0, 0.0, 1.0],
        };
        let model = Model {
            name: "arm".into(),
            planar: false,
            links: vec!["base".into(), "arm".into()],
            joints: vec![Joint {
                name: "R1".into(),
                kind: JointType::R,
                links: [0, 1],
                places: [axis([0.0; 3]), axis([0.0; 3])],
                actuated: true,
            }],
            points: vec![],
        };
        let pose = |about| Output::Pose {
            link: 1,
            local: [1.0, 0.0, 0.0],
            about,
        };
        let outputs = [pose(None), Output::Joint(0), pose(Some([0.0, 0.0, 1.0]))];
        let want = [false, false, false, true, false, false, false, true];
        assert_eq!(output_is_angle(&model, &outputs), want);
        assert_eq!(want.len(), outputs.iter().map(|o| o.len(false)).sum::<usize>());
    }

    #[test]
    fn to_f64_round_trips_f64_values() {
        for x in [0.0, 1.0, -2.5, 1e-300, 6.02e23, -1.0 / 3.0] {
            assert_eq!(to_f64(f256::from(x)), x);
        }
    }

    #[test]
    fn f256_carries_more_than_forty_digits() {
        // sin²(1) + cos²(1) = 1 and √2·√2 = 2 to within 1e-68.
        let one = f256::ONE;
        let (s, c) = (Scalar::sin(one), Scalar::cos(one));
        assert!(to_f64((s * s + c * c - one).abs()) < 1e-68);
        let r2 = Scalar::sqrt(f256::from(2.0));
        assert!(to_f64((r2 * r2 - f256::from(2.0)).abs()) < 1e-68);
    }

    #[test]
    fn atan2_covers_the_four_quadrants_and_the_diagonals() {
        // (y, x, the angle in units of π/4) at the diagonals and axes, where
        // f256's own atan2 fails; then atan2(0.3, 0.7) against f64.
        let pi = ::f256::consts::PI;
        let quarter = pi / f256::from(4.0);
        for (y, x, k) in [
            (1.0, 1.0, 1.0),
            (1.0, -1.0, 3.0),
            (-1.0, -1.0, -3.0),
            (-2.0, 2.0, -1.0),
            (0.0, 1.0, 0.0),
            (1.0, 0.0, 2.0),
            (-1.0, 0.0, -2.0),
            (0.0, -1.0, 4.0),
        ] {
            let got = Scalar::atan2(f256::from(y), f256::from(x));
            let d = to_f64((got - quarter * f256::from(k)).abs());
            assert!(d < 1e-68, "atan2({y}, {x}) is off by {d:e}");
        }
        let got = to_f64(Scalar::atan2(f256::from(0.3), f256::from(0.7)));
        assert!((got - 0.3f64.atan2(0.7)).abs() < 1e-16);
    }

    #[test]
    fn solve_by_elimination_matches_a_hand_solution() {
        // 2x + y = 5, x + 3y = 10: x = 1, y = 3.
        let a = |x: f64| f256::from(x);
        let x = solve(vec![vec![a(2.0), a(1.0)], vec![a(1.0), a(3.0)]], vec![a(5.0), a(10.0)]).unwrap();
        assert_eq!(x, vec![a(1.0), a(3.0)]);
        assert_eq!(solve(vec![vec![a(0.0)]], vec![a(1.0)]), None);
    }
}
