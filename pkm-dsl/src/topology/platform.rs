//! The platform's characteristics: its POC set, and which outputs depend
//! on which inputs (motion decoupling).

use super::*;
use crate::semantics::mechanism::{JointKind, Mechanism};
use nalgebra::{DMatrix, Vector3};
use screw::VelocitySystem;

/// What the topology says of the platform.
pub(super) struct Platform {
    pub(super) platform_poc: Option<PocSet>,
    pub(super) base_point: Option<usize>,
    pub(super) branch_poc: Vec<PocSet>,
    pub(super) branch_own_poc: Vec<Option<(usize, PocSet)>>,
    pub(super) decoupling: Vec<Dependence>,
}
/// The platform's POC set at its base point (the platform joint whose POC
/// set has the fewest translations, or the declared one), each branch's
/// POC set at that point (and at the branch's own joint on the platform,
/// where that differs), and the outputs' motion decoupling.
pub(super) fn platform_characteristics(mech: &Mechanism, ctx: &Context) -> Platform {
    let inst = &ctx.primary[0];
    // The platform, or without one the link the outputs are on.
    let subject = mech.platform.or(mech.output_link.map(|(l, _)| l));
    let labeller = Labeller::new(ctx, subject, None);

    let mut platform_poc = None;
    let mut base_point = None;
    let mut branch_poc = Vec::new();
    let mut branch_own_poc = Vec::new();
    let mut decoupling = Vec::new();
    if let Some(p) = subject {
        let (sys, kernel) = &ctx.whole[0];
        let twists = sys.relative_twists(kernel, 0, p);
        let candidates: Vec<usize> = match mech.base_point.or(mech.output_link.and_then(|(_, j)| j)) {
            Some(j) => vec![j],
            None => (0..mech.joints.len()).filter(|&j| on_platform(mech, j, p)).collect(),
        };
        let best = fewest_translations(&labeller, &twists, inst, candidates);
        let o = best.as_ref().map_or_else(Vector3::zeros, |(j, _)| inst.points[*j]);
        base_point = best.as_ref().map(|(j, _)| *j);
        platform_poc = best.map(|(_, poc)| poc);
        for br in &mech.branches {
            let sys = VelocitySystem::new(mech, inst, ctx.joint_mask(&br.joints));
            let kernel = sys.kernel();
            let labeller = Labeller::new(ctx, mech.platform, Some(&br.joints));
            let twists = sys.relative_twists(&kernel, 0, p);
            let at_o = labeller.poc(&twists, &o);
            // The same branch seen at its own joint on the platform: where
            // o is off that joint, rotations about it add derived
            // translations at o, and identical branches print differently.
            let own = br.joints.iter().copied().filter(|&j| on_platform(mech, j, p)).collect();
            branch_own_poc.push(
                fewest_translations(&labeller, &twists, inst, own)
                    .filter(|(j, poc)| Some(*j) != base_point && *poc != at_o),
            );
            branch_poc.push(at_o);
        }
        decoupling = motion_decoupling(ctx, p, base_point, platform_poc.as_ref().map(|poc| poc.dim));
    }
    Platform {
        platform_poc,
        base_point,
        branch_poc,
        branch_own_poc,
        decoupling,
    }
}

/// Whether joint `j` is on the platform `p` and has a point (not a P or Pa).
fn on_platform(mech: &Mechanism, j: usize, p: usize) -> bool {
    mech.joints[j].links.contains(&p) && !matches!(mech.joints[j].kind, JointKind::P | JointKind::Pa)
}

/// The joint among `candidates` at whose point the motion `twists` has
/// the fewest translations (the first of those), with its POC set there.
fn fewest_translations(
    labeller: &Labeller,
    twists: &DMatrix<f64>,
    inst: &screw::Instance,
    candidates: Vec<usize>,
) -> Option<(usize, PocSet)> {
    let mut best: Option<(usize, PocSet)> = None;
    for j in candidates {
        let poc = labeller.poc(twists, &inst.points[j]);
        if best.as_ref().is_none_or(|(_, b)| poc.t < b.t) {
            best = Some((j, poc));
        }
    }
    best
}
/// Which inputs move each of the platform's six outputs at o, and, where
/// more of them move than the POC set's dimension `dim`, which are
/// parasitic: the file's declared pose parts being independent there (their
/// rates of full rank `dim`), the others that move.
pub(super) fn motion_decoupling(
    ctx: &Context,
    platform: usize,
    base_point: Option<usize>,
    dim: Option<usize>,
) -> Vec<Dependence> {
    let mech = ctx.mech;
    let mut declared_rank: Option<usize> = None;
    let declared: Vec<usize> = mech
        .platform_outputs
        .iter()
        .filter_map(|o| ["x", "y", "z", "rx", "ry", "rz"].iter().position(|n| n == o))
        .collect();
    let actuated: Vec<usize> = (0..mech.joints.len()).filter(|&j| mech.joints[j].actuated).collect();
    let names = ["x", "y", "z", "rx", "ry", "rz"];
    let mut depends = [[false; 64]; 6];
    let mut moves = [false; 6];
    for (inst, (sys, kernel)) in ctx.primary.iter().zip(&ctx.whole) {
        let twists = sys.relative_twists(kernel, 0, platform);
        let o = base_point.map_or_else(Vector3::zeros, |j| inst.points[j]);
        let (w, v) = screw::at_point(&twists, &o);
        let input = input_rows(mech, sys, kernel);
        if input.is_empty() {
            continue; // no motion (F = 0) or no input: nothing depends
        }
        let Ok(pinv) = input.clone().pseudo_inverse(1e-12) else {
            continue;
        };
        if screw::rank_of_part(&input, sys.rate_scale(kernel)) < actuated.len() {
            continue; // an input singularity here: use the other configurations
        }
        let mut out = DMatrix::zeros(6, kernel.ncols());
        for k in 0..3 {
            let axis = inst.frame[k].transpose();
            out.set_row(k, &(axis * &v));
            out.set_row(3 + k, &(axis * &w));
        }
        let g = out * pinv;
        let scale = g.amax().max(1e-300);
        if !declared.is_empty() {
            let mut rows = DMatrix::zeros(declared.len(), g.ncols());
            // Each row in its own unit (a length's rate, an angle's): unit rows.
            for (k, &r) in declared.iter().enumerate() {
                let row = g.row(r);
                rows.set_row(k, &(row / row.norm().max(1e-300)));
            }
            let r = screw::rank_of_part(&rows, 1.0);
            declared_rank = Some(declared_rank.map_or(r, |d| d.max(r)));
        }
        for r in 0..6 {
            for c in 0..actuated.len().min(64) {
                if g[(r, c)].abs() > 1e-8 * scale {
                    depends[r][c] = true;
                    moves[r] = true;
                }
            }
        }
    }
    let moving = moves.iter().filter(|&&m| m).count();
    // The declared parts are the independent outputs where they span the
    // POC set's dimension and fewer than the moving outputs do.
    let independent = dim.is_some_and(|d| moving > d && declared.len() == d && declared_rank == Some(d));
    (0..6)
        .filter(|&r| moves[r])
        .map(|r| Dependence {
            parasitic: independent && !declared.contains(&r),
            output: names[r].to_string(),
            inputs: actuated
                .iter()
                .enumerate()
                .filter(|(c, _)| depends[r][*c])
                .map(|(_, &j)| j)
                .collect(),
        })
        .collect()
}
/// The rates of the actuated joints (the first rate of each) over the kernel.
pub(super) fn input_rows(mech: &Mechanism, sys: &VelocitySystem, kernel: &DMatrix<f64>) -> DMatrix<f64> {
    let actuated: Vec<usize> = (0..mech.joints.len()).filter(|&j| mech.joints[j].actuated).collect();
    let mut input = DMatrix::zeros(actuated.len(), kernel.ncols());
    for (r, &j) in actuated.iter().enumerate() {
        if let Some(c) = sys.joint_col[j] {
            input.set_row(r, &kernel.row(c));
        }
    }
    input
}
