//! The numeric model behind the POC analysis: a generic instance of the
//! mechanism (random axes that satisfy every declared ∥ / ⊥ / ≡ / ∧ relation),
//! the joint twists at that instant, and subspace ranks and kernels.
//!
//! A link's POC set at a generic configuration corresponds to its twist
//! subspace V ⊂ se(3): union is the subspace sum, intersection the subspace
//! intersection, and dim is the rank. Twists are written (ω; v) with v the
//! velocity of the body point at the origin.

use crate::diagnostics::Diagnostic;
use crate::semantics::mechanism::{DirectionClasses, DirectionItem, JointKind, Mechanism};
use nalgebra::{DMatrix, Vector3, Vector6};

/// Singular values below this fraction of the largest count as zero.
pub const RANK_TOLERANCE: f64 = 1e-9;

/// The deterministic generator every analysis draws from (splitmix64), so
/// that each is reproducible.
pub use pkm_runtime::random::SplitMix;

/// One generic instance of a mechanism.
#[derive(Debug, Clone)]
pub struct Instance {
    /// The unit vector of each direction item (indexed like [`DirectionClasses::items`]).
    pub directions: Vec<Vector3<f64>>,
    /// A point on each joint's axis (its centre for S and U joints).
    pub points: Vec<Vector3<f64>>,
    /// The twists each joint allows, f of them, motion of `links[1]` relative to `links[0]`.
    pub twists: Vec<Vec<Vector6<f64>>>,
    /// The frame axes x, y, z.
    pub frame: [Vector3<f64>; 3],
}

/// The twist of angular part `w` and linear part `v`.
pub(crate) fn twist(w: Vector3<f64>, v: Vector3<f64>) -> Vector6<f64> {
    Vector6::new(w.x, w.y, w.z, v.x, v.y, v.z)
}

/// The unit rotation about the axis along `d` through `p`.
pub(crate) fn rotation_about(d: Vector3<f64>, p: Vector3<f64>) -> Vector6<f64> {
    twist(d, p.cross(&d))
}

/// Builds a generic instance: random directions class by class, each made
/// perpendicular to the classes it must be perpendicular to; random points,
/// shared by coaxial joints, and a random centre for each group of
/// concurrent axes.
pub fn realize(mech: &Mechanism, classes: &DirectionClasses, seed: u64) -> Result<Instance, Diagnostic> {
    let mut rng = SplitMix::new(seed);
    let n_items = classes.items().len();
    let mut class_dir: Vec<Option<Vector3<f64>>> = vec![None; n_items];
    // Perpendicular constraints between classes.
    let mut perp: Vec<Perp> = Vec::new();
    for r in &mech.relations {
        if r.kind == crate::syntax::ast::RelationKind::Perpendicular {
            if let (Some(a), Some(b)) = (classes.class_of(r.a), classes.class_of(r.b)) {
                perp.push((a, b, r.span));
            }
        }
    }
    // Most-constrained classes first; should that still fail, a few other
    // orders before reporting the relations as over-constrained.
    let roots: Vec<usize> = {
        let mut r: Vec<usize> = (0..n_items).map(|i| classes.find(i)).collect();
        r.sort_unstable();
        r.dedup();
        r
    };
    let degree = |c: usize| perp.iter().filter(|(a, b, _)| *a == c || *b == c).count();
    let mut order = roots.clone();
    order.sort_by_key(|&c| (std::cmp::Reverse(degree(c)), c));
    let mut failure = None;
    for attempt in 0..8 {
        if attempt > 0 {
            // A deterministic shuffle for the next attempt.
            for i in (1..order.len()).rev() {
                let j = (rng.next_u64() % (i as u64 + 1)) as usize;
                order.swap(i, j);
            }
        }
        class_dir.iter_mut().for_each(|d| *d = None);
        failure = assign_directions(&order, &perp, &mut class_dir, &mut rng).err();
        if failure.is_none() {
            break;
        }
    }
    if let Some(span) = failure {
        let msg = "a direction is required to be perpendicular to three independent directions";
        return Err(match span {
            Some(s) => Diagnostic::new(s, msg).label("over-constrained relation"),
            None => Diagnostic::global(msg),
        });
    }
    let directions: Vec<Vector3<f64>> = (0..n_items)
        .map(|i| class_dir[classes.find(i)].unwrap_or_else(Vector3::x))
        .collect();
    let dir_of = |item: DirectionItem| classes.index(item).map_or_else(Vector3::x, |i| directions[i]);

    // Coaxial joints share one axis line (and one point, as do a U's two axes).
    let n = mech.joints.len();
    let mut coaxial_root: Vec<usize> = (0..n).collect();
    fn root(p: &[usize], mut i: usize) -> usize {
        while p[i] != i {
            i = p[i];
        }
        i
    }
    for r in &mech.relations {
        if let (crate::syntax::ast::RelationKind::Coaxial, DirectionItem::Joint(a), DirectionItem::Joint(b)) =
            (r.kind, r.a, r.b)
        {
            let (ra, rb) = (root(&coaxial_root, a), root(&coaxial_root, b));
            coaxial_root[ra.max(rb)] = ra.min(rb);
        }
    }
    // A U joint's two revolutes meet at its centre.
    for u in &mech.universals {
        let (ra, rb) = (root(&coaxial_root, u.halves[0]), root(&coaxial_root, u.halves[1]));
        coaxial_root[ra.max(rb)] = ra.min(rb);
    }
    let raw_points: Vec<Vector3<f64>> = (0..n).map(|_| rng.vector()).collect();
    let mut points: Vec<Vector3<f64>> = (0..n).map(|j| raw_points[root(&coaxial_root, j)]).collect();
    // Concurrent axes (and those coaxial with them) pass through their
    // group's centre: the centre is the point on each axis.
    let groups = crate::semantics::mechanism::concurrent_groups(&mech.joints, &mech.relations);
    let centres: Vec<Vector3<f64>> = (0..groups.iter().flatten().max().map_or(0, |g| g + 1))
        .map(|_| rng.vector())
        .collect();
    for (p, g) in points.iter_mut().zip(&groups) {
        if let Some(g) = g {
            *p = centres[*g];
        }
    }

    let frame = [
        dir_of(DirectionItem::Frame(0)),
        dir_of(DirectionItem::Frame(1)),
        dir_of(DirectionItem::Frame(2)),
    ];
    let twists = mech
        .joints
        .iter()
        .enumerate()
        .map(|(j, joint)| {
            let p = points[j];
            let d = if joint.kind.has_direction() {
                dir_of(DirectionItem::Joint(j))
            } else {
                Vector3::x()
            };
            match joint.kind {
                JointKind::R => vec![rotation_about(d, p)],
                JointKind::P => vec![twist(Vector3::zeros(), d)],
                JointKind::H => {
                    let pitch = 0.2 + 0.4 * (rng.symmetric() + 1.0);
                    vec![twist(d, p.cross(&d) + d * pitch)]
                }
                JointKind::C => vec![rotation_about(d, p), twist(Vector3::zeros(), d)],
                JointKind::U => vec![
                    rotation_about(d, p),
                    rotation_about(dir_of(DirectionItem::USecond(j)), p),
                ],
                JointKind::S => vec![
                    rotation_about(Vector3::x(), p),
                    rotation_about(Vector3::y(), p),
                    rotation_about(Vector3::z(), p),
                ],
                JointKind::Pa => {
                    // The parallelogram's coupler translates along a circle in
                    // the plane normal to its axes: generically any direction there.
                    let mut t = rng.vector();
                    t -= d * d.dot(&t);
                    vec![twist(Vector3::zeros(), t.normalize())]
                }
            }
        })
        .collect();
    Ok(Instance {
        directions,
        points,
        twists,
        frame,
    })
}

type Perp = (usize, usize, Option<crate::Span>);

/// Gives each class in `order` a random direction perpendicular to the
/// classes already given that it must be perpendicular to. Fails (with the
/// span of a relation involved) when one would need three.
fn assign_directions(
    order: &[usize],
    perp: &[Perp],
    class_dir: &mut [Option<Vector3<f64>>],
    rng: &mut SplitMix,
) -> Result<(), Option<crate::Span>> {
    for &root in order {
        let mut basis: Vec<Vector3<f64>> = Vec::new();
        let mut last_span = None;
        for &(a, b, span) in perp {
            let other = if a == root {
                b
            } else if b == root {
                a
            } else {
                continue;
            };
            if let Some(d) = class_dir[other] {
                last_span = span.or(last_span);
                let mut u = d;
                for e in &basis {
                    u -= e * e.dot(&u);
                }
                if u.norm() > 1e-6 {
                    basis.push(u.normalize());
                }
            }
        }
        if basis.len() >= 3 {
            return Err(last_span);
        }
        let mut dir = None;
        for _ in 0..16 {
            let mut u = rng.vector();
            for e in &basis {
                u -= e * e.dot(&u);
            }
            if u.norm() > 0.1 {
                dir = Some(u.normalize());
                break;
            }
        }
        class_dir[root] = Some(dir.unwrap_or_else(|| basis[0].cross(&basis[basis.len() - 1]).normalize()));
    }
    Ok(())
}

/// The rank of a matrix, with [`RANK_TOLERANCE`] relative to its largest singular value.
pub fn rank(m: &DMatrix<f64>) -> usize {
    rank_at_scale(m, None)
}

/// The rank of rows cut from a larger matrix whose columns are at most
/// `scale` long, with [`RANK_TOLERANCE`] relative to that scale: rows that
/// are round-off of the whole (a joint that does not move in any of its
/// motions) have rank 0, which a tolerance relative to themselves would miss.
pub fn rank_of_part(m: &DMatrix<f64>, scale: f64) -> usize {
    rank_at_scale(m, Some(scale))
}

/// The largest column norm of a matrix (0 without columns).
pub fn column_scale(m: &DMatrix<f64>) -> f64 {
    m.column_iter().map(|c| c.norm()).fold(0.0, f64::max)
}

fn rank_at_scale(m: &DMatrix<f64>, scale: Option<f64>) -> usize {
    if m.nrows() == 0 || m.ncols() == 0 {
        return 0;
    }
    let sv = m.clone().svd(false, false).singular_values;
    let max = sv.iter().cloned().fold(0.0, f64::max);
    let scale = scale.unwrap_or(max);
    if max == 0.0 || scale == 0.0 {
        return 0;
    }
    sv.iter().filter(|s| **s > RANK_TOLERANCE * scale).count()
}

/// An orthonormal basis (columns) of the null space of `m`.
pub fn null_space(m: &DMatrix<f64>) -> DMatrix<f64> {
    let cols = m.ncols();
    if cols == 0 {
        return DMatrix::zeros(0, 0);
    }
    // Pad to at least square so the thin SVD yields every right singular vector.
    let rows = m.nrows().max(cols);
    let mut a = DMatrix::zeros(rows, cols);
    a.view_mut((0, 0), (m.nrows(), cols)).copy_from(m);
    let svd = a.svd(false, true);
    let v_t = svd.v_t.expect("requested V");
    let max = svd.singular_values.iter().cloned().fold(0.0, f64::max);
    let null: Vec<usize> = (0..svd.singular_values.len())
        .filter(|&i| svd.singular_values[i] <= RANK_TOLERANCE * max.max(1e-300))
        .collect();
    let mut n = DMatrix::zeros(cols, null.len());
    for (k, &i) in null.iter().enumerate() {
        n.set_column(k, &v_t.row(i).transpose());
    }
    n
}

/// The velocity equations of a sub-mechanism (a subset of joints): unknowns
/// are the twists of the links it touches (the base's is zero) and the joint
/// rates; each joint says `T_v − T_u − Σ s θ̇ = 0`. Its kernel is the
/// sub-mechanism's instantaneous motion.
///
/// The equations are not solved as they stand (6 per joint, 6 per link
/// plus Σf unknowns). A spanning tree of each connected part expresses every
/// link's twist through the rates of the tree joints from the part's root
/// (zero for the base, free for a part that does not touch it); what is left
/// are the loop-closure equations of the other joints, 6 per independent loop,
/// over the joint rates alone. Their kernel, with the free root twists, is
/// the kernel of the whole system, and the rank computations stay small.
#[derive(Debug, Clone)]
pub struct VelocitySystem {
    /// Row of each link's twist block in a [`kernel`](Self::kernel) (None for the base and untouched links).
    pub link_col: Vec<Option<usize>>,
    /// First row of each joint's rates in a [`kernel`](Self::kernel) (None for joints outside the subset).
    pub joint_col: Vec<Option<usize>>,
    /// The loop-closure equations over the joint rates (6 rows per independent
    /// loop; column `joint_col[j] − link_rows` is joint j's first rate).
    pub loops: DMatrix<f64>,
    /// Σf of the subset.
    pub total_f: usize,
    /// Rows of the link twists in a kernel (6 per link touched, before the rates).
    link_rows: usize,
    /// Each touched link's twist as a function of the joint rates (6 × Σf),
    /// relative to the root of its connected part.
    link_twists: Vec<Option<DMatrix<f64>>>,
    /// The connected parts that do not touch the base: the links of each.
    floating: Vec<Vec<usize>>,
}

impl VelocitySystem {
    /// The system of the joints in `mask`.
    pub fn new(mech: &Mechanism, inst: &Instance, mask: u64) -> Self {
        let joints: Vec<usize> = (0..mech.joints.len()).filter(|j| mask >> j & 1 == 1).collect();
        let n_links = mech.links.len();
        let mut link_col = vec![None; n_links];
        let mut link_rows = 0;
        for &j in &joints {
            for l in mech.joints[j].links {
                if l != 0 && link_col[l].is_none() {
                    link_col[l] = Some(link_rows);
                    link_rows += 6;
                }
            }
        }
        let mut joint_col = vec![None; mech.joints.len()];
        let mut total_f = 0;
        for &j in &joints {
            joint_col[j] = Some(link_rows + total_f);
            total_f += mech.joints[j].kind.dof();
        }
        // Joint j's twists placed at its rate columns: the twist of links[1]
        // relative to links[0] as a function of the rates.
        let joint_twist = |j: usize| {
            let mut m = DMatrix::zeros(6, total_f);
            let c0 = joint_col[j].expect("joint in subset") - link_rows;
            for (i, s) in inst.twists[j].iter().enumerate() {
                m.set_column(c0 + i, s);
            }
            m
        };
        let mut incident: Vec<Vec<usize>> = vec![Vec::new(); n_links];
        for &j in &joints {
            let [u, v] = mech.joints[j].links;
            incident[u].push(j);
            if v != u {
                incident[v].push(j);
            }
        }
        // Spanning trees, breadth first: the base's part first, then the others.
        let touched = |l: usize| !incident[l].is_empty();
        let mut link_twists: Vec<Option<DMatrix<f64>>> = vec![None; n_links];
        let mut in_tree = vec![false; mech.joints.len()];
        let mut floating = Vec::new();
        for root in (0..n_links).filter(|&l| touched(l)) {
            if link_twists[root].is_some() {
                continue;
            }
            link_twists[root] = Some(DMatrix::zeros(6, total_f));
            let mut part = vec![root];
            let mut next = 0;
            while next < part.len() {
                let l = part[next];
                next += 1;
                for &j in &incident[l] {
                    let [u, v] = mech.joints[j].links;
                    let other = if u == l { v } else { u };
                    if link_twists[other].is_some() {
                        continue;
                    }
                    in_tree[j] = true;
                    // T_v = T_u + S θ̇.
                    let from = link_twists[l].as_ref().expect("reached");
                    let t = if other == v {
                        from + joint_twist(j)
                    } else {
                        from - joint_twist(j)
                    };
                    link_twists[other] = Some(t);
                    part.push(other);
                }
            }
            if root != 0 {
                floating.push(part);
            }
        }
        // The other joints close loops: T_v − T_u − S θ̇ = 0.
        let chords: Vec<usize> = joints.iter().copied().filter(|&j| !in_tree[j]).collect();
        let mut loops = DMatrix::zeros(6 * chords.len(), total_f);
        for (row, &j) in chords.iter().enumerate() {
            let [u, v] = mech.joints[j].links;
            let twist_of = |l: usize| link_twists[l].as_ref().expect("a touched link is reached");
            let closure = twist_of(v) - twist_of(u) - joint_twist(j);
            loops.view_mut((6 * row, 0), (6, total_f)).copy_from(&closure);
        }
        VelocitySystem {
            link_col,
            joint_col,
            loops,
            total_f,
            link_rows,
            link_twists,
            floating,
        }
    }

    /// The rank of the loop-closure equations: Σf − (mobility), where the
    /// mobility counts the six free motions of each part that does not touch
    /// the base, as the whole system's kernel does.
    pub fn loop_rank(&self) -> usize {
        let nullity = self.total_f - rank(&self.loops).min(self.total_f) + 6 * self.floating.len();
        self.total_f.saturating_sub(nullity)
    }

    /// The most [`loop_rank`](Self::loop_rank) can be for equations of this
    /// shape (their rank is at most their rows and columns).
    pub fn max_loop_rank(&self) -> usize {
        self.loops
            .nrows()
            .min(self.total_f)
            .saturating_sub(6 * self.floating.len())
    }

    /// A basis (columns) of the system's kernel: for each motion, the twists of
    /// the touched links (rows [`link_col`](Self::link_col)) and the joint
    /// rates (rows [`joint_col`](Self::joint_col)).
    pub fn kernel(&self) -> DMatrix<f64> {
        let f = self.total_f;
        let rates = if self.loops.nrows() == 0 {
            DMatrix::identity(f, f)
        } else {
            null_space(&self.loops)
        };
        let k = rates.ncols();
        let mut n = DMatrix::zeros(self.link_rows + f, k + 6 * self.floating.len());
        n.view_mut((self.link_rows, 0), (f, k)).copy_from(&rates);
        for (l, c) in self.link_col.iter().enumerate() {
            if let (Some(c), Some(t)) = (c, &self.link_twists[l]) {
                n.view_mut((*c, 0), (6, k)).copy_from(&(t * &rates));
            }
        }
        // A part that does not touch the base moves freely as one body.
        for (p, part) in self.floating.iter().enumerate() {
            for &l in part {
                if let Some(c) = self.link_col[l] {
                    for a in 0..6 {
                        n[(c + a, k + 6 * p + a)] = 1.0;
                    }
                }
            }
        }
        n
    }

    /// The size of the joint rates of a kernel's motions (the largest column
    /// norm of its rate rows): the scale against which some joints' rates
    /// count as zero or not.
    pub fn rate_scale(&self, kernel: &DMatrix<f64>) -> f64 {
        column_scale(&kernel.rows(self.link_rows, self.total_f).into_owned())
    }

    /// The twists of link `b` relative to link `a` over the kernel `n` (6 × k).
    pub fn relative_twists(&self, n: &DMatrix<f64>, a: usize, b: usize) -> DMatrix<f64> {
        let mut out = DMatrix::zeros(6, n.ncols());
        if let Some(c) = self.link_col[b] {
            out += n.rows(c, 6);
        }
        if let Some(c) = self.link_col[a] {
            out -= n.rows(c, 6);
        }
        out
    }
}

/// Column-concatenates twist sets.
pub fn hstack(parts: &[&DMatrix<f64>]) -> DMatrix<f64> {
    let cols: usize = parts.iter().map(|p| p.ncols()).sum();
    let mut m = DMatrix::zeros(6, cols);
    let mut c = 0;
    for p in parts {
        m.view_mut((0, c), (6, p.ncols())).copy_from(p);
        c += p.ncols();
    }
    m
}

/// The twists of a list of joints, as columns.
pub fn joint_twists(inst: &Instance, joints: &[usize]) -> DMatrix<f64> {
    let cols: Vec<Vector6<f64>> = joints.iter().flat_map(|&j| inst.twists[j].iter().copied()).collect();
    if cols.is_empty() {
        return DMatrix::zeros(6, 0);
    }
    DMatrix::from_iterator(6, cols.len(), cols.iter().flat_map(|c| c.iter().copied()))
}

/// Splits twists into the rotations (ω) and the velocities of point `o` (v + ω × o).
pub fn at_point(twists: &DMatrix<f64>, o: &Vector3<f64>) -> (DMatrix<f64>, DMatrix<f64>) {
    let k = twists.ncols();
    let mut w = DMatrix::zeros(3, k);
    let mut v = DMatrix::zeros(3, k);
    for c in 0..k {
        let om = Vector3::new(twists[(0, c)], twists[(1, c)], twists[(2, c)]);
        let vo = Vector3::new(twists[(3, c)], twists[(4, c)], twists[(5, c)]) + om.cross(o);
        w.set_column(c, &om);
        v.set_column(c, &vo);
    }
    (w, v)
}

/// An orthonormal basis of the column space of a 3 × k matrix, by
/// Gram–Schmidt with column pivoting. (nalgebra's SVD gave an inaccurate U
/// for rank-deficient 3 × 3 input when V was not requested; this is simpler.)
///
/// Columns shorter than a tolerance relative to `scale` count as zero; pass the
/// size of the whole twists these vectors come from, so that round-off in a
/// part that is really zero (the rotations of a translating platform) is not
/// taken for a direction.
pub fn column_basis(m: &DMatrix<f64>, scale: f64) -> Vec<Vector3<f64>> {
    let mut cols: Vec<Vector3<f64>> = (0..m.ncols())
        .map(|c| Vector3::new(m[(0, c)], m[(1, c)], m[(2, c)]))
        .collect();
    let mut basis: Vec<Vector3<f64>> = Vec::new();
    while basis.len() < 3 {
        let Some((i, norm)) = cols
            .iter()
            .enumerate()
            .map(|(i, c)| (i, c.norm()))
            .max_by(|a, b| a.1.total_cmp(&b.1))
        else {
            break;
        };
        if norm <= RANK_TOLERANCE * 1e3 * scale || norm == 0.0 {
            break;
        }
        let e = cols[i] / norm;
        for c in &mut cols {
            *c -= e * e.dot(c);
        }
        basis.push(e);
    }
    basis
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The velocity equations as they stand: 6 rows per joint over the link
    /// twists and the joint rates, `T_v − T_u − S θ̇ = 0`, in the layout of
    /// `VelocitySystem`'s kernel.
    fn whole_system(mech: &Mechanism, inst: &Instance, sys: &VelocitySystem, mask: u64) -> DMatrix<f64> {
        let joints: Vec<usize> = (0..mech.joints.len()).filter(|j| mask >> j & 1 == 1).collect();
        let mut m = DMatrix::zeros(6 * joints.len(), sys.link_rows + sys.total_f);
        for (row, &j) in joints.iter().enumerate() {
            let [u, v] = mech.joints[j].links;
            for k in 0..6 {
                if let Some(c) = sys.link_col[v] {
                    m[(6 * row + k, c + k)] += 1.0;
                }
                if let Some(c) = sys.link_col[u] {
                    m[(6 * row + k, c + k)] -= 1.0;
                }
                for (i, s) in inst.twists[j].iter().enumerate() {
                    m[(6 * row + k, sys.joint_col[j].unwrap() + i)] = -s[k];
                }
            }
        }
        m
    }

    /// (joint names, expected kernel dimension of the whole system, expected loop rank).
    fn check_kernel(source: &str, subsets: &[(&[&str], usize, usize)]) {
        let ast = crate::parse(source).unwrap();
        let mech = crate::semantics::mechanism::build(&ast).unwrap();
        let classes = DirectionClasses::new(&mech.joints, &mech.relations);
        let inst = realize(&mech, &classes, 11).unwrap();
        for (names, nullity, loop_rank) in subsets {
            let mask = names.iter().fold(0u64, |m, n| m | 1 << mech.joint_index(n).unwrap());
            let sys = VelocitySystem::new(&mech, &inst, mask);
            let k = sys.kernel();
            let whole = whole_system(&mech, &inst, &sys, mask);
            // The kernel solves the whole system and spans all of its null space.
            assert!((&whole * &k).amax() < 1e-12, "{names:?}");
            assert_eq!(k.ncols(), *nullity, "{names:?}");
            assert_eq!(rank(&k), *nullity, "{names:?}");
            assert_eq!(whole.ncols() - rank(&whole), *nullity, "{names:?}");
            assert_eq!(sys.loop_rank(), *loop_rank, "{names:?}");
            assert!(sys.loop_rank() <= sys.max_loop_rank(), "{names:?}");
        }
    }

    #[test]
    fn kernels_by_spanning_tree_are_the_whole_systems_kernels() {
        // Four-bar: one planar loop, 1 DOF, ξ = 3 (its spatial loop equations
        // have rank 3). An open chain R1-R2 from the base: 2 DOF, no loop. R2-R3
        // alone floats: the crank-coupler-rocker chain moves freely, 6 + 2 motions.
        check_kernel(
            "mechanism m { planar; base R1* ∥ R2 [c] ∥ R3 [r] ∥ R4 base; }",
            &[
                (&["R1", "R2", "R3", "R4"], 1, 3),
                (&["R1", "R2"], 2, 0),
                (&["R2", "R3"], 8, 0),
            ],
        );
        // RSSR: Σf 8, one spatial loop of rank 6, mobility 2 (the crank and the coupler's spin).
        check_kernel(
            "mechanism m { base R1* - S1 - S2 - R2 base; }",
            &[(&["R1", "S1", "S2", "R2"], 2, 6)],
        );
    }

    #[test]
    fn null_space_of_a_wide_matrix() {
        let m = DMatrix::from_row_slice(1, 3, &[1.0, 1.0, 0.0]);
        let n = null_space(&m);
        assert_eq!(n.ncols(), 2);
        assert!((&m * &n).norm() < 1e-12);
    }

    #[test]
    fn rank_counts_independent_columns() {
        let m = DMatrix::from_row_slice(3, 3, &[1.0, 2.0, 3.0, 2.0, 4.0, 6.0, 0.0, 1.0, 1.0]);
        assert_eq!(rank(&m), 2);
        assert_eq!(rank(&DMatrix::zeros(3, 2)), 0);
    }

    #[test]
    fn column_basis_of_a_rank_one_matrix_is_its_direction() {
        let d = Vector3::new(-0.8026259498904428, 0.5924484177016449, -0.06925645764318233);
        let m = DMatrix::from_iterator(
            3,
            3,
            [d * 0.26, d * 0.11, d * -0.09].iter().flat_map(|c| c.iter().copied()),
        );
        let b = column_basis(&m, 0.26);
        assert_eq!(b.len(), 1);
        assert!(b[0].cross(&d).norm() < 1e-15);
    }

    #[test]
    fn round_off_is_not_a_direction() {
        let m = DMatrix::from_row_slice(3, 2, &[1e-17, -2e-17, 3e-17, 0.0, -1e-17, 1e-17]);
        assert!(column_basis(&m, 1.0).is_empty());
    }

    #[test]
    fn splitmix_is_reproducible_and_in_range() {
        let mut a = SplitMix::new(7);
        let mut b = SplitMix::new(7);
        for _ in 0..1000 {
            let x = a.symmetric();
            assert_eq!(x, b.symmetric());
            assert!((-1.0..1.0).contains(&x));
        }
    }
}
