//! The joint value that carries a point of the new link to a known position:
//! a turn about the joint's axis (Paden–Kahan subproblem 1) or a slide (the
//! projection onto the guide).

use super::search::{reversed, Search};
use super::{pa_plane, Found, Geometry, JointValue, Motion, Move, RESIDUAL_ROWS};
use crate::frame::Frame;
use crate::plan::{v3, Anchor, ByMiss, Step};
use crate::scalar::{dot, scale, sub, Scalar};
use crate::singular::{joint_point, Condition, Configuration, Factor, LinkPoint};
use crate::solution::{PointRef, SolveError};
use crate::subproblems::rotate_onto::turn;

/// The value of the joint that brings `point` of the new link onto the
/// anchored position `target`.
pub fn execute<T: Scalar>(mv: &Move<'_, T>, point: PointRef, target: &Anchor) -> Result<Found<T>, SolveError> {
    let (_, m) = mv.motion(point);
    let target = mv.geometry.anchor(&mv.state.poses, target);
    Ok(match m {
        Motion::Circle {
            centre, axis, radius, ..
        } => {
            let ([c, s], [cos, sin]) = turn(axis, radius, sub(target, centre), mv.site()).map_err(|e| mv.fail(e))?;
            // The angle from the terms before they are normalised: the
            // same angle, two roundings fewer, and no square root on its way.
            mv.at(JointValue::Turn(cos, sin, Some(s.atan2(c))))
        }
        Motion::Line { start, along } => mv.at(JointValue::Slide(dot(sub(target, start), along))),
    })
}

/// The closure rows of the joint the aim `by.aim` left open
/// ([`crate::plan::Plan::by_miss`]) without the aimed link's pose: the
/// joint's [`super::JointGeometry::closure_residual`] with that link at the aim's
/// zero (its axis rows are the same: the turn keeps the joint's axis), its
/// centres' rows the [`miss`] (or, after a parallelogram plane, the
/// sphere's, [`pa_plane::sphere_miss`]). The same motion and target as
/// [`execute`]'s, so solved code forms them once. The misses are lengths
/// to first order, not the centres' difference as a vector.
pub(crate) fn closure<T: Scalar>(
    geometry: &Geometry<T>,
    poses: &[Frame<T>],
    steps: &[Step],
    by: &ByMiss,
    extent: T,
) -> [T; RESIDUAL_ROWS] {
    let aim = &steps[by.aim];
    let Step::Aim {
        joint,
        from,
        to,
        point,
        target,
    } = aim
    else {
        return [T::c(f64::NAN); RESIDUAL_ROWS];
    };
    let j = &geometry.joints[*joint];
    let forward = j.links[0] == *from;
    let q = geometry.anchor(poses, target);
    // The known link's pose (at the plane's zero where a plane turned it)
    // and the point's miss from there.
    let (known, d) = match by.plane.map(|kp| &steps[kp]) {
        Some(plane @ Step::PaPlane { from: f, .. }) => {
            let (known, m) = pa_plane::swing(geometry, &poses[*f], plane, aim);
            (known, pa_plane::sphere_miss(m, q))
        }
        _ => (
            poses[*from],
            miss(j.motion(&poses[*from], forward, geometry.local(*point, *to)), q),
        ),
    };
    let unturned = known.then(&j.zero[usize::from(!forward)]);
    let o = &geometry.joints[by.joint];
    let (mut rows, sign) = if o.links[0] == *to {
        (o.closure_residual(&unturned, &poses[o.links[1]], extent), 1.0)
    } else {
        (o.closure_residual(&poses[o.links[0]], &unturned, extent), -1.0)
    };
    rows[..3].copy_from_slice(&scale(T::c(sign), d));
    rows
}

/// Whether the aim `step`'s motion keeps the axis of joint `o` on the aimed
/// link: a slide or a parallelogram's swing turns nothing, a revolute keeps
/// an axis parallel to its own.
pub(crate) fn keeps_axis(geometry: &Geometry<f64>, step: &Step, o: usize) -> bool {
    let Step::Aim { joint, from, .. } = step else {
        return false;
    };
    let j = &geometry.joints[*joint];
    let forward = j.links[0] == *from;
    let Some(k) = j.turning_axis(&Frame::identity(), forward) else {
        return true;
    };
    let aimed = j.zero[usize::from(!forward)];
    let og = &geometry.joints[o];
    let side = usize::from(og.links[0] != j.links[usize::from(forward)]);
    Search::parallel(v3(aimed.then(&og.frames[side]).column(2)), v3(k))
}

/// How far the aim leaves its point from the target, known before the
/// turn and without a square root: a turn about `k` carries `p⊥` (of length
/// `rp`, the motion's exact `length`) onto `q⊥`'s direction and keeps the
/// axial parts (`p`, `q` from the circle's centre), so it misses by
/// `rp − |q⊥|` across the axis and `k·(p − q)` along it. The rows are
/// `[(rp² − |q⊥|²)/(2·rp), k·(p − q), 0]`: the first is `rp − |q⊥|` to
/// first order (times `(rp + |q⊥|)/(2·rp)`), zero exactly when it is and
/// never small when it is not (`rp/2` with the target on the axis). A
/// slide leaves `−(Q − start)⊥` (normal to the guide), as a vector. Zero,
/// to rounding, exactly when the joint beyond closes.
///
/// ```
/// use pkm_runtime::steps::aim::miss;
/// use pkm_runtime::steps::Motion;
///
/// // Radius 1 about z, 0.5 up; the target at 3 from the axis, 2 up: the
/// // point lands 2 short across the axis, (1 − 9)/2 = −4 to first order,
/// // and 1.5 below it.
/// let m = Motion::Circle { centre: [0.0; 3], axis: [0.0, 0.0, 1.0], radius: [1.0, 0.0, 0.5], length: 1.0 };
/// assert_eq!(miss(m, [0.0, 3.0, 2.0]), [-4.0, -1.5, 0.0]);
/// ```
pub fn miss<T: Scalar>(m: Motion<T>, target: [T; 3]) -> [T; 3] {
    use crate::scalar::reject;
    match m {
        Motion::Circle {
            centre,
            axis,
            radius,
            length,
        } => {
            let q = sub(target, centre);
            let up = reject(q, axis);
            let across = (length * length - dot(up, up)) * (T::c(0.5) / length);
            [across, dot(axis, sub(radius, q)), T::c(0.0)]
        }
        Motion::Line { start, along } => scale(T::c(-1.0), reject(sub(target, start), along)),
    }
}

/// The planner's match: a point of the new link that stays put along a
/// reach to a known link (or to a pinned link at its pin, the new link's
/// own pin too): the joint turns or slides the point onto it.
pub(crate) fn find(s: &mut Search<'_>) -> bool {
    // From the links known at the start (the base, a placed output link)
    // first: a link aimed from there composes no rotation, and a joint
    // output is then the step's own angle (the four-bar's rocker). Deeper
    // links are not ranked by depth: aiming the five-bar's distal link
    // from the other arm moved its output point off the step that solved
    // it and tripled its worst error next to concentric circles.
    // Among the rest, a joint coaxial with another of the new link's
    // joints first (a compound hinge): that joint's axis does not move with
    // the turn, so what later steps read from it does not wait for the aim.
    let mut candidates = s.candidates();
    candidates.sort_by_cached_key(|&(j, from, to)| (!s.at_start[from], !s.carries_coaxial(j, to)));
    for (j, from, to) in candidates {
        let mut points = s.points_of(to, j);
        // A link pinned off its joints: its pin, aimed back onto itself
        // (not by the joint whose axis holds it: every turn would do).
        if let (Some(pin), Some(x)) = (super::locus::pin::pin_of(s, to), s.pins[to]) {
            if !s.on_axis(j, to, x) && !points.iter().any(|&(_, y)| s.pinned_at(to, y)) {
                points.push((pin, x));
            }
        }
        for (point, x) in points {
            // A known link, or a pinned one at its pin (the new link's own pin too).
            let found = s
                .fixed_reach(to, x, &[j])
                .into_iter()
                .find(|r| (s.known[r.link] && !r.hops.is_empty()) || s.pinned_at(r.link, r.x));
            if let Some(r) = found {
                let target = Anchor {
                    link: r.link,
                    hops: reversed(&r.hops),
                    point,
                };
                let step = Step::Aim {
                    joint: j,
                    from,
                    to,
                    point,
                    target,
                };
                s.push(step, to, j);
                return true;
            }
        }
    }
    false
}

/// The aim's factor: the moving point's distance from the joint's axis, in
/// units of the model's size (0: the point is on the axis, every turn aims it).
pub(crate) fn factor(
    at: &Configuration,
    k: usize,
    joint: usize,
    from: usize,
    to: usize,
    point: PointRef,
    target: &Anchor,
) -> Factor {
    let (_, t) = at.path(joint, from, to, point);
    Factor {
        step: k,
        joint,
        condition: Condition::OnAxis,
        points: [
            joint_point(joint, from),
            LinkPoint { link: to, point },
            at.anchored(target).1,
        ],
        // The point's distance from the axis, in units of the size.
        value: (t.norm() / at.scale).min(1.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::subproblems::rotate_onto::turn_onto;

    /// The miss against the point the turn really puts there (Rodrigues'
    /// formula at turn_onto's angle), for oblique axes and axial offsets:
    /// across the axis `rp − |q⊥|` times `(rp + |q⊥|)/(2·rp)`, along it
    /// the axial part.
    #[test]
    fn miss_is_where_the_turn_leaves_the_point() {
        use crate::scalar::{add, cross, norm, reject, scale, sub, unit};
        type V = [f64; 3];
        let cases: [(V, V, V, V); 3] = [
            ([0.0, 0.0, 1.0], [1.0, 2.0, 0.5], [2.0, -1.0, 3.0], [0.5, -3.0, 1.0]),
            ([1.0, 2.0, 2.0], [0.2, -0.3, 1.0], [3.0, 1.0, -2.0], [-1.0, 4.0, 0.0]),
            ([0.0, 1.0, 0.0], [5.0, 0.0, 0.0], [0.0, 7.0, 5.0], [0.0, 0.0, 0.0]),
        ];
        for (k, centre, radius, target) in cases {
            let k = unit(k);
            let length = norm(reject(radius, k));
            let [c, s] = turn_onto(k, radius, sub(target, centre), [0, 0]).unwrap();
            // R(θ)r = r c + (k × r) s + k (k·r)(1 − c).
            let turned = add(
                add(scale(c, radius), scale(s, cross(k, radius))),
                scale(dot(k, radius) * (1.0 - c), k),
            );
            let d = sub(add(centre, turned), target);
            let q = reject(sub(target, centre), k);
            let (n, across) = (norm(q), scale(1.0 / norm(q), q));
            let want = [dot(d, across) * (length + n) / (2.0 * length), dot(d, k), 0.0];
            let m = Motion::Circle {
                centre,
                axis: k,
                radius,
                length,
            };
            let got = miss(m, target);
            assert!(
                norm(sub(got, want)) < 1e-14 * norm(target).max(10.0).powi(2),
                "{got:?} vs {want:?}"
            );
            // Nothing is left across the axis but along the target's direction.
            assert!(norm(reject(reject(d, k), across)) < 1e-13, "{d:?}");
        }
        // A slide leaves the part normal to its guide.
        let line = Motion::Line {
            start: [1.0, 0.0, 0.0],
            along: [1.0, 0.0, 0.0],
        };
        assert_eq!(miss(line, [4.0, 2.0, -1.0]), [0.0, -2.0, 1.0]);
        // The target on the axis: half the radius, not nothing.
        let m = Motion::Circle {
            centre: [0.0; 3],
            axis: [0.0, 0.0, 1.0],
            radius: [2.0, 0.0, 0.0],
            length: 2.0,
        };
        assert_eq!(miss(m, [0.0, 0.0, 0.0]), [1.0, 0.0, 0.0]);
    }
}
