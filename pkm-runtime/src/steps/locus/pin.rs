//! A point of the new link held at a fixed distance from a pin: a planar
//! point output pins its link at the given point without its angle
//! ([`crate::plan::Turn::Free`]), so every point of that link, and every
//! point carried onto it across revolutes whose axes hold it, lies on a
//! circle about the pin. A new link turning about a known revolute meets
//! that circle where the two circles cross (two roots), a new link sliding
//! where its line does (`locus::cylinder::about`): the pinned link turned
//! about its tool point until its other joint reaches a crank's circle, as
//! a five-bar's coupler carrying the tool point off its joints. A later
//! step (an aim onto the pin) turns the pinned link itself.
//!
//! A spatial point output pins its link the same way, without its
//! orientation: the point then lies on a sphere about the pin (radius its
//! distance there), which the new link's circle or line meets
//! ([`super::sphere::to_distance`], two roots). A spherical five-bar's
//! inverse: the pointing direction given, each arm turns until its distal
//! joint keeps the distal link's distance from the pinned point.

use crate::plan::{v3, Constraint, Hop, Step, Turn};
use crate::scalar::{norm, reject, sub, Scalar};
use crate::singular::{Condition, Configuration, LinkPoint};
use crate::solution::{PointRef, SolveError};
use crate::steps::search::{Reach, Search};
use crate::steps::{Found, Motion, Move};
use nalgebra::{UnitQuaternion, Vector3};

/// The value of the joint that puts `point` of the new link (carried across
/// `hops` to the pinned `link`) at the distance it keeps there from
/// `link`'s pin `pin`.
pub fn execute<T: Scalar>(
    mv: &Move<'_, T>,
    point: PointRef,
    hops: &[Hop],
    link: usize,
    pin: PointRef,
    sphere: bool,
    branch: Option<usize>,
) -> Result<Found<T>, SolveError> {
    let (x, m) = mv.motion(point);
    Ok(mv.found(meet(mv, m, x, hops, link, pin, sphere, branch)?))
}

/// The value that puts the point moving as `m` (its carrier `x`, carried
/// across `hops` to the pinned `link`) at its distance there from the pin
/// `pin`, on the circle about the pin's place in the plane (the planar
/// axis z: the pinned link's placing keeps the base's orientation, so its
/// z is the world's), or with `sphere` on the sphere about it; `branch`
/// picks the root.
#[allow(clippy::too_many_arguments)]
pub fn meet<T: Scalar>(
    mv: &Move<'_, T>,
    m: Motion<T>,
    x: [T; 3],
    hops: &[Hop],
    link: usize,
    pin: PointRef,
    sphere: bool,
    branch: Option<usize>,
) -> Result<[T; 2], SolveError> {
    let g = mv.geometry;
    let centre = g.local(pin, link);
    let y = g.carry(x, hops);
    let world = mv.state.poses[link].apply(centre);
    if sphere {
        // Spatial: the sphere about the pin.
        return super::sphere::to_distance(mv, m, world, norm(sub(y, centre)), mv.choice(branch));
    }
    let (zero, one) = (T::c(0.0), T::c(1.0));
    let z = [zero, zero, one];
    let radius = norm(reject(sub(y, centre), z));
    super::cylinder::about(mv, m, world, mv.state.poses[link].rotate(z), radius, branch)
}

/// The point a start step pins `link` by (a planar point output), if one does.
pub(crate) fn pin_of(s: &Search<'_>, link: usize) -> Option<PointRef> {
    s.pins[link]?;
    s.steps.iter().find_map(|step| match *step {
        Step::Place {
            link: l,
            point,
            turn: Turn::Free,
            ..
        } if l == link => Some(point),
        _ => None,
    })
}

/// The planner's match for a pin: the reach `r` ends, across at least one
/// hop, at a link pinned by a planar point output, not at its pin (a point
/// at the pin is the pin: `locus::cylinder` or an aim takes it), and the
/// new link's point moves in the plane: on a circle whose axis, like the
/// hops that carry the point, is the plane's normal (`turning`), or along
/// a slide normal to it (`k`, in the new link's frame, `to`'s; `rot` turns
/// the reach's link's frame into it).
pub(crate) fn find(
    s: &Search<'_>,
    to: usize,
    r: &Reach,
    k: Vector3<f64>,
    rot: UnitQuaternion<f64>,
    turning: bool,
    circle: bool,
) -> Option<Constraint> {
    if r.hops.is_empty() || s.known[r.link] {
        return None;
    }
    let pin = pin_of(s, r.link)?;
    if s.pinned_at(r.link, r.x) {
        return None;
    }
    if !s.model.planar {
        // The reach keeps the point put on the pinned link: a sphere.
        return Some(Constraint::Pin {
            hops: r.hops.clone().into(),
            link: r.link,
            pin,
            sphere: true,
        });
    }
    let normal = rot * Vector3::z();
    let held = if circle {
        turning && Search::parallel(normal, k)
    } else {
        s.hops_about(to, &r.hops, normal) && Search::normal(normal, k)
    };
    held.then(|| Constraint::Pin {
        hops: r.hops.clone().into(),
        link: r.link,
        pin,
        sphere: false,
    })
}

/// The circle's normal at the moving point `p`: `p`'s offset from the pin
/// of `link` in the plane, for the locus's factor
/// ([`crate::steps::locus_factor`]).
pub(crate) fn normal(
    at: &Configuration,
    p: Vector3<f64>,
    link: usize,
    pin: PointRef,
    sphere: bool,
) -> (Vector3<f64>, Condition, LinkPoint) {
    let c = v3(at.frames[link].apply(at.g.local(pin, link)));
    let d = p - c;
    if sphere {
        return (d, Condition::TouchesSphere, LinkPoint { link, point: pin });
    }
    let w = v3(at.frames[link].rotate([0.0, 0.0, 1.0])).normalize();
    (
        d - w * w.dot(&d),
        Condition::TouchesCircle,
        LinkPoint { link, point: pin },
    )
}
