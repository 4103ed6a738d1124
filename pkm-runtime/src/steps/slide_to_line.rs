//! A slide that brings a point onto a line, where neither can turn: the
//! planar dyads with two prismatic joints, whose links keep their
//! orientation (a P joint keeps it), so the unknown is where two lines meet.
//!
//! * RPP (a Scotch yoke): the new link `to` slides (prismatic `j`) and
//!   carries a line, the one the point across its other prismatic `q`
//!   travels on seen from `to`; that point is known (it reaches a known link
//!   through revolutes on their axes: the yoke's slot must pass the crank
//!   pin). [`Meet::Through`].
//! * PRP (a 3-PRP leg, a tangent mechanism): a point of `to`, reaching a link
//!   through revolutes on their axes, must lie on the line that link's
//!   point travels on as it slides (prismatic `q`) on a known link. [`Meet::Onto`].
//!
//! Either way, with the point `P(s)` or the line's point `L(s)` moving as
//! `X₀ + s·g` (`g` the slide's unit direction) and the other fixed, the two
//! meet where the difference `d − s·g` (`d` from the moving start to the
//! fixed one) is along the line's direction `u`:
//!
//! `(d − s·g) × u = 0`, so `s = (g⊥·d)/(g⊥·g⊥)`, `g⊥ = g − (g·u)u`,
//!
//! two lines in a plane meeting once (in space, where the two lines are
//! skew, the slide that brings them nearest: the check after the last step
//! would then refuse the solution; the planner matches planar mechanisms
//! only). A slide along the line (`g⊥ = 0`) is degenerate: every slide or
//! none. One root.

use super::search::{reversed, Search};
use super::{Found, Motion, Move};
use crate::model::JointType;
use crate::plan::{v3, Anchor, Hops, Step};
use crate::primitives::Error as GeomError;
use crate::scalar::{dot, reject, sub, Failure, Scalar};
use crate::singular::{joint_point, sine, Condition, Configuration, Factor, LinkPoint};
use crate::solution::{PointRef, SolveError};

/// Which of the point and the line the new link carries.
#[derive(Debug, Clone, PartialEq)]
pub enum Meet {
    /// The line: the one `point` (on the link across the slide from the
    /// new link) travels on seen from the new link, through the anchored
    /// position (the same point, known).
    Through(Anchor),
    /// The point (of the new link, carried across `hops` to the slider's
    /// link): on the line it travels on as the slide moves it on the known
    /// `link`.
    Onto {
        /// From the new link to the slider's link.
        hops: Hops,
        /// The known link the slide's other side is on.
        link: usize,
    },
}

/// The slide of prismatic `mv.joint` that brings `point` and the line of
/// prismatic `slide` together, as `meet` says.
pub fn execute<T: Scalar>(
    mv: &Move<'_, T>,
    slide: usize,
    point: PointRef,
    meet: &Meet,
) -> Result<Found<T>, SolveError> {
    let g = mv.geometry;
    let q = &g.joints[slide];
    let not_a_slide = || mv.fail(super::degenerate("a slide onto a line needs two slides"));
    let s = match meet {
        Meet::Through(target) => {
            // The new link at slide 0, the slide's direction, and the line
            // seen from the new link there.
            let beyond = q.other(mv.to);
            let j = mv.joint();
            let from = &mv.state.poses[mv.from];
            let Motion::Line { along, .. } = j.motion(from, mv.forward(), crate::scalar::constant([0.0; 3])) else {
                return Err(not_a_slide());
            };
            let zero = from.then(&j.zero[usize::from(!mv.forward())]);
            let Motion::Line { start, along: u } = q.motion(&zero, q.links[0] == mv.to, g.local(point, beyond)) else {
                return Err(not_a_slide());
            };
            let fixed = g.anchor(&mv.state.poses, target);
            onto_line(sub(fixed, start), along, u, mv.site()).map_err(|e| mv.fail(e))?
        }
        Meet::Onto { hops, link } => {
            let (x, Motion::Line { start, along }) = mv.motion(point) else {
                return Err(not_a_slide());
            };
            onto_slider(mv, start, along, x, hops, slide, *link)?
        }
    };
    Ok(mv.found([s, T::c(0.0)]))
}

/// The slide that brings the point moving from `start` along `along` onto
/// the line its carrier `x` (carried across `hops` to the link of
/// prismatic `slide`) runs on as that slide moves it on the known `link`
/// ([`onto_line`]; [`Meet::Onto`], and a point carried across a given
/// joint, `beyond`).
pub(crate) fn onto_slider<T: Scalar>(
    mv: &Move<'_, T>,
    start: [T; 3],
    along: [T; 3],
    x: [T; 3],
    hops: &[crate::plan::Hop],
    slide: usize,
    link: usize,
) -> Result<T, SolveError> {
    let q = &mv.geometry.joints[slide];
    let Motion::Line { start: fixed, along: u } =
        q.motion(&mv.state.poses[link], q.links[0] == link, mv.geometry.carry(x, hops))
    else {
        return Err(mv.fail(super::degenerate("a slide onto a line needs two slides")));
    };
    onto_line(sub(fixed, start), along, u, mv.site()).map_err(|e| mv.fail(e))
}

/// The slide `s` along the unit `g` that makes `d − s·g` lie along the
/// unit `u` (`d` from the moving start to a point of the fixed line, or
/// from the moving line's start to the fixed point): with `g⊥ = g − (g·u)u`,
/// `s = (g⊥·d)/(g⊥·g⊥)` (the module's derivation).
///
/// # Errors
/// [`GeomError::Degenerate`] when the slide runs along the line
/// (`|g⊥| ≤ 1e-12`).
///
/// ```
/// use pkm_runtime::steps::slide_to_line::onto_line;
///
/// // From (0, 0) along x onto the line through (3, 1) along (1, 1)/√2: at x = 2.
/// let h = std::f64::consts::FRAC_1_SQRT_2;
/// let s = onto_line([3.0, 1.0, 0.0], [1.0, 0.0, 0.0], [h, h, 0.0], [0, 0]).unwrap();
/// assert!((s - 2.0).abs() < 1e-14);
/// assert!(onto_line([3.0, 1.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0, 0]).is_err());
/// ```
#[inline]
pub fn onto_line<T: Scalar>(d: [T; 3], g: [T; 3], u: [T; 3], site: [usize; 2]) -> Result<T, GeomError<f64>> {
    let gp = reject(g, u);
    let gg = dot(gp, gp);
    let along = Failure::Degenerate("the slide runs along the line it must meet");
    T::require(T::c(1e-24), gg, along, site)?;
    Ok(dot(gp, d) / gg)
}

/// The planner's match, in a planar mechanism: a prismatic `j` moving the
/// new link `to`, and either (RPP) another prismatic `q` of `to`, not along
/// `j`, with beyond it a link whose joint's place reaches a known link
/// through revolutes on their axes (the place is known; the line it travels
/// on seen from `to` must pass it), or (PRP) a joint's place of `to` that
/// reaches, through revolutes on their axes, a link sliding on a known link
/// by a prismatic `q` (the place must lie on the line it travels on; `q`
/// not along `j` where no revolute turns one from the other). One root.
/// Tried after every other kind.
pub(crate) fn find(s: &mut Search<'_>) -> bool {
    if !s.model.planar {
        return false;
    }
    for (j, from, to) in s.candidates() {
        if s.kind(j) != JointType::P {
            continue;
        }
        let g = s.axis(j, to);
        // The plane's normal, in every link's frame.
        let z = nalgebra::Vector3::z();
        // RPP: the line on `to`, the point known.
        for (q, joint) in s.model.joints.iter().enumerate() {
            let free = q != j && joint.kind == JointType::P && !s.used[q] && s.given[q].is_none();
            if !free || !joint.links.contains(&to) || Search::parallel(s.axis(q, to), g) {
                continue;
            }
            let beyond = s.other(q, to);
            if s.known[beyond] {
                continue;
            }
            let (z_beyond, places) = s.across(q, to, j, z);
            for (point, x) in places {
                let reach = s
                    .fixed_reach(beyond, x, &[j, q])
                    .into_iter()
                    .find(|r| !r.hops.is_empty() && s.known[r.link] && s.hops_about(beyond, &r.hops, z_beyond));
                let Some(r) = reach else { continue };
                let target = Anchor {
                    link: r.link,
                    hops: reversed(&r.hops),
                    point,
                };
                let step = Step::SlideToLine {
                    joint: j,
                    from,
                    to,
                    slide: q,
                    point,
                    meet: Meet::Through(target),
                };
                s.push(step, to, j);
                return true;
            }
        }
        // PRP: the point on `to`, the line known.
        for (point, x) in s.points_of(to, j) {
            for r in s.fixed_reach(to, x, &[j]) {
                if s.known[r.link] {
                    continue;
                }
                let rot = s.rotation(&r.hops);
                let found = s.model.joints.iter().enumerate().find(|&(q, joint)| {
                    let free = q != j && joint.kind == JointType::P && !s.used[q] && s.given[q].is_none();
                    if !free || !joint.links.contains(&r.link) || r.hops.iter().any(|h| h.joint == q) {
                        return false;
                    }
                    // Across revolutes the two directions turn: parallel
                    // at value 0 is no reason to refuse.
                    let parallel = r.hops.is_empty() && Search::parallel(rot * s.axis(q, r.link), g);
                    s.known[s.other(q, r.link)] && !parallel && s.hops_about(to, &r.hops, z)
                });
                let Some((q, _)) = found else { continue };
                let step = Step::SlideToLine {
                    joint: j,
                    from,
                    to,
                    slide: q,
                    point,
                    meet: Meet::Onto {
                        hops: r.hops.clone().into(),
                        link: s.other(q, r.link),
                    },
                };
                s.push(step, to, j);
                return true;
            }
        }
    }
    false
}

/// The step's factor: the derivative of the meeting condition's component
/// normal to the line, `|g⊥| = |g × u|`, the sine between the slide and the
/// line; zero where the slide runs along the line (the two lines parallel).
pub(crate) fn factor(at: &Configuration, k: usize, step: &Step) -> Option<Factor> {
    let Step::SlideToLine {
        joint,
        from,
        to,
        slide,
        point,
        ref meet,
    } = *step
    else {
        return None;
    };
    let j = &at.g.joints[joint];
    let g = match j.motion(&at.frames[from], j.links[0] == from, [0.0; 3]) {
        Motion::Line { along, .. } => v3(along),
        Motion::Circle { .. } => return None,
    };
    let q = &at.g.joints[slide];
    // The line's direction: the slide `q`'s guide, from either of its links.
    let u = match q.motion(&at.frames[q.links[0]], true, [0.0; 3]) {
        Motion::Line { along, .. } => v3(along),
        Motion::Circle { .. } => return None,
    };
    let other = match meet {
        Meet::Through(target) => at.anchored(target).1,
        Meet::Onto { link, .. } => joint_point(slide, *link),
    };
    let moving = match meet {
        Meet::Through(_) => joint_point(slide, to),
        Meet::Onto { .. } => LinkPoint { link: to, point },
    };
    Some(Factor {
        step: k,
        joint,
        condition: Condition::SlideAlongLine,
        points: [joint_point(joint, from), moving, other],
        value: sine(g, u),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// By hand: the slide from the origin along g = (cos α, sin α) meets the
    /// line through D = (dx, dy) along u = (cos β, sin β) where
    /// s·g = D + t·u; by Cramer's rule (2D cross products `a × b = a₁b₂ − a₂b₁`)
    /// `s = (D × u)/(g × u)`.
    #[test]
    fn meets_by_cramer() {
        for &(alpha, beta, dx, dy) in &[
            (0.0, std::f64::consts::FRAC_PI_2, 60.0 * 0.5, 7.0),
            (0.3, 1.2, 100.0, -40.0),
            (-2.0, 0.1, -3.0, 250.0),
            (1.0, 1.0 + 1e-3, 5.0, 5.0),
        ] {
            let (g, u) = ([alpha.cos(), alpha.sin(), 0.0], [beta.cos(), beta.sin(), 0.0]);
            let cross = |a: [f64; 3], b: [f64; 3]| a[0] * b[1] - a[1] * b[0];
            let want = cross([dx, dy, 0.0], u) / cross(g, u);
            let s = onto_line([dx, dy, 0.0], g, u, [0, 0]).unwrap();
            assert!(
                (s - want).abs() <= 1e-12 * want.abs().max(1.0),
                "{alpha} {beta}: {s} vs {want}"
            );
            // The slid point is on the line: (s·g − D) × u = 0.
            let off = cross([s * g[0] - dx, s * g[1] - dy, 0.0], u);
            assert!(off.abs() <= 1e-10 * want.abs().max(1.0), "{off}");
        }
        // The Scotch yoke: the slot along y through the yoke's origin at s
        // along x passes the crank pin (r cos θ, r sin θ) at s = r cos θ.
        let (r, th) = (60.0, 0.7_f64);
        let s = onto_line(
            [r * th.cos(), r * th.sin(), 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0, 0],
        )
        .unwrap();
        assert_eq!(s, r * th.cos());
    }

    #[test]
    fn parallel_is_degenerate() {
        let g = [0.6, 0.8, 0.0];
        for u in [g, [-0.6, -0.8, 0.0]] {
            assert!(matches!(
                onto_line([1.0, 2.0, 0.0], g, u, [0, 0]),
                Err(GeomError::Degenerate { .. })
            ));
        }
        // Just off parallel (1e-9 rad): determined, s = (D × u)/(g × u).
        let b = 0.9272952180016122 + 1e-9;
        let u = [b.cos(), b.sin(), 0.0];
        let s = onto_line([0.0, 1.0, 0.0], g, u, [0, 0]).unwrap();
        let want = (-u[0]) / (g[0] * u[1] - g[1] * u[0]);
        assert!((s / want - 1.0).abs() < 1e-6, "{s} vs {want}");
    }
}
