//! Three spheres meeting: the points at distances `ρ₁, ρ₂, ρ₃` from three
//! centres (trilateration), the position of a translating link three of
//! whose points are each held at a fixed distance from a known point (a
//! Delta's forearms).

use crate::primitives::Error as GeomError;
use crate::scalar::{cross, dot, norm, sub, Failure, Scalar};

/// The two points `p` with `|p − sᵢ| = ρᵢ` (`i = 1, 2, 3`), for every
/// [`Scalar`]; `choice` picks one. With `d = |s₂ − s₁|`, `eₓ = (s₂ − s₁)/d`,
/// `v = s₃ − s₁`, `i = eₓ·v`, `j = |v − i·eₓ|` and `e_y = (v − i·eₓ)/j`
/// (the centres' plane), the radical planes of the spheres meet in the
/// line through `s₁ + x·eₓ + y·e_y` along `e_z = eₓ × e_y`, where
/// `x = ((ρ₁ − ρ₂)(ρ₁ + ρ₂) + d²)/(2d)` and
/// `y = ((ρ₁ − ρ₃)(ρ₁ + ρ₃) + i² + j² − 2i·x)/(2j)` (no squared radii
/// subtracted); the line meets the first sphere at
/// `±√((ρ₁ − e)(ρ₁ + e))` along `e_z`, `e = |x·eₓ + y·e_y|` its distance
/// from `s₁` ([`crate::subproblems::line_sphere::line_distance`]). `Plus`
/// is the point on the side of the centres' plane that `eₓ × e_y` points
/// to. Within `TANGENCY_TOL·e` beyond tangency both are the double root in
/// the plane.
///
/// # Errors
/// [`GeomError::Degenerate`] where two centres coincide or the three are
/// on one line (within 10⁻¹² of their spread: the spheres then meet in a
/// circle, or not at all); [`GeomError::Unreachable`] where the spheres do
/// not meet, by how far the line of the radical planes passes outside the
/// first sphere.
///
/// ```
/// use pkm_runtime::primitives::Sign;
/// use pkm_runtime::subproblems::three_spheres::three_spheres;
///
/// // Radius √2 about the unit points of the three axes: (1, 1, 1) and
/// // (−1/3, −1/3, −1/3).
/// let s = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// let r = [2f64.sqrt(); 3];
/// let p = three_spheres(s, r, Sign::Plus, [0, 0]).unwrap();
/// let m = three_spheres(s, r, Sign::Minus, [0, 0]).unwrap();
/// let near = |a: [f64; 3], b: [f64; 3]| (0..3).all(|k| (a[k] - b[k]).abs() < 1e-15);
/// assert!(near(p, [1.0, 1.0, 1.0]) && near(m, [-1.0 / 3.0, -1.0 / 3.0, -1.0 / 3.0]));
/// ```
#[inline]
pub fn three_spheres<T: Scalar>(
    s: [[T; 3]; 3],
    rho: [T; 3],
    choice: T::Choice,
    site: [usize; 2],
) -> Result<[T; 3], GeomError<f64>> {
    let u = sub(s[1], s[0]);
    let v = sub(s[2], s[0]);
    let d = norm(u);
    let spread = d + norm(v);
    let together = Failure::Degenerate("two of the three spheres' centres coincide");
    T::require(T::c(1e-12) * spread, d, together, site)?;
    let ex = [u[0] / d, u[1] / d, u[2] / d];
    let i = dot(ex, v);
    let w = [v[0] - i * ex[0], v[1] - i * ex[1], v[2] - i * ex[2]];
    let j = norm(w);
    let inline = Failure::Degenerate("the three spheres' centres are on one line");
    T::require(T::c(1e-12) * spread, j, inline, site)?;
    let ey = [w[0] / j, w[1] / j, w[2] / j];
    let ez = cross(ex, ey);
    let two = T::c(2.0);
    let x = ((rho[0] - rho[1]) * (rho[0] + rho[1]) + d * d) / (two * d);
    let y = ((rho[0] - rho[2]) * (rho[0] + rho[2]) + i * i + j * j - two * i * x) / (two * j);
    let foot: [T; 3] = core::array::from_fn(|k| s[0][k] + x * ex[k] + y * ey[k]);
    let [plus, minus] = crate::subproblems::line_sphere::line_distance(foot, ez, s[0], rho[0], site)?;
    let t = T::pick(choice, plus, minus);
    Ok(core::array::from_fn(|k| foot[k] + t * ez[k]))
}

#[cfg(test)]
mod tests {
    use super::three_spheres;
    use crate::primitives::Sign;

    /// Points placed by hand: each root at the given distances from the
    /// centres (to rounding), on the side its sign names, and the two
    /// mirror images in the centres' plane.
    #[test]
    fn both_points_at_the_three_distances() {
        let s: [[f64; 3]; 3] = [[100.0, -20.0, 5.0], [-40.0, 90.0, -10.0], [-60.0, -70.0, 30.0]];
        for p in [[10.0f64, 20.0, -300.0], [3.0, -7.0, 250.0], [0.5, 0.25, 40.0]] {
            let rho: [f64; 3] = core::array::from_fn(|i| (0..3).map(|k| (p[k] - s[i][k]).powi(2)).sum::<f64>().sqrt());
            let found = [Sign::Plus, Sign::Minus].map(|c| three_spheres(s, rho, c, [0, 0]).unwrap());
            for q in found {
                for i in 0..3 {
                    let d = (0..3).map(|k| (q[k] - s[i][k]).powi(2)).sum::<f64>().sqrt();
                    assert!((d - rho[i]).abs() <= 1e-12 * rho[i], "{q:?} {i}");
                }
            }
            let off = |q: [f64; 3]| (0..3).map(|k| (q[k] - p[k]).abs()).fold(0.0, f64::max);
            assert!(off(found[0]).min(off(found[1])) <= 1e-12 * 300.0, "{found:?} {p:?}");
        }
        // Out of reach, and on one line.
        assert!(three_spheres(s, [1.0; 3], Sign::Plus, [0, 0]).is_err());
        let line = [[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
        assert!(three_spheres(line, [3.0; 3], Sign::Plus, [0, 0]).is_err());
    }
}
