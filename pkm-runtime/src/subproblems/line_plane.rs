//! A slide onto a plane: one division, refused where the slide runs
//! parallel to the plane.

use crate::primitives::Error as GeomError;
use crate::scalar::{Failure, Scalar};

/// The slide `[num / den, 0]` onto a plane, `num` the plane's offset from
/// the line's start along the normal, `den` the normal's component along
/// the line, `scale` the normal's length.
///
/// # Errors
/// [`GeomError::Degenerate`] when the slide is parallel to the plane
/// (`|den| ≤ 1e-12·scale`).
///
/// ```
/// use pkm_runtime::subproblems::line_plane::line_plane;
///
/// assert_eq!(line_plane(3.0, 2.0, 2.0, [0, 0]).unwrap(), [1.5, 0.0]);
/// assert!(line_plane(3.0, 0.0, 2.0, [0, 0]).is_err());
/// ```
#[inline]
pub fn line_plane<T: Scalar>(num: T, den: T, scale: T, site: [usize; 2]) -> Result<[T; 2], GeomError<f64>> {
    let parallel = Failure::Degenerate("the slide is parallel to the plane it must reach");
    T::require(T::c(1e-12) * scale, den.abs(), parallel, site)?;
    Ok([num / den, T::c(0.0)])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The line `start + t·along` onto the plane `n·x = offset`, by the
    /// caller's terms (`num = offset − n·start`, `den = n·along`): the point
    /// at the slide returned lies on the plane.
    #[test]
    fn slides_onto_the_plane_and_refuses_a_parallel_slide() {
        let (start, along, n, offset) = ([1.0, 2.0, 0.0], [1.0, 1.0, 1.0], [0.0, 0.0, 2.0], 6.0);
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let [t, zero] = line_plane(offset - dot(n, start), dot(n, along), 2.0, [0, 0]).unwrap();
        // By hand: z = 3 is reached at t = 3, the point (4, 5, 3).
        assert_eq!((t, zero), (3.0, 0.0));
        let at = [
            start[0] + t * along[0],
            start[1] + t * along[1],
            start[2] + t * along[2],
        ];
        assert_eq!(at, [4.0, 5.0, 3.0]);
        // Parallel, and within 1e-12 of the normal's length of parallel: refused.
        for den in [0.0, 1e-12 * 2.0, -1e-13] {
            match line_plane(6.0, den, 2.0, [0, 0]) {
                Err(GeomError::Degenerate { what }) => assert!(what.contains("parallel"), "{what}"),
                got => panic!("den {den}: {got:?}"),
            }
        }
        // Just beyond that: a (long) slide.
        assert_eq!(line_plane(6.0, 1e-11, 2.0, [0, 0]).unwrap()[0], 6.0 / 1e-11);
    }
}
