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
//! joints' reactions: the reduced matrix's singular values give the
//! kinematic conditioning, which refuses an answer next to a change point
//! that would keep fewer than six digits
//! ([`pkm_runtime::force_system::near_change_point`]); then a determined
//! system by its reduced matrix's inverse, an overconstrained one by the minimum-norm
//! solve of its reduction, and the whole system's singular value
//! decomposition ([`pkm_runtime::force_system::min_norm`]) is the way out
//! where neither serves. Every link's balance is verified.

use super::{sym, sym3, Branch, Direction};
use crate::analysis::Analysis;
use crate::emit::{lit, Emit};
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
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

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

/// `sign · x` for a sign ±1.
fn signed(sign: f64, x: TokenStream) -> TokenStream {
    if sign < 0.0 {
        quote! { -#x }
    } else {
        x
    }
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

/// The time derivative along the given values' rates.
fn rate(x: &[Sym]) -> Vec<Sym> {
    crate::trace::derivative(x, &Sym::rate)
}

/// The derivative along the given values' accelerations (the part of a
/// second derivative linear in them).
fn along_accelerations(x: &[Sym]) -> Vec<Sym> {
    crate::trace::derivative(x, &Sym::accel)
}

/// How a body at `pose` with its centroid at `c` (its frame) moves: its
/// angular velocity and acceleration and its centroid's acceleration, the
/// exact time derivatives of the pose through the trace (`[ω]× = Ṙ Rᵀ`;
/// α = ∂ω/∂q·q̇ + ∂ω/∂q̇·q̈, the latter ω with q̈ for q̇).
fn traced_motion(pose: &Frame<Sym>, c: [Sym; 3]) -> CentroidMotion<Sym> {
    let r = pose.r;
    let rd = unflat(&rate(&flat(&r)));
    let w = angular(&r, &rd);
    let dw = rate(&w);
    let w_acc = angular(&r, &unflat(&along_accelerations(&flat(&r))));
    let alpha: [Sym; 3] = std::array::from_fn(|i| dw[i] + w_acc[i]);
    let centroid = pose.apply(c);
    let v = rate(&centroid);
    let curvature = rate(&v);
    let along = along_accelerations(&centroid);
    let a_c: [Sym; 3] = std::array::from_fn(|i| curvature[i] + along[i]);
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

/// The generated functions: the terms (straight-line, verified like the
/// forward solution) and `inverse_dynamics`, which solves the SKCs.
pub(super) fn functions(
    ident: &proc_macro2::Ident,
    emit: &Emit,
    d: &Direction,
    t: &Traced,
    given_sig: &TokenStream,
    finite: &TokenStream,
    check_of: &dyn Fn(&[TokenStream]) -> TokenStream,
) -> TokenStream {
    let n_terms = t.terms.len();
    let mut roots = t.terms.clone();
    roots.extend(&d.given.residual);
    roots.push(d.given.extent);
    let (lets, exprs) = emit.straight(&roots, &emit.needed_guards(&roots, &d.given.guards, &d.given.waivable));
    let (values, rest) = exprs.split_at(n_terms);
    let check = check_of(rest);
    let (n_given, n_choices) = (d.plan.n_inputs, d.plan.branches);
    let rt = quote! { ::pkm::runtime::__private };
    let body_checks = t.bodies.iter().map(|(name, mass, moments)| {
        let (mass, moments) = (term(mass), moments.iter().map(term));
        quote! {
            if let ::core::option::Option::Some(problem) = #rt::mass_properties::body_problem(#mass, &[#(#moments),*]) {
                return ::core::result::Result::Err(#rt::newton_euler::DynamicsError::MassProperties { body: ::std::borrow::Cow::Borrowed(#name), problem });
            }
        }
    });
    let spin_checks = t.spins.iter().map(|spin| {
        let v3 = |x: &[Term; 3]| {
            let [a, b, c] = x.each_ref().map(term);
            quote! { &#rt::nalgebra::Vector3::new(#a, #b, #c) }
        };
        let (name, call) = match spin {
            Spin::Body(name, point, axis, centroid, inertia) => {
                let (point, axis, centroid) = (v3(point), v3(axis), v3(centroid));
                let inertia = inertia.iter().map(term);
                (
                    name,
                    quote! { #rt::mass_properties::idle_spin_problem(#centroid, &#rt::nalgebra::Matrix3::new(#(#inertia),*), #point, #axis, size) },
                )
            }
            Spin::Load(name, point, axis, at, moment) => {
                let (point, axis, at, moment) = (v3(point), v3(axis), v3(at), v3(moment));
                (
                    name,
                    quote! { #rt::mass_properties::idle_spin_load_problem(#at, #moment, #point, #axis, size) },
                )
            }
        };
        quote! {
            if let ::core::option::Option::Some(problem) = #call {
                return ::core::result::Result::Err(#rt::newton_euler::DynamicsError::MassProperties { body: ::std::borrow::Cow::Borrowed(#name), problem });
            }
        }
    });
    // The SKCs in reverse order.
    let solves = t.skcs.iter().enumerate().rev().map(|(k, s)| solve_skc(t, k, s));
    let balances = t.balances.iter().map(|b| balance_check(t, b));
    let reactions = (0..t.points.len()).map(|j| reaction(t, j));
    let actuators = t.actuators.iter().map(|(j, xi, bars)| actuator(t, *j, xi, bars));
    let size = term(&t.size);
    let n_skcs = t.skcs.len();
    let result = format_ident!("{}Dynamics", ident);
    quote! {
        /// The terms of the inverse dynamics for one branch: the forward
        /// solution's link motions turned into every SKC's reaction
        /// equations, verified like the forward solution.
        #[allow(clippy::type_complexity)]
        fn inverse_dynamics_terms(
            &self,
            #given_sig,
            rates: &[f64; #n_given],
            accelerations: &[f64; #n_given],
        ) -> ::core::result::Result<[f64; #n_terms], #rt::solution::SolveError> {
            let _ = (&signs, rates, accelerations);
            #finite
            #lets
            #check
            ::core::result::Result::Ok([#(#values),*])
        }

        /// Inverse dynamics for one branch by Newton–Euler over the ordered
        /// SKCs: the actuators' forces (N) or torques (N·L) that drive the
        /// mechanism at the inputs `given` with `rates` and `accelerations`
        /// against gravity and the declared loads, and every joint's
        /// reaction. The SKCs are solved in reverse order, each from its own
        /// links' balances; where statics leaves reactions undetermined
        /// they are the minimum-norm ones. Verified: every link balances.
        pub fn inverse_dynamics(
            &self,
            given: &[f64; #n_given],
            signs: [#rt::primitives::Sign; #n_choices],
            rates: &[f64; #n_given],
            accelerations: &[f64; #n_given],
        ) -> ::core::result::Result<#result, #rt::newton_euler::DynamicsError> {
            if !rates.iter().chain(accelerations.iter()).all(|v| v.is_finite()) {
                return ::core::result::Result::Err(#rt::newton_euler::DynamicsError::NotFinite);
            }
            let t = self
                .inverse_dynamics_terms(given, signs, rates, accelerations)
                .map_err(#rt::newton_euler::DynamicsError::Position)?;
            #(#body_checks)*
            if !t.iter().all(|v| v.is_finite()) {
                return ::core::result::Result::Err(#rt::newton_euler::DynamicsError::NotFinite);
            }
            let size = #size;
            #(#spin_checks)*
            // At rest the forces lose digits more slowly than in motion.
            let moving = rates.iter().chain(accelerations.iter()).any(|v| *v != 0.0);
            let mut conditioning = [1.0f64; #n_skcs];
            let mut undetermined = [0usize; #n_skcs];
            #(#solves)*
            let mut balance = 0.0f64;
            #(#balances)*
            if balance.is_nan() || balance > #rt::newton_euler::UNBALANCED {
                return ::core::result::Result::Err(#rt::newton_euler::DynamicsError::Unbalanced { balance });
            }
            ::core::result::Result::Ok(#result {
                actuators: [#(#actuators),*],
                joints: [#(#reactions),*],
                conditioning,
                undetermined,
                balance,
            })
        }
    }
}

/// A term as the generated function reads it.
fn term(x: &Term) -> TokenStream {
    match x {
        Term::Const(c) => lit(*c),
        Term::At(i) => quote! { t[#i] },
    }
}

fn is_zero(x: &Term) -> bool {
    matches!(x, Term::Const(z) if *z == 0.0)
}

/// The name of SKC `k`'s solution.
fn x_of(k: usize) -> proc_macro2::Ident {
    format_ident!("x{}", k)
}

/// Component `c` of a solution `x` in N (or N·L: a moment was solved over the size).
fn in_units(t: &Traced, x: TokenStream, c: usize) -> TokenStream {
    if c >= t.moments_from {
        quote! { #x * size }
    } else {
        x
    }
}

/// SKC `k`'s matrix and right-hand side filled in, decomposed and solved
/// on the stack: `let xk = …;`.
fn solve_skc(t: &Traced, k: usize, s: &Skc) -> TokenStream {
    let rt = quote! { ::pkm::runtime::__private };
    let n = s.rows.max(s.joints.len() * t.d);
    let x = x_of(k);
    let entries = s.entries.iter().filter(|e| !is_zero(&e.2)).map(|(r, c, v)| {
        let v = term(v);
        quote! { a[(#r, #c)] = #v; }
    });
    let rhs = s.rhs.iter().enumerate().filter(|(_, v)| !is_zero(v)).map(|(r, v)| {
        let v = term(v);
        quote! { b[#r] = #v; }
    });
    // b −= sign·x for the reactions later SKCs found.
    let known = s.known.iter().map(|&(r, j, c, sign)| {
        let (owner, at) = t.place[j];
        let (xk, col) = (x_of(owner), at + c);
        if sign < 0.0 {
            quote! { b[#r] += #xk[#col]; }
        } else {
            quote! { b[#r] -= #xk[#col]; }
        }
    });
    let n_act = s.actuated.len();
    let actuated = if n_act == 0 {
        quote! { let actuated = [0.0f64; 0]; }
    } else {
        let len = n_act * n;
        let fill = s.actuated.iter().enumerate().flat_map(|(i, row)| {
            row.iter().filter(|(_, v)| !is_zero(v)).map(move |(c, v)| {
                let (at, v) = (i * n + c, term(v));
                quote! { actuated[#at] = #v; }
            })
        });
        quote! {
            let mut actuated = [0.0f64; #len];
            #(#fill)*
        }
    };
    let joints = &s.joints;
    let undetermined = s.undetermined;
    let unknowns = s.joints.len() * t.d;
    // Where the SKC reduces to its cut joints, the reduced solve has set
    // its kinematic conditioning; else the whole system's is.
    let kinematic = if s.reduction.is_some() {
        quote! {}
    } else {
        quote! {
            #rt::force_system::near_change_point(solved.conditioning, moving, #k, &[#(#joints),*])?;
            conditioning[#k] = solved.conditioning;
        }
    };
    let full = quote! {
        let mut a = #rt::nalgebra::SMatrix::<f64, #n, #n>::zeros();
        #(#entries)*
        let svd = a.svd(true, true);
        let (::core::option::Option::Some(u), ::core::option::Option::Some(v_t)) = (svd.u.as_ref(), svd.v_t.as_ref()) else {
            return ::core::result::Result::Err(#rt::newton_euler::DynamicsError::NotFinite);
        };
        let decomposition = #rt::force_system::Decomposition {
            n: #n,
            singular_values: svd.singular_values.as_slice(),
            u: u.as_slice(),
            v_t: v_t.as_slice(),
            matrix: a.as_slice(),
        };
        let mut x = [0.0f64; #n];
        let solved = #rt::force_system::min_norm(&decomposition, b.as_slice(), #k, &[#(#joints),*], #unknowns, #undetermined, &actuated, size, &mut x)?;
        #kinematic
        undetermined[#k] = solved.undetermined;
        x
    };
    let reduced = s.reduction.as_ref().map(|r| reduced_solve(t, k, s, r));
    let body = match reduced {
        Some(reduced) => quote! {
            'solve: {
                let mut b = #rt::nalgebra::SVector::<f64, #n>::zeros();
                #(#rhs)*
                #(#known)*
                #actuated
                #reduced
                #full
            }
        },
        None => quote! {
            {
                let mut b = #rt::nalgebra::SVector::<f64, #n>::zeros();
                #(#rhs)*
                #(#known)*
                #actuated
                #full
            }
        },
    };
    quote! {
        let #x: [f64; #n] = #body;
    }
}

/// SKC `k`'s reduced solve ([`Reduction`]): `x0` from the link rows'
/// right-hand sides in `b`, `q` and `G`, then `y` by `G⁻¹ q` (a determined
/// SKC) or the minimum-norm solve of the reduction; `break 'solve x` with
/// the reactions, or on to the whole system near a change point.
fn reduced_solve(t: &Traced, k: usize, s: &Skc, r: &Reduction) -> TokenStream {
    let rt = quote! { ::pkm::runtime::__private };
    let d = t.d;
    let n = s.joints.len() * d;
    let m = r.cuts.len() * d;
    let link_rows = s.rows - r.passive.len();
    let joints = &s.joints;
    // x0: a tree joint's subtree sums.
    let x0 = r
        .tree
        .iter()
        .enumerate()
        .filter_map(|(i, t)| t.as_ref().map(|ts| (i, ts)))
        .flat_map(|(i, (sign, subtree))| {
            (0..d).map(move |c| {
                let sum = subtree.iter().map(|l| {
                    let row = l * d + c;
                    quote! { b[#row] }
                });
                let at = i * d + c;
                let sum = quote! { (#(#sum)+*) };
                let value = signed(*sign, sum);
                quote! { x0[#at] = #value; }
            })
        });
    // q = the passive rows' right-hand sides − P x0.
    let q = r.passive.iter().enumerate().map(|(row, (i, p, _))| {
        let from = link_rows + row;
        let terms = p.iter().enumerate().filter(|(_, v)| !is_zero(v)).map(|(cc, v)| {
            let (v, at) = (term(v), i * d + cc);
            quote! { #v * x0[#at] }
        });
        quote! { q[#row] = b[#from] #(- #terms)*; }
    });
    let g = r.g.iter().filter(|e| !is_zero(&e.2)).map(|(row, col, v)| {
        let v = term(v);
        quote! { g[(#row, #col)] = #v; }
    });
    let prelude = quote! {
        let mut x0 = [0.0f64; #n];
        #(#x0)*
        let mut q = #rt::nalgebra::SVector::<f64, #m>::zeros();
        #(#q)*
        let mut g = #rt::nalgebra::SMatrix::<f64, #m, #m>::zeros();
        #(#g)*
        // Each passive row as a direction: the kinematic conditioning's.
        #rt::force_system::unit_rows(g.as_mut_slice(), #m, q.as_mut_slice());
    };
    if s.undetermined == 0 && r.passive.len() == m {
        // x = x0 + C y.
        let add = c_times(s, r, d, quote! { += });
        quote! {
            #prelude
            // The bound from the inverse where it is above the least, else σ_m/σ_1.
            let inverse = g.try_inverse();
            let bound = inverse.as_ref().map_or(0.0, |inverse| {
                #rt::force_system::conditioning_bound(g.as_slice(), inverse.as_slice())
            });
            let kinematic = #rt::force_system::determined_conditioning(bound, || {
                #rt::force_system::conditioning_of(g.singular_values().as_slice(), #m)
            });
            conditioning[#k] = kinematic;
            #rt::force_system::near_change_point(kinematic, moving, #k, &[#(#joints),*])?;
            if let (true, ::core::option::Option::Some(inverse)) = (bound > #rt::force_system::LU_TRUSTED, inverse) {
                let y = inverse * q;
                let _ = &actuated;
                let mut x = x0;
                #(#add)*
                break 'solve x;
            }
        }
    } else {
        // C y, written out: C is block-diagonal in the components.
        let set = c_times(s, r, d, quote! { = });
        let undetermined = s.undetermined;
        let rank = m.saturating_sub(undetermined);
        let null = undetermined.min(m);
        let passive = r.passive.len();
        if passive > 0 && passive == rank {
            // The passive rows independent (as the topology has them): the
            // row space of G by Householder, its null space with it.
            return quote! {
                #prelude
                let rows: [[f64; #m]; #passive] = ::core::array::from_fn(|i| ::core::array::from_fn(|j| g[(i, j)]));
                let (basis, r) = #rt::force_system::row_space::<#m, #passive>(&rows);
                let kinematic = #rt::force_system::conditioning_of(r.singular_values().as_slice(), #rank);
                conditioning[#k] = kinematic;
                #rt::force_system::near_change_point(kinematic, moving, #k, &[#(#joints),*])?;
                let c = |y: &[f64; #m]| -> [f64; #n] {
                    let mut x = [0.0f64; #n];
                    #(#set)*
                    x
                };
                let mut x = [0.0f64; #n];
                if let ::core::option::Option::Some(solved) = #rt::force_system::reduced_min_norm_qr::<#n, #m, #passive, #null>(&basis, &r, kinematic, &q.into(), &x0, c, #k, &actuated, size, &mut x)? {
                    undetermined[#k] = solved.undetermined;
                    break 'solve x;
                }
            };
        }
        quote! {
            #prelude
            let svd = g.svd(true, true);
            let kinematic = #rt::force_system::conditioning_of(svd.singular_values.as_slice(), #rank);
            conditioning[#k] = kinematic;
            #rt::force_system::near_change_point(kinematic, moving, #k, &[#(#joints),*])?;
            if let (::core::option::Option::Some(u), ::core::option::Option::Some(v_t)) = (svd.u.as_ref(), svd.v_t.as_ref()) {
                let decomposition = #rt::force_system::Decomposition {
                    n: #m,
                    singular_values: svd.singular_values.as_slice(),
                    u: u.as_slice(),
                    v_t: v_t.as_slice(),
                    matrix: g.as_slice(),
                };
                let c = |y: &[f64; #m]| -> [f64; #n] {
                    let mut x = [0.0f64; #n];
                    #(#set)*
                    x
                };
                let mut x = [0.0f64; #n];
                if let ::core::option::Option::Some(solved) = #rt::force_system::reduced_min_norm::<#n, #m, #null>(&decomposition, &q.into(), &x0, c, #k, #undetermined, &actuated, size, &mut x)? {
                    undetermined[#k] = solved.undetermined;
                    break 'solve x;
                }
            }
        }
    }
}

/// `x[i] op (C y)[i]` for each reaction component `i` that a cut joint's
/// reaction reaches: `C` is ±1 per joint and cut joint, the same for each
/// of the `d` components.
fn c_times(s: &Skc, r: &Reduction, d: usize, op: TokenStream) -> Vec<TokenStream> {
    (0..s.joints.len())
        .flat_map(|i| {
            let op = op.clone();
            (0..d).filter_map(move |c| {
                let at = i * d + c;
                let parts: Vec<TokenStream> = r.coef[i]
                    .iter()
                    .enumerate()
                    .filter(|(_, v)| **v != 0.0)
                    .map(|(kk, v)| {
                        signed(*v, {
                            let col = kk * d + c;
                            quote! { y[#col] }
                        })
                    })
                    .collect();
                (!parts.is_empty()).then(|| quote! { x[#at] #op #(#parts)+*; })
            })
        })
        .collect()
}

/// One link's balance: the demand against its joints' reactions, folded
/// into `balance`.
fn balance_check(t: &Traced, b: &Balance) -> TokenStream {
    let components = (0..t.d).map(|c| {
        let reactions = b.on.iter().map(|&(j, sign)| {
            let (k, at) = t.place[j];
            let (xk, col) = (x_of(k), at + c);
            signed(sign, quote! { #xk[#col] })
        });
        let need = match &b.need[c] {
            Term::Const(v) => lit(-v),
            at => {
                let v = term(at);
                quote! { -#v }
            }
        };
        quote! { [#need, #(#reactions),*] }
    });
    quote! {
        balance = balance.max(::pkm::runtime::__private::force_system::relative_residual(&[#(#components),*]));
    }
}

/// Joint `j`'s reaction at its point, in N and N·L.
fn reaction(t: &Traced, j: usize) -> TokenStream {
    let (k, at) = t.place[j];
    let xk = x_of(k);
    let w: Vec<TokenStream> = (0..t.d)
        .map(|c| {
            let col = at + c;
            in_units(t, quote! { #xk[#col] }, c)
        })
        .collect();
    let (f, mo) = if t.d == 3 {
        let (fx, fy, mz) = (&w[0], &w[1], &w[2]);
        (quote! { [#fx, #fy, 0.0] }, quote! { [0.0, 0.0, #mz] })
    } else {
        let (fx, fy, fz, mx, my, mz) = (&w[0], &w[1], &w[2], &w[3], &w[4], &w[5]);
        (quote! { [#fx, #fy, #fz] }, quote! { [#mx, #my, #mz] })
    };
    let p = t.points[j].iter().map(term);
    let metres = lit(t.metres);
    quote! {
        {
            let (f, m, p): ([f64; 3], [f64; 3], [f64; 3]) = (#f, #mo, [#(#p),*]);
            // The moment about the joint's point: m_o − p × f.
            let at = [
                m[0] - (p[1] * f[2] - p[2] * f[1]),
                m[1] - (p[2] * f[0] - p[0] * f[2]),
                m[2] - (p[0] * f[1] - p[1] * f[0]),
            ];
            ::pkm::runtime::__private::newton_euler::JointReaction {
                force: [f[0] * #metres, f[1] * #metres, f[2] * #metres],
                moment: [at[0] * #metres, at[1] * #metres, at[2] * #metres],
            }
        }
    }
}

/// An actuator's force: its joint's reaction's power along its twist, in N or N·L.
fn actuator(t: &Traced, j: usize, xi: &[Term], bars: &Term) -> TokenStream {
    let (k, at) = t.place[j];
    let xk = x_of(k);
    let sum: Vec<TokenStream> = (0..t.d)
        .filter(|&c| !is_zero(&xi[c]))
        .map(|c| {
            let col = at + c;
            let x = in_units(t, quote! { #xk[#col] }, c);
            match xi[c] {
                Term::Const(1.0) => x,
                Term::Const(-1.0) => quote! { -(#x) },
                other => {
                    let k = term(&other);
                    quote! { #k * (#x) }
                }
            }
        })
        .collect();
    let metres = lit(t.metres);
    let bars = (!is_zero(bars)).then(|| {
        let b = term(bars);
        quote! { + #b }
    });
    if sum.is_empty() {
        quote! { (0.0 #bars) * #metres }
    } else {
        quote! { (#(#sum)+* #bars) * #metres }
    }
}

/// `NameDynamics`, what `inverse_dynamics` returns, and `Name::inverse_dynamics`.
pub(super) fn items(ident: &proc_macro2::Ident, vis: &syn::Visibility, d: &Direction, t: &Traced) -> TokenStream {
    let rt = quote! { ::pkm::runtime::__private };
    let result = format_ident!("{}Dynamics", ident);
    let params_ty = format_ident!("{}Params", ident);
    let (n_act, n_joints, n_skcs) = (t.actuators.len(), t.points.len(), t.skcs.len());
    let (n_given, n_choices) = (d.plan.n_inputs, d.plan.branches);
    let doc = format!(" What [`{ident}Prepared::inverse_dynamics`] finds.");
    let fn_doc = format!(" Inverse dynamics for one branch ([`{ident}Prepared::inverse_dynamics`]).");
    quote! {
        #[doc = #doc]
        #[derive(Debug, Clone, Copy, PartialEq)]
        #vis struct #result {
            /// The actuators' forces (N) or torques (N·L), in `INPUTS` order.
            pub actuators: [f64; #n_act],
            /// Every joint's reaction (`JOINTS` order): the force and the
            /// moment about its point that its first link exerts on its
            /// second, base axes (N and N·L).
            pub joints: [#rt::newton_euler::JointReaction; #n_joints],
            /// Per SKC (position solution's order), its kinematic
            /// conditioning, near 0 at a change point: σ_r/σ_1 of its
            /// passive rows on its cut joints' reactions (the transpose of
            /// its passive velocity equations; for a determined SKC where
            /// the lower bound 1/(‖G‖_F ‖G⁻¹‖_F) is 6.06e-4 or more, that
            /// bound), as the runtime's Newton–Euler reports it; below
            /// 6.06e-4 in motion (1.5e-5 at rest) the answer is
            /// `DynamicsError::NearChangePoint` instead.
            pub conditioning: [f64; #n_skcs],
            /// Per SKC, the reaction components statics leaves undetermined.
            pub undetermined: [usize; #n_skcs],
            /// The largest residual of a link's balance, relative to its largest term.
            pub balance: f64,
        }

        #[automatically_derived]
        impl #ident {
            #[doc = #fn_doc]
            /// Prepares the solver and solves: to solve often at the same
            /// parameters, prepare once (`prepare`) and call its `inverse_dynamics`.
            pub fn inverse_dynamics(
                params: &#params_ty,
                q: &[f64; #n_given],
                signs: [#rt::primitives::Sign; #n_choices],
                rates: &[f64; #n_given],
                accelerations: &[f64; #n_given],
            ) -> ::core::result::Result<#result, #rt::newton_euler::DynamicsError> {
                Self::prepare(params).inverse_dynamics(q, signs, rates, accelerations)
            }
        }
    }
}
