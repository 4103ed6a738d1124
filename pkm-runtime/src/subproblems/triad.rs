//! The rotation that carries an orthonormal pair onto another (TRIAD).

use crate::scalar::{cross, Scalar};

/// The rotation that carries the orthonormal pair `local` onto the
/// orthonormal pair `world` (the TRIAD method): `[a, b, a × b]` in the world
/// times the transpose of the same in the link.
///
/// ```
/// use pkm_runtime::subproblems::triad::triad;
///
/// // x, y onto y, −x: a quarter turn about z.
/// let r = triad([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]], [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
/// assert_eq!(r, [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]);
/// ```
pub fn triad<T: Scalar>(world: [[T; 3]; 2], local: [[T; 3]; 2]) -> [[T; 3]; 3] {
    let w = [world[0], world[1], cross(world[0], world[1])];
    let l = [local[0], local[1], cross(local[0], local[1])];
    std::array::from_fn(|i| std::array::from_fn(|j| w[0][i] * l[0][j] + w[1][i] * l[1][j] + w[2][i] * l[2][j]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Frame;
    use crate::scalar::{add, dot, norm, scale, sub, unit};

    /// Rodrigues' rotation about unit `k` by `theta`, by rows, written out.
    fn rodrigues(k: [f64; 3], theta: f64) -> [[f64; 3]; 3] {
        let (s, c) = theta.sin_cos();
        let e = |i: usize| std::array::from_fn::<f64, 3, _>(|j| f64::from(u8::from(i == j)));
        let col = |v: [f64; 3]| add(add(scale(c, v), scale(s, cross(k, v))), scale(dot(k, v) * (1.0 - c), k));
        let cols = [col(e(0)), col(e(1)), col(e(2))];
        std::array::from_fn(|i| std::array::from_fn(|j| cols[j][i]))
    }

    /// The frame from two directions is the rotation that made them: a
    /// slanted turn carries an orthonormal pair of the link into the world.
    #[test]
    fn triad_recovers_the_rotation_that_carried_the_pair() {
        let pairs = [
            ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
            (unit([1.0, 2.0, 2.0]), unit([2.0, -1.0, 0.0])),
            (unit([0.0, -3.0, 4.0]), [1.0, 0.0, 0.0]),
        ];
        for (k, theta) in [
            ([0.0, 0.0, 1.0], 0.3),
            (unit([1.0, -2.0, 0.5]), 2.9),
            (unit([3.0, 1.0, 1.0]), -1.7),
        ] {
            let r = rodrigues(k, theta);
            let turned = Frame { r, ..Frame::identity() };
            for (a, b) in pairs {
                let got = triad([turned.rotate(a), turned.rotate(b)], [a, b]);
                for i in 0..3 {
                    assert!(norm(sub(got[i], r[i])) < 1e-15, "{got:?} vs {r:?}");
                }
            }
        }
    }
}
