//! The prepared solver: the plan's steps (`pkm_runtime::steps`) run on
//! symbols ([`crate::codegen::trace`]) and written out as straight-line Rust
//! ([`crate::codegen::emit`]). `Name::prepare(&params)` computes once what depends on
//! the parameters alone; `fk_branch`, `fk` (every branch, sharing what the
//! branches share), `fk_solution` and their `ik` twins compute the rest.

use crate::codegen::emit::Emit;
use crate::codegen::trace::{record, Choice, Graph, Sym};
use crate::semantics::geometry::{OutputKind, Vec3};
use crate::semantics::mechanism::JointKind;
use crate::syntax::expr::Expr;
use crate::topology::analysis::Analysis;
use pkm_runtime::model::JointType;
use pkm_runtime::plan::Plan;
use pkm_runtime::primitives::Sign;
use pkm_runtime::scalar::Scalar;
use pkm_runtime::steps::{self, Geometry, Given, JointGeometry, RESIDUAL_ROWS};
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

// A child module: it reads this one's traced branches.
#[path = "batch.rs"]
mod batch;
#[path = "dynamics.rs"]
mod dynamics;
#[path = "numeric.rs"]
pub(crate) mod numeric;
#[path = "stiffness.rs"]
mod stiffness;

/// A parameter expression as a symbol: arithmetic traced, anything else
/// (powers, functions) kept as Rust source.
fn sym(e: &Expr) -> Sym {
    match e {
        Expr::Num(v) => Sym::c(*v),
        Expr::Var(n, _) if n == "pi" => Sym::c(std::f64::consts::PI),
        Expr::Var(n, _) => Sym::param(n),
        Expr::Neg(a) => -sym(a),
        Expr::Bin('+', a, b) => sym(a) + sym(b),
        Expr::Bin('-', a, b) => sym(a) - sym(b),
        Expr::Bin('*', a, b) => sym(a) * sym(b),
        Expr::Bin('/', a, b) => sym(a) / sym(b),
        _ => Sym::raw(e.to_tokens(&quote! { params }).to_string()),
    }
}

fn sym3(v: &Vec3) -> [Sym; 3] {
    [sym(&v[0]), sym(&v[1]), sym(&v[2])]
}

/// The runtime's joint type of a joint kind (every kind with a numeric
/// model: the planners refuse the others before code is generated).
pub(crate) fn joint_type(kind: JointKind) -> JointType {
    match kind {
        JointKind::P => JointType::P,
        JointKind::Pa => JointType::Pa,
        JointKind::S => JointType::S,
        _ => JointType::R,
    }
}

/// The mechanism's geometry in symbols of its parameters.
fn geometry(a: &Analysis) -> Geometry<Sym> {
    let m = &a.mechanism;
    Geometry {
        joints: m
            .joints
            .iter()
            .enumerate()
            .map(|(j, joint)| {
                let [u, v] = joint.links;
                JointGeometry::new(
                    joint_type(joint.kind),
                    joint.links,
                    [a.place(j, u).place(sym3), a.place(j, v).place(sym3)],
                )
            })
            .collect(),
        named: a.geometry.points.iter().map(|p| sym3(&p.at)).collect(),
    }
}

/// One branch's symbols: what the lean solver returns (the outputs, or the
/// actuators' values), every joint value, every point, the declared
/// outputs, the open joints' residual rows (rotation rows times the
/// extent) and the extent they are measured against.
struct Branch {
    guards: Vec<Sym>,
    /// The steps a miss stands for ([`Plan::by_miss`]), each with the
    /// values it solves: their guards bind only where something reads those.
    waivable: Vec<(usize, Vec<Sym>)>,
    result: Vec<Sym>,
    /// What the plan's choices solved ([`steps::choice_values`]): what
    /// tells this branch's solution from the others'.
    choices: Vec<Sym>,
    values: Vec<Sym>,
    /// Each ball's rotation vector, in joint order (`full` only).
    balls: Vec<[Sym; 3]>,
    points: Vec<[Sym; 3]>,
    outputs: Vec<Sym>,
    residual: Vec<Sym>,
    extent: Sym,
    /// Every link's pose and every joint's value (`full` only).
    poses: Vec<pkm_runtime::frame::Frame<Sym>>,
    states: Vec<Option<steps::JointValue<Sym>>>,
}

/// Runs the plan on symbols.
/// `full`: every joint value and point too (the solution); otherwise only
/// what the lean solver returns and checks, so that tracing every branch
/// records no more than the every-branch solver uses.
/// The name of each step's loop, for errors (`R2–R3–R4`).
fn loop_names(a: &Analysis, plan: &Plan) -> Vec<String> {
    let joints = &a.mechanism.joints;
    plan.steps
        .iter()
        .map(|s| steps::loop_name(s, |j| joints[j].name.clone()))
        .collect()
}

#[allow(clippy::too_many_arguments)]
fn branch(
    a: &Analysis,
    g: &Geometry<Sym>,
    plan: &Plan,
    sites: usize,
    forward: bool,
    signs: &[Choice],
    full: bool,
) -> Result<Branch, String> {
    let m = &a.mechanism;
    let values: Vec<Sym> = (0..plan.n_inputs).map(Sym::given).collect();
    let names = loop_names(a, plan);
    let name = |k: usize| std::borrow::Cow::Owned(names[k].clone());
    let given = Given {
        values: &values,
        signs,
        name: &name,
        sites,
    };
    crate::codegen::trace::take_guards();
    let state = steps::run(plan, g, m.links.len(), &given).map_err(|e| e.to_string())?;
    // Names for the generated code's variables.
    for (l, pose) in state.poses.iter().enumerate() {
        for (i, c) in ["x", "y", "z"].iter().enumerate() {
            pose.t[i].named(&|| format!("{}_{c}", m.links[l].name));
        }
    }
    for (j, v) in state.values.iter().enumerate() {
        match v {
            Some(steps::JointValue::Turn(c, s, _)) => {
                c.named(&|| format!("cos_{}", m.joints[j].name));
                s.named(&|| format!("sin_{}", m.joints[j].name));
            }
            Some(steps::JointValue::Slide(t)) => {
                t.named(&|| m.joints[j].name.clone());
            }
            None => {}
        }
    }
    let value = |j: usize| steps::value(g, &state, j);
    // A ball's value in `q` is its rotation's angle; its rotation vector
    // is in `balls` (`steps::ball_rotation`).
    let ball = |j: usize| g.joints[j].kind == pkm_runtime::model::JointType::S;
    let (joint_values, balls): (Vec<Sym>, Vec<[Sym; 3]>) = if full {
        let rotations: Vec<_> = (0..m.joints.len())
            .map(|j| ball(j).then(|| steps::ball_rotation(g, &state, j)))
            .collect();
        (
            (0..m.joints.len())
                .map(|j| rotations[j].map_or_else(|| value(j), |(_, theta)| theta))
                .collect(),
            rotations.iter().flatten().map(|&(r, _)| r).collect(),
        )
    } else {
        (Vec::new(), Vec::new())
    };
    let mut points: Vec<[Sym; 3]> = Vec::new();
    if full {
        points.extend((0..m.joints.len()).map(|j| {
            let l = a.point_link(j);
            state.poses[l].apply(g.local(pkm_runtime::solution::PointRef::Joint(j), l))
        }));
        points.extend(
            a.geometry
                .points
                .iter()
                .enumerate()
                .map(|(k, p)| state.poses[p.link].apply(g.named[k])),
        );
    }
    // A planar mechanism's positions are (x, y).
    let dim = if m.planar { 2 } else { 3 };
    let mut outputs = Vec::new();
    for o in &a.geometry.outputs {
        match &o.kind {
            OutputKind::Pose { link, point, about } => {
                let pose = &state.poses[*link];
                outputs.extend(pose.apply(g.local(*point, *link)).into_iter().take(dim));
                match about {
                    Some(k) => outputs.push(steps::place::angle_about(pose, sym3(k))),
                    None if m.planar => outputs.push(pose.r[1][0].atan2(pose.r[0][0])),
                    None => {}
                }
            }
            OutputKind::Point { link, point } => {
                outputs.extend(state.poses[*link].apply(g.local(*point, *link)).into_iter().take(dim))
            }
            OutputKind::Parts { link, point, parts } => {
                let six = steps::place::pose_values(&state.poses[*link], g.local(*point, *link));
                outputs.extend(parts.given().map(|i| six[i]));
            }
            OutputKind::Joint(j) => outputs.push(value(*j)),
        }
    }
    // Names for what the solvers return: the outputs, every joint's value
    // and every point's coordinates (those no step named already).
    for (v, n) in outputs.iter().zip(a.geometry.outputs.iter().flat_map(|o| &o.names)) {
        v.named(&|| n.clone());
    }
    for (v, joint) in joint_values.iter().zip(&m.joints) {
        v.named(&|| joint.name.clone());
    }
    let point_names = m
        .joints
        .iter()
        .map(|j| &j.name)
        .chain(a.geometry.points.iter().map(|p| &p.name));
    for (p, n) in points.iter().zip(point_names) {
        for (v, c) in p.iter().zip(["x", "y", "z"]) {
            v.named(&|| format!("{n}_{c}"));
        }
    }
    let choices = steps::choice_values(plan, &state);
    let guards = crate::codegen::trace::take_guards();
    let checks = plan.checks(m.joints.len());
    // The largest coordinate of the origins of the links the results need, at least 1.
    let origins: Vec<[Sym; 3]> = state.poses.iter().map(|p| p.t).collect();
    let extent = Sym::extent(&plan.measured(&origins).into_iter().flatten().collect::<Vec<_>>());
    // Rotation rows scale with the extent (see `closure_residual`).
    let residual = steps::check_residual(g, plan, &checks, &state.poses, &values, extent);
    let result = if forward {
        outputs.clone()
    } else {
        (0..m.joints.len())
            .filter(|&j| m.joints[j].actuated)
            .map(value)
            .collect()
    };
    let waivable = plan
        .by_miss
        .iter()
        .flat_map(|b| [Some(b.aim), b.plane])
        .flatten()
        .filter_map(|k| {
            let v = state.values[plan.steps[k].joint()?]?;
            Some((
                k,
                match v {
                    steps::JointValue::Turn(c, s, _) => vec![c, s],
                    steps::JointValue::Slide(t) => vec![t],
                },
            ))
        })
        .collect();
    let (poses, states) = if full {
        (state.poses.clone(), state.values.clone())
    } else {
        (Vec::new(), Vec::new())
    };
    Ok(Branch {
        guards,
        waivable,
        result,
        choices,
        values: joint_values,
        balls,
        points,
        outputs,
        residual,
        extent,
        poses,
        states,
    })
}

/// The traced branches of one direction: with the caller's signs, and each
/// branch with fixed signs.
struct Direction<'p> {
    forward: bool,
    plan: &'p Plan,
    given: Branch,
    every: Vec<Branch>,
    /// Which of the plan's residual rows each branch keeps, in order (a
    /// row is `Plan::checks`' `row / RESIDUAL_ROWS`-th check's): a row that
    /// is exactly 0 in every branch checks nothing and is not emitted.
    rows: Vec<usize>,
    /// The result's rates along the given values' rates, where the
    /// description asks for velocity, Jacobians or accelerations.
    rates: Option<Vec<Sym>>,
    /// The result's derivative along each given value (columns).
    jacobian: Option<Vec<Vec<Sym>>>,
    /// The result's second derivative in time for the given values' rates
    /// and accelerations, where `acceleration` is asked for.
    accelerations: Option<Vec<Sym>>,
    /// The inverse dynamics, forward only, where `dynamics` is asked for.
    dynamics: Option<dynamics::Traced>,
    /// The static stiffness, inverse only, where `stiffness` is asked for.
    stiffness: Option<stiffness::Traced>,
}

/// Drops the residual rows that are exactly 0 in every branch (a check's
/// rows the joint's freedom leaves unconstrained, folded to 0 by the
/// trace): the solvers then measure only rows that can fail.
fn keep_live_rows(emit: &Emit, d: &mut Direction) {
    let n = d.given.residual.len();
    let live = |i: usize| {
        std::iter::once(&d.given)
            .chain(&d.every)
            .any(|b| emit.constant(b.residual[i]) != Some(0.0))
    };
    let rows: Vec<usize> = (0..n).filter(|&i| live(i)).collect();
    for b in std::iter::once(&mut d.given).chain(&mut d.every) {
        b.residual = rows.iter().map(|&i| b.residual[i]).collect();
    }
    d.rows = rows;
}

fn xyz(p: &[TokenStream]) -> TokenStream {
    quote! { [#(#p),*] }
}

/// The prepared solver of a spatial mechanism: `NamePrepared` and its
/// functions, `Name::prepare`. `Err` names a step the symbols could not run.
/// The generated solvers, and the inverse solution's choice groups.
pub struct Generated {
    /// The prepared struct and every direction's functions.
    pub items: TokenStream,
    /// The inverse plan's ± choices grouped by the actuated joints they
    /// move ([`choice_groups`]); empty without an inverse plan.
    pub inverse_groups: Vec<ChoiceGroup>,
}

/// Some ± choices and the actuated joints (indices into the inputs) whose
/// values depend on them alone (`pkm_runtime::ball_legs::solve::ChoiceGroup`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ChoiceGroup {
    /// The choices.
    pub choices: Vec<usize>,
    /// The actuated joints.
    pub joints: Vec<usize>,
}

/// The inverse plan's ± choices in groups, each with the actuated joints
/// that depend on its choices alone, read off the traced branches: a
/// joint's value depends on the choices some branch's value of it was
/// chosen by (the graph's sign marks), proven by the value being the same
/// recorded operation on every two branches that differ only in other
/// choices; choices that share a joint are one group. Where the proof
/// fails (a sign that picks a constant leaves no mark) the whole plan is
/// one group.
fn choice_groups(graph: &Graph, d: &Direction) -> Vec<ChoiceGroup> {
    let n = d.plan.branches;
    let joints = d.given.result.len();
    let whole = vec![ChoiceGroup {
        choices: (0..n).collect(),
        joints: (0..joints).collect(),
    }];
    let mut depends = vec![0u64; joints];
    for b in &d.every {
        for (i, r) in b.result.iter().enumerate() {
            depends[i] |= graph.signs[r.0 as usize].0;
        }
    }
    for (i, &mask) in depends.iter().enumerate() {
        for k in (0..n).filter(|k| mask >> k & 1 == 0) {
            if (0..d.every.len()).any(|b| d.every[b].result[i] != d.every[b ^ 1 << k].result[i]) {
                return whole;
            }
        }
    }
    // Choices that share a joint are one group (smallest choice as root).
    let mut root: Vec<usize> = (0..n).collect();
    fn find(root: &mut [usize], k: usize) -> usize {
        let mut r = k;
        while root[r] != r {
            r = root[r];
        }
        root[k] = r;
        r
    }
    for &mask in &depends {
        let ks: Vec<usize> = (0..n).filter(|k| mask >> k & 1 == 1).collect();
        for w in ks.windows(2) {
            let (x, y) = (find(&mut root, w[0]), find(&mut root, w[1]));
            root[x.max(y)] = x.min(y);
        }
    }
    let mut groups: Vec<ChoiceGroup> = Vec::new();
    for k in 0..n {
        if find(&mut root, k) == k {
            groups.push(ChoiceGroup {
                choices: (k..n).filter(|&c| find(&mut root, c) == k).collect(),
                joints: Vec::new(),
            });
        }
    }
    // Joints no choice moves: a group of their own, without choices.
    let mut fixed = ChoiceGroup {
        choices: Vec::new(),
        joints: Vec::new(),
    };
    for (i, &mask) in depends.iter().enumerate() {
        match (0..n).find(|k| mask >> k & 1 == 1) {
            Some(k) => {
                let r = find(&mut root, k);
                if let Some(g) = groups.iter_mut().find(|g| g.choices[0] == r) {
                    g.joints.push(i);
                }
            }
            None => fixed.joints.push(i),
        }
    }
    if !fixed.joints.is_empty() {
        groups.push(fixed);
    }
    groups
}

pub fn generate(
    a: &Analysis,
    ident: &proc_macro2::Ident,
    vis: &syn::Visibility,
    fk: Option<&Plan>,
    ik: Option<&Plan>,
) -> Result<Generated, String> {
    let (directions, graph) = record(|| -> Result<Vec<Direction>, String> {
        let g = geometry(a);
        let mut out = Vec::new();
        for (forward, plan) in [(true, fk), (false, ik)] {
            let Some(plan) = plan else { continue };
            // The steps' sites: fk's, then ik's.
            let sites = if forward { 0 } else { fk.map_or(0, |p| p.steps.len()) };
            let given_signs: Vec<Choice> = (0..plan.branches).map(Choice::Given).collect();
            let given = branch(a, &g, plan, sites, forward, &given_signs, true)?;
            let every = (0..1usize << plan.branches)
                .map(|b| {
                    let signs: Vec<Choice> = (0..plan.branches)
                        .map(|k| Choice::Fixed(k, if (b >> k) & 1 == 1 { Sign::Minus } else { Sign::Plus }))
                        .collect();
                    branch(a, &g, plan, sites, forward, &signs, false)
                })
                .collect::<Result<_, _>>()?;
            // Rates and Jacobians only where the description asks for them.
            use crate::semantics::mechanism::Capability;
            let m = &a.mechanism;
            let wanted = [Capability::Jacobian, Capability::Velocity, Capability::Acceleration]
                .iter()
                .any(|c| m.wants(*c));
            let (rates, jacobian) = if wanted {
                let rates = crate::codegen::trace::derivative(&given.result, &Sym::rate);
                let jacobian = (0..plan.n_inputs)
                    .map(|k| {
                        crate::codegen::trace::derivative(&given.result, &|i| Sym::c(if i == k { 1.0 } else { 0.0 }))
                    })
                    .collect();
                (Some(rates), Some(jacobian))
            } else {
                (None, None)
            };
            // d²f/dt² = D²f[q̇, q̇] + Df·q̈: the rates differentiated again
            // along the rates (constant in that derivative), plus the result
            // differentiated along the accelerations.
            let accelerations = match &rates {
                Some(rates) if m.wants(Capability::Acceleration) => {
                    let curvature = crate::codegen::trace::derivative(rates, &Sym::rate);
                    let along = crate::codegen::trace::derivative(&given.result, &Sym::accel);
                    Some(curvature.iter().zip(&along).map(|(&c, &a)| c + a).collect())
                }
                _ => None,
            };
            let dynamics = if forward && m.wants(Capability::Dynamics) {
                Some(dynamics::trace(a, &g, plan, &given)?)
            } else {
                None
            };
            let stiffness = if !forward && m.wants(Capability::Stiffness) {
                Some(stiffness::trace(a, &g, &given)?)
            } else {
                None
            };
            out.push(Direction {
                forward,
                plan,
                rows: (0..given.residual.len()).collect(),
                given,
                every,
                rates,
                jacobian,
                accelerations,
                dynamics,
                stiffness,
            });
        }
        Ok(out)
    });
    let mut directions = directions?;
    let inverse_groups = directions
        .iter()
        .find(|d| !d.forward)
        .map_or_else(Vec::new, |d| choice_groups(&graph, d));
    let sites = [fk, ik].into_iter().flatten().flat_map(|p| loop_names(a, p)).collect();
    let emit = Emit::new(&graph, sites);
    for d in &mut directions {
        keep_live_rows(&emit, d);
    }
    let mut fns = Vec::new();
    for d in &directions {
        fns.push(direction(a, ident, &emit, d));
        if let Some(t) = &d.dynamics {
            fns.push(dynamics::items(ident, vis, d, t));
        }
        if d.stiffness.is_some() {
            fns.push(stiffness::items(ident, d));
        }
        // The slice solvers only where the description asks for sweeps.
        if a.mechanism.wants(crate::semantics::mechanism::Capability::Workspace) {
            fns.push(batch::generate(ident, &emit, d));
        }
    }
    let prepared = format_ident!("{}Prepared", ident);
    let params_ty = format_ident!("{}Params", ident);
    let (fields, prepare) = emit.prepared(&prepared);
    let doc = format!(
        " `{}` prepared at its parameters ([`{ident}::prepare`]): what depends on the dimensions alone, computed once.",
        a.mechanism.name
    );
    let prepared_struct = prepared_struct(&doc, vis, &prepared, &fields);
    let items = quote! {
        #prepared_struct

        #[automatically_derived]
        impl #ident {
            /// The solver prepared at `params`: every product of the
            /// dimensions the solvers use, computed once.
            pub fn prepare(params: &#params_ty) -> #prepared {
                let _ = params;
                #prepare
            }
        }

        #(#fns)*
    };
    Ok(Generated { items, inverse_groups })
}

/// The prepared struct of a solver (`NamePrepared`, `NameFkNumeric`): the
/// named slots `Emit::prepared` computed from the dimensions alone.
fn prepared_struct(
    doc: &str,
    vis: &syn::Visibility,
    prepared: &proc_macro2::Ident,
    fields: &TokenStream,
) -> TokenStream {
    quote! {
        #[doc = #doc]
        #[derive(Debug, Clone, Copy, PartialEq)]
        #[allow(non_snake_case)]
        #vis struct #prepared {
            #fields
        }
    }
}

/// The first check of every generated function that takes `given`: a value
/// that is not finite is refused before any arithmetic.
fn given_is_finite() -> TokenStream {
    quote! {
        if !given.iter().all(|v| v.is_finite()) {
            return ::core::result::Result::Err(::pkm::runtime::__private::solution::SolveError::BadInput {
                what: ::std::borrow::Cow::Borrowed("a given value is not finite"),
            });
        }
    }
}

/// The prepared functions of one direction: one branch (lean and with the
/// whole solution), every branch, and the derivatives.
fn direction(a: &Analysis, ident: &proc_macro2::Ident, emit: &Emit, d: &Direction) -> TokenStream {
    let m = &a.mechanism;
    let (name, what) = if d.forward {
        ("fk", "Forward")
    } else {
        ("ik", "Inverse")
    };
    let n_given = d.plan.n_inputs;
    let n_choices = d.plan.branches;
    // What the solution is verified by, and whose it is (for errors).
    let open = d.plan.checks(m.joints.len());
    let open_names: Vec<String> = open
        .iter()
        .map(|c| c.owner(d.plan, |j| m.joints[j].name.clone(), |l| m.links[l].name.clone()))
        .collect();
    // The owner of each emitted row.
    let row_owners: Vec<String> = d.rows.iter().map(|r| open_names[r / RESIDUAL_ROWS].clone()).collect();
    let given_names = if d.forward {
        quote! { #ident::INPUTS }
    } else {
        quote! { #ident::OUTPUTS }
    };
    let angular: Vec<bool> = match crate::lowering::numeric::model(a, &Default::default()) {
        Ok(model) => d.plan.angular_inputs(&model),
        Err(_) => vec![false; n_given],
    };
    let parts = Parts {
        emit,
        d,
        what,
        rt: quote! { ::pkm::runtime::__private::solution },
        f_branch: format_ident!("{}_branch", name),
        f_unverified: format_ident!("{}_unverified", name),
        f_inconsistent: format_ident!("{}_inconsistent", name),
        n_result: d.given.result.len(),
        n_rows: d.given.residual.len(),
        verified: !d.rows.is_empty(),
        given_sig: quote! { given: &[f64; #n_given], signs: [::pkm::runtime::__private::primitives::Sign; #n_choices] },
        finite: given_is_finite(),
    };
    let lean = parts.lean(&row_owners, &angular, &given_names);
    let solution = parts.solution(
        &format_ident!("{}_solution", name),
        &format_ident!("{}Solution", ident),
        m,
    );
    let all = parts.every_branch(&format_ident!("{}", name), &conventions_doc(a, d.plan));
    let check_of = |rest: &[TokenStream]| parts.check_of(rest);
    let derivatives = derivative_fns(emit, d, &parts.given_sig, &parts.finite, &check_of, name, what);
    let inverse_dynamics = d
        .dynamics
        .as_ref()
        .map(|t| dynamics::functions(ident, emit, d, t, &parts.given_sig, &parts.finite, &check_of));
    let stiffness = d
        .stiffness
        .as_ref()
        .map(|t| stiffness::functions(emit, d, t, &parts.given_sig, &parts.finite, &check_of));
    let prepared = format_ident!("{}Prepared", ident);
    quote! {
        #[automatically_derived]
        impl #prepared {
            #lean
            #all
            #solution
            #derivatives
            #inverse_dynamics
            #stiffness
        }
    }
}

/// What the functions of one direction share: names, sizes and the
/// pieces of code every one of them writes.
struct Parts<'a> {
    emit: &'a Emit<'a>,
    d: &'a Direction<'a>,
    what: &'static str,
    rt: TokenStream,
    f_branch: proc_macro2::Ident,
    f_unverified: proc_macro2::Ident,
    f_inconsistent: proc_macro2::Ident,
    n_result: usize,
    n_rows: usize,
    /// Whether some joint no step closes (or a pin) verifies the solution.
    verified: bool,
    given_sig: TokenStream,
    finite: TokenStream,
}

impl Parts<'_> {
    /// The residual rows, then the extent they are measured against.
    fn rows_of(&self, rest: &[TokenStream]) -> (TokenStream, TokenStream) {
        let (residual, extent) = rest.split_at(self.n_rows);
        (quote! { [#(#residual),*] }, extent[0].clone())
    }

    /// The verification of a function whose last roots are the residual rows and the extent.
    fn check_of(&self, rest: &[TokenStream]) -> TokenStream {
        self.check(
            rest,
            &quote! { signs },
            |e| quote! { return ::core::result::Result::Err(#e); },
        )
    }

    /// The residual rows measured against the extent: where one is beyond,
    /// `exit` leaves with the inconsistency of the branch `signs`.
    fn check(
        &self,
        rest: &[TokenStream],
        signs: &TokenStream,
        exit: impl FnOnce(TokenStream) -> TokenStream,
    ) -> TokenStream {
        if !self.verified {
            return quote! {};
        }
        let f_inconsistent = &self.f_inconsistent;
        let (rows, extent) = self.rows_of(rest);
        let exit = exit(quote! { self.#f_inconsistent(given, #signs, row, gap, extent) });
        quote! {
            let extent = #extent;
            let rows = #rows;
            if let ::core::option::Option::Some((row, gap)) = ::pkm::runtime::__private::consistency::beyond(&rows, extent) {
                #exit
            }
        }
    }

    /// One branch, the caller's signs: the result alone (with its
    /// unverified core and the inconsistency it may find).
    fn lean(&self, row_owners: &[String], angular: &[bool], given_names: &TokenStream) -> TokenStream {
        let Parts {
            emit,
            d,
            what,
            rt,
            f_branch,
            f_unverified,
            f_inconsistent,
            n_result,
            n_rows,
            given_sig,
            finite,
            ..
        } = self;
        let n_given = d.plan.n_inputs;
        let mut roots = d.given.result.clone();
        roots.extend(&d.given.residual);
        roots.push(d.given.extent);
        let (lets, exprs) = emit.straight(&roots, &emit.needed_guards(&roots, &d.given.guards, &d.given.waivable));
        let (result, rest) = exprs.split_at(*n_result);
        let (rows, extent) = self.rows_of(rest);
        let verified_doc = " Verified: the joints no step closes must close.";
        let lean_doc = if d.forward {
            format!(" {what} position for one branch (`signs[k]` for the plan's k-th ± choice): the declared outputs (`OUTPUTS`).")
        } else {
            format!(" {what} position for one branch (`signs[k]` for the plan's k-th ± choice): the actuators' values (`INPUTS`).")
        };
        if !self.verified {
            quote! {
                #[doc = #lean_doc]
                pub fn #f_branch(&self, #given_sig) -> ::core::result::Result<[f64; #n_result], #rt::SolveError> {
                    let _ = &signs;
                    #finite
                    #lets
                    ::core::result::Result::Ok([#(#result),*])
                }
            }
        } else {
            quote! {
                #[doc = #lean_doc]
                #[doc = #verified_doc]
                #[inline]
                pub fn #f_branch(&self, #given_sig) -> ::core::result::Result<[f64; #n_result], #rt::SolveError> {
                    let (result, rows, extent) = self.#f_unverified(given, signs)?;
                    if let ::core::option::Option::Some((row, gap)) = ::pkm::runtime::__private::consistency::beyond(&rows, extent) {
                        return ::core::result::Result::Err(self.#f_inconsistent(given, signs, row, gap, extent));
                    }
                    ::core::result::Result::Ok(result)
                }

                /// One branch unverified: the result, the open joints' residual rows, their extent.
                #[inline]
                fn #f_unverified(&self, #given_sig) -> ::core::result::Result<([f64; #n_result], [f64; #n_rows], f64), #rt::SolveError> {
                    let _ = &signs;
                    #finite
                    #lets
                    let extent = #extent;
                    ::core::result::Result::Ok(([#(#result),*], #rows, extent))
                }

                /// Why a branch whose open joint does not close is inconsistent:
                /// the given value the others contradict, found by re-solving nearby.
                #[cold]
                fn #f_inconsistent(&self, #given_sig, row: usize, gap: f64, extent: f64) -> #rt::SolveError {
                    const OWNER: [&str; #n_rows] = [#(#row_owners),*];
                    const ANGULAR: [bool; #n_given] = [#(#angular),*];
                    let owner = ::std::borrow::Cow::Borrowed(OWNER[row]);
                    let e = ::pkm::runtime::__private::consistency::inconsistent(owner, gap, given, &ANGULAR, extent, |g| {
                        let g: &[f64; #n_given] = g.try_into().ok()?;
                        self.#f_unverified(g, signs).ok().map(|r| r.1.to_vec())
                    });
                    ::pkm::runtime::__private::consistency::name_given(e, &#given_names)
                }
            }
        }
    }

    /// The whole solution, one branch: every joint value and every point.
    fn solution(
        &self,
        f_solution: &proc_macro2::Ident,
        sol_ty: &proc_macro2::Ident,
        m: &crate::semantics::mechanism::Mechanism,
    ) -> TokenStream {
        let Parts {
            emit,
            d,
            what,
            rt,
            given_sig,
            finite,
            ..
        } = self;
        let mut roots: Vec<Sym> = d.given.values.clone();
        roots.extend(d.given.balls.iter().flatten());
        roots.extend(d.given.points.iter().flatten());
        roots.extend(&d.given.outputs);
        roots.extend(&d.given.residual);
        roots.push(d.given.extent);
        let (lets, exprs) = emit.straight(&roots, &emit.needed_guards(&roots, &d.given.guards, &d.given.waivable));
        let n_joints = m.joints.len();
        let n_points = d.given.points.len();
        let n_outputs = d.given.outputs.len();
        let (values, rest) = exprs.split_at(n_joints);
        let (balls, rest) = rest.split_at(3 * d.given.balls.len());
        let balls: Vec<TokenStream> = balls.chunks(3).map(xyz).collect();
        let (points, rest) = rest.split_at(3 * n_points);
        let (outputs, rest) = rest.split_at(n_outputs);
        // A planar mechanism's points are (x, y): its plane is z = 0.
        let dim = if m.planar { 2 } else { 3 };
        let points: Vec<TokenStream> = points.chunks(3).map(|p| xyz(&p[..dim])).collect();
        let check = self.check_of(rest);
        let solution_doc = format!(" {what} position for one branch: every joint value and every point.");
        quote! {
            #[doc = #solution_doc]
            pub fn #f_solution(&self, #given_sig) -> ::core::result::Result<#sol_ty, #rt::SolveError> {
                let _ = &signs;
                #finite
                #lets
                #check
                ::core::result::Result::Ok(#sol_ty {
                    q: [#(#values),*],
                    balls: [#(#balls),*],
                    points: [#(#points),*],
                    outputs: [#(#outputs),*],
                })
            }
        }
    }

    /// Every branch, what they share computed once; double roots marked.
    fn every_branch(&self, f_all: &proc_macro2::Ident, conventions: &TokenStream) -> TokenStream {
        let Parts {
            emit,
            d,
            what,
            rt,
            n_result,
            ..
        } = self;
        let n_given = d.plan.n_inputs;
        let n_choices = d.plan.branches;
        // Each branch's result, what its choices solved (what tells it
        // from the others, as two assemblies may give one result), then
        // its check.
        let n_key = d.every[0].choices.len();
        let roots: Vec<Vec<Sym>> = d
            .every
            .iter()
            .map(|b| {
                let mut r = b.result.clone();
                r.extend(&b.choices);
                r.extend(&b.residual);
                r.push(b.extent);
                r
            })
            .collect();
        let n_solutions = d.every.len();
        let guards: Vec<Vec<Sym>> = d
            .every
            .iter()
            .zip(&roots)
            .map(|(b, r)| emit.needed_guards(r, &b.guards, &b.waivable))
            .collect();
        let body = emit.branches(&roots, &guards, n_choices, &|b, exprs, label| {
            let (result, rest) = exprs.split_at(*n_result);
            let (key, rest) = rest.split_at(n_key);
            let signs = quote! { #rt::signs_of::<#n_choices>(#b) };
            let check = self.check(
                rest,
                &signs,
                |e| quote! { break #label (::core::result::Result::Err(#e)); },
            );
            let keep = (n_key > 0).then(|| quote! { keys[#b] = [#(#key),*]; });
            quote! {
                #check
                #keep
                ::core::result::Result::Ok([#(#result),*])
            }
        });
        // One branch has no twin to tell it from.
        let (keys, mark) = if n_key == 0 {
            (quote! {}, quote! {})
        } else {
            (
                quote! { let mut keys = [[0.0f64; #n_key]; #n_solutions]; },
                quote! { ::pkm::runtime::__private::consistency::mark_double_roots_by(&mut all, &keys); },
            )
        };
        let all_doc = format!(
            " {what} position, every branch ({n_solutions}, in `signs_of` order), \
             what the branches share computed once."
        );
        quote! {
            #[doc = #all_doc]
            /// A branch that is another's solution again (a double root: what
            /// its ± choices solved agrees) is `SolveError::DoubleRoot`, and
            /// its twin is `tangent`; two assemblies with one result (the two
            /// postures of a leg that reach the same platform) are both listed.
            #conventions
            pub fn #f_all(&self, given: &[f64; #n_given]) -> [#rt::Branch<[f64; #n_result], #n_choices>; #n_solutions] {
                let mut all: [#rt::Branch<[f64; #n_result], #n_choices>; #n_solutions] = ::core::array::from_fn(|i| #rt::Branch {
                    signs: #rt::signs_of::<#n_choices>(i),
                    result: ::core::result::Result::Err(#rt::SolveError::BadInput {
                        what: ::std::borrow::Cow::Borrowed("a given value is not finite"),
                    }),
                    tangent: false,
                });
                #keys
                if given.iter().all(|v| v.is_finite()) {
                    #body
                }
                #mark
                all
            }
        }
    }
}

/// The doc lines naming the postures `plan` fixes by a convention instead
/// of listing them ([`Plan::conventions`]); none where it lists every one.
pub(crate) fn conventions_doc(a: &Analysis, plan: &Plan) -> TokenStream {
    let m = &a.mechanism;
    let lines = plan.conventions(|j| m.joints[j].name.clone(), |l| m.links[l].name.clone());
    if lines.is_empty() {
        return TokenStream::new();
    }
    let lines = lines.iter().map(|l| format!(" - {l}."));
    quote! {
        ///
        /// Postures not listed, by convention (the outputs and the actuators' values do not depend on them):
        #(#[doc = #lines])*
    }
}

/// `fk_rates` and `fk_jacobian` (or `ik_…`): the result's derivative along
/// given rates and along each given value, written out with the solution,
/// verified like it; `fk_accelerations` where `acceleration` is asked for.
#[allow(clippy::too_many_arguments)]
fn derivative_fns(
    emit: &Emit,
    d: &Direction,
    given_sig: &TokenStream,
    finite: &TokenStream,
    check_of: &dyn Fn(&[TokenStream]) -> TokenStream,
    name: &str,
    what: &str,
) -> TokenStream {
    let (Some(rates), Some(jacobian)) = (&d.rates, &d.jacobian) else {
        return TokenStream::new();
    };
    let rt = quote! { ::pkm::runtime::__private::solution };
    let (n_given, n_result) = (d.plan.n_inputs, d.given.result.len());
    let tail = |roots: &mut Vec<Sym>| {
        roots.extend(&d.given.residual);
        roots.push(d.given.extent);
    };
    let f_rates = format_ident!("{}_rates", name);
    let f_jacobian = format_ident!("{}_jacobian", name);
    let mut roots = d.given.result.clone();
    roots.extend(rates);
    tail(&mut roots);
    let (lets, exprs) = emit.straight(&roots, &emit.needed_guards(&roots, &d.given.guards, &d.given.waivable));
    let (result, rest) = exprs.split_at(n_result);
    let (rate, rest) = rest.split_at(n_result);
    let check = check_of(rest);
    let rates_doc = format!(
        " {what} position and its rates for one branch: the result of `{name}_branch` and its derivative along the given values' `rates`, written out with it (no finite differences)."
    );
    let mut roots: Vec<Sym> = jacobian.iter().flatten().copied().collect();
    tail(&mut roots);
    let (jlets, jexprs) = emit.straight(&roots, &emit.needed_guards(&roots, &d.given.guards, &d.given.waivable));
    let (columns, rest) = jexprs.split_at(n_given * n_result);
    let jcheck = check_of(rest);
    let rows = (0..n_result).map(|r| {
        let row = (0..n_given).map(|k| &columns[k * n_result + r]);
        quote! { [#(#row),*] }
    });
    let jacobian_doc =
        format!(" {what} Jacobian for one branch: row r, column k is the derivative of result r along given value k.");
    let accelerations = d.accelerations.as_ref().map(|accelerations| {
        let f_accelerations = format_ident!("{}_accelerations", name);
        let mut roots = d.given.result.clone();
        roots.extend(rates);
        roots.extend(accelerations);
        tail(&mut roots);
        let (lets, exprs) = emit.straight(&roots, &emit.needed_guards(&roots, &d.given.guards, &d.given.waivable));
        let (result, rest) = exprs.split_at(n_result);
        let (rate, rest) = rest.split_at(n_result);
        let (acceleration, rest) = rest.split_at(n_result);
        let check = check_of(rest);
        let doc = format!(
            " {what} position, its rates and its accelerations for one branch: the result of `{name}_branch`, its first derivative in time for the given values' `rates`, and its second for their `rates` and `accelerations` (d²f/dt² = D²f[q̇, q̇] + Df·q̈), written out with it."
        );
        quote! {
            #[doc = #doc]
            #[allow(clippy::type_complexity)]
            pub fn #f_accelerations(
                &self,
                #given_sig,
                rates: &[f64; #n_given],
                accelerations: &[f64; #n_given],
            ) -> ::core::result::Result<([f64; #n_result], [f64; #n_result], [f64; #n_result]), #rt::SolveError> {
                let _ = (&signs, rates, accelerations);
                #finite
                #lets
                #check
                ::core::result::Result::Ok(([#(#result),*], [#(#rate),*], [#(#acceleration),*]))
            }
        }
    });
    quote! {
        #accelerations

        #[doc = #rates_doc]
        pub fn #f_rates(&self, #given_sig, rates: &[f64; #n_given]) -> ::core::result::Result<([f64; #n_result], [f64; #n_result]), #rt::SolveError> {
            let _ = (&signs, rates);
            #finite
            #lets
            #check
            ::core::result::Result::Ok(([#(#result),*], [#(#rate),*]))
        }

        #[doc = #jacobian_doc]
        pub fn #f_jacobian(&self, #given_sig) -> ::core::result::Result<[[f64; #n_given]; #n_result], #rt::SolveError> {
            let _ = &signs;
            #finite
            #jlets
            #jcheck
            ::core::result::Result::Ok([#(#rows),*])
        }
    }
}

#[cfg(test)]
mod tests {
    /// The inverse plan's choice groups of an example, as
    /// `(choices, actuated joints)`.
    fn groups(file: &str) -> Vec<(Vec<usize>, Vec<usize>)> {
        let path = format!("{}/../examples/mechanisms/{file}", env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(path).unwrap();
        let a = crate::topology::analysis::analyze_source(&text).unwrap();
        let ik = crate::plan::planner::inverse_plan(&a).unwrap();
        let ident = quote::format_ident!("M");
        let vis: syn::Visibility = syn::parse_quote!(pub);
        let g = super::generate(&a, &ident, &vis, None, Some(&ik)).unwrap();
        g.inverse_groups.into_iter().map(|g| (g.choices, g.joints)).collect()
    }

    /// The 6-UPS (Dietmaier's `fk_numeric` solves each root by these):
    /// each leg's sense is its own choice and moves only its own slide (the
    /// file's comment: 2⁶ branches, one with every slide positive), so six
    /// groups of one. The 3-UPU: the same, three legs. The 3-RPS: the
    /// platform's parasitic motion (its x, y and turn about z, solved from
    /// the declared z, rx, ry with ± choices) moves every leg, so one group
    /// holds every choice and every slide, and every branch is solved.
    #[test]
    fn choices_are_grouped_by_the_actuated_joints_they_move() {
        let one_each = |n: usize| (0..n).map(|k| (vec![k], vec![k])).collect::<Vec<_>>();
        assert_eq!(groups("ups_6.pkm"), one_each(6));
        assert_eq!(groups("upu_3.pkm"), one_each(3));
        assert_eq!(groups("rps_3.pkm"), [(vec![0, 1, 2, 3], vec![0, 1, 2])]);
    }
}
