//! The independent cross-check of ξ_L: the POC formula
//! `ξ_Lj = dim{(∩ M_b) ∪ M_b(j+1)}` on configurations of their own,
//! against the loop-closure ranks.

use super::*;
use crate::diagnostics::{Diagnostic, Diagnostics};
use crate::semantics::mechanism::{JointKind, Mechanism};
use nalgebra::DMatrix;
use screw::VelocitySystem;

/// Seeds of the configurations the cross-check uses (independent of the primary ones).
pub(super) const CHECK_SEEDS: [u64; 3] = [0xc4ec_0001, 0xc4ec_0002, 0xc4ec_0003];
/// ξ_L by the POC formula at independent configurations must equal ξ_L by
/// the loop-closure rank, and F must be Σf − Σξ_L by both.
pub(super) fn cross_check(
    mech: &Mechanism,
    ctx: &Context,
    socs: &[Soc],
    total_f: usize,
    dof: usize,
) -> Result<Vec<usize>, Diagnostics> {
    let xi_by_poc_formula = poc_formula_xi(ctx, socs);
    let dof_check = total_f as i64 - xi_by_poc_formula.iter().sum::<usize>() as i64;
    let mut errors = Diagnostics::default();
    for (j, (soc, x)) in socs.iter().zip(&xi_by_poc_formula).enumerate() {
        if soc.xi != *x {
            errors.push(
                Diagnostic::new(
                    mech.joints[soc.joints[0]].span,
                    format!(
                        "analysis error: ξ_L{} of SOC {} is {} by the loop-closure rank but {} by the POC formula",
                        j + 1,
                        soc.notation,
                        soc.xi,
                        x
                    ),
                )
                .label("in this chain")
                .note("the two computations use independent generic configurations; please report this mechanism"),
            );
        }
    }
    if errors.is_empty() && dof_check != dof as i64 {
        errors.push(Diagnostic::new(
            mech.joints[0].span,
            format!("analysis error: F is {dof} by rank but {dof_check} by Σf − Σξ"),
        ));
    }
    errors.into_result(xi_by_poc_formula)
}
pub(super) fn poc_formula_xi(ctx: &Context, socs: &[Soc]) -> Vec<usize> {
    let mut used = 0u64;
    let mut out = Vec::new();
    for soc in socs {
        // The generic value is the largest (no configuration exceeds it): the
        // first configuration that reaches the loop-closure ξ confirms it, and
        // the others are tried only when it does not (each costs a null space
        // of the whole system built so far).
        let mut xi = 0;
        for inst in &ctx.check {
            // M_rel: what the mechanism built so far allows between the SOC's end links.
            let m_rel = if used == 0 {
                DMatrix::zeros(6, 0)
            } else {
                let sys = VelocitySystem::new(ctx.mech, inst, used);
                sys.relative_twists(&sys.kernel(), soc.ends[0], soc.ends[1])
            };
            let m_soc = screw::joint_twists(inst, &soc.joints);
            xi = xi.max(screw::rank(&screw::hstack(&[&m_rel, &m_soc])));
            if xi >= soc.xi {
                break;
            }
        }
        out.push(xi);
        used |= ctx.joint_mask(&soc.joints);
    }
    out
}
pub(super) fn joint_poc(mech: &Mechanism, j: usize) -> PocSet {
    let name = &mech.joints[j].name;
    let on = |n: usize| Some(format!("∥{name}")).filter(|_| n > 0);
    let (t, t_dir, r, r_dir, dim) = match mech.joints[j].kind {
        JointKind::R => (0, None, 1, on(1), 1),
        JointKind::P => (1, on(1), 0, None, 1),
        JointKind::H => (1, on(1), 1, on(1), 1),
        JointKind::C => (1, on(1), 1, on(1), 2),
        JointKind::U => (0, None, 2, Some(format!("∥◇({name}.a,{name}.b)")), 2),
        JointKind::S => (0, None, 3, None, 3),
        JointKind::Pa => (1, Some(format!("∥◇{name}")), 0, None, 1),
    };
    PocSet {
        t,
        t_dir,
        r,
        r_dir,
        dim,
    }
}
