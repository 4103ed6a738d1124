//! The forward plan of a κ = 1 mechanism with one virtual variable
//! (capability `fk_numeric`, [`pkm_runtime::fk_numeric`]; at κ ≥ 2 the same
//! capability solves legs that end in balls by their pose equations,
//! [`ball_legs`]): one joint of the
//! coupled SKC's SOCs is given as if it were an input, the closed-form
//! planner ([`crate::plan::planner`]) solves the rest, and the one check the plan
//! cannot make hold by construction is the compatibility residual.
//!
//! The candidates are the joints of the coupled SKC's SOCs that
//! [`crate::topology::Topology::coupling_notes`] names, those of the SOCs
//! with Δ > 0 first (their surplus motion is what the virtual variable
//! fixes), revolutes before slides (a revolute's range is its turn), in
//! path order. A candidate is taken when the planner solves every link
//! with it given and exactly one of the plan's checks is not closed by
//! construction, and that one is an aim's miss across a revolute's axis
//! (a signed length: [`pkm_runtime::steps::aim::miss`]). Which checks are
//! closed by construction is measured, not assumed: over random inputs
//! and virtual values the others' rows stay at rounding.
//!
//! Where no candidate leaves such a miss (the last SOC closes on a given
//! length between two known joints, as a 3-RPR's third leg, and the
//! closed-form step meeting that length has no solution but at the
//! roots), one actuated joint is left out of the given values instead,
//! slides first: the plan computes it, nothing else stays open, and the
//! residual is its computed value less its given one
//! ([`Compatibility::Input`]).

use crate::diagnostics::{Diagnostic, Diagnostics};
use crate::topology::analysis::Analysis;
use crate::topology::screw::SplitMix;
use pkm_runtime::fk_numeric::{self, Compatibility, VirtualPlan};
use pkm_runtime::model::{JointType, Model};
use pkm_runtime::plan::{Check, Plan, Step};
use std::collections::HashMap;

/// A diagnostic on the mechanism's name with the coupling notes.
fn refusal(a: &Analysis, msg: String) -> Diagnostics {
    let mut d = Diagnostic::new(a.mechanism.name_span(), msg).label("in this mechanism");
    for note in a.topology.coupling_notes() {
        d = d.note(note);
    }
    d.into()
}

/// What `fk_numeric` needs of the topology alone: κ = 1 in one SKC.
///
/// # Errors
/// κ = 0 (the closed-form `fk` solves it), κ ≥ 2 or several coupled SKCs
/// (one virtual variable is all this does).
pub fn coupling(a: &Analysis) -> Result<(), Diagnostics> {
    let t = &a.topology;
    if t.kappa == 0 {
        return Err(refusal(
            a,
            "`fk_numeric` is for κ > 0: this mechanism has κ = 0, request `fk`".into(),
        ));
    }
    let coupled = t.skcs.iter().filter(|s| s.kappa > 0).count();
    if t.kappa > 1 || coupled > 1 {
        return Err(refusal(
            a,
            format!(
                "`fk_numeric` solves one SKC with κ = 1 (one virtual variable); this mechanism has κ = {} in {coupled} SKC{}",
                t.kappa,
                if coupled == 1 { "" } else { "s" }
            ),
        ));
    }
    Ok(())
}

/// Whether `fk_numeric` solves this mechanism by one virtual variable: it
/// asks for `fk_numeric` and its topology passes [`coupling`] (else, at
/// κ ≥ 2, by its ball legs' pose equations, [`ball_legs`]).
pub fn by_virtual_variable(a: &Analysis) -> bool {
    a.mechanism.wants(crate::semantics::mechanism::Capability::FkNumeric) && coupling(a).is_ok()
}

/// What `fk_numeric` needs where one virtual variable does not do
/// ([`coupling`] refuses the topology, κ ≥ 2): legs that each end in one
/// ball between the base and the platform the declared outputs place
/// ([`pkm_runtime::ball_legs::BallLegs::for_outputs`], at the nominal
/// dimensions), whose pose equations are solved, and the inverse solution
/// (`ik`), which solves each root's joints.
///
/// # Errors
/// The refusal of [`coupling`] with why the legs do not serve, or that
/// `ik` is not asked for.
pub fn ball_legs(a: &Analysis) -> Result<pkm_runtime::ball_legs::BallLegs, Diagnostics> {
    let Err(refused) = coupling(a) else {
        return Err(refusal(
            a,
            "`fk_numeric` solves this mechanism by one virtual variable".into(),
        ));
    };
    let why = |why: String| -> Diagnostics {
        let mut d = refused.clone();
        if let Some(first) = d.0.first_mut() {
            first.message = format!(
                "{}; at κ ≥ 2 it solves legs that each end in a ball, by the platform's pose equations, but {why}",
                first.message
            );
        }
        d
    };
    if a.topology.kappa == 0 {
        return Err(refused);
    }
    if !a.mechanism.wants(crate::semantics::mechanism::Capability::Ik) {
        return Err(why(
            "each root's joints are solved by the inverse solution: request `ik` too".into(),
        ));
    }
    let model = crate::lowering::numeric::model(a, &HashMap::new())?;
    let outputs = crate::lowering::numeric::newton_outputs(a, &model, &HashMap::new())?;
    pkm_runtime::ball_legs::BallLegs::for_outputs(&model, &outputs).map_err(why)
}

/// The virtual-variable forward plan of a κ = 1 mechanism.
///
/// # Errors
/// A diagnostic for κ = 0 (the closed-form `fk` solves it), κ ≥ 2 (one
/// virtual variable per SKC is all this does), or where no candidate
/// joint gives a plan with one compatibility residual.
pub fn forward_numeric_plan(a: &Analysis) -> Result<VirtualPlan, Diagnostics> {
    coupling(a)?;
    let m = &a.mechanism;
    let t = &a.topology;
    let refuse = |msg: String| -> Diagnostics { refusal(a, msg) };
    let coupled: Vec<_> = t.skcs.iter().filter(|s| s.kappa > 0).collect();
    let model = crate::lowering::numeric::model(a, &HashMap::new())?;
    let skc = coupled[0];
    let mut socs: Vec<usize> = skc.socs.clone().collect();
    socs.sort_by_key(|&j| t.socs[j].delta <= 0);
    let mut candidates: Vec<usize> = Vec::new();
    for j in socs.iter().flat_map(|&s| t.socs[s].joints.iter().copied()) {
        if !model.joints[j].actuated && !candidates.contains(&j) {
            candidates.push(j);
        }
    }
    candidates.sort_by_key(|&j| model.joints[j].kind != JointType::R);
    let mut tried = Vec::new();
    for &v in &candidates {
        match with_virtual(a, &model, v, None) {
            Ok(vp) => return Ok(vp),
            Err(why) => tried.push(format!("{}: {why}", m.joints[v].name)),
        }
    }
    // No aim left open: an input not given instead, slides first (their
    // value is a length, without a turn's wrap).
    let mut inputs = model.inputs();
    inputs.sort_by_key(|&j| model.joints[j].kind != JointType::P);
    for &v in &candidates {
        for &k in &inputs {
            match with_virtual(a, &model, v, Some(k)) {
                Ok(vp) => return Ok(vp),
                Err(why) => tried.push(format!(
                    "{} with {} computed: {why}",
                    m.joints[v].name, m.joints[k].name
                )),
            }
        }
    }
    let mut d = refuse(
        "`fk_numeric` found no virtual variable: no joint of the coupled SKC, given, leaves one compatibility residual"
            .into(),
    )
    .0
    .remove(0);
    for t in tried {
        d = d.note(t);
    }
    Err(d.into())
}

/// The plan with joint `v` given, and its compatibility residual: with
/// every input given, the one aim's miss the plan leaves open; with the
/// input `dropped` not given, its computed value less its given one,
/// where the plan leaves nothing else open.
fn with_virtual(a: &Analysis, model: &Model, v: usize, dropped: Option<usize>) -> Result<VirtualPlan, String> {
    if !matches!(model.joints[v].kind, JointType::R | JointType::P) {
        return Err("not a revolute or a slide".into());
    }
    let mut inputs = model.inputs();
    let n = inputs.len();
    let mut given = vec![None; model.joints.len()];
    for (i, &j) in inputs.iter().enumerate() {
        if Some(j) != dropped {
            given[j] = Some(i);
        }
    }
    given[v] = Some(n);
    inputs.push(v);
    let mut plan: Plan = crate::plan::planner::solve(a, model, given, vec![], &[], n + 1, inputs, "forward")
        .map_err(|_| "no closed-form plan")?;
    // Every link is read (the residual is checked on the whole solution).
    plan.check_by_miss(model, &vec![true; model.links.len()]);
    let (range, periodic) = fk_numeric::range_of(model, v);
    let checks = plan.checks(model.joints.len());
    let live = live_checks(model, &plan, &checks, range)?;
    if let Some(joint) = dropped {
        if !live.is_empty() {
            return Err(format!("{} checks not closed by construction, not none", live.len()));
        }
        let input = plan.inputs.iter().position(|&j| j == joint).ok_or("not an input")?;
        let arc = (model.joints[joint].kind != JointType::P).then(|| pkm_runtime::kinematics::model_scale(model));
        return Ok(VirtualPlan {
            plan,
            joint: v,
            range,
            periodic,
            compatibility: Compatibility::Input { joint, input, arc },
        });
    }
    let [(check, row)] = live[..] else {
        return Err(format!("{} checks not closed by construction, not one", live.len()));
    };
    let by = match checks[check] {
        Check::Joint(k) => plan.by_miss.iter().find(|b| b.joint == k && b.plane.is_none()),
        Check::Pin(_) => None,
    };
    let across_axis = by.is_some_and(
        |b| matches!(plan.steps[b.aim], Step::Aim { joint, .. } if model.joints[joint].kind == JointType::R),
    );
    if !across_axis {
        return Err("its compatibility check is not an aim's miss across a revolute's axis".into());
    }
    Ok(VirtualPlan {
        plan,
        joint: v,
        range,
        periodic,
        compatibility: Compatibility::Miss { check, row },
    })
}

/// The checks whose rows leave rounding somewhere over random inputs
/// (revolutes over their turn, slides over the virtual slide's range) and
/// virtual values, on every branch where the plan runs, each with the row
/// that does (the miss's component: row 0 of a planar aim's, another of a
/// spatial one's); a check with two such rows is an error (one virtual
/// variable leaves one scalar condition).
fn live_checks(model: &Model, plan: &Plan, checks: &[Check], range: [f64; 2]) -> Result<Vec<(usize, usize)>, String> {
    let geometry = pkm_runtime::steps::Geometry::of(model);
    let scale = pkm_runtime::kinematics::model_scale(model);
    let slide = fk_numeric::slide_range(model);
    let mut rng = SplitMix::new(0x7669_7274);
    let rows_per = pkm_runtime::steps::RESIDUAL_ROWS;
    let mut worst = vec![0.0f64; checks.len() * rows_per];
    let mut ran = 0;
    let joints = plan.inputs.clone();
    for _ in 0..4000 {
        if ran >= 200 {
            break;
        }
        let given: Vec<f64> = joints
            .iter()
            .enumerate()
            .map(|(i, &j)| {
                let u = rng.symmetric();
                if i + 1 == joints.len() {
                    0.5 * (range[0] + range[1]) + 0.5 * (range[1] - range[0]) * u
                } else if model.joints[j].kind == JointType::P {
                    slide * u
                } else {
                    std::f64::consts::PI * u
                }
            })
            .collect();
        let name = |_: usize| -> std::borrow::Cow<'static, str> { std::borrow::Cow::Borrowed("") };
        for (signs, ()) in pkm_runtime::solution::every_branch(plan.branches, |_| ()) {
            let g = pkm_runtime::steps::Given {
                values: &given,
                signs: &signs,
                name: &name,
                sites: 0,
            };
            let Ok(state) = pkm_runtime::steps::run(plan, &geometry, model.links.len(), &g) else {
                continue;
            };
            ran += 1;
            let rows = pkm_runtime::steps::check_residual(&geometry, plan, checks, &state.poses, &given, scale);
            for (w, x) in worst.iter_mut().zip(&rows) {
                *w = w.max(x.abs());
            }
        }
    }
    if ran == 0 {
        return Err("its plan has no real solution at any sampled input".into());
    }
    let mut live = Vec::new();
    for k in 0..checks.len() {
        let rows: Vec<usize> = (0..rows_per)
            .filter(|&r| worst[k * rows_per + r] > 1e-6 * scale)
            .collect();
        match rows[..] {
            [] => {}
            [row] => live.push((k, row)),
            _ => return Err(format!("a check's miss has {} components, not one", rows.len())),
        }
    }
    Ok(live)
}
