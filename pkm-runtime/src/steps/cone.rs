//! A revolute's angle that turns the axis of another revolute of the new
//! link to the angle a third link keeps it at from a known axis, where the
//! three axes meet at one point: the spherical RRR dyad (a spherical
//! four-bar's coupler and rocker, a limb of a spherical parallel
//! mechanism). The new link turns about the known axis `k` of revolute J;
//! its revolute Q's axis `u` sweeps a cone about `k`; the link beyond Q
//! turns about the known axis `w` of revolute H and holds Q's axis at the
//! angle α it has from H's axis in that link's frame, a cone about `w`.
//! With all three axes through one centre, the angle is all there is to
//! close: the link beyond then turns about H onto Q (an aim or an
//! alignment), and Q's place on either side is the same point of its axis
//! (the compiler checks the geometry's centres).
//!
//! With `u₀` the axis at θ = 0 (unit), `u(θ) = (k·u₀)k + cosθ·u₀⊥ +
//! sinθ·(k × u₀⊥)`, and `u(θ)·w = cos α` is
//!
//! `a·cosθ + b·sinθ = c`, `a = u₀⊥·w`, `b = k·(u₀⊥ × w)`,
//! `c = cos α − (k·u₀)(k·w)`:
//!
//! the circle the tip of `u` runs on against the sphere of radius
//! `|u − w| = 2 sin(α/2)` (the chord of the angle, measured on the link
//! beyond) about the tip of `w`, [`crate::subproblems::circle_distance::circle_distance`] on
//! unit directions. Two roots, one double where the three axes lie in one
//! plane (the dyad folded: tangency, reported as such), none where the
//! cones do not meet; `w` along `k` is degenerate (every θ or none).

use super::search::Search;
use super::{place_axis, Found, Move};
use crate::model::JointType;
use crate::plan::{v3, Direction, Step};
use crate::primitives::Error as GeomError;
use crate::scalar::{constant, norm, reject, sub, unit, Scalar};
use crate::singular::{crossing, joint_point, Condition, Configuration, Factor};
use crate::solution::SolveError;
use nalgebra::Vector3;

/// The angle of revolute `mv.joint` that turns the axis of revolute
/// `across` (on the new link) to the angle the link beyond it keeps
/// between that axis and the axis of `target.joint`, known on
/// `target.link`; `branch` chooses the root.
pub fn execute<T: Scalar>(
    mv: &Move<'_, T>,
    across: usize,
    target: &Direction,
    branch: usize,
) -> Result<Found<T>, SolveError> {
    let (axis, zero) = mv.turning("a cone needs a revolute")?;
    let g = mv.geometry;
    let j = mv.joint();
    let q = &g.joints[across];
    let to_side = usize::from(q.links[0] != mv.to);
    let beyond = q.links[1 - to_side];
    // On the new link: Q's axis and J's, constants of the geometry.
    let a_to = unit(place_axis(&q.places[to_side]));
    let k_to = unit(place_axis(&j.places[usize::from(j.links[0] != mv.to)]));
    let u0 = zero.rotate(a_to);
    let length = norm(reject(a_to, k_to));
    // The known axis, and the chord of the angle the link beyond keeps.
    let w = unit(g.direction(mv.state.poses[target.link], target.link, target));
    let h = &g.joints[target.joint];
    let a_beyond = unit(place_axis(&q.places[1 - to_side]));
    let h_beyond = unit(place_axis(&h.places[usize::from(h.links[0] != beyond)]));
    let chord = norm(sub(a_beyond, h_beyond));
    let r = cone(axis, u0, length, w, chord, mv.choice(Some(branch)), mv.site()).map_err(|e| mv.fail(e))?;
    Ok(mv.found(r))
}

/// The turn `[cos θ, sin θ]` about the unit `axis` that carries the unit
/// direction `u0` to the angle α from the unit direction `w` where
/// `chord = |u − w| = 2 sin(α/2)`: the module's `a·cosθ + b·sinθ = c`,
/// solved as the circle–sphere distance on the directions' tips
/// ([`crate::subproblems::circle_distance::circle_distance`] with the centre at the origin;
/// `length` is `|u0⊥|`, the sine of the angle between `u0` and the axis,
/// from the link's own geometry). `Plus` is the root counter-clockwise
/// (about the axis) of `w⊥`'s direction.
///
/// # Errors
/// [`GeomError::Unreachable`] when the cones do not meet, by the chord's
/// excess over the largest (or shortfall from the smallest) chord the
/// circle reaches; [`GeomError::Degenerate`] when `u0` or `w` is along the
/// axis.
///
/// ```
/// use pkm_runtime::primitives::Sign;
/// use pkm_runtime::steps::cone::cone;
///
/// // x turned about z to 60° from y: sin θ = cos 60°, θ = 90° ± 60°, Plus 150°.
/// let (z, x, y) = ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
/// let chord = 2.0 * (std::f64::consts::FRAC_PI_6).sin();
/// let [c, s] = cone(z, x, 1.0, y, chord, Sign::Plus, [0, 0]).unwrap();
/// assert!((c + 0.75f64.sqrt()).abs() < 1e-15 && (s - 0.5).abs() < 1e-15);
/// ```
#[inline]
pub fn cone<T: Scalar>(
    axis: [T; 3],
    u0: [T; 3],
    length: T,
    w: [T; 3],
    chord: T,
    choice: T::Choice,
    site: [usize; 2],
) -> Result<[T; 2], GeomError<f64>> {
    crate::subproblems::circle_distance::circle_distance(constant([0.0; 3]), axis, u0, length, w, chord, choice, site)
}

/// The planner's match: a revolute `j` turning the new link `to` about its
/// axis, another revolute `q` of `to` whose axis meets `j`'s at a point
/// (not parallel), the link beyond `q` unknown, and a revolute `h` of that
/// link to a known link whose axis passes through the same point (carried
/// across `q`, the point stays on both axes): the three axes meet at one
/// centre, and `j`'s angle is `q`'s axis at the angle from `h`'s that the
/// link beyond keeps. Two roots.
pub(crate) fn find(s: &mut Search<'_>) -> bool {
    for (j, from, to) in s.candidates() {
        if s.kind(j) != JointType::R {
            continue;
        }
        for q in 0..s.model.joints.len() {
            if q == j || !revolute_open(s, q) || !s.model.joints[q].links.contains(&to) {
                continue;
            }
            let beyond = s.other(q, to);
            if s.known[beyond] {
                continue;
            }
            let Some(c) = meeting(s, j, q, to) else { continue };
            // The centre on the link beyond.
            let cb = s.zero(q, to).inverse_transform_point(&c.into()).coords;
            let found = (0..s.model.joints.len()).find(|&h| {
                h != q
                    && h != j
                    && revolute_open(s, h)
                    && s.model.joints[h].links.contains(&beyond)
                    && s.known[s.other(h, beyond)]
                    && s.on_axis(h, beyond, cb)
                    && !Search::parallel(s.axis(h, beyond), s.axis(q, beyond))
            });
            let Some(h) = found else { continue };
            s.branches += 1;
            let step = Step::Cone {
                joint: j,
                from,
                to,
                across: q,
                target: Direction {
                    link: s.other(h, beyond),
                    hops: Vec::new().into(),
                    joint: h,
                },
                branch: s.branches - 1,
            };
            s.push(step, to, j);
            return true;
        }
    }
    false
}

/// Whether `q` is a revolute no step has solved and no input gives.
fn revolute_open(s: &Search<'_>, q: usize) -> bool {
    s.kind(q) == JointType::R && !s.used[q] && s.given[q].is_none()
}

/// Where the axes of revolutes `j` and `q` meet on link `l` (in its
/// frame), if they meet at one point.
fn meeting(s: &Search<'_>, j: usize, q: usize, l: usize) -> Option<Vector3<f64>> {
    let (dj, dq) = (s.axis(j, l).normalize(), s.axis(q, l).normalize());
    if Search::parallel(dj, dq) {
        return None;
    }
    let (pj, pq) = (v3(s.place(j, l).at()), v3(s.place(q, l).at()));
    // The closest points of the two lines.
    let w = pj - pq;
    let (e, f, g) = (dj.dot(&dq), dj.dot(&w), dq.dot(&w));
    let den = 1.0 - e * e;
    let (a, b) = (pj + dj * ((e * g - f) / den), pq + dq * ((g - e * f) / den));
    ((a - b).norm() <= s.tol).then(|| (a + b) / 2.0)
}

/// The step's factor: the derivative of `u(θ)·w − cos α`, `(k × u)·w`,
/// over `|k × u|·|w⊥|` (`w⊥` normal to `u`): the cosine between the path of
/// `u`'s tip and the cone's normal there, zero where the three axes lie in
/// one plane (the two roots meet).
pub(crate) fn factor(
    at: &Configuration,
    k: usize,
    joint: usize,
    from: usize,
    to: usize,
    across: usize,
    target: &Direction,
) -> Factor {
    let j = &at.g.joints[joint];
    let q = &at.g.joints[across];
    let axis_of = |link: usize, g: &super::JointGeometry<f64>| -> Vector3<f64> {
        let side = usize::from(g.links[0] != link);
        v3(at.frames[link].rotate(place_axis(&g.places[side]))).normalize()
    };
    let (kk, u) = (axis_of(from, j), axis_of(to, q));
    let w = v3(at.g.direction(at.frames[target.link], target.link, target)).normalize();
    Factor {
        step: k,
        joint,
        condition: Condition::Coplanar,
        points: [
            joint_point(joint, from),
            joint_point(across, to),
            joint_point(target.joint, target.link),
        ],
        value: crossing(kk.cross(&u), w - u * u.dot(&w), 1.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::primitives::Sign;
    use std::f64::consts::{FRAC_PI_2, PI};

    fn dir(polar: f64, azimuth: f64) -> [f64; 3] {
        [polar.sin() * azimuth.cos(), polar.sin() * azimuth.sin(), polar.cos()]
    }

    /// The axis z; `u0` at polar angle β in xoz, `w` at polar angle γ and
    /// azimuth φ, the angle α between them asked for. By the spherical law
    /// of cosines, `cos α = cos β cos γ + sin β sin γ cos(θ − φ)`, so
    /// `θ = φ ± acos((cos α − cos β cos γ)/(sin β sin γ))`, Plus `+`.
    fn check(beta: f64, gamma: f64, phi: f64, alpha: f64) {
        let z = [0.0, 0.0, 1.0];
        let (u0, w) = (dir(beta, 0.0), dir(gamma, phi));
        let chord = 2.0 * (alpha / 2.0).sin();
        let x = (alpha.cos() - beta.cos() * gamma.cos()) / (beta.sin() * gamma.sin());
        for (sign, pm) in [(Sign::Plus, 1.0), (Sign::Minus, -1.0)] {
            let want = phi + pm * x.acos();
            let [c, s] = cone(z, u0, beta.sin(), w, chord, sign, [0, 0]).unwrap();
            assert!(
                (c - want.cos()).abs() < 1e-13 && (s - want.sin()).abs() < 1e-13,
                "β {beta} γ {gamma} φ {phi} α {alpha}: ({c}, {s}) vs {want}"
            );
            // The turned axis is α from w.
            let u = [c * u0[0] - s * u0[1], s * u0[0] + c * u0[1], u0[2]];
            let dot: f64 = (0..3).map(|i| u[i] * w[i]).sum();
            assert!((dot - alpha.cos()).abs() < 1e-13);
        }
    }

    #[test]
    fn both_roots_by_the_spherical_law_of_cosines() {
        // β = γ = α = 60°: cos θ = (1/2 − 1/4)/(3/4) = 1/3.
        check(PI / 3.0, PI / 3.0, 0.0, PI / 3.0);
        // Right angles everywhere: θ = φ ± 90°.
        check(FRAC_PI_2, FRAC_PI_2, 0.4, FRAC_PI_2);
        // The spherical four-bar's coupler: 70° against 60° at 80° with w off the plane.
        check(70f64.to_radians(), 80f64.to_radians(), 2.0, 60f64.to_radians());
        check(0.3, 2.5, -1.0, 2.4);
    }

    #[test]
    fn folded_cones_touch_and_apart_refuse() {
        let z = [0.0, 0.0, 1.0];
        let (u0, w) = (dir(PI / 3.0, 0.0), dir(PI / 6.0, 1.0));
        // α = β + γ = 90°: the cones touch, the double root θ = φ + π (the axes in one plane).
        let touch = 2.0 * (FRAC_PI_2 / 2.0).sin();
        for sign in [Sign::Plus, Sign::Minus] {
            let [c, s] = cone(z, u0, (PI / 3.0).sin(), w, touch, sign, [0, 0]).unwrap();
            assert!((c - (1.0 + PI).cos()).abs() < 1e-7 && (s - (1.0 + PI).sin()).abs() < 1e-7);
        }
        // α = 100° > β + γ: out of reach by the chord's excess 2 sin 50° − 2 sin 45°.
        let far = 2.0 * (50f64.to_radians()).sin();
        match cone(z, u0, (PI / 3.0).sin(), w, far, Sign::Plus, [0, 0]) {
            Err(GeomError::Unreachable { by, .. }) => {
                assert!((by - (far - 2.0 * (PI / 4.0).sin())).abs() < 1e-12, "{by}")
            }
            other => panic!("{other:?}"),
        }
        // w along the axis: every turn or none.
        assert!(matches!(
            cone(z, u0, (PI / 3.0).sin(), z, 1.0, Sign::Plus, [0, 0]),
            Err(GeomError::Degenerate { .. })
        ));
    }
}
