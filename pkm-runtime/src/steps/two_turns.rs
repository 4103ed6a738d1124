//! Two revolutes in series whose axes meet at a point `c`, turning a point
//! of the link beyond the second onto a known position: IK-Geo's
//! subproblem 2 (Paden–Kahan's second). The new link (a U's cross) turns
//! about the known axis `k₁` of revolute J; its revolute Q, axis `k₂`
//! through `c` (at θ₁ = 0), turns the link beyond, whose point `x` must
//! reach the known `t` (through joints that keep it put: a spherical
//! joint's centre). With `p = x − c` at θ₁ = θ₂ = 0 and `q = t − c`:
//!
//! `R(k₁, θ₁)·R(k₂, θ₂)·p = q`.
//!
//! Both turns keep distances from `c`, so `|p| = |q|` is needed (another
//! step holds it: `t` on the sphere of radius `|p|` about `c`,
//! [`super::rod`]); this step does not impose it, the joint at `t`
//! stays open and its closure checks it. The point between the two turns,
//! `z = R(k₂, θ₂)·p = R(k₁, −θ₁)·q`, lies on the cone of `p` about `k₂`
//! (`k₂·z = k₂·p`) and on the cone of `q` about `k₁` (`k₁·z = k₁·q`), at
//! `|z| = |p|`: the two cones meet where
//!
//! `z = α·k₁ + β·k₂ ± γ·(k₁ × k₂)`, with `c₁₂ = k₁·k₂`, `n² = |k₁ × k₂|² = 1 − c₁₂²`,
//! `α = (k₁·q − c₁₂·k₂·p)/n²`, `β = (k₂·p − c₁₂·k₁·q)/n²`,
//! `γ²·n² = |p|² − |α·k₁ + β·k₂|²` (`|α·k₁ + β·k₂|² = α·k₁·q + β·k₂·p`),
//!
//! two points, one double where the radicand is zero (the cones touch: `z`,
//! and so `q` turned back, in the plane of the two axes; tangency, within
//! [`TANGENCY_TOL`]), none where it is negative beyond it. Then `θ₁` turns
//! `z` onto `q` about `k₁` and `θ₂` turns `p` onto `z` about `k₂`, both
//! Paden–Kahan subproblem 1 ([`crate::subproblems::rotate_onto::turn_onto`]). The step places
//! the new link at `θ₁` ([`first_turn`]); the planner then finds the link
//! beyond by an aim, the same subproblem 1 as `θ₂` from the placed link
//! (one link per step), and the aim's miss checks the open joint at `t`.
//! [`turns`] gives both angles. `k₁ ∥ k₂` is degenerate (the cones
//! coaxial), and so is `q` on `k₁` (every `θ₁`).

use super::search::{reversed, Search};
use super::{place_axis, Found, Move};
use crate::model::JointType;
use crate::plan::{v3, Anchor, Step};
use crate::primitives::{Error as GeomError, TANGENCY_TOL};
use crate::scalar::{add, cross, dot, norm, scale, sub, unit, Failure, Scalar};
use crate::singular::{crossing, joint_point, Condition, Configuration, Factor};
use crate::solution::{PointRef, SolveError};

/// The angle of revolute `mv.joint` that lets revolute `across` (on the
/// new link) carry `point` of the link beyond it onto the anchored
/// position `target`; `branch` chooses the root.
pub fn execute<T: Scalar>(
    mv: &Move<'_, T>,
    across: usize,
    point: PointRef,
    target: &Anchor,
    branch: usize,
) -> Result<Found<T>, SolveError> {
    let (k1, zero) = mv.turning("two turns need a revolute")?;
    let g = mv.geometry;
    let q = &g.joints[across];
    let side = usize::from(q.links[0] != mv.to);
    let beyond = q.links[1 - side];
    // The meeting point: Q's place, on J's axis too (the planner's match).
    let at = q.places[side].at();
    let centre = zero.apply(at);
    let k2_to = unit(place_axis(&q.places[side]));
    let k2 = zero.rotate(k2_to);
    // The axes' cosine on the new link: a constant of the geometry.
    let j = mv.joint();
    let k1_to = unit(place_axis(&j.places[usize::from(j.links[0] != mv.to)]));
    let cos12 = dot(k1_to, k2_to) * T::c(if mv.forward() { 1.0 } else { -1.0 });
    // The point beyond, on the new link's frame at Q = 0, from the centre:
    // constants of the geometry, turned once.
    let x = g.local(point, beyond);
    let p = zero.rotate(sub(q.zero[side].apply(x), at));
    let length = norm(sub(x, q.places[1 - side].at()));
    let t = sub(g.anchor(&mv.state.poses, target), centre);
    let turn = first_turn([k1, k2], cos12, p, length, t, mv.choice(Some(branch)), mv.site()).map_err(|e| mv.fail(e))?;
    Ok(mv.found(turn))
}

/// The point `z` between the two turns, where the cone of `p` about `k2`
/// meets the cone of `q` about `k1` at `|z| = length`: the module's
/// `α·k₁ + β·k₂ ± γ·(k₁ × k₂)`, `k` the unit axes `[k1, k2]`. `length`
/// (`|p|`) and `cos12` (`k₁·k₂`) come from the links' own geometry, where
/// they are the same at every pose (`n² = (1 − c₁₂)(1 + c₁₂)`). `Plus` is
/// `+γ`, the side of `k₁ × k₂`. An excess of
/// `|α·k₁ + β·k₂|²` over `length²` up to `2·TANGENCY_TOL·length²` (the
/// distance `TANGENCY_TOL·length`, to first order) is rounding: the double
/// root.
///
/// # Errors
/// [`GeomError::Unreachable`] by `|α·k₁ + β·k₂| − length` when the cones
/// do not meet; [`GeomError::Degenerate`] when the axes are parallel
/// (`|k₁ × k₂|² ≤ 1e-18`).
///
/// ```
/// use pkm_runtime::primitives::Sign;
/// use pkm_runtime::steps::two_turns::meet;
///
/// // The cone of (0, 5, 0) about x (z_x = 0) and that of (3, 0, 4) about z (z_z = 4),
/// // at |z| = 5: z = (0, ±3, 4), Plus on the side of z × x = y.
/// let k = [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]];
/// let z = meet(k, 0.0, [0.0, 5.0, 0.0], 5.0, [3.0, 0.0, 4.0], Sign::Plus, [0, 0]).unwrap();
/// assert_eq!(z, [0.0, 3.0, 4.0]);
/// ```
#[inline]
pub fn meet<T: Scalar>(
    [k1, k2]: [[T; 3]; 2],
    cos12: T,
    p: [T; 3],
    length: T,
    q: [T; 3],
    choice: T::Choice,
    site: [usize; 2],
) -> Result<[T; 3], GeomError<f64>> {
    let c12 = cos12;
    let n2 = (T::c(1.0) - c12) * (T::c(1.0) + c12);
    T::require(T::c(1e-18), n2, Failure::Degenerate("the two axes are parallel"), site)?;
    let n = cross(k1, k2);
    let (a1, a2) = (dot(k1, q), dot(k2, p));
    let alpha = (a1 - c12 * a2) / n2;
    let beta = (a2 - c12 * a1) / n2;
    // |α·k₁ + β·k₂|², the part of z in the plane of the axes.
    let v2 = alpha * a1 + beta * a2;
    let l2 = length * length;
    let far = Failure::Unreachable("|the cones' common part in the axes' plane| <= |p|", v2.sqrt() - length);
    T::require(v2 - l2, T::c(2.0 * TANGENCY_TOL * (1.0 + f64::EPSILON)) * l2, far, site)?;
    // Within the tolerance beyond tangency: the double root.
    let r2 = T::if_less_continuous(v2, l2, l2 - v2, T::c(0.0));
    let gamma = (r2 / n2).sqrt();
    let v = add(scale(alpha, k1), scale(beta, k2));
    Ok(add(v, scale(T::pick(choice, gamma, -gamma), n)))
}

/// The first turn `[cos θ₁, sin θ₁]` of `R(k1, θ₁)·R(k2, θ₂)·p = q`:
/// [`meet`]'s `z` turned onto `q` about `k1` (subproblem 1).
///
/// # Errors
/// [`meet`]'s, and [`GeomError::Degenerate`] when `q` (or `z`) lies on
/// `k1`: every `θ₁`.
///
/// ```
/// use pkm_runtime::primitives::Sign;
/// use pkm_runtime::steps::two_turns::first_turn;
///
/// // Above: (0, 3, 4) turned about z onto (3, 0, 4), a quarter turn back.
/// let k = [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]];
/// let t = first_turn(k, 0.0, [0.0, 5.0, 0.0], 5.0, [3.0, 0.0, 4.0], Sign::Plus, [0, 0]).unwrap();
/// assert_eq!(t, [0.0, -1.0]);
/// ```
#[inline]
pub fn first_turn<T: Scalar>(
    k: [[T; 3]; 2],
    cos12: T,
    p: [T; 3],
    length: T,
    q: [T; 3],
    choice: T::Choice,
    site: [usize; 2],
) -> Result<[T; 2], GeomError<f64>> {
    let z = meet(k, cos12, p, length, q, choice, site)?;
    crate::subproblems::rotate_onto::turn_onto(k[0], z, q, site)
}

/// Both turns `[[cos θ₁, sin θ₁], [cos θ₂, sin θ₂]]` of
/// `R(k1, θ₁)·R(k2, θ₂)·p = q` (IK-Geo's subproblem 2): [`first_turn`],
/// and `p` turned onto [`meet`]'s `z` about `k2`.
///
/// # Errors
/// [`first_turn`]'s, and [`GeomError::Degenerate`] when `p` lies on `k2`.
pub fn turns<T: Scalar>(
    k: [[T; 3]; 2],
    cos12: T,
    p: [T; 3],
    length: T,
    q: [T; 3],
    choice: T::Choice,
    site: [usize; 2],
) -> Result<[[T; 2]; 2], GeomError<f64>> {
    let z = meet(k, cos12, p, length, q, choice, site)?;
    Ok([
        crate::subproblems::rotate_onto::turn_onto(k[0], z, q, site)?,
        crate::subproblems::rotate_onto::turn_onto(k[1], p, z, site)?,
    ])
}

/// The planner's match: a revolute `j` turning the new link `to`, an open
/// revolute `r` of `to` to an unknown link `beyond`, `r`'s place on `to`
/// on `j`'s axis (the axes meet there; not parallel), and a joint's place
/// on `beyond` off `r`'s axis that stays put through joints to a known
/// link (a spherical joint's centre, a point on revolutes' axes): the two
/// turns must carry it there. Two roots.
pub(crate) fn find(s: &mut Search<'_>) -> bool {
    let open_r = |s: &Search<'_>, q: usize| s.kind(q) == JointType::R && !s.used[q] && s.given[q].is_none();
    for (j, from, to) in s.candidates() {
        if s.kind(j) != JointType::R {
            continue;
        }
        let k = s.axis(j, to);
        for r in 0..s.model.joints.len() {
            if r == j || !open_r(s, r) || !s.model.joints[r].links.contains(&to) {
                continue;
            }
            let beyond = s.other(r, to);
            if s.known[beyond] || Search::parallel(s.axis(r, to), k) || !s.on_axis(j, to, v3(s.place(r, to).at())) {
                continue;
            }
            let (_, places) = s.across(r, to, j, k);
            for (point, x) in places {
                if s.on_axis(r, beyond, x) {
                    continue;
                }
                let reach = s
                    .fixed_reach(beyond, x, &[j, r])
                    .into_iter()
                    .find(|h| !h.hops.is_empty() && s.known[h.link]);
                let Some(h) = reach else { continue };
                s.branches += 1;
                let step = Step::TwoTurns {
                    joint: j,
                    from,
                    to,
                    across: r,
                    point,
                    target: Anchor {
                        link: h.link,
                        hops: reversed(&h.hops),
                        point,
                    },
                    branch: s.branches - 1,
                };
                s.push(step, to, j);
                return true;
            }
        }
    }
    false
}

/// The step's factor: the derivative of `k₂(θ₁)·q − k₂·p` (the first
/// turn's equation, `z` on the cone of `p` about `k₂`), `(k₁ × k₂(θ₁))·q`,
/// over `|k₁ × k₂|·|q|`: the cosine between the normal of the axes' plane
/// and `q`, zero where `q` lies in that plane (the two roots meet: the
/// cones touch) or on `k₁`.
pub(crate) fn factor(
    at: &Configuration,
    k: usize,
    joint: usize,
    from: usize,
    to: usize,
    across: usize,
    target: &Anchor,
) -> Factor {
    let axis_of = |link: usize, j: usize| -> ([f64; 3], [f64; 3]) {
        let g = &at.g.joints[j];
        let place = &g.places[usize::from(g.links[0] != link)];
        (
            at.frames[link].apply(place.at()),
            at.frames[link].rotate(unit(place_axis(place))),
        )
    };
    let (_, k1) = axis_of(from, joint);
    let (centre, k2) = axis_of(to, across);
    let (t, point) = at.anchored(target);
    Factor {
        step: k,
        joint,
        condition: Condition::InAxesPlane,
        points: [joint_point(joint, from), joint_point(across, to), point],
        value: crossing(v3(k1).cross(&v3(k2)), t - v3(centre), at.scale),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::primitives::Sign;
    use std::f64::consts::{FRAC_PI_2, PI};

    /// `R(k, θ)·v` by Rodrigues' formula, written out for the tests.
    fn rotate(k: [f64; 3], theta: f64, v: [f64; 3]) -> [f64; 3] {
        let (s, c) = theta.sin_cos();
        let kv = dot(k, v);
        let kxv = cross(k, v);
        std::array::from_fn(|i| v[i] * c + kxv[i] * s + k[i] * kv * (1.0 - c))
    }

    fn same_turn(t: [f64; 2], angle: f64, tol: f64) -> bool {
        (t[0] - angle.cos()).abs() < tol && (t[1] - angle.sin()).abs() < tol
    }

    /// Axes z then x, `p = L·(0, cos φ, sin φ)` normal to x: by hand
    /// `R(x, θ₂)·p = L·(0, cos(φ + θ₂), sin(φ + θ₂))` and
    /// `q = L·(−sin θ₁ cos(φ + θ₂), cos θ₁ cos(φ + θ₂), sin(φ + θ₂))`, so
    /// `sin(φ + θ₂) = q_z/L`, `cos(φ + θ₂) = ±√(1 − (q_z/L)²)` (Plus `+`:
    /// `z` on the side of z × x = y) and `θ₁ = atan2(−q_x, q_y)` for `+`,
    /// half a turn on for `−`.
    #[test]
    fn a_right_angled_pair_by_hand() {
        let (kz, kx) = ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
        for &(l, phi, qx, qy, qz) in &[
            (160.0, 0.0, -30.0, 150.0, 45.0),
            (160.0, 0.0, 100.0, -120.0, -30.0),
            (2.0, 0.4, 0.6, 1.2, -1.4),
            (5.0, -1.0, -3.0, -4.0, 0.0),
        ] {
            // q at the distance l from the centre.
            let f = l / f64::hypot(f64::hypot(qx, qy), qz);
            let q = [qx * f, qy * f, qz * f];
            let p = [0.0, l * phi.cos(), l * phi.sin()];
            let s2 = q[2] / l;
            let c2 = (1.0 - s2 * s2).sqrt();
            for (sign, pm) in [(Sign::Plus, 1.0), (Sign::Minus, -1.0)] {
                let theta1 = f64::atan2(-pm * q[0], pm * q[1]);
                let theta2 = f64::atan2(s2, pm * c2) - phi;
                let [t1, t2] = turns([kz, kx], 0.0, p, l, q, sign, [0, 0]).unwrap();
                assert!(same_turn(t1, theta1, 1e-14), "{q:?} {sign:?}: {t1:?} vs {theta1}");
                assert!(same_turn(t2, theta2, 1e-14), "{q:?} {sign:?}: {t2:?} vs {theta2}");
                assert_eq!(first_turn([kz, kx], 0.0, p, l, q, sign, [0, 0]).unwrap(), t1);
            }
        }
    }

    /// Oblique axes (k₁ = z, k₂ at β from it, not through a right angle)
    /// and a point off the normal plane of `k₂`: `q` made by turning `p`
    /// by chosen angles (Rodrigues, above); one of the two roots is those
    /// angles, and both carry `p` onto `q`.
    #[test]
    fn oblique_axes_give_back_the_angles_that_made_q() {
        let cases = [
            (0.7, [40.0, -25.0, 90.0], 0.9, -2.1),
            (1.2, [-10.0, 60.0, 20.0], -2.8, 0.4),
            (2.3, [5.0, 5.0, -50.0], 3.0, 1.5),
            (FRAC_PI_2, [0.0, 160.0, 0.0], -0.2, 0.3),
        ];
        for (beta, p, a1, a2) in cases {
            let k1 = [0.0, 0.0, 1.0];
            let k2 = [beta.sin(), 0.0, beta.cos()];
            let q = rotate(k1, a1, rotate(k2, a2, p));
            let length = norm(p);
            let roots =
                [Sign::Plus, Sign::Minus].map(|s| turns([k1, k2], beta.cos(), p, length, q, s, [0, 0]).unwrap());
            assert!(
                roots
                    .iter()
                    .any(|[t1, t2]| same_turn(*t1, a1, 1e-13) && same_turn(*t2, a2, 1e-13)),
                "β {beta}: {roots:?} vs {a1}, {a2}"
            );
            for [t1, t2] in roots {
                let back = rotate(k1, t1[1].atan2(t1[0]), rotate(k2, t2[1].atan2(t2[0]), p));
                assert!(norm(sub(back, q)) < 1e-12 * length, "β {beta}: {back:?} vs {q:?}");
            }
            // The two roots differ.
            let (r, m) = (roots[0][0], roots[1][0]);
            assert!((r[0] - m[0]).abs() + (r[1] - m[1]).abs() > 1e-3, "β {beta}: {roots:?}");
        }
    }

    /// `p = (3, 4, 0)` about x sweeps the cone `z_x = 3`; `q` at height 4
    /// about z sweeps `z_z = 4`; at `|z| = 5` they touch at `z = (3, 0, 4)`:
    /// the double root, `θ₂ = 90°` (`(3, 4, 0)` onto `(3, 0, 4)`) and `θ₁`
    /// the angle of `q` about z. Higher, the cones miss.
    #[test]
    fn touching_cones_and_refusals() {
        let (kz, kx) = ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
        let p = [3.0, 4.0, 0.0];
        let a = 0.8;
        let touch = [3.0 * f64::cos(a), 3.0 * f64::sin(a), 4.0];
        for sign in [Sign::Plus, Sign::Minus] {
            let [t1, t2] = turns([kz, kx], 0.0, p, 5.0, touch, sign, [0, 0]).unwrap();
            assert!(
                same_turn(t1, a, 1e-15) && same_turn(t2, FRAC_PI_2, 1e-15),
                "{t1:?} {t2:?}"
            );
            // A hair higher (within the tolerance): the same double root.
            let hair = [touch[0], touch[1], 4.0 * (1.0 + 1e-11)];
            let [h1, _] = turns([kz, kx], 0.0, p, 5.0, hair, sign, [0, 0]).unwrap();
            assert!(same_turn(h1, a, 1e-9), "{h1:?}");
        }
        // At height 4.5 the axes' part is √(9 + 20.25) > 5: out of reach by √29.25 − 5.
        match turns([kz, kx], 0.0, p, 5.0, [3.0, 0.0, 4.5], Sign::Plus, [0, 0]) {
            Err(GeomError::Unreachable { by, .. }) => assert!((by - (29.25f64.sqrt() - 5.0)).abs() < 1e-14, "{by}"),
            other => panic!("{other:?}"),
        }
        // Parallel axes; q on the first axis (every θ₁); p on the second (every θ₂).
        let degenerate = |r: Result<[[f64; 2]; 2], GeomError<f64>>| matches!(r, Err(GeomError::Degenerate { .. }));
        assert!(degenerate(turns(
            [kz, kz],
            1.0,
            p,
            5.0,
            [3.0, 0.0, 4.0],
            Sign::Plus,
            [0, 0]
        )));
        assert!(degenerate(turns(
            [kz, kx],
            0.0,
            [0.0, 5.0, 0.0],
            5.0,
            [0.0, 0.0, 5.0],
            Sign::Plus,
            [0, 0]
        )));
        assert!(degenerate(turns(
            [kz, kx],
            0.0,
            [5.0, 0.0, 0.0],
            5.0,
            [3.0, 4.0, 0.0],
            Sign::Plus,
            [0, 0]
        )));
        // Half a turn about the first axis and the second root: PI apart for p ⊥ k₂.
        let q = [0.0, 3.0, 4.0];
        let [plus, _] = turns([kz, kx], 0.0, [0.0, 5.0, 0.0], 5.0, q, Sign::Plus, [0, 0]).unwrap();
        let [minus, _] = turns([kz, kx], 0.0, [0.0, 5.0, 0.0], 5.0, q, Sign::Minus, [0, 0]).unwrap();
        assert!(
            same_turn(plus, 0.0, 1e-15) && same_turn(minus, PI, 1e-15),
            "{plus:?} {minus:?}"
        );
    }
}
