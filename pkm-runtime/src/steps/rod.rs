//! A link with a spherical joint. Every point of it keeps its distance
//! from the joint's centre, so once that centre is known, a point of the
//! new link that reaches the link without moving (at its other spherical
//! centre: an S–S link, a rod, the coupler of an RSSR four-bar; on a
//! revolute's axis: an R–S leg of a 3-PRS, a U–S coupler) lies on the
//! sphere about it ([`find_sphere`]; the circle or line meeting the sphere
//! is [`super::locus::sphere`]'s). A link ending in spherical joints at both
//! ends, both centres known, is placed between them ([`execute`]).
//!
//! Such an S–S link has an idle spin about its S–S line: no joint value or
//! output sees it, the topology does not count it (a local DOF), and a
//! position solution must still give the link a pose. The convention
//! ([`carry_line`]): the link is turned from the world's axes by the
//! smallest rotation that carries its S–S line, as drawn in its own frame
//! (from the centre on the known link to the other), onto the line between
//! the two centres. Its rotation's axis is normal to both lines, so a
//! direction normal to both keeps its world direction. It is defined
//! unless the link points exactly against its drawn direction (a typed
//! error within [`ANTIPODAL_TOL`]). A point of the link off its S–S line
//! moves with this convention; its centres, and everything else, do not
//! depend on it.

use super::search::{reversed, Reach, Search};
use super::{Found, Geometry, JointValue, Move};
use crate::frame::Frame;
use crate::model::JointType;
use crate::plan::{v3, Anchor, Constraint, Radius, Step};
use crate::primitives::Error as GeomError;
use crate::scalar::{add, cross, dot, norm, sub, unit, Scalar};
use crate::solution::{PointRef, SolveError};

/// How near (in `1 + cos`, the cosine between the drawn and the found
/// S–S line) the link may come to pointing against its drawn direction
/// before its spin is refused as undetermined: `1e-9`, about 4.5e-5 rad
/// from antipodal, where the turn's axis still has about eleven digits.
pub const ANTIPODAL_TOL: f64 = 1e-9;

/// The distance, fixed on `link`, of its `point` from the centre of its
/// spherical joint `joint` (in its frame; prepared once): an S–S link's
/// length when the point is its other centre.
pub fn length<T: Scalar>(geometry: &Geometry<T>, link: usize, point: PointRef, joint: usize) -> T {
    let a = geometry.local(point, link);
    let b = geometry.local(PointRef::Joint(joint), link);
    norm(sub(b, a))
}

/// The S–S link placed with its centre of `joint` at that joint's centre
/// on the known link and its centre of `other` towards the anchored
/// `target`, turned by [`carry_line`]. The joint is spherical: it has no
/// one value (as [`super::JointGeometry::value_between`] says, NaN). The
/// distance between the centres is not imposed here: `other` stays open,
/// and its closure (the centres only) checks it.
pub fn execute<T: Scalar>(mv: &Move<'_, T>, other: usize, target: &Anchor) -> Result<Found<T>, SolveError> {
    let p = mv.state.poses[mv.from].apply(mv.geometry.local(PointRef::Joint(mv.joint), mv.from));
    let q = mv.geometry.anchor(&mv.state.poses, target);
    let c1 = mv.geometry.local(PointRef::Joint(mv.joint), mv.to);
    let c2 = mv.geometry.local(PointRef::Joint(other), mv.to);
    let r = carry_line(sub(c2, c1), sub(q, p), mv.site()).map_err(|e| mv.fail(e))?;
    let turned = Frame { r, t: [T::c(0.0); 3] };
    let pose = Frame {
        r,
        t: sub(p, turned.apply(c1)),
    };
    Ok((mv.joint, mv.to, pose, JointValue::Slide(T::c(f64::NAN))))
}

/// The smallest rotation that carries the direction of `u` onto that of
/// `w` (the S–S link's convention), for every [`Scalar`]: with `û`, `ŵ`
/// their unit vectors, `v = û × ŵ` and `1 + c = |û + ŵ|²/2` (`c = û·ŵ`,
/// formed without cancelling near antipodal lines),
/// `R = c·I + [v]ₓ + v vᵀ/(1 + c)`, the turn by `acos c` about `v`
/// (Rodrigues with `(1 − c)/|v|² = 1/(1 + c)`). A vector normal to both
/// keeps its direction.
///
/// # Errors
/// [`GeomError::Degenerate`] where `1 + c` is below [`ANTIPODAL_TOL`]
/// (every turn about a normal carries `û` onto `ŵ = −û`) or either vector
/// is zero.
///
/// ```
/// use pkm_runtime::steps::rod::carry_line;
///
/// // x onto y: a quarter turn about z.
/// let r = carry_line([2.0, 0.0, 0.0], [0.0, 3.0, 0.0], [0, 0]).unwrap();
/// assert_eq!(r, [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]);
/// ```
pub fn carry_line<T: Scalar>(u: [T; 3], w: [T; 3], site: [usize; 2]) -> Result<[[T; 3]; 3], GeomError<f64>> {
    use crate::scalar::Failure;
    let zero = T::c(0.0);
    T::require(zero, dot(u, u), Failure::Degenerate("the S–S link has no length"), site)?;
    T::require(
        zero,
        dot(w, w),
        Failure::Degenerate("the S–S link's centres coincide"),
        site,
    )?;
    let (u, w) = (unit(u), unit(w));
    let s = add(u, w);
    let one_plus = dot(s, s) * T::c(0.5);
    T::require(
        T::c(ANTIPODAL_TOL),
        one_plus,
        Failure::Degenerate("the S–S link points against its drawn direction: its spin is undetermined"),
        site,
    )?;
    let c = dot(u, w);
    let v = cross(u, w);
    let k = T::c(1.0) / one_plus;
    let entry = |i: usize, j: usize| {
        let skew = match (i, j) {
            (0, 1) => -v[2],
            (0, 2) => v[1],
            (1, 0) => v[2],
            (1, 2) => -v[0],
            (2, 0) => -v[1],
            (2, 1) => v[0],
            _ => zero,
        };
        let diagonal = if i == j { c } else { zero };
        diagonal + skew + v[i] * v[j] * k
    };
    Ok(std::array::from_fn(|i| std::array::from_fn(|j| entry(i, j))))
}

/// The planner's match: an S–S link placed between its two known centres
/// (tried first, no branch), or else a point of the new link on the sphere
/// about a link's known spherical centre ([`find_sphere`], through the
/// locus steps' search, [`super::find_locus_by`]).
pub(crate) fn find(s: &mut Search<'_>) -> bool {
    find_rod(s) || super::find_locus_by(s, true, true)
}

/// The two spherical joints of `link` when they are its only joints.
fn rod_joints(s: &Search<'_>, link: usize) -> Option<[usize; 2]> {
    let joints: Vec<usize> = (0..s.model.joints.len())
        .filter(|&k| s.model.joints[k].links.contains(&link))
        .collect();
    match joints[..] {
        [a, b] if s.kind(a) == JointType::S && s.kind(b) == JointType::S => Some([a, b]),
        _ => None,
    }
}

/// Where the centre of spherical joint `o`, on the side away from `rod`,
/// is known: along a reach from the link beyond `o` to a known link.
fn centre_beyond(s: &Search<'_>, rod: usize, o: usize, exclude: &[usize]) -> Option<Anchor> {
    let beyond = s.other(o, rod);
    let b = v3(s.place(o, beyond).at());
    let c = s
        .fixed_reach(beyond, b, exclude)
        .into_iter()
        .find(|c| s.known[c.link])?;
    Some(Anchor {
        link: c.link,
        hops: reversed(&c.hops),
        point: PointRef::Joint(o),
    })
}

/// An unknown link whose only joints are two spherical ones, one on a
/// known link, the other's centre known: [`Step::Rod`].
fn find_rod(s: &mut Search<'_>) -> bool {
    for to in 0..s.model.links.len() {
        if s.known[to] {
            continue;
        }
        let Some([a, b]) = rod_joints(s, to) else { continue };
        for (j, o) in [(a, b), (b, a)] {
            let from = s.other(j, to);
            if !s.known[from] || s.used[j] || s.used[o] {
                continue;
            }
            if let Some(target) = centre_beyond(s, to, o, &[j, o]) {
                let step = Step::Rod {
                    joint: j,
                    from,
                    to,
                    other: o,
                    target,
                };
                s.push(step, to, j);
                return true;
            }
        }
    }
    false
}

/// The planner's match for the sphere a link with a known spherical
/// centre holds a point on: the reach `r` carries the point of the new
/// link (moved by `j`) to unknown link `r.link` without moving it, and
/// `q`, a spherical joint of `r.link`, has its centre known along a reach
/// beyond it (the sphere's centre); or `q` is a revolute of `r.link` whose
/// place is known along a reach across it (a U's centre, its cross and the
/// link beyond turning about axes through it). A rigid link keeps every point's
/// distance from that centre, so the point lies on the sphere whose radius
/// is its distance there: an S–S link's length (the point at its other
/// centre), or an R–S or U–S link's, the point on the revolute's axis.
/// The point is named on `r.link` as a joint's place there (the joint the
/// reach entered by first); none, or a point at the centre, is no match.
pub(crate) fn find_sphere(s: &Search<'_>, j: usize, r: &Reach, q: usize) -> Option<Constraint> {
    if !matches!(s.kind(q), JointType::S | JointType::R) {
        return None;
    }
    let centre = v3(s.place(q, r.link).at());
    if (r.x - centre).norm() <= s.tol {
        return None;
    }
    let entered = r.hops.last().map(|h| h.joint);
    let point = entered
        .into_iter()
        .chain((0..s.model.joints.len()).filter(|&k| Some(k) != entered))
        .find(|&k| {
            k != q && s.model.joints[k].links.contains(&r.link) && (r.x - v3(s.place(k, r.link).at())).norm() <= s.tol
        })?;
    let mut excl = vec![j, q];
    excl.extend(r.hops.iter().map(|h| h.joint));
    let centre = if s.kind(q) == JointType::S {
        centre_beyond(s, r.link, q, &excl)?
    } else {
        // A revolute's place held by its own axis and those beyond (a U's
        // centre on the link beyond a known one): the reach starts here.
        excl.retain(|&k| k != q);
        let c = s
            .fixed_reach(r.link, centre, &excl)
            .into_iter()
            .find(|c| s.known[c.link] && !c.hops.is_empty())?;
        Anchor {
            link: c.link,
            hops: reversed(&c.hops),
            point: PointRef::Joint(q),
        }
    };
    // A centre on the moving joint's own axis, known on the link the joint
    // turns from, is as far from every point of the circle: the sphere
    // would hold at every turn or at none (a spherical chain's common
    // centre), no equation for the joint.
    let from = s.model.joints[j].links.into_iter().find(|&l| s.known[l])?;
    if centre.link == from && s.on_axis(j, from, v3(s.geometry.anchor_local(&centre))) {
        return None;
    }
    Some(Constraint::Sphere {
        centre,
        radius: Radius::Rod {
            link: r.link,
            point: PointRef::Joint(point),
            joint: q,
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What [`carry_line`] should give: the rotation by hand, or a
    /// degeneracy naming this word.
    fn check(u: [f64; 3], w: [f64; 3], want: Result<[[f64; 3]; 3], &str>) {
        match (carry_line(u, w, [0, 0]), want) {
            (Ok(r), Ok(m)) => {
                for i in 0..3 {
                    for j in 0..3 {
                        assert!((r[i][j] - m[i][j]).abs() < 1e-15, "{u:?} → {w:?}: {r:?} vs {m:?}");
                    }
                }
            }
            (Err(GeomError::Degenerate { what }), Err(word)) => assert!(what.contains(word), "{what}"),
            (got, want) => panic!("{u:?} → {w:?}: {got:?} vs {want:?}"),
        }
    }

    #[test]
    fn carries_lines_by_the_smallest_turn() {
        let h = 0.5f64.sqrt();
        // The same direction: no turn.
        check(
            [3.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            Ok([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]),
        );
        // x onto z: a quarter turn about x × z = −y.
        check(
            [1.0, 0.0, 0.0],
            [0.0, 0.0, 5.0],
            Ok([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]),
        );
        // x onto (1, 1, 0): an eighth turn about z.
        check(
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            Ok([[h, -h, 0.0], [h, h, 0.0], [0.0, 0.0, 1.0]]),
        );
        // z onto −z is no one turn; nor is a point.
        check([0.0, 0.0, 2.0], [0.0, 0.0, -1.0], Err("against its drawn direction"));
        check([0.0, 0.0, 2.0], [1e-6, 0.0, -1.0], Err("against its drawn direction"));
        check([0.0; 3], [1.0, 0.0, 0.0], Err("no length"));
        check([1.0, 0.0, 0.0], [0.0; 3], Err("coincide"));
    }

    /// By hand for a generic pair: `R û = ŵ`, the common normal `n = û × ŵ`
    /// kept, `R (n × û) = n × ŵ` (the turn by the angle between them about
    /// `n`), and `R` orthonormal, near antipodal lines too.
    #[test]
    fn the_turn_keeps_the_common_normal() {
        let cases = [
            ([1.0, 2.0, 2.0], [-2.0, 1.0, 0.5]),
            ([0.3, -0.4, 1.2], [0.1, 0.9, -0.2]),
            // 1e-3 rad from antipodal.
            ([1.0, 0.0, 0.0], [-(1e-3f64.cos()), 1e-3f64.sin(), 0.0]),
        ];
        for (u, w) in cases {
            let r = carry_line(u, w, [0, 0]).unwrap();
            let f = Frame { r, t: [0.0; 3] };
            let (uh, wh) = (unit(u), unit(w));
            let n = unit(cross(uh, wh));
            let close = |a: [f64; 3], b: [f64; 3]| norm(sub(a, b)) < 1e-14;
            assert!(close(f.apply(uh), wh), "{u:?} {w:?}");
            assert!(close(f.apply(n), n), "{u:?} {w:?}");
            assert!(close(f.apply(cross(n, uh)), cross(n, wh)), "{u:?} {w:?}");
            for i in 0..3 {
                for j in 0..3 {
                    let g: f64 = (0..3).map(|k| r[k][i] * r[k][j]).sum();
                    assert!((g - f64::from(u8::from(i == j))).abs() < 1e-14, "{u:?} {w:?}");
                }
            }
        }
        // A scale on either vector changes nothing.
        let a = carry_line([1.0, 2.0, 2.0], [-2.0, 1.0, 0.5], [0, 0]).unwrap();
        let b = carry_line([3.0, 6.0, 6.0], [-8.0, 4.0, 2.0], [0, 0]).unwrap();
        assert!(a
            .iter()
            .flatten()
            .zip(b.iter().flatten())
            .all(|(x, y)| (x - y).abs() < 1e-15));
    }
}
