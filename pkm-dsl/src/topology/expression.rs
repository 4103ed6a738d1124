//! The topological expression in the literature's notation: relation
//! symbols between axes, the joints' labels (frame planes and axes), each
//! SKC's kind.

use super::*;
use crate::semantics::mechanism::{DirectionItem, JointKind, Mechanism};
use nalgebra::{DMatrix, Vector3};

pub(super) fn relation_symbol(ctx: &Context, a: usize, b: usize) -> &'static str {
    let mech = ctx.mech;
    let (ka, kb) = (mech.joints[a].kind, mech.joints[b].kind);
    if !ka.has_direction() || !kb.has_direction() {
        return "-";
    }
    let (ca, cb) = (
        ctx.classes.class_of(DirectionItem::Joint(a)),
        ctx.classes.class_of(DirectionItem::Joint(b)),
    );
    if ca == cb {
        return "∥";
    }
    let perp = mech.relations.iter().any(|r| {
        r.kind == crate::syntax::ast::RelationKind::Perpendicular && {
            let (x, y) = (ctx.classes.class_of(r.a), ctx.classes.class_of(r.b));
            (x == ca && y == cb) || (x == cb && y == ca)
        }
    });
    let groups = crate::semantics::mechanism::concurrent_groups(&mech.joints, &mech.relations);
    if perp {
        "⊥"
    } else if groups[a].is_some() && groups[a] == groups[b] {
        "∧"
    } else {
        "-"
    }
}
pub(super) fn notation(ctx: &Context, joints: &[usize]) -> String {
    let mut s = String::new();
    for (i, &j) in joints.iter().enumerate() {
        if i > 0 {
            s.push_str(relation_symbol(ctx, joints[i - 1], j));
        }
        s.push_str(&ctx.mech.joints[j].name);
    }
    s
}
/// Names the directions of twist subspaces in the theory's words.
pub(super) struct Labeller<'a> {
    pub(super) ctx: &'a Context<'a>,
    /// Joints with a direction, most preferred first (nearest the subject link, then latest declared).
    pub(super) preferred: Vec<usize>,
}
pub(super) const FRAME_PLANES: [&str; 3] = ["yoz", "xoz", "xoy"];
pub(super) const FRAME_AXIS_NAMES: [&str; 3] = ["x", "y", "z"];
impl<'a> Labeller<'a> {
    pub(super) fn new(ctx: &'a Context<'a>, subject: Option<usize>, scope: Option<&[usize]>) -> Self {
        let mech = ctx.mech;
        let mut dist = vec![usize::MAX; mech.links.len()];
        let start = subject.unwrap_or(0);
        dist[start] = 0;
        let mut queue = std::collections::VecDeque::from([start]);
        while let Some(l) = queue.pop_front() {
            for &j in &ctx.incidence[l] {
                let o = mech.joints[j].other(l);
                if dist[o] == usize::MAX {
                    dist[o] = dist[l] + 1;
                    queue.push_back(o);
                }
            }
        }
        let mut preferred: Vec<usize> = (0..mech.joints.len())
            .filter(|&j| mech.joints[j].kind.has_direction() && scope.is_none_or(|s| s.contains(&j)))
            .collect();
        preferred.sort_by_key(|&j| {
            let [a, b] = mech.joints[j].links;
            (dist[a].min(dist[b]), std::cmp::Reverse(j))
        });
        Labeller { ctx, preferred }
    }

    pub(super) fn dir(&self, item: DirectionItem) -> Vector3<f64> {
        let inst = &self.ctx.primary[0];
        self.ctx
            .classes
            .index(item)
            .map_or_else(Vector3::zeros, |i| inst.directions[i])
    }

    pub(super) fn poc(&self, twists: &DMatrix<f64>, o: &Vector3<f64>) -> PocSet {
        let (w, v) = screw::at_point(twists, o);
        // One scale for both parts: the size of the twists at o.
        let scale = (0..w.ncols())
            .map(|c| w.column(c).norm().max(v.column(c).norm()))
            .fold(0.0, f64::max);
        let rb = screw::column_basis(&w, scale);
        let tb = screw::column_basis(&v, scale);
        PocSet {
            t: tb.len(),
            t_dir: self.label(&tb, false),
            r: rb.len(),
            r_dir: self.label(&rb, true),
            dim: screw::rank(twists),
        }
    }

    /// Candidate names in order of preference for rotations or translations.
    pub(super) fn names(&self, rotation: bool) -> Vec<(String, Vector3<f64>)> {
        let mech = self.ctx.mech;
        let joints = |pred: &dyn Fn(JointKind) -> bool| -> Vec<(String, Vector3<f64>)> {
            self.preferred
                .iter()
                .filter(|&&j| pred(mech.joints[j].kind))
                .map(|&j| (mech.joints[j].name.clone(), self.dir(DirectionItem::Joint(j))))
                .collect()
        };
        let frame: Vec<(String, Vector3<f64>)> = (0..3)
            .filter(|&k| mech.frame_declared[k])
            .map(|k| (FRAME_AXIS_NAMES[k].to_string(), self.dir(DirectionItem::Frame(k))))
            .collect();
        if rotation {
            [joints(&|k| k.is_rotational()), frame, joints(&|k| !k.is_rotational())].concat()
        } else {
            [
                frame,
                joints(&|k| matches!(k, JointKind::P | JointKind::C | JointKind::H)),
                joints(&|k| k.is_rotational()),
            ]
            .concat()
        }
    }

    pub(super) fn label(&self, basis: &[Vector3<f64>], rotation: bool) -> Option<String> {
        const TOL: f64 = 1e-7;
        let names = self.names(rotation);
        let mech = self.ctx.mech;
        match basis.len() {
            1 => names
                .iter()
                .find(|(_, d)| d.cross(&basis[0]).norm() < TOL)
                .map(|(n, _)| format!("∥{n}")),
            2 => {
                let normal = basis[0].cross(&basis[1]).normalize();
                let frame_plane = (0..3)
                    .filter(|&k| mech.frame_declared.iter().filter(|d| **d).count() >= 2 || mech.frame_declared[k])
                    .find(|&k| self.dir(DirectionItem::Frame(k)).cross(&normal).norm() < TOL)
                    .map(|k| format!("∥◇{}", FRAME_PLANES[k]));
                let in_plane: Vec<&(String, Vector3<f64>)> = names
                    .iter()
                    .filter(|(_, d)| d.norm() > 0.5 && d.dot(&normal).abs() < TOL)
                    .collect();
                let pair = in_plane.first().and_then(|a| {
                    in_plane.iter().find(|b| b.1.cross(&a.1).norm() > 1e-3).map(|b| {
                        let (i, k) = (self.order_of(&a.0), self.order_of(&b.0));
                        if i <= k {
                            format!("∥◇({},{})", a.0, b.0)
                        } else {
                            format!("∥◇({},{})", b.0, a.0)
                        }
                    })
                });
                let perp = names
                    .iter()
                    .filter(|(n, _)| !FRAME_AXIS_NAMES.contains(&n.as_str()))
                    .find(|(_, d)| d.cross(&normal).norm() < TOL)
                    .map(|(n, _)| format!("⊥{n}"));
                if rotation {
                    pair.or(frame_plane).or(perp)
                } else {
                    frame_plane.or(perp).or(pair)
                }
            }
            _ => None,
        }
    }

    /// Declaration order of a name (frame axes first).
    pub(super) fn order_of(&self, name: &str) -> usize {
        FRAME_AXIS_NAMES
            .iter()
            .position(|a| *a == name)
            .unwrap_or_else(|| 3 + self.ctx.mech.joint_index(name).unwrap_or(usize::MAX - 3))
    }
}
pub(super) fn skc_kind(mech: &Mechanism, socs: &[Soc], branch_poc: &[PocSet]) -> Option<String> {
    if mech.branches.is_empty() || branch_poc.len() != mech.branches.len() {
        return None;
    }
    let joints: Vec<usize> = socs.iter().flat_map(|s| s.joints.iter().copied()).collect();
    // The branch that holds the SKC's actuators (ties: the one with more of its joints).
    let score = |b: usize| {
        let act = joints
            .iter()
            .filter(|&&j| mech.joints[j].actuated && mech.joints[j].branch == Some(b))
            .count();
        let all = joints.iter().filter(|&&j| mech.joints[j].branch == Some(b)).count();
        (act, all, b)
    };
    let b = (0..mech.branches.len()).max_by_key(|&b| score(b))?;
    Some(branch_poc[b].kind())
}
pub(super) fn kind_sup(kind: &str) -> String {
    kind.chars()
        .map(|c| match c {
            'T' => 'ᵀ',
            'R' => 'ᴿ',
            c => c.to_digit(10).map_or(c, |d| SUPERSCRIPT[d as usize]),
        })
        .collect()
}
pub(super) fn expression(
    mech: &Mechanism,
    dof: usize,
    socs: &[Soc],
    skcs: &[Skc],
    kappa: usize,
    platform: Option<&PocSet>,
) -> String {
    let pm_kind = platform.map(|p| kind_sup(&p.kind())).unwrap_or_default();
    let per_soc: Vec<String> = socs.iter().map(|s| s.dof.to_string()).collect();
    let mut s = format!(
        "{pm_kind}PM{}[{dof}, {}({})]",
        sup(kappa),
        socs.len(),
        per_soc.join(", ")
    );
    let bracket = |skc: &Skc| {
        let d: Vec<String> = socs[skc.socs.clone()].iter().map(|s| signed(s.delta)).collect();
        let x: Vec<String> = socs[skc.socs.clone()].iter().map(|s| s.xi.to_string()).collect();
        format!("{}; {}", d.join(", "), x.join(", "))
    };
    let skc_terms: Vec<String> = skcs
        .iter()
        .enumerate()
        .map(|(k, skc)| {
            format!(
                "{}SKC{}{}[{}]",
                skc.kind.as_deref().map(kind_sup).unwrap_or_default(),
                sub(k + 1),
                sup(skc.kappa),
                bracket(skc)
            )
        })
        .collect();
    let bkc_terms: Vec<String> = skcs
        .iter()
        .enumerate()
        .map(|(k, skc)| format!("BKC{}{}({})", sub(k + 1), sup(skc.kappa), bracket(skc)))
        .collect();
    s.push_str(&format!(
        " = {} = {}−J_in + {}",
        skc_terms.join(" + "),
        mech.actuator_count(),
        bkc_terms.join(" + ")
    ));
    s
}
