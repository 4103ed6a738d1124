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
//! circle-meets-plane kernel ([`crate::subproblems::trig::trig_turn`], two roots);
//! then `u` from `M·u = r − a·cosθ − b·sinθ`, by the same cross products
//! (`u₀ = ((q × M₁)·w)/|w|²`, `u₁ = ((M₀ × q)·w)/|w|²`). Without a free
//! angle `M·u = r` is square and solved by Cramer's rule. At most one free
//! angle and three rows: the planner refuses more.
//!
//! A limb may hold it the other way round (a 3-SPR's): from the link,
//! revolutes about one direction `n` fixed in the link and slides normal to
//! it, ending in a spherical joint on a known link, whose centre `c` (world)
//! is then held on the plane `n·(Y − o) = e` of the link's own frame. With
//! `m = B·n`, `x = Aᵀ·(c − p₀)` (`p₀` the given coordinates of `p`, the
//! free ones 0) and `v = R_k(−θ)·Aᵀ·p_f` (`p_f` the free coordinates),
//! `(A·R_k(θ)·m)·(c − p) = e` reads
//!
//! `−m·v + cosθ·(m⊥·x) + sinθ·((k × m⊥)·x) = e − m∥·x`,
//!
//! the same kind of row in the coordinates of `v` along `Aᵀ·e_t` for each
//! free coordinate `t`, provided `Aᵀ·span{e_t}` is turned into itself by
//! `R_k` whatever the given angles are: no free coordinate, or `rz` free
//! (`A = I`) with `z` alone or `x, y` free (the planner checks this). Then
//! `p_f = A·R_k(θ)·v`. Both kinds of rows mix where `v = Aᵀ·p_f` (no free
//! coordinate, or `z` alone with `rz`), and always without a free angle
//! (`R` known: `−(R·n)·p_f = e − (R·n)·(c − p₀)`, linear).

use super::place::{elementary, rotation_of_angles, PoseParts};
use super::search::{reversed, Search};
use super::{Geometry, Given};
use crate::frame::Frame;
use crate::model::JointType;
use crate::plan::{Anchor, Direction, Hop, Step};
use crate::primitives::Error as GeomError;
use crate::scalar::{add, constant, cross, dot, norm, scale, sub, Failure, Scalar};
use crate::solution::{step_error, PointRef, SolveError};
use nalgebra::Vector3;

/// One limb's hold on the link: `point` of the link on the plane with
/// normal `normal` through `anchor` (`known: None`), or `point` of link
/// `known` on the link's own plane with normal `normal` through `anchor`,
/// both starting from the link (`known: Some(..)`, see the module).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Limb {
    /// The point held: of the link (`known: None`) or of link `known` (a
    /// spherical joint's centre).
    pub point: PointRef,
    /// The plane's normal, known through the limb (from the link itself
    /// when `known` is set).
    pub normal: Direction,
    /// A point of the plane: the joint's centre carried back at value 0
    /// (into the link's frame when `known` is set).
    pub anchor: Anchor,
    /// The known link whose point is held on a plane of the link, if the
    /// limb holds it that way round.
    pub known: Option<usize>,
}

/// One plane condition of [`free_parts`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Hold<T> {
    /// `point` of the link (in its frame) on the world plane `normal · X = offset`.
    Point {
        /// The link's point, in its frame.
        point: [T; 3],
        /// The plane's world normal.
        normal: [T; 3],
        /// The plane's offset along it.
        offset: T,
    },
    /// The world point `point` on the link's plane `normal · Y = offset`
    /// (`Y` in the link's frame).
    Plane {
        /// The world point.
        point: [T; 3],
        /// The plane's normal in the link's frame.
        normal: [T; 3],
        /// The plane's offset along it from the link's origin.
        offset: T,
    },
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
    let rows: Vec<Hold<T>> = limbs
        .iter()
        .map(|limb| match limb.known {
            None => {
                let n = geometry.direction(poses[limb.normal.link], limb.normal.link, &limb.normal);
                Hold::Point {
                    point: geometry.local(limb.point, link),
                    normal: n,
                    offset: dot(n, geometry.anchor(poses, &limb.anchor)),
                }
            }
            Some(known) => {
                // The plane in the link's own frame (its pose the identity).
                let n = geometry.direction(Frame::identity(), link, &limb.normal);
                let (hops, last) = geometry.across(Frame::identity(), link, &limb.anchor.hops);
                let at = hops.apply(geometry.local(limb.anchor.point, last));
                Hold::Plane {
                    point: poses[known].apply(geometry.local(limb.point, known)),
                    normal: n,
                    offset: dot(n, at),
                }
            }
        })
        .collect();
    let values = &given.values[input..input + parts.count()];
    let site = [k, given.sites + k];
    free_parts(
        parts,
        values,
        geometry.local(point, link),
        &rows,
        T::choice(given.signs, branch),
        site,
    )
    .map_err(|e| step_error(k, (given.name)(k), e))
}

/// The pose with the given parts `values` (in order) and the free ones
/// that hold each row's point on its plane ([`Hold`]); `o` is the output's
/// point in the link's frame. One row per free part (see the module's
/// derivation).
///
/// # Errors
/// [`GeomError::Degenerate`] when the planes do not determine the free
/// parts (their normals dependent); [`GeomError::Unreachable`] when no
/// angle puts the points on their planes.
///
/// ```
/// use pkm_runtime::primitives::Sign;
/// use pkm_runtime::steps::parasitic::{free_parts, Hold};
/// use pkm_runtime::steps::place::PoseParts;
///
/// // z, rx, ry given (0.1, 0, 0); x, y, rz free. Three points at radius 1
/// // on the planes x = 0.2, y = 0.3, y = 0.3 + 0.5.
/// let parts = PoseParts([false, false, true, true, true, false]);
/// let (ex, ey) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
/// let hold = |point, normal, offset| Hold::Point { point, normal, offset };
/// let rows = [hold([0.0; 3], ex, 0.2), hold([0.0; 3], ey, 0.3), hold([1.0, 0.0, 0.0], ey, 0.8)];
/// let pose = free_parts(parts, &[0.1, 0.0, 0.0], [0.0; 3], &rows, Sign::Plus, [0, 0]).unwrap();
/// // The platform turned by asin(0.5) about z (or π − that), its origin at (0.2, 0.3, 0.1).
/// assert!((pose.t[0] - 0.2).abs() < 1e-15 && (pose.t[1] - 0.3).abs() < 1e-15 && pose.t[2] == 0.1);
/// assert!((pose.r[1][0] - 0.5).abs() < 1e-15);
/// ```
pub fn free_parts<T: Scalar>(
    parts: PoseParts,
    values: &[T],
    o: [T; 3],
    rows: &[Hold<T>],
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
    // The given coordinates of the point, the free ones 0.
    let p0 = [0, 1, 2].map(|i| if parts.0[i] { six[i] } else { zero });
    let unit = |t: usize| {
        let mut e = [zero; 3];
        e[t] = T::c(1.0);
        e
    };
    let degenerate = Failure::Degenerate("the limbs' planes do not determine the free parts of the pose");
    let turn = |i: usize| (six[3 + i].cos(), six[3 + i].sin());
    let mut cols: Vec<[T; 3]> = vec![[zero; 3]; free_t.len()];
    // `A` and `A·R_k(θ)` when the unknowns are the coordinates of `v` (some
    // row of the link's own plane and a free angle), not those of `p_f`.
    let mut turned: Option<(Frame<T>, Frame<T>)> = None;
    let (rotation, u) = match angle {
        None => {
            let r = rotation_of_angles([six[3], six[4], six[5]]);
            // M·u = r, square.
            let mut rhs: Vec<T> = Vec::with_capacity(rows.len());
            for (i, row) in rows.iter().enumerate() {
                match *row {
                    Hold::Point { point, normal, offset } => {
                        for (col, &t) in cols.iter_mut().zip(&free_t) {
                            col[i] = normal[t];
                        }
                        rhs.push(offset - known(normal) - dot(normal, r.rotate(sub(point, o))));
                    }
                    Hold::Plane { point, normal, offset } => {
                        // (R·n)·(c − p₀ − p_f) = e.
                        let n = r.rotate(normal);
                        for (col, &t) in cols.iter_mut().zip(&free_t) {
                            col[i] = -n[t];
                        }
                        rhs.push(offset - dot(normal, o) - dot(n, sub(point, p0)));
                    }
                }
            }
            let u = cramer(&cols, &rhs, degenerate, site)?;
            (r, u)
        }
        Some(k) => {
            let (a_turn, b_turn) = match k {
                2 => (Frame::identity(), elementary(1, turn(1)).then(&elementary(0, turn(0)))),
                1 => (elementary(2, turn(2)), elementary(0, turn(0))),
                _ => (elementary(2, turn(2)).then(&elementary(1, turn(1))), Frame::identity()),
            };
            let mut e = [zero; 3];
            e[k] = T::c(1.0);
            // `along` and `normal` to k of a vector.
            let split = |c: [T; 3]| {
                let mut along = [zero; 3];
                along[k] = c[k];
                let mut normal = c;
                normal[k] = zero;
                (along, normal)
            };
            let mut a = [zero; 3];
            let mut b = [zero; 3];
            let mut r = [zero; 3];
            for (i, row) in rows.iter().enumerate() {
                match *row {
                    Hold::Point {
                        point: x,
                        normal: n,
                        offset: d,
                    } => {
                        let (along, normal) = split(b_turn.rotate(sub(x, o)));
                        a[i] = dot(n, a_turn.rotate(normal));
                        b[i] = dot(n, a_turn.rotate(cross(e, normal)));
                        r[i] = d - known(n) - dot(n, a_turn.rotate(along));
                        for (col, &t) in cols.iter_mut().zip(&free_t) {
                            col[i] = n[t];
                        }
                    }
                    Hold::Plane { point, normal, offset } => {
                        let m = b_turn.rotate(normal);
                        let (along, across) = split(m);
                        let x = a_turn.rotate_back(sub(point, p0));
                        a[i] = dot(across, x);
                        b[i] = dot(cross(e, across), x);
                        r[i] = offset - dot(normal, o) - dot(along, x);
                        for (col, &t) in cols.iter_mut().zip(&free_t) {
                            col[i] = -dot(m, a_turn.rotate_back(unit(t)));
                        }
                        turned = Some((a_turn, a_turn));
                    }
                }
            }
            // w normal to M's columns.
            let w = match cols.len() {
                0 => [T::c(1.0), zero, zero],
                1 => [cols[0][1], -cols[0][0], zero],
                _ => cross(cols[0], cols[1]),
            };
            let size = cols.iter().fold(T::c(1.0), |acc, c| acc * norm(*c));
            T::require(T::c(1e-12) * size, norm(w), degenerate, site)?;
            let [c, s] = crate::subproblems::trig::trig_turn(dot(w, a), dot(w, b), dot(w, r), choice, site, None)?;
            let q = [0, 1, 2].map(|i| r[i] - a[i] * c - b[i] * s);
            let ww = dot(w, w);
            let u: Vec<T> = match cols.len() {
                0 => vec![],
                1 => {
                    vec![(cols[0][0] * q[0] + cols[0][1] * q[1]) / (cols[0][0] * cols[0][0] + cols[0][1] * cols[0][1])]
                }
                _ => vec![dot(cross(q, cols[1]), w) / ww, dot(cross(cols[0], q), w) / ww],
            };
            let turn_k = elementary(k, (c, s));
            turned = turned.map(|(a_turn, _)| (a_turn, a_turn.then(&turn_k)));
            (a_turn.then(&turn_k).then(&b_turn), u)
        }
    };
    match turned {
        None => {
            for (t, v) in free_t.iter().zip(u) {
                six[*t] = v;
            }
        }
        Some((a_turn, full)) => {
            // p_f = A·R_k(θ)·v, v = Σ u_t·Aᵀ·e_t.
            let v = free_t.iter().zip(&u).fold([zero; 3], |acc, (&t, &ut)| {
                add(acc, scale(ut, a_turn.rotate_back(unit(t))))
            });
            let p = full.rotate(v);
            for t in &free_t {
                six[*t] = p[*t];
            }
        }
    }
    let mut pose = rotation;
    pose.t = sub([six[0], six[1], six[2]], pose.rotate(o));
    Ok(pose)
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
    let on_link = |j: usize| s.model.joints[j].links.contains(&link);
    let limbs: Vec<Limb> = (0..s.model.joints.len())
        .filter(|&j| s.kind(j) == JointType::S && on_link(j))
        .filter_map(|j| limb_plane(s, link, j))
        .chain(
            (0..s.model.joints.len())
                .filter(|&j| s.kind(j) != JointType::S && on_link(j))
                .filter_map(|j| held_plane(s, link, j)),
        )
        .take(free)
        .collect();
    if limbs.len() < free {
        return Err(format!(
            "{free} values of the pose are left to the mechanism, and {} of its limbs hold a spherical joint's \
             centre on a plane (revolutes about one direction and slides normal to it)",
            limbs.len()
        ));
    }
    if limbs.iter().any(|l| l.known.is_some()) {
        held_rows_solvable(parts, limbs.iter().all(|l| l.known.is_some()))?;
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

/// Whether rows of the link's own planes ([`Hold::Plane`]) keep the free
/// parts solvable in closed form (see the module): without a free angle
/// always; with one, when the free coordinates span a space `R_k` turns
/// into itself whatever the given angles are: none, or `rz` free with `z`
/// alone or (all rows the link's own) `x, y`.
///
/// # Errors
/// The combination refused, for the planner's message.
pub fn held_rows_solvable(parts: PoseParts, all_held: bool) -> Result<(), String> {
    let Some(k) = parts.free().find(|&i| i >= 3) else {
        return Ok(());
    };
    let free_t: Vec<usize> = parts.free().filter(|&i| i < 3).collect();
    let ok = match free_t[..] {
        [] => true,
        [2] => k == 5,
        [0, 1] => k == 5 && all_held,
        _ => false,
    };
    if ok {
        Ok(())
    } else {
        let names: Vec<&str> = parts.free().map(|i| PoseParts::NAMES[i]).collect();
        Err(format!(
            "limbs that hold a known spherical joint's centre on a plane of the link leave {} to the mechanism, \
             which they determine in closed form only with no free angle, or with rz free and z alone or \
             (every limb held that way) x and y",
            names.join(", ")
        ))
    }
}

/// A chain of links with two joints each walked joint by joint, as a plane
/// of the link it starts from: its revolutes about one direction (the
/// plane's normal) and its slides normal to it.
#[derive(Default)]
struct PlaneChain {
    /// The hops walked.
    hops: Vec<Hop>,
    /// The first revolute's place among the hops and its direction.
    normal: Option<(usize, Vector3<f64>)>,
    /// The slides' directions.
    slides: Vec<Vector3<f64>>,
}

impl PlaneChain {
    /// Walks joint `q` from link `cur`: `None` where the chain stops being
    /// a plane (a revolute not parallel to the first, or a spherical joint).
    fn take(&mut self, s: &Search<'_>, q: usize, cur: usize) -> Option<()> {
        let dir = s.rotation(&self.hops) * s.axis(q, cur);
        match s.kind(q) {
            JointType::R | JointType::Pa => match self.normal {
                None => self.normal = Some((self.hops.len(), dir)),
                Some((_, n)) if Search::parallel(dir, n) => {}
                Some(_) => return None,
            },
            JointType::P => self.slides.push(dir),
            JointType::S => return None,
        }
        self.hops.push(s.hop(q, cur));
        Some(())
    }

    /// Where the normal's revolute is among the hops, if the chain has one
    /// and every slide is normal to it.
    fn normal_at(&self) -> Option<usize> {
        let (at, n) = self.normal?;
        self.slides.iter().all(|d| Search::normal(*d, n)).then_some(at)
    }
}

/// The plane of `link` that holds the centre of a known link's spherical
/// joint, reached from `link`'s joint `first`: a chain of links with two
/// joints each, its revolutes about one direction fixed in `link` and its
/// slides normal to it, ending in a spherical joint whose other link is
/// known (a 3-SPR leg from its platform).
fn held_plane(s: &Search<'_>, link: usize, first: usize) -> Option<Limb> {
    let (mut cur, mut q) = (link, first);
    let mut plane = PlaneChain::default();
    loop {
        if s.kind(q) == JointType::S {
            let known = s.other(q, cur);
            if !s.known[known] || known == link {
                return None;
            }
            let g_pos = plane.normal_at()?;
            let hops = plane.hops;
            return Some(Limb {
                point: PointRef::Joint(q),
                normal: Direction {
                    link,
                    hops: hops[..g_pos].to_vec().into(),
                    joint: hops[g_pos].joint,
                },
                anchor: Anchor {
                    link,
                    hops: hops.into(),
                    point: PointRef::Joint(q),
                },
                known: Some(known),
            });
        }
        plane.take(s, q, cur)?;
        let to = s.other(q, cur);
        if to == link || s.known[to] || plane.hops.len() > s.model.joints.len() {
            return None;
        }
        let next: Vec<usize> = (0..s.model.joints.len())
            .filter(|&j| j != q && s.model.joints[j].links.contains(&to))
            .collect();
        let [nq] = next[..] else { return None };
        (cur, q) = (to, nq);
    }
}

/// The plane spherical joint `sj` of `link` is held on: from its other
/// link, a chain of links with two joints each to a known link, its
/// revolutes about one direction and its slides normal to it.
fn limb_plane(s: &Search<'_>, link: usize, sj: usize) -> Option<Limb> {
    let start = s.other(sj, link);
    let (mut cur, mut prev) = (start, sj);
    let mut plane = PlaneChain::default();
    loop {
        if s.known[cur] && cur != start {
            break;
        }
        let next: Vec<usize> = (0..s.model.joints.len())
            .filter(|&q| q != prev && s.model.joints[q].links.contains(&cur))
            .collect();
        let [q] = next[..] else { return None };
        plane.take(s, q, cur)?;
        let to = s.other(q, cur);
        if to == link || plane.hops.len() > s.model.joints.len() {
            return None;
        }
        (cur, prev) = (to, q);
        if s.known[cur] {
            break;
        }
    }
    let g_pos = plane.normal_at()?;
    let hops = &plane.hops;
    Some(Limb {
        point: PointRef::Joint(sj),
        normal: Direction {
            link: cur,
            hops: reversed(&hops[g_pos..]),
            joint: hops[g_pos].joint,
        },
        anchor: Anchor {
            link: cur,
            hops: reversed(hops),
            point: PointRef::Joint(sj),
        },
        known: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::primitives::Sign;

    /// Rows of points of the link on world planes.
    fn points(rows: &[([f64; 3], [f64; 3], f64)]) -> Vec<Hold<f64>> {
        rows.iter()
            .map(|&(point, normal, offset)| Hold::Point { point, normal, offset })
            .collect()
    }

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
            let pose = free_parts(parts, &[z, rx, ry], [0.0; 3], &points(&rows), sign, [0, 0]).unwrap();
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
        let pose = free_parts(parts, &[0.0, 0.0, 0.0], o, &points(&rows), Sign::Plus, [0, 0]).unwrap();
        assert_eq!(pose.t, [3.0, -2.0, 5.0]);
        // Two parallel planes leave a coordinate undetermined.
        let rows = [rows[0], rows[0], rows[2]];
        assert!(free_parts(parts, &[0.0, 0.0, 0.0], o, &points(&rows), Sign::Plus, [0, 0]).is_err());
    }

    /// A 3-SPR's platform given z, rx = α, ry = β: each base ball
    /// `c_i = 100·(cos θᵢ, sin θᵢ, 0)` on the platform's plane through its
    /// centre normal to `(−sin θᵢ, cos θᵢ, 0)`. By hand (the 3-RPS's
    /// conditions on the inverse pose `(Rᵀ, p' = −Rᵀ·p)`): `R₁₂ = R₂₁`, so
    /// `tan γ = sα·sβ / (cα + cβ)` (or γ + π), `p'ₓ = 100·(R₁₁ − R₂₂)/2`,
    /// `p'ᵧ = −100·R₁₂`, `p'_z` from `(R·p')_z = −z`, and `p = −R·p'`.
    #[test]
    fn known_points_on_the_links_planes_give_the_hand_pose() {
        let parts = PoseParts([false, false, true, true, true, false]);
        let rows: Vec<Hold<f64>> = (0..3)
            .map(|i| {
                let t = f64::from(i) * 2.0 * std::f64::consts::PI / 3.0;
                Hold::Plane {
                    point: [100.0 * t.cos(), 100.0 * t.sin(), 0.0],
                    normal: [-t.sin(), t.cos(), 0.0],
                    offset: 0.0,
                }
            })
            .collect();
        for (z, al, be) in [(75.0, 0.2, -0.15), (120.0, -0.3, 0.25), (60.0, 0.0, 0.3)] {
            let (sa, ca, sb, cb) = (f64::sin(al), f64::cos(al), f64::sin(be), f64::cos(be));
            let g0 = (sa * sb / (ca + cb)).atan();
            let mut found = Vec::new();
            for sign in [Sign::Plus, Sign::Minus] {
                let pose = free_parts(parts, &[z, al, be], [0.0; 3], &rows, sign, [0, 0]).unwrap();
                found.push(pose);
            }
            for g in [g0, g0 + std::f64::consts::PI] {
                let r = rotation_of_angles([al, be, g]).r;
                let px = 100.0 * (r[0][0] - r[1][1]) / 2.0;
                let py = -100.0 * r[0][1];
                let pz = -(z + r[2][0] * px + r[2][1] * py) / r[2][2];
                let p = [0, 1, 2].map(|i| -(r[i][0] * px + r[i][1] * py + r[i][2] * pz));
                assert!((p[2] - z).abs() < 1e-12);
                let close = found.iter().any(|f| {
                    (0..3).all(|i| (f.t[i] - p[i]).abs() < 1e-11 && (0..3).all(|j| (f.r[i][j] - r[i][j]).abs() < 1e-14))
                });
                assert!(close, "({z}, {al}, {be}), γ = {g}: {p:?} not among {found:?}");
            }
        }
    }

    /// All three angles given and x, y, z free: the link (unturned) holds
    /// the world point (5, 5, 5) on its planes x = 1, y = 2, z = 3 from o =
    /// (0, 0, 1), so o sits at (5, 5, 5) − (1, 2, 3) = (4, 3, 2).
    #[test]
    fn known_points_alone_fix_the_translation() {
        let parts = PoseParts([false, false, false, true, true, true]);
        let c = [5.0, 5.0, 5.0];
        let rows = [
            Hold::Plane {
                point: c,
                normal: [1.0, 0.0, 0.0],
                offset: 1.0,
            },
            Hold::Plane {
                point: c,
                normal: [0.0, 1.0, 0.0],
                offset: 2.0,
            },
            Hold::Plane {
                point: c,
                normal: [0.0, 0.0, 1.0],
                offset: 4.0,
            },
        ];
        let pose = free_parts(parts, &[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], &rows, Sign::Plus, [0, 0]).unwrap();
        let o = pose.apply([0.0, 0.0, 1.0]);
        assert!(
            o.iter().zip([4.0, 3.0, 2.0]).all(|(a, b)| (a - b).abs() < 1e-15),
            "{o:?}"
        );
    }

    /// Both kinds mixed, rz and z free (x = y = rx = ry = 0 given): the
    /// link's point (1, 0, 0) on the world plane z = 0.5 gives z = 0.5; the
    /// world point (0, 2, 0.5) on the link's plane x = 1 needs
    /// `2·sin γ = 1`: γ = π/6 or 5π/6.
    #[test]
    fn both_kinds_of_rows_mix_along_the_free_axis() {
        let parts = PoseParts([true, true, false, true, true, false]);
        let rows = [
            Hold::Point {
                point: [1.0, 0.0, 0.0],
                normal: [0.0, 0.0, 1.0],
                offset: 0.5,
            },
            Hold::Plane {
                point: [0.0, 2.0, 0.5],
                normal: [1.0, 0.0, 0.0],
                offset: 1.0,
            },
        ];
        let mut angles = Vec::new();
        for sign in [Sign::Plus, Sign::Minus] {
            let pose = free_parts(parts, &[0.0, 0.0, 0.0, 0.0], [0.0; 3], &rows, sign, [0, 0]).unwrap();
            assert!(
                (pose.t[2] - 0.5).abs() < 1e-15 && pose.t[0] == 0.0 && pose.t[1] == 0.0,
                "{:?}",
                pose.t
            );
            angles.push(pose.r[1][0].atan2(pose.r[0][0]));
        }
        angles.sort_by(f64::total_cmp);
        let pi = std::f64::consts::PI;
        assert!(
            (angles[0] - pi / 6.0).abs() < 1e-15 && (angles[1] - 5.0 * pi / 6.0).abs() < 1e-15,
            "{angles:?}"
        );
    }

    /// Which free parts the link's own planes solve in closed form.
    #[test]
    fn held_rows_are_refused_where_not_linear() {
        let check = |free: &[usize], all_held: bool, ok: bool| {
            let mut given = [true; 6];
            free.iter().for_each(|&i| given[i] = false);
            assert_eq!(
                held_rows_solvable(PoseParts(given), all_held).is_ok(),
                ok,
                "{free:?} {all_held}"
            );
        };
        check(&[0, 1, 2], false, true);
        check(&[0, 1, 5], true, true);
        check(&[0, 1, 5], false, false);
        check(&[2, 5], false, true);
        check(&[5], false, true);
        check(&[4], false, true);
        check(&[0, 5], true, false);
        check(&[0, 2, 4], true, false);
        check(&[2, 3], true, false);
    }
}
