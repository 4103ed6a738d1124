//! Generated inverse dynamics (capability `dynamics`): Newton–Euler over
//! the ordered SKCs, as `pkm_runtime::newton_euler` computes it, written
//! out for one mechanism.
//!
//! The forward solution runs on symbols; every link's velocity and
//! acceleration are its pose's exact time derivatives through the trace
//! (no loop-closure velocity equations are solved), its inertial wrench
//! and the joints' unit twists follow, and each SKC's reaction equations
//! are written out as entries of a fixed-size matrix. At run time the
//! SKCs are solved in reverse order on the stack, each reduced to its cut
//! joints' reactions: a lower bound from the reduced matrix's inverse (or
//! its passive rows' triangular factor's), or nearer a change point its
//! singular values, give the kinematic conditioning, which refuses an
//! answer next to a change point
//! that would keep fewer than six digits
//! ([`pkm_runtime::force_system::near_change_point`]); then a determined
//! system by its reduced matrix's inverse, an overconstrained one by the minimum-norm
//! solve of its reduction, and the whole system's singular value
//! decomposition ([`pkm_runtime::force_system::min_norm`]) is the way out
//! where neither serves. Every link's balance is verified.
//!
//! This file traces the terms; `dynamics_solve.rs` writes the run-time
//! function that fills, solves and checks the SKCs' systems.

#[path = "dynamics_solve.rs"]
mod solve;
pub(super) use solve::{functions, items};

use super::{sym, sym3, Branch, Direction};
use crate::analysis::Analysis;
use crate::mass_and_loads::Inertia;
use crate::trace::Sym;
use pkm_runtime::frame::Frame;
use pkm_runtime::model::{JointType, Place};
use pkm_runtime::scalar::{cross, unit, Scalar};
use pkm_runtime::skc_reactions::{
    self, Assembly, Carried, CentroidMotion, Demands, Layout, Load, MovingBody, PassiveRow,
};
use pkm_runtime::steps::{Geometry, JointValue};
use pkm_runtime::velocity::{unit_twists, Screw};

/// The most unknowns one SKC's reaction system may have: nalgebra
/// decomposes fixed-size matrices up to 127 × 127.
pub const MAX_SKC_UNKNOWNS: usize = 127;

/// A number the generated function reads: a literal, or a term it computes.
#[derive(Debug, Clone, Copy)]
enum Term {
    Const(f64),
    At(usize),
}

/// One SKC's reaction system: `a x = b` with `x` its joints' reactions
/// (d numbers each, moments over the size).
struct Skc {
    joints: Vec<usize>,
    undetermined: usize,
    rows: usize,
    /// The nonzero entries of `a`.
    entries: Vec<(usize, usize, Term)>,
    /// `b` without the reactions of later SKCs' joints.
    rhs: Vec<Term>,
    /// `b[row] −= sign · x_joint[c]` for those reactions: (row, joint, c, sign).
    known: Vec<(usize, usize, usize, f64)>,
    /// Per actuator twist, its coefficients against the unknowns.
    actuated: Vec<Vec<(usize, Term)>>,
    /// The system reduced to the cut joints' reactions, where it has no
    /// more passive rows than those unknowns.
    reduction: Option<Reduction>,
}

/// An SKC's system reduced to its cut joints' reactions `y` (the spanning
/// tree of its links carries the rest): `x = x0 + C y`, where a tree
/// joint's `x0` is the signed sum of its subtree's right-hand sides and
/// `C` is ±1 where a cut joint crosses that subtree; the passive rows
/// become `G y = q` with `q = rhs − P x0`.
struct Reduction {
    /// Per joint (its position in the SKC): for a tree joint its sign and
    /// its subtree's link rows; `None` for a cut joint.
    tree: Vec<Option<(f64, Vec<usize>)>>,
    /// `C` per joint and cut joint (the cut joints' order).
    coef: Vec<Vec<f64>>,
    /// The cut joints' positions.
    cuts: Vec<usize>,
    /// Per passive row: its joint's position, its coefficients (d), its right-hand side.
    passive: Vec<(usize, Vec<Term>, Term)>,
    /// `G`'s entries (row, column, value), columns `cut · d + component`.
    g: Vec<(usize, usize, Term)>,
}

/// The dynamics of one mechanism in terms of the forward solution.
pub(super) struct Traced {
    /// What the terms function returns, in order.
    terms: Vec<Sym>,
    /// Numbers per wrench: 3 planar, 6 spatial.
    d: usize,
    /// Where a wrench turns from forces to moments ([`Layout::moments_from`]).
    moments_from: usize,
    skcs: Vec<Skc>,
    /// The SKC and the column where each joint's reaction starts.
    place: Vec<(usize, usize)>,
    /// Each joint's point (where its moment is given).
    points: Vec<[Term; 3]>,
    /// Per actuator (input order): the joint, its twist's power
    /// coefficients, and the work of its bars (a parallelogram's).
    actuators: Vec<(usize, Vec<Term>, Term)>,
    /// Per moving link, its balance.
    balances: Vec<Balance>,
    /// Bodies whose mass properties come through the parameters.
    bodies: Vec<Body>,
    /// Bodies and loads on S–S links, checked against the idle spin.
    spins: Vec<Spin>,
    /// The mechanism's size: moments are solved over it.
    size: Term,
    /// The file's length unit in metres: results come back to N and N·L by it.
    metres: f64,
}

/// Collects the terms, each once (constants stay literals), and the
/// bodies whose mass properties they hold.
#[derive(Default)]
struct Terms {
    list: Vec<Sym>,
    index: std::collections::HashMap<Sym, usize>,
    bodies: Vec<Body>,
    spins: Vec<Spin>,
}

/// A body or a load on an S–S link, checked at run time not to depend on
/// the link's idle spin (`mass_properties::idle_spin_problem` and
/// `idle_spin_load_problem`): the link's name, the line's point and unit
/// direction (link frame), and the body's centroid and inertia (row-major)
/// or the load's point and moment.
enum Spin {
    Body(String, [Term; 3], [Term; 3], [Term; 3], [Term; 9]),
    Load(String, [Term; 3], [Term; 3], [Term; 3], [Term; 3]),
}

/// The line an S–S link turns freely about, in its frame
/// ([`skc_reactions::idle_spin_line`], as the runtime takes it).
fn idle_spin_line(g: &Geometry<Sym>, link: usize) -> Option<([Sym; 3], [Sym; 3])> {
    skc_reactions::idle_spin_line(g.joints.iter().map(|j| (j.kind, j.links, j.places)), link)
}

impl Terms {
    /// A body whose mass or inertia the parameters give is checked at
    /// run time: its terms are kept.
    fn check_body(&mut self, name: String, mass: Sym, inertia: &Inertia) {
        let moments = moments_of(inertia);
        if std::iter::once(&mass)
            .chain(&moments)
            .any(|s| crate::trace::constant_of(*s).is_none())
        {
            let mass = self.of(mass);
            let moments = moments.into_iter().map(|s| self.of(s)).collect();
            self.bodies.push((name, mass, moments));
        }
    }

    fn of(&mut self, s: Sym) -> Term {
        match crate::trace::constant_of(s) {
            Some(c) => Term::Const(c),
            None => Term::At(*self.index.entry(s).or_insert_with(|| {
                self.list.push(s);
                self.list.len() - 1
            })),
        }
    }
}

/// A body whose mass properties the parameters give: its name, its mass,
/// its moments as declared (checked at run time).
type Body = (String, Term, Vec<Term>);

/// One link's balance: its demand's components, and the joints acting on
/// it with their signs.
struct Balance {
    need: Vec<Term>,
    on: Vec<(usize, f64)>,
}

/// The angular velocity of a frame whose rotation is `r` and its rate `rd`: `[ω]× = Ṙ Rᵀ`.
fn angular(r: &[[Sym; 3]; 3], rd: &[[Sym; 3]; 3]) -> [Sym; 3] {
    let e = |i: usize, j: usize| (0..3).map(|k| rd[i][k] * r[j][k]).fold(Sym::c(0.0), |a, x| a + x);
    [e(2, 1), e(0, 2), e(1, 0)]
}

fn flat(r: &[[Sym; 3]; 3]) -> Vec<Sym> {
    r.iter().flatten().copied().collect()
}

fn unflat(v: &[Sym]) -> [[Sym; 3]; 3] {
    [[v[0], v[1], v[2]], [v[3], v[4], v[5]], [v[6], v[7], v[8]]]
}

/// How a body at `pose` with its centroid at `c` (its frame) moves: its
/// angular velocity and acceleration and its centroid's acceleration, the
/// exact time derivatives of the pose through the trace, first and second
/// in one pass ([`crate::trace::second_derivatives`]): `[ω]× = Ṙ Rᵀ`, and
/// α read from its derivative `R̈ Rᵀ + Ṙ Ṙᵀ` as ω is from `Ṙ Rᵀ`.
fn traced_motion(pose: &Frame<Sym>, c: [Sym; 3]) -> CentroidMotion<Sym> {
    let r = pose.r;
    let centroid = pose.apply(c);
    let mut roots = flat(&r);
    roots.extend(centroid);
    let (first, second) = crate::trace::second_derivatives(&roots, &Sym::rate, &Sym::accel);
    let (rd, rdd) = (unflat(&first[..9]), unflat(&second[..9]));
    let w = angular(&r, &rd);
    let (along, turning) = (angular(&r, &rdd), angular(&rd, &rd));
    let alpha: [Sym; 3] = std::array::from_fn(|i| along[i] + turning[i]);
    let a_c: [Sym; 3] = std::array::from_fn(|i| second[9 + i]);
    CentroidMotion { w, alpha, a_c }
}

/// The inertia tensor of a declared inertia, in kg·L².
fn inertia_of(i: &Inertia, k: Sym) -> [[Sym; 3]; 3] {
    let z = Sym::c(0.0);
    match i {
        Inertia::Point => [[z; 3]; 3],
        Inertia::Planar(e) => [[z, z, z], [z, z, z], [z, z, sym(e) * k]],
        Inertia::Principal(e) => {
            let [x, y, zz] = [0, 1, 2].map(|i| sym(&e[i]) * k);
            [[x, z, z], [z, y, z], [z, z, zz]]
        }
        Inertia::Full(e) => {
            let [xx, yy, zz, xy, xz, yz] = std::array::from_fn(|i| sym(&e[i]) * k);
            [[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]
        }
    }
}

/// The moments as declared (what `inertia_problem` reads), in kg·L².
fn moments_of(i: &Inertia) -> Vec<Sym> {
    match i {
        Inertia::Point => vec![Sym::c(0.0); 3],
        Inertia::Planar(e) => vec![sym(e)],
        Inertia::Principal(e) => e.iter().map(sym).collect(),
        Inertia::Full(e) => e.iter().map(sym).collect(),
    }
}

/// What each link's joints must supply ([`skc_reactions::demands`]: its
/// bodies' inertial wrenches less gravity, less the loads on it, about the
/// base origin), and the bodies whose mass properties the parameters give
/// and those on S–S links (to check at run time).
fn demands(
    a: &Analysis,
    g: &Geometry<Sym>,
    b: &Branch,
    w: &Layout<Sym>,
    twists: &[Vec<Vec<Sym>>],
    terms: &mut Terms,
) -> Result<Demands<Sym>, String> {
    let m = &a.mechanism;
    let ml = &a.mass_and_loads;
    let units = ml.units.ok_or("dynamics needs the file's units")?;
    let kg = Sym::c(units.mass.kilograms());
    // Gravity and loads in L/s² and kg·L/s².
    let per_metre = Sym::c(1.0 / units.length.metres());
    let gravity: [Sym; 3] = match &ml.gravity_declared {
        Some(e) => sym3(e),
        None => ml.gravity.map(Sym::c),
    }
    .map(|x| x * per_metre);
    let lines: Vec<Option<([Sym; 3], [Sym; 3])>> = (0..m.links.len()).map(|l| idle_spin_line(g, l)).collect();
    let mut bodies = Vec::new();
    for body in &ml.masses {
        let mass = sym(&body.mass_expr);
        let name = &m.links[body.link].name;
        // An S–S link's idle spin does no work: its body is checked at run
        // time, its moment about the line dropped in the demand.
        if let Some((point, axis)) = lines[body.link] {
            let all = |x: [Sym; 3], t: &mut Terms| x.map(|s| t.of(s));
            let declared = inertia_of(&body.inertia, Sym::c(1.0));
            let row_major = std::array::from_fn(|k| terms.of(declared[k / 3][k % 3]));
            let check = Spin::Body(
                name.clone(),
                all(point, terms),
                all(axis, terms),
                all(sym3(&body.centroid), terms),
                row_major,
            );
            terms.spins.push(check);
        }
        let pose = b.poses[body.link];
        let centroid = sym3(&body.centroid);
        bodies.push(MovingBody {
            on: Carried::Link(body.link),
            pose,
            motion: traced_motion(&pose, centroid),
            mass: mass * kg,
            centroid,
            inertia: inertia_of(&body.inertia, kg),
        });
        terms.check_body(m.links[body.link].name.clone(), mass, &body.inertia);
    }
    for bar in &ml.bars {
        let j = bar.joint;
        let jg = &g.joints[j];
        let Some((side, axis)) = (0..2).find_map(|side| match jg.places[side] {
            Place::Arm { axis, .. } => Some((side, unit(axis))),
            _ => None,
        }) else {
            return Err(format!("a bar of joint {}, which has no arm", m.joints[j].name));
        };
        let carrier = jg.links[side];
        let (c, s) = match b.states[j] {
            Some(JointValue::Turn(c, s, _)) => (c, s),
            Some(JointValue::Slide(t)) => (t.cos(), t.sin()),
            None => return Err(format!("no value for joint {}", m.joints[j].name)),
        };
        // The bar's frame: the carrier's turned by the value about the hinge axis.
        let hinge = sym3(&bar.hinge);
        let turn = Frame {
            t: hinge,
            ..Frame::about(axis, c, s)
        };
        let pose = b.poses[carrier].then(&turn);
        let mass = sym(&bar.mass_expr);
        let centroid = sym3(&bar.centroid);
        // Its unit twist relative to the carrier: the turn about the hinge axis.
        let omega = b.poses[carrier].rotate(axis);
        let xi = Screw {
            w: omega,
            v: cross(pose.t, omega),
        };
        bodies.push(MovingBody {
            on: Carried::Bar { joint: j, carrier, xi },
            pose,
            motion: traced_motion(&pose, centroid),
            mass: mass * kg,
            centroid,
            inertia: inertia_of(&bar.inertia, kg),
        });
        terms.check_body(format!("{}'s bar", m.joints[j].name), mass, &bar.inertia);
    }
    let mut loads = Vec::new();
    for load in &ml.loads {
        let at = match load.at {
            Some(point) => g.local(point, load.link),
            None => [Sym::c(0.0); 3],
        };
        if let Some((point, axis)) = lines[load.link] {
            let all = |x: [Sym; 3], t: &mut Terms| x.map(|s| t.of(s));
            let check = Spin::Load(
                m.links[load.link].name.clone(),
                all(point, terms),
                all(axis, terms),
                all(at, terms),
                all(sym3(&load.moment), terms),
            );
            terms.spins.push(check);
        }
        loads.push(Load {
            link: load.link,
            at: b.poses[load.link].apply(at),
            force: sym3(&load.force).map(|x| x * per_metre),
            moment: sym3(&load.moment).map(|x| x * per_metre),
        });
    }
    let first: Vec<usize> = g.joints.iter().map(|j| j.links[0]).collect();
    Ok(skc_reactions::demands(
        w,
        m.links.len(),
        &first,
        &lines,
        twists,
        &bodies,
        &loads,
        gravity,
    ))
}

/// SKC `k`'s reaction system ([`Assembly::system`]) as terms, its
/// reduction to its cut joints where it has one.
fn skc_system(
    k: usize,
    skc: &pkm_runtime::newton_euler::SkcParts,
    x: &Assembly<'_, Sym>,
    terms: &mut Terms,
) -> Result<Skc, String> {
    let s = x.system(k, skc);
    if s.rows.max(s.unknowns) > MAX_SKC_UNKNOWNS {
        return Err(format!(
            "SKC {} has a reaction system of {} × {}; the generated inverse dynamics solves at most {MAX_SKC_UNKNOWNS} × {MAX_SKC_UNKNOWNS}",
            k + 1,
            s.rows,
            s.unknowns
        ));
    }
    // The terms in the system's order: the links' right-hand sides, then
    // joint by joint its twists' coefficients (and a passive row's
    // right-hand side).
    let link_rows = skc.links.len() * x.layout.d();
    let (mut active, mut passive) = (s.actuated.iter(), s.passive.iter());
    let mut actuated = Vec::new();
    let mut rows = Vec::new();
    let mut rhs: Vec<Term> = s.rhs[..link_rows].iter().map(|v| terms.of(*v)).collect();
    for &j in &skc.joints {
        for _ in &x.twists[j] {
            if x.actuated[j] {
                let row = active.next().expect("an actuated row per twist");
                actuated.push(row.iter().map(|&(c, v)| (c, terms.of(v))).collect());
            } else {
                let row = passive.next().expect("a passive row per twist");
                let coefficients: Vec<Term> = row.coefficients.iter().map(|v| terms.of(*v)).collect();
                let right = terms.of(row.rhs);
                rhs.push(right);
                rows.push((row.at, coefficients, right));
            }
        }
    }
    let entries = s.entries.iter().map(|&(r, c, v)| (r, c, terms.of(v))).collect();
    let reduction = reduce(skc, x, &s.passive, &rows, terms);
    Ok(Skc {
        joints: skc.joints.clone(),
        undetermined: skc.undetermined,
        rows: s.rows,
        entries,
        rhs,
        known: s.known,
        actuated,
        reduction,
    })
}

/// The reduction of an SKC's system to its cut joints ([`Reduction`]):
/// the runtime's spanning tree ([`Assembly::tree`], which the runtime's
/// Newton–Euler reads too), with `G`'s entries as terms; `rows` are the
/// passive rows as terms. `None` where the tree does not reach every link
/// or the passive rows outnumber the cut joints' unknowns.
fn reduce(
    skc: &pkm_runtime::newton_euler::SkcParts,
    x: &Assembly<'_, Sym>,
    passive: &[PassiveRow<Sym>],
    rows: &[(usize, Vec<Term>, Term)],
    terms: &mut Terms,
) -> Option<Reduction> {
    let tree = x.tree(skc, passive.len())?;
    let at: Vec<usize> = passive.iter().map(|p| p.at).collect();
    let g = tree
        .g_entries(&at, x.layout.d())
        .map(|(r, column, c, factor)| (r, column, terms.of(passive[r].coefficients[c] * Sym::c(factor))))
        .collect();
    Some(Reduction {
        tree: tree.tree,
        coef: tree.coef,
        cuts: tree.cuts,
        passive: rows.to_vec(),
        g,
    })
}

/// Traces the inverse dynamics on the forward solution's branch `b` of `plan`.
pub(super) fn trace(
    a: &Analysis,
    g: &Geometry<Sym>,
    plan: &pkm_runtime::plan::Plan,
    b: &Branch,
) -> Result<Traced, String> {
    let m = &a.mechanism;
    let metres = a
        .mass_and_loads
        .units
        .ok_or("dynamics needs the file's units")?
        .length
        .metres();
    let w = Layout {
        planar: m.planar,
        size: g.scale(),
    };
    let d = w.d();
    let mut terms = Terms::default();
    let size = terms.of(w.size);
    // Every joint's unit twists, as power coefficients against (f, m).
    let twists: Vec<Vec<Vec<Sym>>> = g
        .joints
        .iter()
        .enumerate()
        .map(|(j, jg)| {
            unit_twists(jg, b.states[j], &b.poses[jg.links[0]])
                .iter()
                .map(|t| w.coefficients(t))
                .collect()
        })
        .collect();
    let demands = demands(a, g, b, &w, &twists, &mut terms)?;
    let parts = crate::numeric::skc_parts(a);
    let place = skc_reactions::places(&parts, m.joints.len(), d).ok_or("a joint is in no SKC")?;
    let links: Vec<[usize; 2]> = g.joints.iter().map(|j| j.links).collect();
    let kinds: Vec<JointType> = g.joints.iter().map(|j| j.kind).collect();
    let actuated: Vec<bool> = m.joints.iter().map(|j| j.actuated).collect();
    let assembly = Assembly {
        layout: &w,
        links: &links,
        kinds: &kinds,
        actuated: &actuated,
        twists: &twists,
        demands: &demands,
        place: &place,
    };
    let skcs = parts
        .iter()
        .enumerate()
        .map(|(k, skc)| skc_system(k, skc, &assembly, &mut terms))
        .collect::<Result<Vec<_>, _>>()?;
    let points = (0..m.joints.len())
        .map(|j| {
            let jg = &g.joints[j];
            // A P joint's point is its slider's (`Joint::point_side`).
            let side = usize::from(matches!(jg.places[0], Place::Line { .. }));
            let p = b.poses[jg.links[side]].apply(jg.places[side].at());
            p.map(|x| terms.of(x))
        })
        .collect();
    // The inputs in the plan's order, as `Plan::input_joints` takes them.
    let input_joints: Vec<usize> = if plan.inputs.len() == plan.n_inputs {
        plan.inputs.clone()
    } else {
        (0..m.joints.len()).filter(|&j| actuated[j]).collect()
    };
    // An actuated parallelogram also drives its bars.
    let actuators = input_joints
        .iter()
        .map(|&j| {
            (
                j,
                twists[j][0].iter().map(|x| terms.of(*x)).collect(),
                terms.of(demands.bar_work[j]),
            )
        })
        .collect();
    let balances = (1..m.links.len())
        .map(|l| {
            let (need, on) = assembly.balance(l);
            Balance {
                need: need.into_iter().map(|x| terms.of(x)).collect(),
                on,
            }
        })
        .collect();
    Ok(Traced {
        terms: terms.list,
        bodies: terms.bodies,
        spins: terms.spins,
        d,
        moments_from: w.moments_from(),
        skcs,
        place,
        points,
        actuators,
        balances,
        size,
        metres,
    })
}
