//! A revolute's angle that puts a parallelogram's plane through a known
//! point (the other hinge): `a·cosθ + b·sinθ = c`, the root nearer 0.

use super::search::{reversed, Search};
use super::{Found, Move};
use crate::model::JointType;
use crate::primitives::Error as GeomError;
use crate::scalar::{cross, dot, scale, sub, Scalar};
use crate::singular::{crossing, joint_point, Condition, Configuration, Factor};
use crate::solution::PointRef;
use crate::solution::SolveError;
use crate::spatial::v3;
use crate::spatial::{Anchor, Step};

/// The angle of the revolute that puts parallelogram `pa`'s plane (its
/// hinge on the new link) through the anchored point `target`.
pub fn execute<T: Scalar>(mv: &Move<'_, T>, pa: usize, target: &Anchor) -> Result<Found<T>, SolveError> {
    let (axis, zero) = mv.turning("a parallelogram turned by a non-revolute")?;
    let p = &mv.geometry.joints[pa];
    let side = usize::from(p.links[0] != mv.to);
    let normal = zero.rotate(super::place_axis(&p.places[side]));
    let hinge = zero.apply(p.places[side].at());
    let target = mv.geometry.anchor(&mv.state.poses, target);
    Ok(mv.found(pa_plane(axis, normal, hinge, target, mv.site()).map_err(|e| mv.fail(e))?))
}

/// The turn about unit `k` that puts the plane through `hinge` with normal
/// `n` (at angle 0) through `target`: `(n⊥·u) cosθ + ((k × n⊥)·u) sinθ =
/// −(n∥·u)` with `u = target − hinge`. Of the two roots, the one nearer 0
/// (the larger cosine): the half-turned parallelogram moves its coupler the
/// same way.
///
/// ```
/// use pkm_runtime::steps::pa_plane::pa_plane;
///
/// // The plane x = 0 (normal x) about z, through (1, 1, 0): turned by ±45°;
/// // the root nearer 0 is −45° (the normal turned to (1, −1)/√2).
/// let z = [0.0, 0.0, 1.0];
/// let [c, s] = pa_plane(z, [1.0, 0.0, 0.0], [0.0; 3], [1.0, 1.0, 0.0], [0, 0]).unwrap();
/// assert!((c - 0.5f64.sqrt()).abs() < 1e-15 && (s + 0.5f64.sqrt()).abs() < 1e-15);
/// ```
#[inline]
pub fn pa_plane<T: Scalar>(
    k: [T; 3],
    n: [T; 3],
    hinge: [T; 3],
    target: [T; 3],
    site: [usize; 2],
) -> Result<[T; 2], GeomError<f64>> {
    let u = sub(target, hinge);
    let n_par = scale(dot(k, n), k);
    let n_perp = sub(n, n_par);
    let a = dot(n_perp, u);
    let b = dot(cross(k, n_perp), u);
    let c = -dot(n_par, u);
    let [p, m] = super::on_plane::trig_turns(a, b, c, site, None)?;
    // The root with the larger cosine.
    let nearer = |x: T, y: T| T::if_less(p[0], m[0], y, x);
    Ok([nearer(p[0], m[0]), nearer(p[1], m[1])])
}

/// The planner's match: a revolute whose axis carries the hinge of a
/// parallelogram on the new link (and is not parallel to the parallelogram's
/// axis), the other hinge staying put along a reach to a known link: the
/// revolute turns the parallelogram's plane through that hinge.
pub(crate) fn find(s: &mut Search<'_>) -> bool {
    for (j, from, to) in s.candidates() {
        if s.kind(j) != JointType::R {
            continue;
        }
        for (p, joint) in s.model.joints.iter().enumerate() {
            if p == j || joint.kind != JointType::Pa || !joint.links.contains(&to) {
                continue;
            }
            let hinge = v3(s.place(p, to).at());
            if !s.on_axis(j, to, hinge) || Search::parallel(s.axis(p, to), s.axis(j, to)) {
                continue;
            }
            let b = s.other(p, to);
            let x = v3(s.place(p, b).at());
            let found = s.fixed_reach(b, x, &[j, p]).into_iter().find(|r| s.known[r.link]);
            if let Some(r) = found {
                let step = Step::PaPlane {
                    joint: j,
                    from,
                    to,
                    pa: p,
                    target: Anchor {
                        link: r.link,
                        hops: reversed(&r.hops),
                        point: PointRef::Joint(p),
                    },
                };
                s.push(step, to, j);
                return true;
            }
        }
    }
    false
}

/// The parallelogram plane's factor: how fast the plane's normal turns
/// against the direction from its hinge to the target (0: the plane only
/// touches the target as the joint turns).
pub(crate) fn factor(
    at: &Configuration,
    k: usize,
    joint: usize,
    from: usize,
    to: usize,
    pa: usize,
    target: &Anchor,
) -> Factor {
    let (g, frames) = (&at.g, &at.frames);
    let j = &g.joints[joint];
    let k_axis = v3(j.turning_axis(&frames[from], j.links[0] == from).unwrap_or([0.0; 3]));
    let p = &g.joints[pa];
    let side = usize::from(p.links[0] != to);
    let n = v3(frames[to].rotate(super::place_axis(&p.places[side])));
    let hinge = v3(frames[to].apply(p.places[side].at()));
    let (c, point) = at.anchored(target);
    // d/dθ (n·u) = (k × n)·u: the plane's normal turning against the target's direction.
    Factor {
        step: k,
        joint,
        condition: Condition::PlaneTouches,
        points: [joint_point(joint, from), joint_point(pa, to), point],
        value: crossing(k_axis.cross(&n), c - hinge, at.scale),
    }
}
