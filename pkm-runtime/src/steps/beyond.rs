//! A revolute's angle that puts a point beyond a joint whose value is
//! given on a cylinder: an input between two moving links (a hydraulic
//! cylinder pinned to a rocker and to the base) makes those two links one
//! body of known shape for the step. The new link `to` turns about the
//! known revolute; across the given joint `q` the link beyond it carries
//! the point `x` (a joint's place there), which the rest of the mechanism
//! holds at a fixed distance from the axis of a known revolute parallel to
//! the turning axis ([`super::locus::cylinder`]'s constraint).
//!
//! With `T_q(v)`, the pose of `q`'s second link in its first's at the
//! given value `v`, the point in the frame of `to` is
//!
//! `y = T_q(v)·x` (`to` is `q`'s first link), `y = T_q(v)⁻¹·x` otherwise,
//!
//! and it moves on the circle the revolute turns `y` on: the circle meets
//! the cylinder ([`super::locus::cylinder::meet`], circle–circle by
//! [`crate::subproblems::circle_distance::circle_distance`]), two roots. For the cylinder's
//! barrel, its guide through its pivot C along x and the rod's point c
//! behind its pin B sliding on it, `y = B = C + (c + s)·x`: the barrel
//! turns about C until B is on the circle about the rocker's pivot, the
//! triangle of the RRR dyad with side `|CB| = c + s`.
//!
//! The same carried point `y` meets the other loci a dyad's point meets:
//! turned, the plane a known slider sweeps ([`super::locus::slider`], a
//! slider-crank driven at the crank–rod joint: the rod's slider pin on the
//! guide); slid, in a planar mechanism, a cylinder
//! ([`super::locus::cylinder::meet`]'s line–circle: a slider-crank driven at
//! the rod–slider joint, the rod then translating with the slider; a Scotch
//! yoke driven at the block's slide in the slot). Two roots each. Slid
//! against a slider's guide on a known link, it meets a line (an
//! elliptical trammel driven at the joint between a block and the bar: the
//! block slides, the bar turned on it at the given angle, until the bar's
//! other pin is on the other block's guide): one root,
//! [`super::slide_to_line::onto_line`].

use super::search::Search;
use super::{JointValue, Motion, Move};
use crate::model::JointType;
use crate::plan::{v3, Constraint, Step};
use crate::scalar::Scalar;
use crate::singular::{crossing, joint_point, sine, Condition, Configuration, Factor, LinkPoint};
use crate::solution::{PointRef, SolveError};

/// The value of the revolute (or slide) that puts `point` (on the link
/// across the given joint `given` from the new link, carried at input
/// `input`) on `constraint` (a cylinder, or a slider's plane), `branch`
/// choosing the root.
pub fn execute<T: Scalar>(
    mv: &Move<'_, T>,
    given: usize,
    input: usize,
    point: PointRef,
    constraint: &Constraint,
    branch: Option<usize>,
) -> Result<super::Found<T>, SolveError> {
    let g = mv.geometry;
    let q = &g.joints[given];
    let beyond = q.other(mv.to);
    let x = g.local(point, beyond);
    let y = carried(q, q.links[0] == mv.to, x, mv.given.values[input]);
    let m = mv.joint().motion(&mv.state.poses[mv.from], mv.forward(), y);
    let r = match (constraint, m) {
        (Constraint::Cylinder { hops, joint: h, link }, _) => {
            super::locus::cylinder::meet(mv, m, x, hops, *h, *link, branch)?
        }
        // Slid onto the line the slider's point runs on along its guide.
        (Constraint::Slider { hops, joint: h, link }, Motion::Line { start, along }) => [
            super::slide_to_line::onto_slider(mv, start, along, x, hops, *h, *link)?,
            T::c(0.0),
        ],
        (Constraint::Slider { hops, joint: h, link }, _) => {
            super::locus::slider::meet(mv, m, x, hops, *h, *link, branch)?
        }
        (Constraint::Sphere { .. } | Constraint::Plane { .. } | Constraint::Pin { .. }, _) => {
            return Err(mv.fail(super::degenerate(
                "a point beyond a given joint needs a cylinder or a slider",
            )))
        }
    };
    Ok(mv.found(r))
}

/// The point `x` of the link across joint `q` in the frame of the link on
/// this side at `q`'s value `v`: `T_q(v)·x` when this side is `q`'s first
/// link (`first`), `T_q(v)⁻¹·x` otherwise ([`super::JointGeometry::transform`]).
///
/// ```
/// use pkm_runtime::model::{JointType, Place};
/// use pkm_runtime::steps::{beyond::carried, JointGeometry};
///
/// // A guide along x through the origin; the slider point sits 2 behind its link's origin.
/// let guide = Place::Line { through: [0.0; 3], along: [1.0, 0.0, 0.0] };
/// let q = JointGeometry::new(JointType::P, [0, 1], [guide, Place::Point { at: [-2.0, 0.0, 0.0] }]);
/// let y = carried(&q, true, [0.0; 3], 5.0);
/// assert!((y[0] - 7.0).abs() < 1e-15 && y[1].abs() < 1e-15);
/// ```
pub fn carried<T: Scalar>(q: &super::JointGeometry<T>, first: bool, x: [T; 3], v: T) -> [T; 3] {
    let t = q.transform(JointValue::given(q.kind, v));
    if first {
        t.apply(x)
    } else {
        t.inverse().apply(x)
    }
}

/// The planner's match: a revolute `j` turning the new link `to` about
/// `k`, a joint `q` of `to` whose value is given (a slide, or a revolute
/// about `k`: either keeps `k`), its other link not known, and there a
/// joint's place that reaches, through revolutes on its axis about `k`, a
/// link whose revolute about `k` turns on a known link (a cylinder) or
/// whose slide normal to `k` runs on a known link (a slider's plane). In a
/// planar mechanism `j` may be a slide too, `k` then the plane's normal,
/// against a cylinder, or against a slider's line: a slide `c` on a known
/// link, its guide not along `j` (one root). Tried after `guide`, so it
/// only plans what nothing before it did.
pub(crate) fn find(s: &mut Search<'_>) -> bool {
    for (j, from, to) in s.candidates() {
        let slide = s.kind(j) == JointType::P && s.model.planar;
        if s.kind(j) != JointType::R && !slide {
            continue;
        }
        // A slide's point runs on a line in the plane, which meets a
        // cylinder about the plane's normal.
        let k = if slide { nalgebra::Vector3::z() } else { s.axis(j, to) };
        for (q, jq) in s.model.joints.iter().enumerate() {
            let Some(input) = s.given[q] else { continue };
            if q == j || s.used[q] || !jq.links.contains(&to) {
                continue;
            }
            let keeps_k = match jq.kind {
                JointType::P => true,
                JointType::R => Search::parallel(s.axis(q, to), k),
                _ => false,
            };
            let beyond = s.other(q, to);
            if !keeps_k || s.known[beyond] {
                continue;
            }
            let (k_beyond, places) = s.across(q, to, j, k);
            for (point, x) in places {
                for r in s.fixed_reach(beyond, x, &[j, q]) {
                    if s.known[r.link] {
                        continue;
                    }
                    let rot = s.rotation(&r.hops);
                    let turning = s.hops_about(beyond, &r.hops, k_beyond);
                    let found = s.model.joints.iter().enumerate().find_map(|(c, jc)| {
                        let skip = c == q || c == j || !jc.links.contains(&r.link);
                        if skip || r.hops.iter().any(|hop| hop.joint == c) {
                            return None;
                        }
                        match jc.kind {
                            JointType::R => {
                                super::locus::cylinder::find(s, &r, c, k_beyond, rot, turning).map(|c| (c, true))
                            }
                            JointType::P if !slide => {
                                super::locus::slider::find(s, &r, c, k_beyond, rot, turning).map(|c| (c, true))
                            }
                            JointType::P => onto_guide(s, j, to, &r, c).map(|c| (c, false)),
                            _ => None,
                        }
                    });
                    let Some((constraint, two)) = found else { continue };
                    let branch = two.then(|| {
                        s.branches += 1;
                        s.branches - 1
                    });
                    let step = Step::Beyond {
                        joint: j,
                        from,
                        to,
                        given: q,
                        input,
                        point,
                        constraint,
                        branch,
                    };
                    s.push(step, to, j);
                    return true;
                }
            }
        }
    }
    false
}

/// The match of a slide `j` (moving `to`) against slide `c`'s line: `c`
/// on the reach `r`'s link, its other link known and, where both guides
/// are on one known link, its guide not along `j`'s, so the two lines meet
/// once (elsewhere the step refuses a slide along the line when it runs).
fn onto_guide(s: &Search<'_>, j: usize, to: usize, r: &super::search::Reach, c: usize) -> Option<Constraint> {
    let next = s.other(c, r.link);
    let from = s.other(j, to);
    if !s.known[next] || (next == from && Search::parallel(s.axis(c, next), s.axis(j, from))) {
        return None;
    }
    Some(Constraint::Slider {
        hops: r.hops.clone().into(),
        joint: c,
        link: next,
    })
}

/// The step's factor: as a locus's ([`super::locus_factor`]), the cosine
/// between the carried point's path and the locus's normal there, zero
/// where the path touches the cylinder or the slider's plane (the triangle
/// folds flat, the two roots meet).
pub(crate) fn factor(at: &Configuration, k: usize, step: &Step) -> Option<Factor> {
    let Step::Beyond {
        joint,
        from,
        to,
        given,
        point,
        ref constraint,
        ..
    } = *step
    else {
        return None;
    };
    let q = &at.g.joints[given];
    let beyond = q.other(to);
    let p = v3(at.frames[beyond].apply(at.g.local(point, beyond)));
    let j = &at.g.joints[joint];
    let motion = j.motion(&at.frames[from], j.links[0] == from, [0.0; 3]);
    let path = match motion {
        Motion::Circle { centre, axis, .. } => v3(axis).cross(&(p - v3(centre))),
        Motion::Line { along, .. } => v3(along) * at.scale,
    };
    if let (Constraint::Slider { joint: h, link, .. }, Motion::Line { along, .. }) = (constraint, motion) {
        // Slid onto a line: the sine between the slide and the guide (as
        // `slide_to_line`'s factor), zero where the slide runs along it.
        let jh = &at.g.joints[*h];
        let Motion::Line { along: u, .. } = jh.motion(&at.frames[*link], jh.links[0] == *link, [0.0; 3]) else {
            return None;
        };
        return Some(Factor {
            step: k,
            joint,
            condition: Condition::SlideAlongLine,
            points: [
                joint_point(joint, from),
                LinkPoint { link: beyond, point },
                joint_point(*h, *link),
            ],
            value: sine(v3(along), v3(u)),
        });
    }
    let (n, condition, other) = match *constraint {
        Constraint::Cylinder { joint: h, link, .. } => super::locus::cylinder::normal(at, p, h, link),
        Constraint::Slider { joint: h, link, .. } => super::locus::slider::normal(at, joint, from, h, link),
        _ => return None,
    };
    Some(Factor {
        step: k,
        joint,
        condition,
        points: [joint_point(joint, from), LinkPoint { link: beyond, point }, other],
        value: crossing(path, n, at.scale),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Place;
    use crate::steps::JointGeometry;

    /// By hand: the barrel's guide through C = (3, 1) along (cos β, sin β),
    /// the rod's slider point c behind its pin B (the rod's origin), the
    /// rod turned as the barrel: B = C + (c + s)(cos β, sin β) in the
    /// barrel's frame, and back across the joint the rod's own origin.
    #[test]
    fn the_rod_pin_is_c_plus_s_along_the_guide() {
        for &(beta, c, s) in &[(0.0, 2.0, 5.0), (0.7, 200.0, 130.0), (-2.0, 0.5, -0.25)] {
            let u = [f64::cos(beta), f64::sin(beta), 0.0];
            let guide = Place::Line {
                through: [3.0, 1.0, 0.0],
                along: u,
            };
            let slider = Place::Point {
                at: [-c * u[0], -c * u[1], 0.0],
            };
            let q = JointGeometry::new(JointType::P, [0, 1], [guide, slider]);
            let b = carried(&q, true, [0.0; 3], s);
            let want = [3.0 + (c + s) * u[0], 1.0 + (c + s) * u[1], 0.0];
            for i in 0..3 {
                assert!(
                    (b[i] - want[i]).abs() < 1e-12 * (1.0 + c + s.abs()),
                    "{beta} {c} {s}: {b:?}"
                );
            }
            // The other way: the barrel's C seen from the rod is back by c + s.
            let back = carried(&q, false, [3.0, 1.0, 0.0], s);
            for i in 0..2 {
                assert!((back[i] + (c + s) * u[i]).abs() < 1e-12 * (1.0 + c + s.abs()));
            }
        }
    }
}
