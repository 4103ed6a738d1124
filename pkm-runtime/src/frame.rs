//! A rigid transform as a rotation matrix and a translation, generic over
//! [`Scalar`]: the pose algebra of the solver steps. Written out entry by
//! entry so that, traced, a rotation about a coordinate axis keeps only its
//! four moving entries (the zeros and ones fold away).

use crate::scalar::{add, Scalar};

/// `x ↦ r·x + t`; `r[i][j]` is row i, column j.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame<T> {
    /// The rotation.
    pub r: [[T; 3]; 3],
    /// The translation (the frame's origin).
    pub t: [T; 3],
}

impl<T: Scalar> Frame<T> {
    /// The identity.
    pub fn identity() -> Self {
        let (o, z) = (T::c(1.0), T::c(0.0));
        Frame {
            r: [[o, z, z], [z, o, z], [z, z, o]],
            t: [z, z, z],
        }
    }

    /// A pure translation.
    pub fn translation(t: [T; 3]) -> Self {
        Frame { t, ..Frame::identity() }
    }

    /// A rotation about z by the angle whose cosine and sine are `c`, `s`.
    pub fn about_z(c: T, s: T) -> Self {
        let (o, z) = (T::c(1.0), T::c(0.0));
        Frame {
            r: [[c, -s, z], [s, c, z], [z, z, o]],
            t: [z, z, z],
        }
    }

    /// A rotation by the angle (cosine `c`, sine `s`) about unit `k`
    /// (Rodrigues: `c·I + s·[k]ₓ + (1 − c)·k kᵀ`). The diagonal is written
    /// `kᵢ² + c·(1 − kᵢ²)`, so that about a coordinate axis it folds to the
    /// exact 1 and `c` where `c + (1 − c)` would round.
    pub fn about(k: [T; 3], c: T, s: T) -> Self {
        let one = T::c(1.0);
        let v = one - c;
        let diagonal = |x: T| {
            let xx = x * x;
            xx + c * (one - xx)
        };
        let z = T::c(0.0);
        Frame {
            r: [
                [diagonal(k[0]), v * k[0] * k[1] - s * k[2], v * k[0] * k[2] + s * k[1]],
                [v * k[1] * k[0] + s * k[2], diagonal(k[1]), v * k[1] * k[2] - s * k[0]],
                [v * k[2] * k[0] - s * k[1], v * k[2] * k[1] + s * k[0], diagonal(k[2])],
            ],
            t: [z, z, z],
        }
    }

    /// `r·v`.
    #[inline]
    pub fn rotate(&self, v: [T; 3]) -> [T; 3] {
        let r = &self.r;
        [
            r[0][0] * v[0] + r[0][1] * v[1] + r[0][2] * v[2],
            r[1][0] * v[0] + r[1][1] * v[1] + r[1][2] * v[2],
            r[2][0] * v[0] + r[2][1] * v[1] + r[2][2] * v[2],
        ]
    }

    /// `rᵀ·v`.
    #[inline]
    pub fn rotate_back(&self, v: [T; 3]) -> [T; 3] {
        let r = &self.r;
        [
            r[0][0] * v[0] + r[1][0] * v[1] + r[2][0] * v[2],
            r[0][1] * v[0] + r[1][1] * v[1] + r[2][1] * v[2],
            r[0][2] * v[0] + r[1][2] * v[1] + r[2][2] * v[2],
        ]
    }

    /// The world point of the local point `p`.
    #[inline]
    pub fn apply(&self, p: [T; 3]) -> [T; 3] {
        add(self.rotate(p), self.t)
    }

    /// The local point of the world point `p`.
    #[inline]
    pub fn apply_back(&self, p: [T; 3]) -> [T; 3] {
        self.rotate_back([p[0] - self.t[0], p[1] - self.t[1], p[2] - self.t[2]])
    }

    /// `self · other`.
    pub fn then(&self, other: &Frame<T>) -> Frame<T> {
        let a = &self.r;
        let b = &other.r;
        let e = |i: usize, j: usize| a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
        Frame {
            r: [
                [e(0, 0), e(0, 1), e(0, 2)],
                [e(1, 0), e(1, 1), e(1, 2)],
                [e(2, 0), e(2, 1), e(2, 2)],
            ],
            t: self.apply(other.t),
        }
    }

    /// The inverse transform.
    pub fn inverse(&self) -> Frame<T> {
        let r = &self.r;
        let rt = [
            [r[0][0], r[1][0], r[2][0]],
            [r[0][1], r[1][1], r[2][1]],
            [r[0][2], r[1][2], r[2][2]],
        ];
        let back = Frame { r: rt, t: self.t };
        let t = back.rotate(self.t);
        Frame {
            r: rt,
            t: [-t[0], -t[1], -t[2]],
        }
    }

    /// The columns of `r`.
    pub fn column(&self, j: usize) -> [T; 3] {
        [self.r[0][j], self.r[1][j], self.r[2][j]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        (0..3).all(|i| (a[i] - b[i]).abs() < 1e-14)
    }

    #[test]
    fn rodrigues_about_z_is_about_z() {
        let (c, s) = (0.3f64.cos(), 0.3f64.sin());
        let a = Frame::about([0.0, 0.0, 1.0], c, s);
        let b = Frame::about_z(c, s);
        assert_eq!(a.r, b.r);
    }

    #[test]
    fn inverse_undoes() {
        let k = crate::scalar::unit([1.0, 2.0, 2.0]);
        let mut f = Frame::about(k, 0.7f64.cos(), 0.7f64.sin());
        f.t = [1.0, -2.0, 3.0];
        let p = [0.5, 0.25, -4.0];
        assert!(close(f.inverse().apply(f.apply(p)), p));
        assert!(close(f.apply_back(f.apply(p)), p));
        assert!(close(f.then(&f.inverse()).apply(p), p));
    }
}
