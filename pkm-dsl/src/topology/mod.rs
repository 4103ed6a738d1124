//! POC topology analysis: POC sets, full-cycle DOF, ordered single open
//! chains (SOC) with their ξ_L and constraint degrees Δ, sub-kinematic chains
//! (SKC), the coupling degree κ, the topological expression and motion
//! decoupling, with an independent cross-check.
//!
//! Two computations of ξ_Lj must agree:
//! - the **loop-closure rank**: ξ_Lj is the rank that the loop equations of
//!   SOC_j add to those of SOC_1..SOC_{j-1}, at several generic configurations;
//! - the **POC formula** `ξ_Lj = dim{(∩ M_b) ∪ M_b(j+1)}`: the motion that the
//!   mechanism built so far allows between the two end links of SOC_j, united
//!   with the POC set of SOC_j's own joints, at other generic configurations.
//!
//! A disagreement is reported as an analysis error.
//!
//! The topology stage: it imports only `syntax` and `semantics`. Its
//! screw-system algebra (`screw`) and the analysis that joins model,
//! geometry and topology (`analysis`, [`analysis::analyze_source`]) are its
//! children.

pub mod analysis;
mod context;
mod cross_check;
mod expression;
mod ordering;
mod platform;
pub mod screw;

use context::*;
use cross_check::*;
use expression::*;
pub use ordering::evaluate_order;
use ordering::*;
use platform::*;

use crate::diagnostics::{Diagnostic, Diagnostics};
use crate::semantics::mechanism::Mechanism;
use std::fmt;

/// Seeds of the generic configurations the analysis uses.
const PRIMARY_SEEDS: [u64; 3] = [0x5eed_0001, 0x5eed_0002, 0x5eed_0003];
/// A POC set `[t^α(dir); r^β(dir)]` with the dimension of its motion.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PocSet {
    /// α: independent translations of the base point.
    pub t: usize,
    /// Direction of the translations (`∥◇xoz`, `⊥R12`, `∥P3`), when they have one.
    pub t_dir: Option<String>,
    /// β: independent rotations.
    pub r: usize,
    /// Direction of the rotations (`∥R6`, `∥◇(R12,R4)`), when they have one.
    pub r_dir: Option<String>,
    /// The dimension of the motion (≤ α + β: derived translations add none).
    pub dim: usize,
}

const SUPERSCRIPT: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
const SUBSCRIPT: [char; 10] = ['₀', '₁', '₂', '₃', '₄', '₅', '₆', '₇', '₈', '₉'];

fn script(n: i64, digits: &[char; 10]) -> String {
    let s: String = n
        .abs()
        .to_string()
        .chars()
        .map(|c| digits[c.to_digit(10).unwrap_or(0) as usize])
        .collect();
    if n < 0 {
        format!("⁻{s}")
    } else {
        s
    }
}

fn sup(n: usize) -> String {
    script(n as i64, &SUPERSCRIPT)
}

fn sub(n: usize) -> String {
    script(n as i64, &SUBSCRIPT)
}

fn signed(d: i32) -> String {
    match d {
        0 => "0".into(),
        d if d > 0 => format!("+{d}"),
        d => format!("−{}", -d),
    }
}

impl PocSet {
    /// The set in the papers' Unicode notation, e.g. `[t²(∥◇xoz); r¹(∥R6)]`.
    pub fn unicode(&self) -> String {
        let part = |letter: &str, n: usize, dir: &Option<String>| match dir {
            Some(d) if n > 0 && n < 3 => format!("{letter}{}({d})", sup(n)),
            _ => format!("{letter}{}", sup(n)),
        };
        format!(
            "[{}; {}]",
            part("t", self.t, &self.t_dir),
            part("r", self.r, &self.r_dir)
        )
    }

    /// The same in ASCII, e.g. `[t^2(||<>xoz); r^1(||R6)]`.
    pub fn ascii(&self) -> String {
        to_ascii(&self.unicode())
    }

    /// The type, e.g. `2T1R` (`3T`, `3R`, `0T0R` for no motion).
    pub fn kind(&self) -> String {
        poc_kind(self.t, self.r)
    }
}

fn poc_kind(t: usize, r: usize) -> String {
    match (t, r) {
        (0, 0) => "0T0R".into(),
        (t, 0) => format!("{t}T"),
        (0, r) => format!("{r}R"),
        (t, r) => format!("{t}T{r}R"),
    }
}

/// Rewrites the Unicode notation in ASCII.
pub fn to_ascii(s: &str) -> String {
    let mut out = String::new();
    // Runs of super- or subscript digits become `^12` or `_12`.
    let mut run: Option<char> = None;
    for c in s.chars() {
        let script = [('^', &SUPERSCRIPT), ('_', &SUBSCRIPT)]
            .into_iter()
            .find_map(|(mark, table)| table.iter().position(|x| *x == c).map(|d| (mark, d)));
        if let Some((mark, d)) = script {
            if run != Some(mark) {
                out.push(mark);
                run = Some(mark);
            }
            out.push(char::from(b'0' + d as u8));
            continue;
        }
        run = None;
        match c {
            '∥' => out.push_str("||"),
            '⊥' => out.push_str("_|_"),
            '◇' => out.push_str("<>"),
            '≡' => out.push_str("=="),
            '∧' => out.push_str("/\\"),
            '−' => out.push('-'),
            '⁻' => out.push_str("^-"),
            'ᵀ' => out.push('T'),
            'ᴿ' => out.push('R'),
            'κ' => out.push_str("kappa"),
            'Δ' => out.push_str("Delta"),
            'ξ' => out.push_str("xi"),
            '–' => out.push('-'),
            c => out.push(c),
        }
    }
    out
}

impl fmt::Display for PocSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.unicode())
    }
}

/// One single open chain of the ordered decomposition.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Soc {
    /// Its joints in path order.
    pub joints: Vec<usize>,
    /// The links it starts and ends at (already in the chain built before it).
    pub ends: [usize; 2],
    /// Σf of its joints.
    pub dof: usize,
    /// I_j: its actuated joints.
    pub actuators: usize,
    /// ξ_Lj: independent displacement equations of the loop it closes.
    pub xi: usize,
    /// Δ_j = Σf − I_j − ξ_Lj.
    pub delta: i32,
    /// The chain in the papers' notation, e.g. `P1⊥R11∥R12∥R13⊥P2`.
    pub notation: String,
}

/// A sub-kinematic chain: consecutive SOCs whose Δ sum to zero.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Skc {
    /// The indices of its SOCs.
    pub socs: std::ops::Range<usize>,
    /// κ_k = ½ Σ|Δ_j|.
    pub kappa: usize,
    /// Its POC type (that of the branch that holds its actuators), if it belongs to a branch.
    pub kind: Option<String>,
}

/// An output of the platform and the actuated joints it depends on.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Dependence {
    /// `x`, `y`, `z` (base-point translation along a frame axis) or `rx`, `ry`, `rz` (rotation about it).
    pub output: String,
    /// The actuated joints (indices) whose motion changes it.
    pub inputs: Vec<usize>,
    /// A parasitic motion: the platform moves this way too, but only as
    /// the declared outputs (`pose (z, rx, ry) of platform`) make it, which
    /// span the POC set's dimension.
    pub parasitic: bool,
}

/// The result of the topology analysis.
#[derive(Debug, Clone, PartialEq)]
pub struct Topology {
    /// Full-cycle DOF F = Σf − Σξ_Lj.
    pub dof: usize,
    /// Σf.
    pub total_f: usize,
    /// v = m − n + 1 independent loops.
    pub loops: usize,
    /// The ordered SOCs (the ordering that minimises Σ|Δ_j|; ties: more SKCs).
    pub socs: Vec<Soc>,
    /// The sub-kinematic chains.
    pub skcs: Vec<Skc>,
    /// κ = max κ_k.
    pub kappa: usize,
    /// POC set of each joint (base point on its axis).
    pub joint_poc: Vec<PocSet>,
    /// POC set of each branch's end (at the platform's base point).
    pub branch_poc: Vec<PocSet>,
    /// Per branch, where its POC set at its own joint on the platform
    /// differs from that at o (o off that joint: rotations about it add
    /// translations at o that the branch alone derives): that joint and
    /// the set there, so that identical branches read the same.
    pub branch_own_poc: Vec<Option<(usize, PocSet)>>,
    /// POC set of the platform.
    pub platform_poc: Option<PocSet>,
    /// The joint on whose axis the platform's base point o lies.
    pub base_point: Option<usize>,
    /// Which outputs depend on which actuators.
    pub decoupling: Vec<Dependence>,
    /// ξ_Lj by the POC formula at the cross-check configurations (equal to `socs[j].xi`).
    pub xi_by_poc_formula: Vec<usize>,
    /// The topological expression (seed 000 eq. 9), Unicode.
    pub expression: String,
    /// Under `mobility by geometry`: F at generic instances of the
    /// relations, where this topology was counted at the declared geometry.
    pub generic_dof: Option<usize>,
}

impl Topology {
    /// Per SKC with κ > 0: its SOCs, their Δ, its κ, and the virtual
    /// variables its forward solution needs (what a refusal of `fk` says).
    pub fn coupling_notes(&self) -> Vec<String> {
        self.skcs
            .iter()
            .enumerate()
            .filter(|(_, s)| s.kappa > 0)
            .map(|(k, skc)| {
                let socs: Vec<String> = skc
                    .clone()
                    .socs
                    .map(|j| format!("SOC{} {{{}}}", j + 1, self.socs[j].notation))
                    .collect();
                let deltas: Vec<String> = skc.clone().socs.map(|j| delta_unicode(self.socs[j].delta)).collect();
                format!(
                    "SKC{} = {} has Δ = ({}), so κ{} = ½Σ|Δ| = {}: its forward solution needs {} virtual variable{} solved by iteration",
                    k + 1,
                    socs.join(" + "),
                    deltas.join(", "),
                    k + 1,
                    skc.kappa,
                    skc.kappa,
                    if skc.kappa == 1 { "" } else { "s" }
                )
            })
            .collect()
    }

    /// ξ_Lj for every SOC.
    pub fn xi(&self) -> Vec<usize> {
        self.socs.iter().map(|s| s.xi).collect()
    }

    /// Δ_j for every SOC.
    pub fn delta(&self) -> Vec<i32> {
        self.socs.iter().map(|s| s.delta).collect()
    }
}

/// Runs the whole analysis.
///
/// ```
/// let ast = pkm_dsl::parse("mechanism four_bar { planar; base R1* - R2 - R3 - R4 base; }").unwrap();
/// let mech = pkm_dsl::mechanism::build(&ast).unwrap();
/// let topo = pkm_dsl::topology::analyze(&mech).unwrap();
/// assert_eq!((topo.dof, topo.xi(), topo.delta(), topo.kappa), (1, vec![3], vec![0], 0));
/// ```
pub fn analyze(mech: &Mechanism) -> Result<Topology, Diagnostics> {
    if mech.mobility_by_geometry.is_some() {
        // With `mobility by geometry` the actuators are counted against
        // the F of the declared geometry ([`analyze_at`]): the generic
        // topology here counts none (I = 0), for its F alone.
        let mut generic = mech.clone();
        generic.joints.iter_mut().for_each(|j| j.actuated = false);
        return analyze_in(&generic, context(&generic)?, false);
    }
    analyze_in(mech, context(mech)?, true)
}

/// The analysis at given configurations of the mechanism instead of
/// generic instances of its relations: `primary` for the ranks, `check`
/// for the cross-check (the declared geometry's, for `mobility by
/// geometry`; `lowering::mobility::accept`).
pub fn analyze_at(
    mech: &Mechanism,
    primary: Vec<screw::Instance>,
    check: Vec<screw::Instance>,
) -> Result<Topology, Diagnostics> {
    analyze_in(mech, context_at(mech, primary, check), true)
}

fn analyze_in(mech: &Mechanism, mut ctx: Context<'_>, count_actuators: bool) -> Result<Topology, Diagnostics> {
    let n = mech.joints.len();
    let all = all_joints(n);
    let total_f = ctx.f_of(all);
    let total_rank = ctx.loop_rank(all);
    let dof = total_f - total_rank;
    let loops = n + 1 - mech.links.len();
    if count_actuators {
        check_actuator_count(mech, dof, total_f, total_rank).map_err(|mut d| {
            if mech.actuator_count() > dof && !mech.branches.is_empty() {
                let notes = &mut d.0[0].notes;
                notes.extend(overconstrained_branches(mech, &ctx, dof));
            }
            d
        })?;
        check_actuators_drive(mech, &ctx, dof)?;
    }
    let order = soc_order(mech, &mut ctx, all, loops)?;
    let socs = ordered_socs(&mut ctx, order);
    let (mut skcs, kappa) = sub_kinematic_chains(&socs);
    let xi_by_poc_formula = cross_check(mech, &ctx, &socs, total_f, dof)?;
    let joint_poc = (0..n).map(|j| joint_poc(mech, j)).collect();
    let Platform {
        platform_poc,
        base_point,
        branch_poc,
        branch_own_poc,
        decoupling,
    } = platform_characteristics(mech, &ctx);
    for skc in &mut skcs {
        skc.kind = skc_kind(mech, &socs[skc.socs.clone()], &branch_poc);
    }
    let expression = expression(mech, dof, &socs, &skcs, kappa, platform_poc.as_ref());
    Ok(Topology {
        dof,
        total_f,
        loops,
        socs,
        skcs,
        kappa,
        joint_poc,
        branch_poc,
        branch_own_poc,
        platform_poc,
        base_point,
        decoupling,
        xi_by_poc_formula,
        expression,
        generic_dof: None,
    })
}

/// The number of actuated joints must be the DOF F = Σf − Σξ_L.
fn check_actuator_count(mech: &Mechanism, dof: usize, total_f: usize, total_rank: usize) -> Result<(), Diagnostics> {
    let actuators = mech.actuator_count();
    if actuators != dof {
        let names: Vec<&str> = mech
            .joints
            .iter()
            .filter(|j| j.actuated)
            .map(|j| j.name.as_str())
            .collect();
        let mut d = Diagnostic::new(
            mech.joints
                .iter()
                .find(|j| j.actuated)
                .map_or_else(|| mech.joints[0].span, |j| j.span),
            format!(
                "the mechanism has {dof} DOF but {actuators} actuated joint{}",
                if actuators == 1 { "" } else { "s" }
            ),
        )
        .label(if actuators == 0 {
            "no joint is marked `*`"
        } else {
            "actuated here"
        })
        .note(format!("F = Σf − Σξ_L = {total_f} − {total_rank} = {dof}"));
        if !names.is_empty() {
            d = d.note(format!("actuated: {}", names.join(", ")));
        }
        d = d.note("mark exactly F joints as actuated with `*`");
        return Err(d.into());
    }
    Ok(())
}

/// Where more joints are actuated than F: each branch's POC set at o and
/// the platform's, and the branch with the most motion, where one has
/// more than the others (a relation in it, or with another branch, left
/// out: `∥`, `⊥`, `≡`, `∧`).
fn overconstrained_branches(mech: &Mechanism, ctx: &Context, dof: usize) -> Vec<String> {
    let p = platform_characteristics(mech, ctx);
    let Some(platform) = p.platform_poc else {
        return Vec::new();
    };
    let mut notes = vec![format!(
        "the branches' POC sets at o meet in the platform's M_Pa = {platform} (dim {}, o on {}): F = {dof} \
         leaves {} actuated joint{} nothing to drive",
        platform.dim,
        p.base_point.map_or("?", |j| mech.joints[j].name.as_str()),
        mech.actuator_count() - dof,
        if mech.actuator_count() - dof == 1 { "" } else { "s" }
    )];
    let listed: Vec<String> = mech
        .branches
        .iter()
        .zip(&p.branch_poc)
        .map(|(b, poc)| format!("{} {poc} (dim {})", b.name, poc.dim))
        .collect();
    notes.push(format!("branches: {}", listed.join(", ")));
    // Motions each branch has that their intersection lost: the branches'
    // axes (or guides) want a relation that makes them share those.
    let lost = |part: &str, of: fn(&PocSet) -> (usize, Option<String>)| {
        let least = p.branch_poc.iter().map(|poc| of(poc).0).min().unwrap_or(0);
        (least > of(&platform).0).then(|| {
            let each: Vec<String> = mech
                .branches
                .iter()
                .zip(&p.branch_poc)
                .map(|(b, poc)| {
                    let (n, dir) = of(poc);
                    format!(
                        "{} {part}{}{}",
                        b.name,
                        sup(n),
                        dir.map(|d| format!("({d})")).unwrap_or_default()
                    )
                })
                .collect();
            format!(
                "each branch has at least {part}{} but together they keep {part}{}: {}; a relation between these \
                 axes or guides (∥, ⊥, ≡, ∧) that would make them share the {} is missing",
                sup(least),
                sup(of(&platform).0),
                each.join(", "),
                if part == "r" { "rotations" } else { "translations" }
            )
        })
    };
    notes.extend(lost("r", |poc| (poc.r, poc.r_dir.clone())));
    notes.extend(lost("t", |poc| (poc.t, poc.t_dir.clone())));
    let most = p.branch_poc.iter().map(|poc| poc.dim).max().unwrap_or(0);
    let largest: Vec<&str> = mech
        .branches
        .iter()
        .zip(&p.branch_poc)
        .filter(|(_, poc)| poc.dim == most)
        .map(|(b, _)| b.name.as_str())
        .collect();
    if largest.len() < mech.branches.len() {
        notes.push(format!(
            "branch {} has the largest POC set: each dimension of a branch's motion beyond the platform's adds \
             to Σξ_L and takes one from F; check it for a relation its axes should have (∥, ⊥, ≡, ∧), within it \
             or with another branch",
            largest.join(", ")
        ));
    }
    notes
}

/// Locking the actuators must make the mechanism rigid at a generic configuration.
/// The generic rank is the largest; stop at the first configuration that reaches F.
fn check_actuators_drive(mech: &Mechanism, ctx: &Context, dof: usize) -> Result<(), Diagnostics> {
    let mut driven = 0;
    for (sys, kernel) in &ctx.whole {
        let input = input_rows(mech, sys, kernel);
        driven = driven.max(screw::rank_of_part(&input, sys.rate_scale(kernel)));
        if driven >= dof {
            break;
        }
    }
    if driven < dof {
        let first = mech
            .joints
            .iter()
            .find(|j| j.actuated)
            .map_or(mech.joints[0].span, |j| j.span);
        return Err(Diagnostic::new(
            first,
            format!(
                "with its actuated joints locked the mechanism still moves ({} DOF): the actuators cannot drive it",
                dof - driven
            ),
        )
        .label("actuated here")
        .note("an actuator in a loop that is already driven over-constrains it and leaves another loop free")
        .into());
    }
    Ok(())
}

/// A Δ written the papers' way (`+1`, `0`, `−1`).
pub fn delta_unicode(d: i32) -> String {
    signed(d)
}

#[cfg(test)]
mod tests {
    use super::to_ascii;

    /// (F, ξ, Δ, κ, platform POC) of a mechanism text, against a hand count.
    fn check(source: &str, dof: usize, xi: &[usize], delta: &[i32], kappa: usize, poc: Option<&str>) {
        let a =
            crate::topology::analysis::analyze_source(source).unwrap_or_else(|e| panic!("{}", e.render(source, "t")));
        let t = &a.topology;
        assert_eq!(
            (t.dof, t.xi(), t.delta(), t.kappa),
            (dof, xi.to_vec(), delta.to_vec(), kappa),
            "{source}"
        );
        if let Some(poc) = poc {
            assert_eq!(a.platform_poc(), poc, "{source}");
        }
    }

    #[test]
    fn idle_spins_are_not_counted() {
        // RSSR: Σf = 1 + 3 + 3 + 1 − 1 (the coupler's spin) = 7, one spatial loop.
        check(
            "mechanism rssr { base R1* - S1 - S2 - R2 base; }",
            1,
            &[6],
            &[0],
            0,
            None,
        );
        // The report says what it left out of Σf.
        let report = crate::topology::analysis::analyze_source("mechanism rssr { base R1* - S1 - S2 - R2 base; }")
            .unwrap()
            .report();
        assert!(report.contains("Σf = 7 (8 less 1 local idle DOF)"), "{report}");
        // 6-SPS: Σf = 42 − 6 leg spins = 36; SOC₁ two legs 12 − 2 − 6 = +4, then 6 − 1 − 1 − 6 = −1 four times.
        let legs: String = (1..=6)
            .map(|i| format!("base S{i} - P{i}* - S{} platform; ", i + 6))
            .collect();
        check(
            &format!("mechanism sps {{ {legs} }}"),
            6,
            &[6, 6, 6, 6, 6],
            &[4, -1, -1, -1, -1],
            4,
            None,
        );
    }

    #[test]
    fn a_translating_platform_has_no_rotation() {
        // Three P∥R∥R∥R legs along x, y, z: the platform only translates.
        check(
            "mechanism cart { branch A { base P1* ∥ R1 ∥ R2 ∥ R3 platform; } branch B { base P2* ∥ R4 ∥ R5 ∥ R6 platform; }
             branch C { base P3* ∥ R7 ∥ R8 ∥ R9 platform; } x ∥ P1 ∥ R1; y ∥ P2 ∥ R4; z ∥ P3 ∥ R7; }",
            3,
            &[5, 4],
            &[1, -1],
            1,
            Some("[t³; r⁰]"),
        );
    }

    #[test]
    fn perpendicularity_does_not_depend_on_declaration_order() {
        // R6 ⊥ R1, R2, R3 is satisfiable (R1, R2, R3 in one plane); a generic 6R loop is rigid.
        for chain in [
            "base R1* - R2 - R3 - R4 - R5 - R6 base;",
            "base R6* - R2 - R3 - R4 - R5 - R1 base;",
        ] {
            let e = crate::topology::analysis::analyze_source(&format!(
                "mechanism m {{ {chain} R6 ⊥ R1; R6 ⊥ R2; R6 ⊥ R3; }}"
            ))
            .unwrap_err();
            assert_eq!(
                e.0[0].message, "the mechanism has 0 DOF but 1 actuated joint",
                "{chain}"
            );
        }
    }

    #[test]
    fn many_loops_are_ordered_quickly() {
        // A planar ladder of eleven four-bar loops (κ = 0): the greedy order is
        // optimal and the exhaustive search never runs.
        let mut s = String::from("mechanism ladder { planar; base R1* [c] ∥ R2 [l0] ∥ R3 [r0] ∥ R4 base; ");
        for i in 1..=10 {
            s.push_str(&format!(
                "l{} R{} [a{i}] ∥ R{} [l{i}] ∥ R{} base; ",
                i - 1,
                3 * i + 2,
                3 * i + 3,
                3 * i + 4
            ));
        }
        s.push('}');
        check(&s, 1, &[3; 11], &[0; 11], 0, None);
    }

    #[test]
    fn ascii_spelling() {
        assert_eq!(to_ascii("[t²(∥◇xoz); r¹(∥R6)]"), "[t^2(||<>xoz); r^1(||R6)]");
        assert_eq!(
            to_ascii("²ᵀ¹ᴿPM⁰[3, 2(5, 6)] = SKC₁₂⁰[+1, −1; 3, 3]"),
            "^2T^1RPM^0[3, 2(5, 6)] = SKC_12^0[+1, -1; 3, 3]"
        );
    }
}
