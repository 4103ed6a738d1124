//! A revolute's angle that puts a parallelogram's plane through a known
//! point (the other hinge): `a·cosθ + b·sinθ = c`, two roots. Where the
//! parallelogram's axis is normal to the revolute's (`c = 0`: seed 000 A's
//! R5 and its parallelogram) they are half a turn apart, and both are
//! assemblies: the second turns the parallelogram's hinge and its arm by
//! π about the revolute's axis, and the parallelogram's swing beyond it
//! reaches the same hinge at π − its angle. The coupler beyond lands where
//! it did, but the links between (the revolute's link, the parallelogram's
//! bars, the coupler's turn about its next joint) are another posture, with
//! other forces where they carry mass off the revolute's axis.
//!
//! `Plus` is the root nearer the revolute's zero (the larger cosine), the
//! only root the plans took before they listed both, so those branches
//! keep their numbers; `Minus` the other. The labels change places where
//! the two roots are a quarter turn either side of the zero (for seed 000
//! A: where D passes the height of B3), so a posture is followed across
//! there by continuity (`fk_follow`), not by its signs.
use super::search::{reversed, Search};
use super::{Found, Geometry, Motion, Move};
use crate::frame::Frame;
use crate::model::JointType;
use crate::plan::v3;
use crate::plan::{Anchor, Step};
use crate::primitives::Error as GeomError;
use crate::scalar::{constant, cross, dot, scale, sub, Scalar};
use crate::singular::{crossing, joint_point, Condition, Configuration, Factor};
use crate::solution::PointRef;
use crate::solution::SolveError;

/// The angle of the revolute that puts parallelogram `pa`'s plane (its
/// hinge on the new link) through the anchored point `target`; `branch`
/// chooses the root ([`pa_plane`]).
pub fn execute<T: Scalar>(mv: &Move<'_, T>, pa: usize, target: &Anchor, branch: usize) -> Result<Found<T>, SolveError> {
    let (axis, zero) = mv.turning("a parallelogram turned by a non-revolute")?;
    let p = &mv.geometry.joints[pa];
    let side = usize::from(p.links[0] != mv.to);
    let normal = zero.rotate(super::place_axis(&p.places[side]));
    let hinge = zero.apply(p.places[side].at());
    let target = mv.geometry.anchor(&mv.state.poses, target);
    let turn = pa_plane(axis, normal, hinge, target, mv.choice(Some(branch)), mv.site()).map_err(|e| mv.fail(e))?;
    Ok(mv.found(turn))
}

/// The turn about unit `k` that puts the plane through `hinge` with normal
/// `n` (at angle 0) through `target`: `(n⊥·u) cosθ + ((k × n⊥)·u) sinθ =
/// −(n∥·u)` with `u = target − hinge`, [`crate::subproblems::trig::trig_turns`].
/// `Plus` is the root nearer 0 (the larger cosine; the first where the two
/// are equal), `Minus` the other: for `n ⊥ k` the plane half-turned, the
/// other posture of the parallelogram's leg (the module's).
///
/// ```
/// use pkm_runtime::primitives::Sign;
/// use pkm_runtime::steps::pa_plane::pa_plane;
///
/// // The plane x = 0 (normal x) about z, through (1, 1, 0): turned by −45°
/// // (Plus: nearer 0, the normal turned to (1, −1)/√2) or by 135° (Minus).
/// let z = [0.0, 0.0, 1.0];
/// let h = 0.5f64.sqrt();
/// let [c, s] = pa_plane(z, [1.0, 0.0, 0.0], [0.0; 3], [1.0, 1.0, 0.0], Sign::Plus, [0, 0]).unwrap();
/// assert!((c - h).abs() < 1e-15 && (s + h).abs() < 1e-15);
/// let [c, s] = pa_plane(z, [1.0, 0.0, 0.0], [0.0; 3], [1.0, 1.0, 0.0], Sign::Minus, [0, 0]).unwrap();
/// assert!((c + h).abs() < 1e-15 && (s - h).abs() < 1e-15);
/// ```
#[inline]
pub fn pa_plane<T: Scalar>(
    k: [T; 3],
    n: [T; 3],
    hinge: [T; 3],
    target: [T; 3],
    choice: T::Choice,
    site: [usize; 2],
) -> Result<[T; 2], GeomError<f64>> {
    let u = sub(target, hinge);
    let n_par = scale(dot(k, n), k);
    let n_perp = sub(n, n_par);
    let a = dot(n_perp, u);
    let b = dot(cross(k, n_perp), u);
    let c = -dot(n_par, u);
    let [p, m] = crate::subproblems::trig::trig_turns(a, b, c, site, None)?;
    // The root with the larger cosine, then the other.
    let nearer = |x: T, y: T| T::if_less(p[0], m[0], y, x);
    let farther = |x: T, y: T| T::if_less(p[0], m[0], x, y);
    let pick = |i: usize| T::pick(choice, nearer(p[i], m[i]), farther(p[i], m[i]));
    Ok([pick(0), pick(1)])
}

/// Numbers the plan's parallelogram planes' choices after every other
/// step's, from `first` (the other steps' count) in plan order, and gives
/// the plan's count of choices: the postures plans listed before a
/// plane branched keep their branch numbers (bit k of a branch's number is
/// choice k's sign), each plane's half-turned postures following them.
pub(crate) fn number_choices(steps: &mut [Step], first: usize) -> usize {
    let mut next = first;
    for s in steps {
        if let Step::PaPlane { branch, .. } = s {
            *branch = next;
            next += 1;
        }
    }
    next
}

/// The pose of the plane's known link at the plane's zero (from that of
/// the link it turns from, `from`) and the aim's point's motion as the
/// parallelogram swings from there: the aim `aim` across the plane's
/// parallelogram, which the plane's turn then carries about its axis.
pub(crate) fn swing<T: Scalar>(
    geometry: &Geometry<T>,
    from: &Frame<T>,
    plane: &Step,
    aim: &Step,
) -> (Frame<T>, Motion<T>) {
    let (
        Step::PaPlane { joint, from: f, .. },
        Step::Aim {
            joint: pa, to, point, ..
        },
    ) = (plane, aim)
    else {
        return (
            Frame::identity(),
            Motion::Line {
                start: constant([f64::NAN; 3]),
                along: constant([f64::NAN; 3]),
            },
        );
    };
    let j = &geometry.joints[*joint];
    let known = from.then(&j.zero[usize::from(j.links[0] != *f)]);
    let p = &geometry.joints[*pa];
    let m = p.motion(&known, p.links[0] != *to, geometry.local(*point, *to));
    (known, m)
}

/// How far a plane's turn and the swing across its parallelogram leave the
/// swung point from the target `Q`, where together they reach the whole
/// sphere about the swing's centre `c` (its axis normal to the plane's,
/// its arm normal to its own axis, the centre on the plane's axis, as the
/// planner checks): the point lands on the sphere towards `Q`, `r − |d|`
/// short of it (`d = Q − c`, `r` the swing's exact length). The rows are
/// `[(r² − |d|²)/(2·r), 0, 0]`, that distance to first order without a
/// square root ([`super::aim::miss`]'s form). Zero, to rounding, exactly
/// when the joint beyond closes.
///
/// ```
/// use pkm_runtime::steps::pa_plane::sphere_miss;
/// use pkm_runtime::steps::Motion;
///
/// // Radius 2 about the origin; the target 4 up: 2 short, (4 − 16)/4 = −3
/// // to first order.
/// let m = Motion::Circle { centre: [0.0; 3], axis: [0.0, 1.0, 0.0], radius: [0.0, 0.0, 2.0], length: 2.0 };
/// assert_eq!(sphere_miss(m, [0.0, 0.0, 4.0]), [-3.0, 0.0, 0.0]);
/// ```
pub fn sphere_miss<T: Scalar>(m: Motion<T>, target: [T; 3]) -> [T; 3] {
    match m {
        Motion::Circle { centre, length, .. } => {
            let d = sub(target, centre);
            let across = (length * length - dot(d, d)) * (T::c(0.5) / length);
            [across, T::c(0.0), T::c(0.0)]
        }
        Motion::Line { .. } => constant([f64::NAN; 3]),
    }
}

/// Whether the plane `plane` and the aim `aim` across its parallelogram
/// carry the aim's point over a whole sphere ([`sphere_miss`]), checked at
/// the model's dimensions within `tol`: if so, whether the turn keeps the
/// axis of the aim's open joint `o` (parallel to the plane's axis; the
/// swing turns nothing).
pub(crate) fn reaches_sphere(geometry: &Geometry<f64>, plane: &Step, aim: &Step, tol: f64) -> Option<bool> {
    use crate::scalar::norm;
    let (
        Step::PaPlane { joint, from, .. },
        Step::Aim {
            joint: pa,
            from: known_link,
            to,
            target,
            ..
        },
    ) = (plane, aim)
    else {
        return None;
    };
    let j = &geometry.joints[*joint];
    let base = Frame::identity();
    let forward = j.links[0] == *from;
    let k = j.turning_axis(&base, forward)?;
    let Motion::Circle { centre: on_axis, .. } = j.motion(&base, forward, constant([0.0; 3])) else {
        return None;
    };
    let (known, m) = swing(geometry, &base, plane, aim);
    let Motion::Circle {
        centre, axis, radius, ..
    } = m
    else {
        return None;
    };
    let sphere =
        norm(cross(sub(centre, on_axis), k)) <= tol && dot(axis, k).abs() <= 1e-9 && dot(radius, axis).abs() <= tol;
    let [hop] = &target.hops[..] else { return None };
    // The swung link at the swing's zero: the open joint's axis there.
    let p = &geometry.joints[*pa];
    let swung = known.then(&p.zero[usize::from(p.links[0] != *known_link)]);
    let o = &geometry.joints[hop.joint];
    let o_axis = swung.then(&o.frames[usize::from(o.links[0] != *to)]).column(2);
    sphere.then(|| Search::parallel(v3(o_axis), v3(k)))
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
                    // Numbered once the plan is found (`number_choices`).
                    branch: 0,
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scalar::{add, norm, unit};

    /// `v` turned by the turn `[c, s]` about unit `k` (Rodrigues), written out.
    fn turn(k: [f64; 3], [c, s]: [f64; 2], v: [f64; 3]) -> [f64; 3] {
        add(add(scale(c, v), scale(s, cross(k, v))), scale(dot(k, v) * (1.0 - c), k))
    }

    /// The sphere's miss against where the two turns really leave the
    /// point: the plane's turn (this kernel) carries the swing's axis and
    /// arm about `k`, then the aim's turn swings the arm towards the target,
    /// `r − |d|` short of it (times `(r + |d|)/(2·r)`).
    #[test]
    fn sphere_miss_is_where_the_plane_and_the_swing_leave_the_point() {
        type V = [f64; 3];
        // (the plane's axis k, the swing's axis ⊥ k, its arm ⊥ that axis, a point on k, the target)
        let cases: [(V, V, V, V, V); 3] = [
            (
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 320.0],
                [0.0, 300.0, 100.0],
                [40.0, -150.0, 20.0],
            ),
            (
                [0.0, 0.0, 1.0],
                [1.0, 1.0, 0.0],
                [-2.0, 2.0, 1.0],
                [1.0, 2.0, 3.0],
                [4.0, 0.0, 2.0],
            ),
            (
                [1.0, 2.0, 2.0],
                [2.0, -1.0, 0.0],
                [2.0, 4.0, -5.0],
                [0.0, 0.0, 0.0],
                [3.0, -1.0, 8.0],
            ),
        ];
        for (k, a, arm, c, q) in cases {
            let (k, a) = (unit(k), unit(a));
            let plane = pa_plane(k, a, c, q, crate::primitives::Sign::Plus, [0, 0]).unwrap();
            let (a1, arm1) = (turn(k, plane, a), turn(k, plane, arm));
            let swing = crate::subproblems::rotate_onto::turn_onto(a1, arm1, sub(q, c), [0, 0]).unwrap();
            let d = sub(add(c, turn(a1, swing, arm1)), q);
            // The point lands towards the target: along d = Q − c only.
            let (r, dq) = (norm(arm), sub(q, c));
            let out = scale(1.0 / norm(dq), dq);
            assert!(norm(sub(d, scale(dot(d, out), out))) < 1e-12 * r, "{d:?}");
            let want = dot(d, out) * (r + norm(dq)) / (2.0 * r);
            let m = Motion::Circle {
                centre: c,
                axis: a,
                radius: arm,
                length: r,
            };
            let got = sphere_miss(m, q);
            assert!((got[0] - want).abs() < 1e-12 * norm(dq).max(r), "{got:?} vs {want}");
            assert_eq!([got[1], got[2]], [0.0, 0.0]);
        }
    }
}
