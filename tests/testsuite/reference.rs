//! The 70-digit reference of the work-precision benchmark
//! (`pkm_runtime::reference`): self-consistent to 1e-38 of the scale at
//! every point, and equal to a hand derivation of the four-bar in the same
//! precision.

use crate::work_precision;

use pkm::runtime::reference::{f256, max_error, to_f64, STEP_TOLERANCE};
use pkm::runtime::scalar::Scalar;
use work_precision::{cases, Case};

/// Every reference closes its loops to 1e-38 (position rows relative to the
/// scale) after a last step below 1e-40, in a few iterations, and is within
/// 1e-11 of the generated solution it was started from (the same branch).
fn check(case: &Case) {
    for (k, p) in case.points.iter().enumerate() {
        for (direction, r) in [("fk", &p.fk), ("ik", &p.ik)] {
            let at = format!("{} {direction} point {k}", case.name);
            assert!(to_f64(r.residual) < 1e-38, "{at}: residual {:e}", r.residual);
            assert!(to_f64(r.step) < STEP_TOLERANCE, "{at}: step {:e}", r.step);
            assert!(r.iterations <= 4, "{at}: {} iterations", r.iterations);
        }
        let n = case.model.value_offsets().1;
        let mut values = vec![0.0; n];
        let mut outputs = vec![0.0; p.outputs.len()];
        assert!((case.generated.fk)(&p.inputs, &mut values, &mut outputs));
        let q_error = max_error(&values, &p.fk.values, &case.value_angles, case.scale);
        let x_error = max_error(&outputs, &p.fk_outputs, &case.output_angles, case.scale);
        assert!(
            q_error < 1e-11 && x_error < 1e-11,
            "{} fk {k}: {q_error:e} {x_error:e}",
            case.name
        );
        assert!((case.generated.ik)(&p.outputs, p.ik_signs, &mut values));
        let ik_error = max_error(&values, &p.ik.values, &case.value_angles, case.scale);
        assert!(ik_error < 1e-11, "{} ik {k}: {ik_error:e}", case.name);
    }
}

#[test]
fn references_close_their_loops_to_1e_38() {
    for case in cases() {
        check(&case);
    }
}

/// The four-bar's rocker angle by hand in f256: B = l1 (cos θ, sin θ), C on
/// the circles (B, l2) and (D, l3) with D = (l4, 0), ψ = atan2(Cy, Cx − l4),
/// the intersection nearer the reference's; they agree to 1e-60.
#[test]
fn four_bar_reference_matches_the_circle_intersection() {
    let case = work_precision::case("four_bar", work_precision::four_bar());
    let f = |x: f64| f256::from(x);
    let (l1, l2, l3, l4) = (f(100.0), f(250.0), f(200.0), f(300.0));
    let two = f(2.0);
    // R4 is the fourth joint: its value is the rocker's angle from the base.
    let psi_index = 3;
    for p in &case.points {
        let theta = f(p.inputs[0]);
        let (bx, by) = (l1 * Scalar::cos(theta), l1 * Scalar::sin(theta));
        let (dx, dy) = (l4 - bx, -by);
        let dist = Scalar::sqrt(dx * dx + dy * dy);
        // The chord's foot at a from B along B→D, half-chord h.
        let a = (l2 * l2 - l3 * l3 + dist * dist) / (two * dist);
        let h = Scalar::sqrt(l2 * l2 - a * a);
        let (ex, ey) = (dx / dist, dy / dist);
        let psi = |h: f256| {
            let (cx, cy) = (bx + a * ex - h * ey, by + a * ey + h * ex);
            Scalar::atan2(cy, cx - l4)
        };
        let reference = p.fk.values[psi_index];
        let error = [psi(h), psi(-h)]
            .iter()
            .map(|&s| to_f64(Scalar::abs(s - reference)))
            .fold(f64::INFINITY, f64::min);
        assert!(error < 1e-60, "θ = {}: ψ off by {error:e}", p.inputs[0]);
    }
}
