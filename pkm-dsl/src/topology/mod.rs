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
pub mod screw;

use crate::diagnostics::{Diagnostic, Diagnostics};
use crate::limits::MAX_ORDERING_WORK;
use crate::semantics::mechanism::{DirectionClasses, DirectionItem, JointKind, Mechanism};
use screw::{Instance, VelocitySystem};
use nalgebra::{DMatrix, Vector3};
use std::collections::HashMap;
use std::fmt;

/// Seeds of the generic configurations the analysis uses.
const PRIMARY_SEEDS: [u64; 3] = [0x5eed_0001, 0x5eed_0002, 0x5eed_0003];
/// Seeds of the configurations the cross-check uses (independent of the primary ones).
const CHECK_SEEDS: [u64; 3] = [0xc4ec_0001, 0xc4ec_0002, 0xc4ec_0003];
/// How many sub-mechanisms the exhaustive ordering search may evaluate
/// before it gives up (and says so).
const SEARCH_BUDGET: usize = 4_000;
/// The most candidate SOCs one state may have before the search gives up.
const CANDIDATE_CAP: usize = 4096;

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

struct Context<'a> {
    mech: &'a Mechanism,
    classes: DirectionClasses,
    primary: Vec<Instance>,
    check: Vec<Instance>,
    incidence: Vec<Vec<usize>>,
    rank_memo: HashMap<u64, usize>,
    evaluations: usize,
    /// Multiply-adds spent in rank computations so far (see [`MAX_ANALYSIS_WORK`]).
    work: u64,
    /// Local (idle) DOF of each sub-mechanism, by joint mask.
    idle_memo: HashMap<u64, usize>,
    /// Per primary instance: the velocity system of the whole mechanism and
    /// its kernel, used by several steps of the analysis.
    whole: Vec<(VelocitySystem, DMatrix<f64>)>,
    /// Per primary instance: the idle motions of the whole mechanism as joint
    /// rates (one row per joint variable, one column per idle DOF), and the
    /// rows of each joint.
    idle_rates: Vec<(DMatrix<f64>, Vec<std::ops::Range<usize>>)>,
}

impl Context<'_> {
    fn joint_mask(&self, joints: &[usize]) -> u64 {
        joints.iter().fold(0, |m, j| m | 1 << j)
    }

    /// Σf of the joints in `mask`, less the local (idle) DOF of that
    /// sub-mechanism: local DOF are not counted in f.
    fn f_of(&mut self, mask: u64) -> usize {
        let f: usize = (0..self.mech.joints.len())
            .filter(|j| mask >> j & 1 == 1)
            .map(|j| self.mech.joints[j].kind.dof())
            .sum();
        f - self.idle_of(mask).min(f)
    }

    /// The local DOF that sub-mechanism `mask` contains: the idle motions of
    /// the whole mechanism whose joint rates vanish outside it.
    fn idle_of(&mut self, mask: u64) -> usize {
        if let Some(&i) = self.idle_memo.get(&mask) {
            return i;
        }
        // The generic count is the least; none is below zero, so a
        // configuration that finds none settles it.
        let mut least: Option<usize> = None;
        for (rates, rows) in &self.idle_rates {
            let outside: Vec<usize> = (0..self.mech.joints.len())
                .filter(|j| mask >> j & 1 == 0)
                .flat_map(|j| rows[j].clone())
                .collect();
            let mut m = DMatrix::zeros(outside.len(), rates.ncols());
            for (r, &row) in outside.iter().enumerate() {
                m.set_row(r, &rates.row(row));
            }
            self.work += svd_work(m.nrows(), m.ncols());
            let idle = rates.ncols() - screw::rank_of_part(&m, screw::column_scale(rates)).min(rates.ncols());
            least = Some(least.map_or(idle, |l| l.min(idle)));
            if idle == 0 {
                break;
            }
        }
        let i = least.unwrap_or(0);
        self.idle_memo.insert(mask, i);
        i
    }

    /// Whether the ordering has spent its budget: [`SEARCH_BUDGET`]
    /// sub-mechanisms or [`MAX_ORDERING_WORK`] multiply-adds.
    fn over_budget(&self) -> bool {
        self.evaluations > SEARCH_BUDGET || self.work > MAX_ORDERING_WORK
    }

    fn actuators_of(&self, mask: u64) -> usize {
        (0..self.mech.joints.len())
            .filter(|j| mask >> j & 1 == 1 && self.mech.joints[*j].actuated)
            .count()
    }

    /// The generic rank of the loop equations of the joints in `mask`.
    fn loop_rank(&mut self, mask: u64) -> usize {
        if let Some(&r) = self.rank_memo.get(&mask) {
            return r;
        }
        self.evaluations += 1;
        // The generic rank is the largest; a configuration that reaches the
        // most the equations' shape allows settles it.
        let mut r = 0;
        for inst in &self.primary {
            let sys = VelocitySystem::new(self.mech, inst, mask);
            self.work += svd_work(sys.loops.nrows(), sys.loops.ncols());
            r = r.max(sys.loop_rank());
            if r >= sys.max_loop_rank() {
                break;
            }
        }
        self.rank_memo.insert(mask, r);
        r
    }

    /// Σf − Σξ − I of the sub-mechanism: the running sum of Δ.
    fn running(&mut self, mask: u64) -> i64 {
        self.f_of(mask) as i64 - self.loop_rank(mask) as i64 - self.actuators_of(mask) as i64
    }

    fn known_links(&self, mask: u64) -> u64 {
        let mut k = 1u64;
        for (j, joint) in self.mech.joints.iter().enumerate() {
            if mask >> j & 1 == 1 {
                k |= 1 << joint.links[0] | 1 << joint.links[1];
            }
        }
        k
    }

    /// Every SOC that can come next: a path of unused joints whose end links
    /// are known and whose inner links are new.
    fn candidates(&self, used: u64) -> Vec<Candidate> {
        let known = self.known_links(used);
        let mut out: Vec<Candidate> = Vec::new();
        let mut seen: Vec<u64> = Vec::new();
        for start in 0..self.mech.links.len() {
            if known >> start & 1 == 0 {
                continue;
            }
            let mut stack: Vec<(usize, Vec<usize>, u64)> = vec![(start, Vec::new(), 0)];
            while let Some((cur, path, inner)) = stack.pop() {
                for &j in self.incidence[cur].iter().rev() {
                    if used >> j & 1 == 1 || path.contains(&j) {
                        continue;
                    }
                    let o = self.mech.joints[j].other(cur);
                    let mut p = path.clone();
                    p.push(j);
                    if known >> o & 1 == 1 {
                        let m = self.joint_mask(&p);
                        if !seen.contains(&m) {
                            seen.push(m);
                            out.push((p, [start, o]));
                        }
                    } else if inner >> o & 1 == 0 && out.len() < CANDIDATE_CAP {
                        stack.push((o, p, inner | 1 << o));
                    }
                }
            }
        }
        out
    }
}

/// The multiply-adds of one singular value decomposition of an r × c matrix, roughly.
fn svd_work(r: usize, c: usize) -> u64 {
    (r * c * r.min(c)) as u64
}

/// The mask of all `n` joints (n ≤ 64).
fn all_joints(n: usize) -> u64 {
    if n == 64 {
        u64::MAX
    } else {
        (1u64 << n) - 1
    }
}

type Cost = (i64, i64);
/// A candidate SOC: its joints in path order and its two end links.
type Candidate = (Vec<usize>, [usize; 2]);

struct Search<'c, 'a> {
    ctx: &'c mut Context<'a>,
    all: u64,
    best: HashMap<u64, Option<(Cost, usize)>>,
    choices: HashMap<u64, Vec<Candidate>>,
    exhausted: bool,
}

impl Search<'_, '_> {
    /// The least (Σ|Δ|, −#SKC) that completes the decomposition from `used`.
    fn solve(&mut self, used: u64) -> Option<Cost> {
        if used == self.all {
            return Some((0, 0));
        }
        if let Some(b) = self.best.get(&used) {
            return b.map(|(c, _)| c);
        }
        if self.ctx.over_budget() {
            self.exhausted = true;
            return None;
        }
        let run_before = self.ctx.running(used);
        let cands = self.ctx.candidates(used);
        if cands.len() >= CANDIDATE_CAP {
            self.exhausted = true;
            return None;
        }
        let mut best: Option<(Cost, usize)> = None;
        for (i, (path, _)) in cands.iter().enumerate() {
            if self.ctx.over_budget() {
                self.exhausted = true;
                return None;
            }
            let next = used | self.ctx.joint_mask(path);
            let run_after = self.ctx.running(next);
            if run_after < 0 {
                continue;
            }
            let delta = run_after - run_before;
            let step = (delta.abs(), if run_after == 0 { -1 } else { 0 });
            if let Some(rest) = self.solve(next) {
                let total = (step.0 + rest.0, step.1 + rest.1);
                if best.is_none_or(|(b, _)| total < b) {
                    best = Some((total, i));
                }
            }
        }
        self.best.insert(used, best);
        self.choices.insert(used, cands);
        best.map(|(c, _)| c)
    }
}

/// A greedy ordering (least |Δ| at each step, first candidate on ties), if it
/// reaches the end with every Δ = 0.
fn greedy_order(ctx: &mut Context, all: u64) -> Option<Vec<Candidate>> {
    let mut used = 0u64;
    let mut order = Vec::new();
    while used != all {
        let run_before = ctx.running(used);
        let cands = ctx.candidates(used);
        let mut pick = None;
        for c in cands {
            // Out of budget: the search that follows stops at once and says so.
            if ctx.over_budget() {
                return None;
            }
            let next = used | ctx.joint_mask(&c.0);
            if ctx.running(next) == run_before && run_before == 0 {
                pick = Some(c);
                break;
            }
        }
        let c = pick?;
        used |= ctx.joint_mask(&c.0);
        order.push(c);
    }
    Some(order)
}

fn relation_symbol(ctx: &Context, a: usize, b: usize) -> &'static str {
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

fn notation(ctx: &Context, joints: &[usize]) -> String {
    let mut s = String::new();
    for (i, &j) in joints.iter().enumerate() {
        if i > 0 {
            s.push_str(relation_symbol(ctx, joints[i - 1], j));
        }
        s.push_str(&ctx.mech.joints[j].name);
    }
    s
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
    let mut ctx = context(mech)?;
    let n = mech.joints.len();
    let all = all_joints(n);
    let total_f = ctx.f_of(all);
    let total_rank = ctx.loop_rank(all);
    let dof = total_f - total_rank;
    let loops = n + 1 - mech.links.len();
    check_actuator_count(mech, dof, total_f, total_rank)?;
    check_actuators_drive(mech, &ctx, dof)?;
    let order = soc_order(mech, &mut ctx, all, loops)?;
    let socs = ordered_socs(&mut ctx, order);
    let (mut skcs, kappa) = sub_kinematic_chains(&socs);
    let xi_by_poc_formula = cross_check(mech, &ctx, &socs, total_f, dof)?;
    let joint_poc = (0..n).map(|j| joint_poc(mech, j)).collect();
    let Platform {
        platform_poc,
        base_point,
        branch_poc,
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
        platform_poc,
        base_point,
        decoupling,
        xi_by_poc_formula,
        expression,
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

/// The order of single open chains: greedy first, a step of least |Δ| each
/// time. If it reaches Σ|Δ| = 0 it is optimal (every Δ is 0, so every SOC
/// is its own SKC: the most SKCs); otherwise the bounded exhaustive search
/// for the least Σ|Δ|.
fn soc_order(mech: &Mechanism, ctx: &mut Context, all: u64, loops: usize) -> Result<Vec<Candidate>, Diagnostics> {
    Ok(match greedy_order(ctx, all) {
        Some(order) => order,
        None => {
            let mut search = Search {
                ctx,
                all,
                best: HashMap::new(),
                choices: HashMap::new(),
                exhausted: false,
            };
            let found = search.solve(0);
            let exhausted = search.exhausted;
            let Search { best, choices, .. } = search;
            if found.is_none() {
                let d = if exhausted {
                    Diagnostic::new(
                        mech.name_span(),
                        format!(
                            "the ordered SOC search gave up after {} sub-mechanisms and {:.1e} multiply-adds ({} loops); the limits are {SEARCH_BUDGET} and {MAX_ORDERING_WORK:.1e}",
                            ctx.evaluations, ctx.work as f64, loops
                        ),
                    )
                    .label("too many orderings to compare")
                    .note(
                        "no ordering was found whose Σ|Δ| is zero; the exhaustive search for the least Σ|Δ| is bounded",
                    )
                } else {
                    let first = mech
                        .joints
                        .iter()
                        .find(|j| j.actuated)
                        .map_or(mech.name_span(), |j| j.span);
                    Diagnostic::new(
                        first,
                        "no ordering of single open chains keeps every running Σ Δ non-negative: the actuators cannot drive this mechanism",
                    )
                    .label("actuated here")
                };
                return Err(d.into());
            }
            let mut order = Vec::new();
            let mut used = 0u64;
            while used != all {
                let (_, i) = best[&used].expect("a solved state has a choice");
                let c = choices[&used][i].clone();
                used |= ctx.joint_mask(&c.0);
                order.push(c);
            }
            order
        }
    })
}

/// The SOCs of the chosen order, with their ξ_L and Δ.
fn ordered_socs(ctx: &mut Context, order: Vec<Candidate>) -> Vec<Soc> {
    let mut socs = Vec::new();
    let mut used = 0u64;
    let mut run_before = 0i64;
    for (mut path, mut ends) in order {
        // Write a chain that ends on the base from its other end, as the papers do.
        if ends[0] == 0 && ends[1] != 0 {
            path.reverse();
            ends = [ends[1], ends[0]];
        }
        let mask = ctx.joint_mask(&path);
        let xi = ctx.loop_rank(used | mask) - ctx.loop_rank(used);
        let run_after = ctx.running(used | mask);
        socs.push(Soc {
            dof: ctx.f_of(mask),
            actuators: ctx.actuators_of(mask),
            xi,
            delta: (run_after - run_before) as i32,
            notation: notation(ctx, &path),
            joints: path,
            ends,
        });
        used |= mask;
        run_before = run_after;
    }
    socs
}

/// The SKCs: the SOCs grouped where the running Σ Δ returns to zero, each
/// with its coupling degree κ = Σ|Δ|/2; and the mechanism's κ, the largest.
fn sub_kinematic_chains(socs: &[Soc]) -> (Vec<Skc>, usize) {
    let mut skcs = Vec::new();
    let mut start = 0;
    let mut run = 0;
    for (j, soc) in socs.iter().enumerate() {
        run += soc.delta;
        if run == 0 {
            let kappa = socs[start..=j]
                .iter()
                .map(|s| s.delta.unsigned_abs() as usize)
                .sum::<usize>()
                / 2;
            skcs.push(Skc {
                socs: start..j + 1,
                kappa,
                kind: None,
            });
            start = j + 1;
        }
    }
    let kappa = skcs.iter().map(|s| s.kappa).max().unwrap_or(0);
    (skcs, kappa)
}

/// ξ_L by the POC formula at independent configurations must equal ξ_L by
/// the loop-closure rank, and F must be Σf − Σξ_L by both.
fn cross_check(
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

/// What the topology says of the platform.
struct Platform {
    platform_poc: Option<PocSet>,
    base_point: Option<usize>,
    branch_poc: Vec<PocSet>,
    decoupling: Vec<Dependence>,
}

/// The platform's POC set at its base point (the platform joint whose POC
/// set has the fewest translations, or the declared one), each branch's
/// POC set at that point, and the outputs' motion decoupling.
fn platform_characteristics(mech: &Mechanism, ctx: &Context) -> Platform {
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

fn context(mech: &Mechanism) -> Result<Context<'_>, Diagnostics> {
    let classes = DirectionClasses::new(&mech.joints, &mech.relations);
    let realize = |seeds: &[u64]| -> Result<Vec<Instance>, Diagnostic> {
        seeds.iter().map(|&s| screw::realize(mech, &classes, s)).collect()
    };
    let primary = realize(&PRIMARY_SEEDS)?;
    let check = realize(&CHECK_SEEDS)?;
    let whole: Vec<(VelocitySystem, DMatrix<f64>)> = primary
        .iter()
        .map(|inst| {
            let sys = VelocitySystem::new(mech, inst, all_joints(mech.joints.len()));
            let kernel = sys.kernel();
            (sys, kernel)
        })
        .collect();
    let idle_rates = primary
        .iter()
        .zip(&whole)
        .map(|(inst, (sys, kernel))| idle_motions(mech, inst, sys, kernel))
        .collect();
    Ok(Context {
        whole,
        idle_rates,
        mech,
        incidence: mech.incidence(),
        classes,
        primary,
        check,
        rank_memo: HashMap::new(),
        evaluations: 0,
        work: 0,
        idle_memo: HashMap::new(),
    })
}

/// The idle (local) motions of the whole mechanism at one instance: motions
/// in which no R, H, C, U or S joint's point moves (seen from either of its
/// links) and no P joint slides, such as the spin of an S–S link or of an
/// S–P–S leg about the line of its centres. Returned as joint rates, with the
/// rows of each joint.
fn idle_motions(
    mech: &Mechanism,
    inst: &Instance,
    sys: &VelocitySystem,
    kernel: &DMatrix<f64>,
) -> (DMatrix<f64>, Vec<std::ops::Range<usize>>) {
    let k = kernel.ncols();
    let mut conditions: Vec<DMatrix<f64>> = Vec::new();
    for (j, joint) in mech.joints.iter().enumerate() {
        let c = sys.joint_col[j].expect("every joint is in the system");
        if joint.kind == JointKind::P {
            conditions.push(kernel.rows(c, 1).into_owned());
            continue;
        }
        for &link in &joint.links {
            let t = sys.relative_twists(kernel, 0, link);
            conditions.push(screw::at_point(&t, &inst.points[j]).1);
        }
    }
    let total: usize = conditions.iter().map(|m| m.nrows()).sum();
    let mut rows = DMatrix::zeros(total, k);
    let mut r = 0;
    for m in &conditions {
        rows.view_mut((r, 0), (m.nrows(), k)).copy_from(m);
        r += m.nrows();
    }
    let z = if k == 0 {
        DMatrix::zeros(0, 0)
    } else {
        screw::null_space(&rows)
    };
    let motions = kernel * &z;
    let mut ranges = Vec::new();
    let mut rates = DMatrix::zeros(mech.total_dof(), z.ncols());
    let mut next = 0;
    for (j, joint) in mech.joints.iter().enumerate() {
        let c = sys.joint_col[j].expect("every joint is in the system");
        let f = joint.kind.dof();
        if z.ncols() > 0 {
            rates.view_mut((next, 0), (f, z.ncols())).copy_from(&motions.rows(c, f));
        }
        ranges.push(next..next + f);
        next += f;
    }
    (rates, ranges)
}

/// ξ_Lj and Δ_j of a given ordering of SOCs (each a list of joint names), for
/// studying orderings other than the chosen one.
pub fn evaluate_order(mech: &Mechanism, order: &[&[&str]]) -> Result<Vec<(usize, i32)>, Diagnostics> {
    let mut ctx = context(mech)?;
    let mut used = 0u64;
    let mut out = Vec::new();
    for soc in order {
        let mut mask = 0u64;
        for name in *soc {
            let j = mech
                .joint_index(name)
                .ok_or_else(|| Diagnostic::global(format!("unknown joint `{name}`")))?;
            mask |= 1 << j;
        }
        let xi = ctx.loop_rank(used | mask) - ctx.loop_rank(used);
        let delta = ctx.f_of(mask) as i64 - ctx.actuators_of(mask) as i64 - xi as i64;
        out.push((xi, delta as i32));
        used |= mask;
    }
    Ok(out)
}

fn poc_formula_xi(ctx: &Context, socs: &[Soc]) -> Vec<usize> {
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

fn joint_poc(mech: &Mechanism, j: usize) -> PocSet {
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

/// Names the directions of twist subspaces in the theory's words.
struct Labeller<'a> {
    ctx: &'a Context<'a>,
    /// Joints with a direction, most preferred first (nearest the subject link, then latest declared).
    preferred: Vec<usize>,
}

const FRAME_PLANES: [&str; 3] = ["yoz", "xoz", "xoy"];
const FRAME_AXIS_NAMES: [&str; 3] = ["x", "y", "z"];

impl<'a> Labeller<'a> {
    fn new(ctx: &'a Context<'a>, subject: Option<usize>, scope: Option<&[usize]>) -> Self {
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

    fn dir(&self, item: DirectionItem) -> Vector3<f64> {
        let inst = &self.ctx.primary[0];
        self.ctx
            .classes
            .index(item)
            .map_or_else(Vector3::zeros, |i| inst.directions[i])
    }

    fn poc(&self, twists: &DMatrix<f64>, o: &Vector3<f64>) -> PocSet {
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
    fn names(&self, rotation: bool) -> Vec<(String, Vector3<f64>)> {
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

    fn label(&self, basis: &[Vector3<f64>], rotation: bool) -> Option<String> {
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
    fn order_of(&self, name: &str) -> usize {
        FRAME_AXIS_NAMES
            .iter()
            .position(|a| *a == name)
            .unwrap_or_else(|| 3 + self.ctx.mech.joint_index(name).unwrap_or(usize::MAX - 3))
    }
}

fn motion_decoupling(ctx: &Context, platform: usize, base_point: Option<usize>) -> Vec<Dependence> {
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
fn input_rows(mech: &Mechanism, sys: &VelocitySystem, kernel: &DMatrix<f64>) -> DMatrix<f64> {
    let actuated: Vec<usize> = (0..mech.joints.len()).filter(|&j| mech.joints[j].actuated).collect();
    let mut input = DMatrix::zeros(actuated.len(), kernel.ncols());
    for (r, &j) in actuated.iter().enumerate() {
        if let Some(c) = sys.joint_col[j] {
            input.set_row(r, &kernel.row(c));
        }
    }
    input
}

fn skc_kind(mech: &Mechanism, socs: &[Soc], branch_poc: &[PocSet]) -> Option<String> {
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

fn kind_sup(kind: &str) -> String {
    kind.chars()
        .map(|c| match c {
            'T' => 'ᵀ',
            'R' => 'ᴿ',
            c => c.to_digit(10).map_or(c, |d| SUPERSCRIPT[d as usize]),
        })
        .collect()
}

fn expression(
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

/// A Δ written the papers' way (`+1`, `0`, `−1`).
pub fn delta_unicode(d: i32) -> String {
    signed(d)
}

#[cfg(test)]
mod tests {
    use super::to_ascii;

    /// (F, ξ, Δ, κ, platform POC) of a mechanism text, against a hand count.
    fn check(source: &str, dof: usize, xi: &[usize], delta: &[i32], kappa: usize, poc: Option<&str>) {
        let a = crate::topology::analysis::analyze_source(source).unwrap_or_else(|e| panic!("{}", e.render(source, "t")));
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
            let e =
                crate::topology::analysis::analyze_source(&format!("mechanism m {{ {chain} R6 ⊥ R1; R6 ⊥ R2; R6 ⊥ R3; }}")).unwrap_err();
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
