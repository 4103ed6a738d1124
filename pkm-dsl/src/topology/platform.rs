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
    pub(super) decoupling: Vec<Dependence>,
}
/// The platform's POC set at its base point (the platform joint whose POC
/// set has the fewest translations, or the declared one), each branch's
/// POC set at that point, and the outputs' motion decoupling.
pub(super) fn platform_characteristics(mech: &Mechanism, ctx: &Context) -> Platform {
    let inst = &ctx.primary[0];
    let labeller = Labeller::new(ctx, mech.platform, None);

    let mut platform_poc = None;
    let mut base_point = None;
    let mut branch_poc = Vec::new();
    let mut decoupling = Vec::new();
    if let Some(p) = mech.platform {
        let (sys, kernel) = &ctx.whole[0];
        let twists = sys.relative_twists(kernel, 0, p);
        let candidates: Vec<usize> = match mech.base_point {
            Some(j) => vec![j],
            None => (0..mech.joints.len())
                .filter(|&j| {
                    mech.joints[j].links.contains(&p) && !matches!(mech.joints[j].kind, JointKind::P | JointKind::Pa)
                })
                .collect(),
        };
        let mut best: Option<(usize, PocSet)> = None;
        for j in candidates {
            let poc = labeller.poc(&twists, &inst.points[j]);
            if best.as_ref().is_none_or(|(_, b)| poc.t < b.t) {
                best = Some((j, poc));
            }
        }
        let o = best.as_ref().map_or_else(Vector3::zeros, |(j, _)| inst.points[*j]);
        base_point = best.as_ref().map(|(j, _)| *j);
        platform_poc = best.map(|(_, poc)| poc);
        for br in &mech.branches {
            let sys = VelocitySystem::new(mech, inst, ctx.joint_mask(&br.joints));
            let kernel = sys.kernel();
            let labeller = Labeller::new(ctx, mech.platform, Some(&br.joints));
            branch_poc.push(labeller.poc(&sys.relative_twists(&kernel, 0, p), &o));
        }
        decoupling = motion_decoupling(ctx, p, base_point);
    }
    Platform {
        platform_poc,
        base_point,
        branch_poc,
        decoupling,
    }
}
pub(super) fn motion_decoupling(ctx: &Context, platform: usize, base_point: Option<usize>) -> Vec<Dependence> {
    let mech = ctx.mech;
    let actuated: Vec<usize> = (0..mech.joints.len()).filter(|&j| mech.joints[j].actuated).collect();
    let names = ["x", "y", "z", "rx", "ry", "rz"];
    let mut depends = [[false; 64]; 6];
    let mut moves = [false; 6];
    for (inst, (sys, kernel)) in ctx.primary.iter().zip(&ctx.whole) {
        let twists = sys.relative_twists(kernel, 0, platform);
        let o = base_point.map_or_else(Vector3::zeros, |j| inst.points[j]);
        let (w, v) = screw::at_point(&twists, &o);
        let input = input_rows(mech, sys, kernel);
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
        for r in 0..6 {
            for c in 0..actuated.len().min(64) {
                if g[(r, c)].abs() > 1e-8 * scale {
                    depends[r][c] = true;
                    moves[r] = true;
                }
            }
        }
    }
    (0..6)
        .filter(|&r| moves[r])
        .map(|r| Dependence {
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
