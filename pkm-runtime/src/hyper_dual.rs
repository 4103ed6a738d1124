//! Hyper-dual numbers `a + b ε₁ + c ε₂ + d ε₁ε₂` (ε₁² = ε₂² = 0): run
//! through a plan's steps (a [`Scalar`]), they give every value's first
//! derivatives along two directions and its mixed second derivative,
//! exactly (no step size, no cancellation). The Lagrange path of inverse
//! dynamics ([`crate::lagrange`]) reads the derivatives of the link poses
//! this way.
//!
//! ```
//! use pkm_runtime::hyper_dual::HyperDual;
//! use pkm_runtime::scalar::Scalar;
//!
//! // f(x) = x·sin x at 2, along ε₁ and ε₂ both: f'(2) and f''(2).
//! let x = HyperDual::variable(2.0, 1.0, 1.0);
//! let f = x * x.sin();
//! assert!((f.e1 - (2f64.sin() + 2.0 * 2f64.cos())).abs() < 1e-15);
//! assert!((f.e12 - (2.0 * 2f64.cos() - 2.0 * 2f64.sin())).abs() < 1e-15);
//! ```

use crate::primitives::{Error as GeomError, Sign};
use crate::scalar::{Failure, Scalar};
use core::ops::{Add, Div, Mul, Neg, Sub};

/// A hyper-dual number.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct HyperDual {
    /// The value.
    pub re: f64,
    /// The derivative along the first direction.
    pub e1: f64,
    /// The derivative along the second direction.
    pub e2: f64,
    /// The mixed second derivative.
    pub e12: f64,
}

impl HyperDual {
    /// A constant.
    pub fn constant(re: f64) -> Self {
        HyperDual {
            re,
            ..Default::default()
        }
    }

    /// A variable at `re` moving by `e1` along the first direction and by
    /// `e2` along the second.
    pub fn variable(re: f64, e1: f64, e2: f64) -> Self {
        HyperDual { re, e1, e2, e12: 0.0 }
    }

    /// `f(self)` from `f`, `f'` and `f''` at the value.
    fn chain(self, f: f64, d1: f64, d2: f64) -> Self {
        HyperDual {
            re: f,
            e1: d1 * self.e1,
            e2: d1 * self.e2,
            e12: d1 * self.e12 + d2 * self.e1 * self.e2,
        }
    }

    fn scale(self, k: f64) -> Self {
        HyperDual {
            re: k * self.re,
            e1: k * self.e1,
            e2: k * self.e2,
            e12: k * self.e12,
        }
    }
}

impl Add for HyperDual {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        HyperDual {
            re: self.re + o.re,
            e1: self.e1 + o.e1,
            e2: self.e2 + o.e2,
            e12: self.e12 + o.e12,
        }
    }
}

impl Sub for HyperDual {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        self + (-o)
    }
}

impl Neg for HyperDual {
    type Output = Self;
    fn neg(self) -> Self {
        self.scale(-1.0)
    }
}

impl Mul for HyperDual {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        HyperDual {
            re: self.re * o.re,
            e1: self.re * o.e1 + self.e1 * o.re,
            e2: self.re * o.e2 + self.e2 * o.re,
            e12: self.re * o.e12 + self.e1 * o.e2 + self.e2 * o.e1 + self.e12 * o.re,
        }
    }
}

impl Div for HyperDual {
    type Output = Self;
    fn div(self, o: Self) -> Self {
        let r = 1.0 / o.re;
        self * o.chain(r, -r * r, 2.0 * r * r * r)
    }
}

impl Scalar for HyperDual {
    type Choice = Sign;

    fn c(x: f64) -> Self {
        HyperDual::constant(x)
    }
    fn sqrt(self) -> Self {
        let s = self.re.sqrt();
        self.chain(s, 0.5 / s, -0.25 / (s * self.re))
    }
    fn sin(self) -> Self {
        let (s, c) = self.re.sin_cos();
        self.chain(s, c, -s)
    }
    fn cos(self) -> Self {
        let (s, c) = self.re.sin_cos();
        self.chain(c, -s, -c)
    }
    /// `θ₀ + u` with θ₀ the angle of the values and
    /// `u = (x₀ y − y₀ x)/(x₀ x + y₀ y)`: u has no value part, so
    /// atan(u) = u − u³/3 = u to second order, exactly.
    fn atan2(self, x: Self) -> Self {
        let y = self;
        let theta = crate::scalar::angle(y.re, x.re);
        let (x0, y0) = (HyperDual::constant(x.re), HyperDual::constant(y.re));
        let u = (x0 * y - y0 * x) / (x0 * x + y0 * y);
        HyperDual {
            re: theta,
            e1: u.e1,
            e2: u.e2,
            e12: u.e12,
        }
    }
    fn abs(self) -> Self {
        if self.re < 0.0 {
            -self
        } else {
            self
        }
    }
    fn if_less(a: Self, b: Self, then: Self, otherwise: Self) -> Self {
        if a.re < b.re {
            then
        } else {
            otherwise
        }
    }
    fn require(a: Self, b: Self, failure: Failure<Self>, _site: [usize; 2]) -> Result<(), GeomError<f64>> {
        if a.re < b.re {
            Ok(())
        } else {
            Err(failure.map(|x| x.re).error())
        }
    }
    fn pick(choice: Sign, plus: Self, minus: Self) -> Self {
        choice.pick(plus, minus)
    }
    fn choice(signs: &[Sign], k: Option<usize>) -> Sign {
        Sign::nth(signs, k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each function's derivatives against its closed-form derivatives.
    #[test]
    fn elementary_functions_carry_first_and_second_derivatives() {
        let x = HyperDual::variable(0.7, 1.0, 1.0);
        let close = |a: f64, b: f64| (a - b).abs() < 1e-14 * b.abs().max(1.0);
        let s = x.sqrt();
        assert!(close(s.e1, 0.5 / 0.7f64.sqrt()) && close(s.e12, -0.25 * 0.7f64.powf(-1.5)));
        let q = HyperDual::c(1.0) / x;
        assert!(close(q.e1, -1.0 / 0.49) && close(q.e12, 2.0 / 0.343));
        let c = x.cos();
        assert!(close(c.e1, -0.7f64.sin()) && close(c.e12, -0.7f64.cos()));
        // atan2(sin x, cos x) = x: first derivative 1, second 0.
        let a = x.sin().atan2(x.cos());
        assert!(close(a.re, 0.7) && close(a.e1, 1.0) && a.e12.abs() < 1e-15);
        // atan2(x, 1): 1/(1 + x²) and −2x/(1 + x²)².
        let t = x.atan2(HyperDual::c(1.0));
        assert!(close(t.e1, 1.0 / 1.49) && close(t.e12, -1.4 / (1.49 * 1.49)));
    }

    /// Two directions: f(x, y) = x² y, along x (ε₁) and y (ε₂):
    /// ∂f/∂x = 2xy, ∂f/∂y = x², ∂²f/∂x∂y = 2x.
    #[test]
    fn the_mixed_part_is_the_mixed_derivative() {
        let (x, y) = (HyperDual::variable(3.0, 1.0, 0.0), HyperDual::variable(-2.0, 0.0, 1.0));
        let f = x * x * y;
        assert_eq!((f.re, f.e1, f.e2, f.e12), (-18.0, -12.0, 9.0, 6.0));
    }
}
