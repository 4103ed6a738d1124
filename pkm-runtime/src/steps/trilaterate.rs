//! A translating link placed by three of its points, each held on a
//! sphere about a known point: three spheres meeting
//! ([`crate::subproblems::three_spheres`]), two roots.
//!
//! A link whose POC set has no rotation (a Delta's, a 3-UPU's or an
//! Orthoglide's platform) keeps the base's orientation; its position is
//! three unknowns. Where three of its points are each held at a distance
//! from a known point, each lies on the sphere about it, and the link's
//! origin on the three spheres moved by the points' offsets
//! ([`held`]): the far end of a rod between two spherical centres, S or U
//! (a Delta's forearm), of a parallelogram's arm (an Orthoglide's leg:
//! the arm's far hinge about its near one), or of a U-P-U leg whose slide
//! is driven (the radius the slide's value). The coupled loops that give
//! such a mechanism κ ≥ 1 then close in closed form: the legs' links are
//! placed afterwards between their known ends by the other steps.

use super::search::{reversed, Search};
use super::{Geometry, Given};
use crate::frame::Frame;
use crate::model::JointType;
use crate::plan::{v3, Anchor, Constraint, OnSphere, Radius, Span, Step};
use crate::scalar::{norm, sub, Scalar};
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
    let radii: [T; 3] = core::array::from_fn(|i| match spheres[i].radius {
        Span::Rigid(r) => super::locus::sphere::radius(geometry, r),
        Span::Slid {
            link: l,
            joint,
            slide,
            input,
            point,
        } => {
            let q = &geometry.joints[slide];
            let x = geometry.local(point, q.other(l));
            let y = super::beyond::carried(q, q.links[0] == l, x, given.values[input]);
            norm(sub(y, geometry.local(PointRef::Joint(joint), l)))
        }
    });
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
            let h = held(s, link, j, x);
            if let Some(on) = h {
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
/// spherical centre: an S, or a U's crossing axes) to an unknown link
/// that holds it at a distance from a point known through its other
/// joints: a rod's other centre, a parallelogram's near hinge
/// ([`super::locus::sphere::find`]), or, across a driven slide, the centre
/// on the link beyond it ([`Span::Slid`]).
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
            let on = match s.kind(q) {
                JointType::Pa => match super::locus::sphere::find(s, j, &r, q) {
                    Some(Constraint::Sphere { centre, radius }) => Some((centre, Span::Rigid(radius))),
                    _ => None,
                },
                // A rod: its other centre, off the point (a length).
                JointType::S | JointType::R if (v3(s.place(q, r.link).at()) - r.x).norm() > s.tol => {
                    centre(s, r.link, q, &crossed).map(|centre| {
                        (
                            centre,
                            Span::Rigid(Radius::Rod {
                                link: r.link,
                                point: PointRef::Joint(entered),
                                joint: q,
                            }),
                        )
                    })
                }
                JointType::S | JointType::R => None,
                JointType::P => s.given[q].and_then(|input| {
                    let beyond = s.other(q, r.link);
                    let mut excl = crossed.clone();
                    excl.push(q);
                    s.model.joints.iter().enumerate().find_map(|(k, other)| {
                        if excl.contains(&k) || !other.links.contains(&beyond) || s.known[beyond] {
                            return None;
                        }
                        let centre = centre(s, beyond, k, &excl)?;
                        Some((
                            centre,
                            Span::Slid {
                                link: beyond,
                                joint: k,
                                slide: q,
                                input,
                                point: PointRef::Joint(entered),
                            },
                        ))
                    })
                }),
            };
            if let Some((centre, radius)) = on {
                return Some(OnSphere {
                    point: PointRef::Joint(j),
                    centre,
                    radius,
                });
            }
        }
    }
    None
}

/// The centre of joint `q` on the unknown link `l` as a point known
/// through `q` and the joints beyond it that keep it put (an S's centre, a
/// U's crossing axes: a revolute alone is no centre), joints in `crossed`
/// not crossed.
fn centre(s: &Search<'_>, l: usize, q: usize, crossed: &[usize]) -> Option<Anchor> {
    if !matches!(s.kind(q), JointType::S | JointType::R) {
        return None;
    }
    let c = v3(s.place(q, l).at());
    let known = s
        .fixed_reach(l, c, crossed)
        .into_iter()
        .find(|k| s.known[k.link] && !k.hops.is_empty() && k.hops[0].joint == q)?;
    // A revolute's place is a centre only where a second axis crosses it.
    if s.kind(q) == JointType::R && known.hops.len() < 2 {
        return None;
    }
    Some(Anchor {
        link: known.link,
        hops: reversed(&known.hops),
        point: PointRef::Joint(q),
    })
}
