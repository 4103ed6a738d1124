//! A link whose pose an output gives in part ([`PoseParts`] that leave
//! some of its six values to the mechanism: a 3-RPS or 3-PRS platform's
//! parasitic motion), the rest found from the planes its limbs hold its
//! points on. A limb whose joints from a known link are revolutes about
//! one direction `n` and slides normal to it, ending in a spherical joint
//! on the link, holds that joint's centre on the plane `n·X = d` it sweeps.
//!
//! With `R = A·R_k(θ)·B` (`θ` the one free angle, `k` its axis; `A`, `B`
//! the given turns before and after it in `R_z(rz)·R_y(ry)·R_x(rx)`), the
//! output point at `p` and a limb's point `b` (`o` the output's point, both
//! in the link's frame), `c = B·(b − o)` splits into `c∥` along `k` and `c⊥`
//! normal to it, and the point is
//!
//! `X = p + A·c∥ + cosθ·A·c⊥ + sinθ·A·(k × c⊥)`.
//!
//! Each plane gives one row linear in the free coordinates `u` of `p` and
//! in `(cos θ, sin θ)`: `M·u + a·cosθ + b·sinθ = r`, `m` rows for `m − 1`
//! free coordinates. A vector `w` normal to `M`'s columns (`wᵀM = 0`: the
//! two components swapped and one negated for one column, the cross
//! product of two) leaves `(w·a)·cosθ + (w·b)·sinθ = w·r`, the
//! circle-meets-plane kernel ([`super::on_plane::trig_turn`], two roots);
//! then `u` from `M·u = r − a·cosθ − b·sinθ`, by the same cross products
//! (`u₀ = ((q × M₁)·w)/|w|²`, `u₁ = ((M₀ × q)·w)/|w|²`). Without a free
//! angle `M·u = r` is square and solved by Cramer's rule. At most one free
//! angle and three rows: the planner refuses more.

use super::place::{elementary, rotation_of_angles, PoseParts};
use super::search::{reversed, Search};
use super::{Geometry, Given};
use crate::frame::Frame;
use crate::model::JointType;
use crate::primitives::Error as GeomError;
use crate::scalar::{constant, cross, dot, norm, sub, Failure, Scalar};
use crate::solution::{step_error, PointRef, SolveError};
use crate::spatial::{Anchor, Direction, Hop, Step};
use nalgebra::Vector3;

/// One limb's hold on the link: `point` of the link on the plane with
/// normal `normal` through `anchor`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Limb {
    /// The point of the link (a spherical joint's centre).
    pub point: PointRef,
    /// The plane's normal, known through the limb.
    pub normal: Direction,
    /// A point of the plane: the joint's centre carried back at value 0.
    pub anchor: Anchor,
}

/// The pose of `link` whose `point` and given parts are the values from
/// `input` (in the order x, y, z, rx, ry, rz, the given ones only), the
/// free parts from the limbs' planes; `branch` picks the angle's root.
#[allow(clippy::too_many_arguments)]
pub fn execute<T: Scalar>(
    k: usize,
    link: usize,
    point: PointRef,
    input: usize,
    parts: PoseParts,
    limbs: &[Limb],
    branch: Option<usize>,
    geometry: &Geometry<T>,
    poses: &[Frame<T>],
    given: &Given<'_, T>,
) -> Result<Frame<T>, SolveError> {
    let mut rows = [([T::c(0.0); 3], [T::c(0.0); 3], T::c(0.0)); 3];
    for (row, limb) in rows.iter_mut().zip(limbs) {
        let n = geometry.direction(poses[limb.normal.link], limb.normal.link, &limb.normal);
        *row = (
            geometry.local(limb.point, link),
            n,
            dot(n, geometry.anchor(poses, &limb.anchor)),
        );
    }
    let values = &given.values[input..input + parts.count()];
    let site = [k, given.sites + k];
    free_parts(
        parts,
        values,
        geometry.local(point, link),
        &rows[..limbs.len()],
        T::choice(given.signs, branch),
        site,
    )
    .map_err(|e| step_error(k, (given.name)(k), e))
}

/// The pose with the given parts `values` (in order) and the free ones
/// that put each `rows[i].0` (a point in the link's frame) on the plane
/// `rows[i].1 · X = rows[i].2`; `o` is the output's point in the link's
/// frame. One row per free part (see the module's derivation).
///
/// # Errors
/// [`GeomError::Degenerate`] when the planes do not determine the free
/// parts (their normals dependent); [`GeomError::Unreachable`] when no
/// angle puts the points on their planes.
///
/// ```
/// use pkm_runtime::primitives::Sign;
/// use pkm_runtime::steps::parasitic::free_parts;
/// use pkm_runtime::steps::place::PoseParts;
///
/// // z, rx, ry given (0.1, 0, 0); x, y, rz free. Three points at radius 1
/// // on the planes x = 0.2, y = 0.3, y = 0.3 + 0.5.
/// let parts = PoseParts([false, false, true, true, true, false]);
/// let (ex, ey) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
/// let rows = [([0.0, 0.0, 0.0], ex, 0.2), ([0.0, 0.0, 0.0], ey, 0.3), ([1.0, 0.0, 0.0], ey, 0.8)];
/// let pose = free_parts(parts, &[0.1, 0.0, 0.0], [0.0; 3], &rows, Sign::Plus, [0, 0]).unwrap();
/// // The platform turned by asin(0.5) about z (or π − that), its origin at (0.2, 0.3, 0.1).
/// assert!((pose.t[0] - 0.2).abs() < 1e-15 && (pose.t[1] - 0.3).abs() < 1e-15 && pose.t[2] == 0.1);
/// assert!((pose.r[1][0] - 0.5).abs() < 1e-15);
/// ```
pub fn free_parts<T: Scalar>(
    parts: PoseParts,
    values: &[T],
    o: [T; 3],
    rows: &[([T; 3], [T; 3], T)],
    choice: T::Choice,
    site: [usize; 2],
) -> Result<Frame<T>, GeomError<f64>> {
    let zero = T::c(0.0);
    let mut six = [zero; 6];
    for (i, v) in parts.given().zip(values) {
        six[i] = *v;
    }
    let free_t: Vec<usize> = parts.free().filter(|&i| i < 3).collect();
    let angle = parts.free().find(|&i| i >= 3).map(|i| i - 3);
    let known = |n: [T; 3]| (0..3).filter(|i| parts.0[*i]).fold(zero, |acc, i| acc + n[i] * six[i]);
    let degenerate = Failure::Degenerate("the limbs' planes do not determine the free parts of the pose");
    let turn = |i: usize| (six[3 + i].cos(), six[3 + i].sin());
    let rotation = match angle {
        None => {
            let r = rotation_of_angles([six[3], six[4], six[5]]);
            // M·u = r, square.
            let rhs: Vec<T> = rows
                .iter()
                .map(|(b, n, d)| *d - known(*n) - dot(*n, r.rotate(sub(*b, o))))
                .collect();
            let cols: Vec<[T; 3]> = free_t.iter().map(|&t| column(rows, t)).collect();
            let u = cramer(&cols, &rhs, degenerate, site)?;
            for (t, v) in free_t.iter().zip(u) {
                six[*t] = v;
            }
            r
        }
        Some(k) => {
            let (a_turn, b_turn) = match k {
                2 => (Frame::identity(), elementary(1, turn(1)).then(&elementary(0, turn(0)))),
                1 => (elementary(2, turn(2)), elementary(0, turn(0))),
                _ => (elementary(2, turn(2)).then(&elementary(1, turn(1))), Frame::identity()),
            };
            let mut a = [zero; 3];
            let mut b = [zero; 3];
            let mut r = [zero; 3];
            for (i, (x, n, d)) in rows.iter().enumerate() {
                let c = b_turn.rotate(sub(*x, o));
                let mut along = [zero; 3];
                along[k] = c[k];
                let mut normal = c;
                normal[k] = zero;
                let mut e = [zero; 3];
                e[k] = T::c(1.0);
                a[i] = dot(*n, a_turn.rotate(normal));
                b[i] = dot(*n, a_turn.rotate(cross(e, normal)));
                r[i] = *d - known(*n) - dot(*n, a_turn.rotate(along));
            }
            let cols: Vec<[T; 3]> = free_t.iter().map(|&t| column(rows, t)).collect();
            // w normal to M's columns.
            let w = match cols.len() {
                0 => [T::c(1.0), zero, zero],
                1 => [cols[0][1], -cols[0][0], zero],
                _ => cross(cols[0], cols[1]),
            };
            let size = cols.iter().fold(T::c(1.0), |acc, c| acc * norm(*c));
            T::require(T::c(1e-12) * size, norm(w), degenerate, site)?;
            let [c, s] = super::on_plane::trig_turn(dot(w, a), dot(w, b), dot(w, r), choice, site, None)?;
            let q = [0, 1, 2].map(|i| r[i] - a[i] * c - b[i] * s);
            let ww = dot(w, w);
            let u: Vec<T> = match cols.len() {
                0 => vec![],
                1 => {
                    vec![(cols[0][0] * q[0] + cols[0][1] * q[1]) / (cols[0][0] * cols[0][0] + cols[0][1] * cols[0][1])]
                }
                _ => vec![dot(cross(q, cols[1]), w) / ww, dot(cross(cols[0], q), w) / ww],
            };
            for (t, v) in free_t.iter().zip(u) {
                six[*t] = v;
            }
            a_turn.then(&elementary(k, (c, s))).then(&b_turn)
        }
    };
    let mut pose = rotation;
    pose.t = sub([six[0], six[1], six[2]], pose.rotate(o));
    Ok(pose)
}

/// Column `t` of the rows' normals: each plane's normal component `t`.
fn column<T: Scalar>(rows: &[([T; 3], [T; 3], T)], t: usize) -> [T; 3] {
    let mut col = constant([0.0; 3]);
    for (i, (_, n, _)) in rows.iter().enumerate().take(3) {
        col[i] = n[t];
    }
    col
}

/// `cols · u = rhs` for one to three columns (Cramer's rule with cross
/// products).
fn cramer<T: Scalar>(
    cols: &[[T; 3]],
    rhs: &[T],
    degenerate: Failure<T>,
    site: [usize; 2],
) -> Result<Vec<T>, GeomError<f64>> {
    let mut r = constant([0.0; 3]);
    for (i, v) in rhs.iter().enumerate().take(3) {
        r[i] = *v;
    }
    let size = cols.iter().fold(T::c(1.0), |acc, c| acc * norm(*c));
    Ok(match cols.len() {
        0 => vec![],
        1 => {
            T::require(T::c(1e-12) * size, cols[0][0].abs(), degenerate, site)?;
            vec![r[0] / cols[0][0]]
        }
        2 => {
            let det = cols[0][0] * cols[1][1] - cols[1][0] * cols[0][1];
            T::require(T::c(1e-12) * size, det.abs(), degenerate, site)?;
            vec![
                (r[0] * cols[1][1] - cols[1][0] * r[1]) / det,
                (cols[0][0] * r[1] - r[0] * cols[0][1]) / det,
            ]
        }
        _ => {
            let det = dot(cols[0], cross(cols[1], cols[2]));
            T::require(T::c(1e-12) * size, det.abs(), degenerate, site)?;
            vec![
                dot(r, cross(cols[1], cols[2])) / det,
                dot(cols[0], cross(r, cols[2])) / det,
                dot(cols[0], cross(cols[1], r)) / det,
            ]
        }
    })
}

/// The planner's start for `link`, given in part by `parts` at its `point`
/// from input `input`: a limb for each free part (see the module), each a
/// chain of links with two joints each from a spherical joint of `link` to
/// a known link. Adds the step and knows the link.
///
/// # Errors
/// What the limbs lack, for the planner's message.
pub fn start(s: &mut Search<'_>, link: usize, point: PointRef, input: usize, parts: PoseParts) -> Result<(), String> {
    let free = 6 - parts.count();
    let free_angles = parts.free().filter(|&i| i >= 3).count();
    if free_angles > 1 {
        return Err(format!(
            "a pose given in part may leave at most one of rx, ry, rz to the mechanism ({free_angles} are left)"
        ));
    }
    if free > 3 {
        return Err(format!(
            "a pose given in part may leave at most three values to the mechanism ({free} are left)"
        ));
    }
    let limbs: Vec<Limb> = (0..s.model.joints.len())
        .filter(|&j| s.kind(j) == JointType::S && s.model.joints[j].links.contains(&link))
        .filter_map(|j| limb_plane(s, link, j))
        .take(free)
        .collect();
    if limbs.len() < free {
        return Err(format!(
            "{free} values of the pose are left to the mechanism, and {} of its limbs hold a spherical joint's \
             centre on a plane (revolutes about one direction and slides normal to it)",
            limbs.len()
        ));
    }
    let branch = if free_angles == 1 {
        s.branches += 1;
        Some(s.branches - 1)
    } else {
        None
    };
    s.steps.push(Step::Parasitic {
        link,
        point,
        input,
        parts,
        limbs,
        branch,
    });
    s.known[link] = true;
    Ok(())
}

/// The plane spherical joint `sj` of `link` is held on: from its other
/// link, a chain of links with two joints each to a known link, its
/// revolutes about one direction and its slides normal to it.
fn limb_plane(s: &Search<'_>, link: usize, sj: usize) -> Option<Limb> {
    let start = s.other(sj, link);
    let (mut cur, mut prev) = (start, sj);
    let mut hops: Vec<Hop> = Vec::new();
    let mut normal: Option<(usize, Vector3<f64>)> = None;
    let mut slides: Vec<Vector3<f64>> = Vec::new();
    loop {
        if s.known[cur] && cur != start {
            break;
        }
        let next: Vec<usize> = (0..s.model.joints.len())
            .filter(|&q| q != prev && s.model.joints[q].links.contains(&cur))
            .collect();
        let [q] = next[..] else { return None };
        let dir = s.rotation(&hops) * s.axis(q, cur);
        match s.kind(q) {
            JointType::R | JointType::Pa => match normal {
                None => normal = Some((hops.len(), dir)),
                Some((_, n)) if Search::parallel(dir, n) => {}
                Some(_) => return None,
            },
            JointType::P => slides.push(dir),
            JointType::S => return None,
        }
        hops.push(s.hop(q, cur));
        let to = s.other(q, cur);
        if to == link || hops.len() > s.model.joints.len() {
            return None;
        }
        (cur, prev) = (to, q);
        if s.known[cur] {
            break;
        }
    }
    let (g_pos, n) = normal?;
    if !slides.iter().all(|d| Search::normal(*d, n)) {
        return None;
    }
    Some(Limb {
        point: PointRef::Joint(sj),
        normal: Direction {
            link: cur,
            hops: reversed(&hops[g_pos..]),
            joint: hops[g_pos].joint,
        },
        anchor: Anchor {
            link: cur,
            hops: reversed(&hops),
            point: PointRef::Joint(sj),
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::primitives::Sign;

    /// A platform given z, rx, ry; its x, y, rz found from three planes
    /// through the base's radial lines (a 3-RPS's: each leg's plane holds
    /// the base's centre line and its ball joint), checked against the
    /// points put back on the planes by hand.
    #[test]
    fn free_parts_put_the_points_on_their_planes() {
        let parts = PoseParts([false, false, true, true, true, false]);
        let (z, rx, ry) = (150.0, 0.2, -0.15);
        let ball = |i: f64| {
            let t = i * 2.0 * std::f64::consts::PI / 3.0;
            [100.0 * t.cos(), 100.0 * t.sin(), 0.0]
        };
        // Leg i's plane: through the z axis and the base point at angle t, its normal horizontal.
        let rows: Vec<([f64; 3], [f64; 3], f64)> = (0..3)
            .map(|i| {
                let t = f64::from(i) * 2.0 * std::f64::consts::PI / 3.0;
                (ball(f64::from(i)), [-t.sin(), t.cos(), 0.0], 0.0)
            })
            .collect();
        for sign in [Sign::Plus, Sign::Minus] {
            let pose = free_parts(parts, &[z, rx, ry], [0.0; 3], &rows, sign, [0, 0]).unwrap();
            for (b, n, d) in &rows {
                let x = pose.apply(*b);
                assert!(
                    (dot(*n, x) - d).abs() < 1e-12,
                    "{sign:?}: off its plane by {}",
                    dot(*n, x) - d
                );
            }
            // The given parts are kept: z, and the tilt (R's third row from rx, ry).
            assert_eq!(pose.t[2], z);
            let r = rotation_of_angles([rx, ry, 0.0]);
            assert!((pose.r[2][0] - r.r[2][0]).abs() < 1e-15 && (pose.r[2][2] - r.r[2][2]).abs() < 1e-15);
        }
    }

    /// Translations alone (all three angles given): Cramer's rule on three
    /// coordinate planes gives their offsets back.
    #[test]
    fn free_translations_alone_are_the_planes_offsets() {
        let parts = PoseParts([false, false, false, true, true, true]);
        let o = [0.0; 3];
        let rows = [
            ([0.0; 3], [1.0, 0.0, 0.0], 3.0),
            ([0.0; 3], [0.0, 1.0, 0.0], -2.0),
            ([0.0; 3], [0.0, 0.0, 1.0], 5.0),
        ];
        let pose = free_parts(parts, &[0.0, 0.0, 0.0], o, &rows, Sign::Plus, [0, 0]).unwrap();
        assert_eq!(pose.t, [3.0, -2.0, 5.0]);
        // Two parallel planes leave a coordinate undetermined.
        let rows = [rows[0], rows[0], rows[2]];
        assert!(free_parts(parts, &[0.0, 0.0, 0.0], o, &rows, Sign::Plus, [0, 0]).is_err());
    }
}
