//! A translating link placed by three of its points, each held on a
//! sphere about a known point: three spheres meeting
//! ([`crate::subproblems::three_spheres`]), two roots.
//!
//! A link whose POC set has no rotation (a Delta's or a 3-UPU's platform)
//! keeps the base's orientation; its position is three unknowns. Where
//! three of its points each end a rod whose other end is a known point (a
//! link between two spherical centres, S or U: a Delta's forearm, an
//! RSSR's coupler), each point lies on the sphere about that point of
//! radius the rod's length, and the link's origin lies on the three
//! spheres moved by the points' offsets. The coupled loops that give such
//! a mechanism κ ≥ 1 then close in closed form: the rods themselves are
//! placed afterwards between their known ends by the other steps.

use super::search::{reversed, Search};
use super::{Geometry, Given};
use crate::frame::Frame;
use crate::model::JointType;
use crate::plan::{v3, Anchor, OnSphere, Radius, Step};
use crate::scalar::{sub, Scalar};
use crate::solution::{step_error, PointRef, SolveError};
use crate::subproblems::three_spheres::three_spheres;
use nalgebra::Vector3;

/// Link `link`'s pose: not turned, at the position where each of its
/// points `spheres[i].point` is on its sphere; `branch` picks the root.
pub fn execute<T: Scalar>(
    k: usize,
    link: usize,
    spheres: &[OnSphere],
    branch: usize,
    geometry: &Geometry<T>,
    poses: &[Frame<T>],
    given: &Given<'_, T>,
) -> Result<Frame<T>, SolveError> {
    let at = |i: usize| {
        let s = &spheres[i];
        // The sphere the link's origin is on: the point's, moved back by
        // the point's offset on the link.
        sub(geometry.anchor(poses, &s.centre), geometry.local(s.point, link))
    };
    let centres = [at(0), at(1), at(2)];
    let radii: [T; 3] = core::array::from_fn(|i| super::locus::sphere::radius(geometry, spheres[i].radius));
    let t = three_spheres(
        centres,
        radii,
        T::choice(given.signs, Some(branch)),
        [k, given.sites + k],
    )
    .map_err(|e| step_error(k, (given.name)(k), e))?;
    Ok(Frame { t, ..Frame::identity() })
}

/// The planner's match: a translating link not yet known, with three
/// points each held on a sphere about a known point ([`held`]); the first
/// three whose points are not on one line.
pub(crate) fn find(s: &mut Search<'_>) -> bool {
    for link in 0..s.model.links.len() {
        if s.known[link] || !s.translating.get(link).copied().unwrap_or(false) {
            continue;
        }
        let mut found: Vec<(Vector3<f64>, OnSphere)> = Vec::new();
        for (j, joint) in s.model.joints.iter().enumerate() {
            if !joint.links.contains(&link) {
                continue;
            }
            let x = v3(s.place(j, link).at());
            if found.iter().any(|(y, _)| (y - x).norm() <= s.tol) {
                continue;
            }
            if let Some(on) = held(s, link, j, x) {
                found.push((x, on));
            }
        }
        for a in 0..found.len() {
            for b in a + 1..found.len() {
                for c in b + 1..found.len() {
                    let (u, v) = (found[b].0 - found[a].0, found[c].0 - found[a].0);
                    if u.cross(&v).norm() <= s.tol * (u.norm() + v.norm()) {
                        continue;
                    }
                    let spheres = vec![found[a].1.clone(), found[b].1.clone(), found[c].1.clone()];
                    s.steps.push(Step::Trilaterate {
                        link,
                        spheres,
                        branch: s.branches,
                    });
                    s.branches += 1;
                    s.known[link] = true;
                    return true;
                }
            }
        }
    }
    false
}

/// Point `x` of `link` (joint `j`'s place) held on a sphere: it stays put
/// through `j` and the joints beyond it whose axes or centres carry it (a
/// spherical centre: an S, or a U's crossing axes) to a rod, an unknown
/// link with another such centre `q` that stays put through its own
/// joints to a known link; the sphere is about `q`'s centre, of radius
/// the rod's length between the two centres.
fn held(s: &Search<'_>, link: usize, j: usize, x: Vector3<f64>) -> Option<OnSphere> {
    for r in s.fixed_reach(link, x, &[]) {
        if s.known[r.link] || r.hops.is_empty() || r.hops[0].joint != j {
            continue;
        }
        let crossed: Vec<usize> = r.hops.iter().map(|h| h.joint).collect();
        let entered = *crossed.last()?;
        for (q, joint) in s.model.joints.iter().enumerate() {
            if crossed.contains(&q) || !joint.links.contains(&r.link) {
                continue;
            }
            if !matches!(s.kind(q), JointType::S | JointType::R) {
                continue;
            }
            let c = v3(s.place(q, r.link).at());
            if (c - r.x).norm() <= s.tol {
                continue;
            }
            let Some(known) = s
                .fixed_reach(r.link, c, &crossed)
                .into_iter()
                .find(|k| s.known[k.link] && !k.hops.is_empty() && k.hops[0].joint == q)
            else {
                continue;
            };
            // A revolute's place is a centre only where a second axis
            // crosses it (a U): the reach crossed more than the revolute.
            if s.kind(q) == JointType::R && known.hops.len() < 2 {
                continue;
            }
            return Some(OnSphere {
                point: PointRef::Joint(j),
                centre: Anchor {
                    link: known.link,
                    hops: reversed(&known.hops),
                    point: PointRef::Joint(q),
                },
                radius: Radius::Rod {
                    link: r.link,
                    point: PointRef::Joint(entered),
                    joint: q,
                },
            });
        }
    }
    None
}
