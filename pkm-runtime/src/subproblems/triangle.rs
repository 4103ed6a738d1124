//! The sine of a triangle's angle from its three sides, by Kahan's area:
//! exact to a few ulps however flat the triangle.

use crate::scalar::Scalar;

/// The sine of the angle between sides `p` and `q` of the triangle with
/// sides `p`, `q`, `r`: `2·area/(p·q)`, the area by Kahan's formula
/// (`¼√((a + (b + c))(c − (a − b))(c + (a − b))(a + (b − c)))`, `a ≥ b ≥ c`),
/// exact to a few ulps however flat the triangle; 0 where the sides are a
/// hair past flat (the tangency the caller allows).
///
/// ```
/// use pkm_runtime::subproblems::triangle::kahan_sine;
///
/// // The 3-4-5 triangle: the right angle is between 3 and 4.
/// assert!((kahan_sine(3.0, 4.0, 5.0) - 1.0).abs() < 1e-15);
/// // A needle: sides 1, 1 and r = 2 − 2⁻⁴⁰ (exact), so by hand
/// // sin = (r/2)·√((4 − 2⁻⁴⁰)·2⁻⁴⁰), within 2⁻⁴¹ of 2⁻¹⁹ (the cosine
/// // route, √((1 − c)(1 + c)) with c = (2 − r²)/2, is 4.5e-13 off here).
/// let r = 2.0 - 2f64.powi(-40);
/// let s = kahan_sine(1.0, 1.0, r);
/// let exact = (r / 2.0) * ((4.0 - 2f64.powi(-40)) * 2f64.powi(-40)).sqrt();
/// assert!((s / exact - 1.0).abs() < 4.0 * f64::EPSILON, "{s}");
/// ```
#[inline]
pub fn kahan_sine<T: Scalar>(p: T, q: T, r: T) -> T {
    use crate::scalar::max;
    let min = |x: T, y: T| T::if_less_continuous(x, y, x, y);
    let a = max(max(p, q), r);
    let b = max(min(p, q), min(max(p, q), r));
    let c = min(min(p, q), r);
    let zero = T::c(0.0);
    let neck = c - (a - b);
    let neck = T::if_less_continuous(neck, zero, zero, neck);
    let area4 = ((a + (b + c)) * (a + (b - c))).sqrt() * (neck * (c + (a - b))).sqrt();
    area4 / (T::c(2.0) * p * q)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sine of the angle between the first two sides.
    fn check_sine(p: f64, q: f64, r: f64, want: f64) {
        let got = kahan_sine(p, q, r);
        assert!(
            (got - want).abs() <= 4.0 * f64::EPSILON * want,
            "({p}, {q}, {r}): {got} vs {want}"
        );
    }

    #[test]
    fn kahan_sine_of_any_angle_and_of_needles() {
        // 3-4-5: the right angle between 3 and 4; sin = 4/5 between 3 and 5, 3/5 between 4 and 5.
        check_sine(3.0, 4.0, 5.0, 1.0);
        check_sine(3.0, 5.0, 4.0, 0.8);
        check_sine(5.0, 4.0, 3.0, 0.6);
        check_sine(1.0, 1.0, 1.0, 0.75f64.sqrt());
        // Flat, and a hair past flat (the tangency the caller allows): 0.
        check_sine(1.0, 2.0, 3.0, 0.0);
        check_sine(1.0, 1.0, 2.0 + 4.0 * f64::EPSILON, 0.0);
        // A needle: unit sides over the base b = 2 − 1e-12 (2 − b exact). The
        // apex's height is h = √(1 − b²/4) = √((2 − b)(2 + b))/2, the area b·h/2,
        // so the sine between the unit sides is b·h.
        let b: f64 = 2.0 - 1e-12;
        let h = ((2.0 - b) * (2.0 + b)).sqrt() / 2.0;
        check_sine(1.0, 1.0, b, b * h);
    }
}
