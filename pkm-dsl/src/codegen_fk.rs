//! Generated forward position solvers: straight-line calls of the runtime's
//! step kernels, with every local coordinate written out as an expression in
//! the parameters. The plan interpreter walks the same plan with the same
//! kernels; only where the coordinates come from differs.

use crate::analysis::Analysis;
use crate::geometry::{JointPlace, Vec3};
use pkm_runtime::plan::{Plan, Step};
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

fn xy(v: &Vec3) -> TokenStream {
    let params = quote! { params };
    let (x, y) = (v[0].to_tokens(&params), v[1].to_tokens(&params));
    quote! { [#x, #y] }
}

fn point(p: &JointPlace) -> TokenStream {
    match p {
        JointPlace::Point(at, _) | JointPlace::Line(at, _) | JointPlace::Arm(at, _, _) => xy(at),
    }
}

/// A point of a link (a joint placed on it or a named point), in its frame.
fn local_point(a: &Analysis, at: pkm_runtime::plan::PointRef, link: usize) -> TokenStream {
    match at {
        pkm_runtime::plan::PointRef::Joint(j) => point(a.place(j, link)),
        pkm_runtime::plan::PointRef::Named(n) => xy(&a.geometry.points[n].at),
    }
}

/// Which angle a point-and-angle output carries.
pub(crate) enum Angle {
    /// None: a point alone.
    None,
    /// The planar angle.
    Planar,
    /// The angle about a spatial axis (the prepared solver writes it).
    About,
}

/// Every declared output's values: `let` statements and the flat list of
/// values in order. `pose` writes a link's point and angle as an array for
/// its dimension; a joint's value is `values[j]`.
pub(crate) fn outputs(
    a: &Analysis,
    mut pose: impl FnMut(usize, pkm_runtime::plan::PointRef, Angle) -> TokenStream,
) -> (TokenStream, Vec<TokenStream>) {
    use crate::geometry::OutputKind;
    let (mut lets, mut flat) = (Vec::new(), Vec::new());
    for (k, o) in a.geometry.outputs.iter().enumerate() {
        let array = match &o.kind {
            OutputKind::Pose { link, point, about } => pose(
                *link,
                *point,
                match about {
                    Some(_) => Angle::About,
                    None if a.mechanism.planar => Angle::Planar,
                    None => Angle::None,
                },
            ),
            OutputKind::Point { link, point } => pose(*link, *point, Angle::None),
            OutputKind::Joint(j) => quote! { [values[#j]] },
        };
        let o_k = format_ident!("output_{}", k);
        lets.push(quote! { let #o_k = #array; });
        flat.extend((0..o.names.len()).map(|i| quote! { #o_k[#i] }));
    }
    (quote! { #(#lets)* }, flat)
}

fn pose(l: usize) -> proc_macro2::Ident {
    format_ident!("pose_{}", l)
}

/// Which solver to generate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// Forward: inputs to every joint and point.
    Forward,
    /// Inverse: outputs to every joint and point.
    Inverse,
}

/// The solution struct and the constants both solvers share.
pub fn solution_items(a: &Analysis, ident: &proc_macro2::Ident, vis: &syn::Visibility) -> TokenStream {
    let m = &a.mechanism;
    let sol_ty = format_ident!("{}Solution", ident);
    let n_joints = m.joints.len();
    let mut point_names: Vec<String> = m.joints.iter().map(|j| j.name.clone()).collect();
    point_names.extend(a.geometry.points.iter().map(|p| p.name.clone()));
    let n_points = point_names.len();
    let joint_names: Vec<&str> = m.joints.iter().map(|j| j.name.as_str()).collect();
    let revolute: Vec<bool> = m.joints.iter().map(|j| j.kind != crate::model::JointKind::P).collect();
    let dim: usize = if m.planar { 2 } else { 3 };
    let output_names: Vec<&str> = a
        .geometry
        .outputs
        .iter()
        .flat_map(|o| o.names.iter().map(String::as_str))
        .collect();
    let n_outputs = output_names.len();
    let output_angles: Vec<bool> = a
        .geometry
        .outputs
        .iter()
        .flat_map(|o| {
            let n = o.names.len();
            (0..n).map(move |i| match &o.kind {
                crate::geometry::OutputKind::Pose { about, .. } => i == 3 || (m.planar && i == 2 && about.is_none()),
                crate::geometry::OutputKind::Point { .. } => false,
                crate::geometry::OutputKind::Joint(j) => m.joints[*j].kind != crate::model::JointKind::P,
            })
        })
        .collect();
    let sol_doc = format!(
        " One position solution of `{}`: every joint value and every point.",
        m.name
    );
    quote! {
        #[doc = #sol_doc]
        #[derive(Debug, Clone, Copy, PartialEq)]
        #vis struct #sol_ty {
            /// Joint values in declaration order (radians for R, lengths for P); see `JOINTS`.
            pub q: [f64; #n_joints],
            /// Every joint's point, then every named point (x, y, and z in a
            /// spatial mechanism); see `POINTS`.
            pub points: [[f64; #dim]; #n_points],
            /// The declared outputs (the inverse solution's given values); see `OUTPUTS`.
            pub outputs: [f64; #n_outputs],
        }

        #[automatically_derived]
        impl #ident {
            /// The joints, in the order of a solution's `q`.
            pub const JOINTS: [&'static str; #n_joints] = [#(#joint_names),*];
            /// The points, in the order of a solution's `points`.
            pub const POINTS: [&'static str; #n_points] = [#(#point_names),*];
            /// Which joints are revolute (their values are angles).
            pub const REVOLUTE: [bool; #n_joints] = [#(#revolute),*];
            /// The declared outputs, in the order of a solution's `outputs` and
            /// of the inverse solution's given values.
            pub const OUTPUTS: [&'static str; #n_outputs] = [#(#output_names),*];
            /// Which outputs are angles (compare them modulo 2π).
            pub const OUTPUT_ANGLES: [bool; #n_outputs] = [#(#output_angles),*];
        }
    }
}

/// The solver functions for one direction: `fk`, `fk_branch`, `fk_follow`
/// (or `ik`, …) and the names of their values (`INPUTS` or `OUTPUTS`).
/// A planar or a spatial plan.
#[derive(Debug, Clone, Copy)]
pub enum PlanRef<'p> {
    /// Planar (`Pose2`, dyads).
    Planar(&'p Plan),
    /// Spatial (`Pose3`, the spatial catalogue).
    Spatial(&'p pkm_runtime::spatial::Plan),
}

/// The solver functions for one direction: `fk`, `fk_branch`, `fk_follow`
/// (or `ik`, …) and the names of their values (`INPUTS` or `OUTPUTS`).
pub fn generate(a: &Analysis, plan: PlanRef, ident: &proc_macro2::Ident, direction: Direction) -> TokenStream {
    let sol_ty = format_ident!("{}Solution", ident);
    let mut checks = None;
    // A spatial plan's solver is prepared once for every branch of `fk`/`ik`.
    let mut prepared = None;
    let (body, result, branches, inputs, extra) = match plan {
        PlanRef::Planar(p) => {
            let (body, result, branches, inputs) = planar_body(a, p, &sol_ty);
            checks = planar_checks(a, p);
            (body, result, branches, inputs, TokenStream::new())
        }
        PlanRef::Spatial(p) => {
            // The prepared solver (`codegen_solver`) does the work.
            let f = match direction {
                Direction::Forward => format_ident!("fk_solution"),
                Direction::Inverse => format_ident!("ik_solution"),
            };
            prepared = Some(f.clone());
            (
                quote! { let solution = Self::prepare(params).#f(q, signs)?; },
                quote! { solution },
                p.branches,
                p.inputs.clone(),
                TokenStream::new(),
            )
        }
    };
    let solver = wrap(a, ident, direction, body, result, branches, &inputs, checks, prepared);
    quote! { #solver #extra }
}

/// What a planar solution is verified by, where its plan leaves something
/// unchecked: each row's expression (2 values each) and owner, and which
/// given values are angles.
struct Checks {
    rows: Vec<TokenStream>,
    owners: Vec<String>,
    angular: Vec<bool>,
}

/// The residual rows of a planar plan (the runtime's `plan::run` checks the
/// same): every open joint, every given point a later dyad moves its link
/// about. `None` when every joint is closed by a step and no point is pinned.
fn planar_checks(a: &Analysis, plan: &Plan) -> Option<Checks> {
    let m = &a.mechanism;
    let rt = quote! { ::pkm::runtime::plan };
    let (mut rows, mut owners) = (Vec::new(), Vec::new());
    for j in plan.open_joints(m.joints.len()) {
        let joint = &m.joints[j];
        let (u, v) = (joint.links[0], joint.links[1]);
        let (pu, pv) = (pose(u), pose(v));
        rows.push(match (joint.kind, a.place(j, u), a.place(j, v)) {
            (crate::model::JointKind::P, JointPlace::Line(t, d), other) => {
                let (t, d, s) = (xy(t), xy(d), point(other));
                quote! { #rt::prismatic_residual(#pu, #t, #d, #pv, #s, extent) }
            }
            (crate::model::JointKind::P, other, JointPlace::Line(t, d)) => {
                let (t, d, s) = (xy(t), xy(d), point(other));
                quote! { #rt::prismatic_residual(#pv, #t, #d, #pu, #s, extent) }
            }
            (_, at_u, at_v) => {
                let (at_u, at_v) = (point(at_u), point(at_v));
                quote! { #rt::point_residual(#pu.apply(#at_u), #pv.apply(#at_v)) }
            }
        });
        owners.extend(std::iter::repeat_n(format!("joint {}", joint.name), 2));
    }
    for s in &plan.steps {
        if let Step::PlacePoint { link, point: at, input } = *s {
            let (p, local, i1) = (pose(link), local_point(a, at, link), input + 1);
            rows.push(quote! { #rt::point_residual(#p.apply(#local), [q[#input], q[#i1]]) });
            owners.extend(std::iter::repeat_n(
                format!("the given point of link {}", m.links[link].name),
                2,
            ));
        }
    }
    if rows.is_empty() {
        return None;
    }
    let angular = match crate::plan::model(a, &Default::default()) {
        Ok(model) => plan.angular_inputs(&model),
        Err(_) => vec![false; plan.inputs.len()],
    };
    Some(Checks { rows, owners, angular })
}

/// The straight-line body of a planar solver, the expression of its
/// solution, its number of ± choices and its input joints.
fn planar_body(
    a: &Analysis,
    plan: &Plan,
    sol_ty: &proc_macro2::Ident,
) -> (TokenStream, TokenStream, usize, Vec<usize>) {
    let m = &a.mechanism;
    let rt = quote! { ::pkm::runtime::plan };
    let mut body = vec![quote! { let pose_0 = #rt::Pose2::IDENTITY; }];
    for (k, step) in plan.steps.iter().enumerate() {
        match *step {
            Step::Place { link, point: at, input } => {
                let p = pose(link);
                let local = local_point(a, at, link);
                let (i1, i2) = (input + 1, input + 2);
                body.push(quote! { let #p = #rt::place_at(#local, q[#input], q[#i1], q[#i2]); });
            }
            Step::PlacePoint { link, point: at, input } => {
                // Only the point is given: angle 0 until a dyad through it fixes the link.
                let p = pose(link);
                let local = local_point(a, at, link);
                let i1 = input + 1;
                body.push(quote! { let #p = #rt::place_at(#local, q[#input], q[#i1], 0.0); });
            }
            Step::Transfer { joint, from, to, input } => {
                let (pf, pt) = (pose(from), pose(to));
                let j = &m.joints[joint];
                let forward = j.links[0] == from;
                let value = if forward {
                    quote! { q[#input] }
                } else {
                    quote! { -q[#input] }
                };
                let call = match (a.place(joint, from), a.place(joint, to)) {
                    (JointPlace::Line(through, along), other) if j.kind == crate::model::JointKind::P => {
                        let (t, d, s) = (xy(through), xy(along), point(other));
                        quote! { #rt::along_guide(#pf, #t, #d, #s, q[#input]) }
                    }
                    (other, JointPlace::Line(through, along)) if j.kind == crate::model::JointKind::P => {
                        let (t, d, s) = (xy(through), xy(along), point(other));
                        quote! { #rt::onto_guide(#pf, #t, #d, #s, q[#input]) }
                    }
                    (f, t) => {
                        let (f, t) = (point(f), point(t));
                        quote! { #rt::through_revolute(#pf, #f, #t, #value) }
                    }
                };
                body.push(quote! { let #pt = #call; });
            }
            Step::Rrr {
                joints: [ja, jb, jc],
                links: [k1, l1, l2, k2],
                branch,
            } => {
                let (p1, p2, pk1, pk2) = (pose(l1), pose(l2), pose(k1), pose(k2));
                let c = [
                    point(a.place(ja, k1)),
                    point(a.place(ja, l1)),
                    point(a.place(jb, l1)),
                    point(a.place(jb, l2)),
                    point(a.place(jc, l2)),
                    point(a.place(jc, k2)),
                ];
                let [c0, c1, c2, c3, c4, c5] = c;
                let name = [ja, jb, jc].map(|j| m.joints[j].name.as_str()).join("–");
                body.push(quote! {
                    let (#p1, #p2) = #rt::rrr_dyad(#pk1, #c0, #c1, #c2, #c3, #c4, #c5, #pk2, signs[#branch])
                        .map_err(|e| #rt::step_error(#k, #name, e))?;
                });
            }
            Step::Rrp {
                joints: [ja, jb, jc],
                links: [k1, l1, l2, k2],
                branch,
            } => {
                let (p1, p2, pk1, pk2) = (pose(l1), pose(l2), pose(k1), pose(k2));
                let (c0, c1, c2, c3) = (
                    point(a.place(ja, k1)),
                    point(a.place(ja, l1)),
                    point(a.place(jb, l1)),
                    point(a.place(jb, l2)),
                );
                let slider = point(a.place(jc, l2));
                let JointPlace::Line(through, along) = a.place(jc, k2) else {
                    unreachable!("the planner checked the guide")
                };
                let (t, d) = (xy(through), xy(along));
                let name = [ja, jb, jc].map(|j| m.joints[j].name.as_str()).join("–");
                body.push(quote! {
                    let (#p1, #p2) = #rt::rrp_dyad(#pk1, #c0, #c1, #c2, #c3, #slider, #t, #d, #pk2, signs[#branch])
                        .map_err(|e| #rt::step_error(#k, #name, e))?;
                });
            }
        }
    }

    // Joint values and points from the poses.
    let values = m.joints.iter().enumerate().map(|(j, joint)| {
        let (u, v) = (joint.links[0], joint.links[1]);
        let (pu, pv) = (pose(u), pose(v));
        match (joint.kind, a.place(j, u), a.place(j, v)) {
            (crate::model::JointKind::P, JointPlace::Line(t, d), other) => {
                let (t, d, s) = (xy(t), xy(d), point(other));
                quote! { #rt::prismatic_value(#pu, #t, #d, #pv, #s) }
            }
            (crate::model::JointKind::P, other, JointPlace::Line(t, d)) => {
                let (t, d, s) = (xy(t), xy(d), point(other));
                quote! { #rt::prismatic_value(#pv, #t, #d, #pu, #s) }
            }
            _ => quote! { #rt::revolute_value(#pu, #pv) },
        }
    });
    let mut points = Vec::new();
    for j in 0..m.joints.len() {
        let l = a.point_link(j);
        let (p, at) = (pose(l), point(a.place(j, l)));
        points.push(quote! { #p.apply(#at) });
    }
    for np in &a.geometry.points {
        let (p, at) = (pose(np.link), xy(&np.at));
        points.push(quote! { #p.apply(#at) });
    }
    let (lets, outputs) = outputs(a, |link, at, about| {
        let (p, local) = (pose(link), local_point(a, at, link));
        match about {
            Angle::None => quote! { #p.apply(#local) },
            // The link's angle in (−π, π].
            _ => quote! {{ let [x, y] = #p.apply(#local); [x, y, #p.sin.atan2(#p.cos)] }},
        }
    });
    let result = quote! {{
        let values = [#(#values),*];
        #lets
        #sol_ty { q: values, points: [#(#points),*], outputs: [#(#outputs),*] }
    }};
    (quote! { #(#body)* }, result, plan.branches, plan.inputs.clone())
}

#[allow(clippy::too_many_arguments)]
fn wrap(
    a: &Analysis,
    ident: &proc_macro2::Ident,
    direction: Direction,
    body: TokenStream,
    result: TokenStream,
    n_branches: usize,
    inputs: &[usize],
    checks: Option<Checks>,
    prepared: Option<proc_macro2::Ident>,
) -> TokenStream {
    let m = &a.mechanism;
    let rt = quote! { ::pkm::runtime::plan };
    let params_ty = format_ident!("{}Params", ident);
    let sol_ty = format_ident!("{}Solution", ident);
    let (f_all, f_branch, f_follow, what) = match direction {
        Direction::Forward => (
            format_ident!("fk"),
            format_ident!("fk_branch"),
            format_ident!("fk_follow"),
            "Forward",
        ),
        Direction::Inverse => (
            format_ident!("ik"),
            format_ident!("ik_branch"),
            format_ident!("ik_follow"),
            "Inverse",
        ),
    };
    let n_solutions = 1usize << n_branches;

    let value_names: Vec<String> = match direction {
        Direction::Forward => inputs.iter().map(|&j| m.joints[j].name.clone()).collect(),
        Direction::Inverse => a
            .geometry
            .outputs
            .iter()
            .flat_map(|o| o.names.iter().cloned())
            .collect(),
    };
    let n_values = value_names.len();
    // Every branch from one prepared solver where there is one.
    let (prelude, solve) = match &prepared {
        Some(f) => (
            quote! { let prepared = Self::prepare(params); },
            quote! { prepared.#f(q, signs) },
        ),
        None => (quote! {}, quote! { Self::#f_branch(params, q, signs) }),
    };
    let branches = (0..n_solutions).map(|i| {
        quote! {{
            let signs = #rt::signs_of::<#n_branches>(#i);
            #rt::Branch { signs, result: #solve, tangent: false }
        }}
    });
    // The outputs' names are the solution's `OUTPUTS`; the inputs' are named here.
    let names_item = match direction {
        Direction::Forward => quote! {
            /// The actuated joints, in the order of the input vector.
            pub const INPUTS: [&'static str; #n_values] = [#(#value_names),*];
        },
        Direction::Inverse => quote! {},
    };
    let all_doc = format!(
        " {what} position, every branch: {n_solutions} solutions, listed by `signs_of` order. Given: {}.",
        value_names.join(", ")
    );
    let branch_doc = format!(" {what} position for one branch (`signs[k]` for the plan's k-th ± choice).");
    let finite = quote! {
        let _ = &signs;
        if !q.iter().all(|v| v.is_finite()) {
            return ::core::result::Result::Err(#rt::SolveError::BadInput {
                what: ::std::borrow::Cow::Borrowed("a given value is not finite"),
            });
        }
    };
    let given = quote! {
        params: &#params_ty,
        q: &[f64; #n_values],
        signs: [::pkm::runtime::primitives::Sign; #n_branches],
    };
    let branch_fns = match checks {
        None => quote! {
            #[doc = #branch_doc]
            pub fn #f_branch(#given) -> ::core::result::Result<#sol_ty, #rt::SolveError> {
                #finite
                #body
                ::core::result::Result::Ok(#result)
            }
        },
        Some(Checks { rows, owners, angular }) => {
            let f_unverified = format_ident!("{}_unverified", f_branch);
            let (n_rows, n_pairs) = (owners.len(), rows.len());
            let names = match direction {
                Direction::Forward => quote! { &Self::INPUTS },
                Direction::Inverse => quote! { &Self::OUTPUTS },
            };
            let n_joints = m.joints.len();
            quote! {
                #[doc = #branch_doc]
                /// The solution is verified: what the plan did not close must close.
                pub fn #f_branch(#given) -> ::core::result::Result<#sol_ty, #rt::SolveError> {
                    let (solution, rows, extent) = Self::#f_unverified(params, q, signs)?;
                    const OWNERS: [&str; #n_rows] = [#(#owners),*];
                    const ANGULAR: [bool; #n_values] = [#(#angular),*];
                    ::pkm::runtime::consistency::verify_rows(&rows, extent, &OWNERS, q, &ANGULAR, #names, |g| {
                        let g: &[f64; #n_values] = g.try_into().ok()?;
                        Self::#f_unverified(params, g, signs).ok().map(|(_, rows, _)| rows.to_vec())
                    })?;
                    ::core::result::Result::Ok(solution)
                }

                /// One branch's solution, its residual rows and their extent, unverified.
                fn #f_unverified(#given) -> ::core::result::Result<(#sol_ty, [f64; #n_rows], f64), #rt::SolveError> {
                    #finite
                    #body
                    let solution = #result;
                    let extent = ::pkm::runtime::consistency::extent(&solution.points[..#n_joints]);
                    let pairs: [[f64; 2]; #n_pairs] = [#(#rows),*];
                    let rows: [f64; #n_rows] = ::core::array::from_fn(|i| pairs.as_flattened()[i]);
                    ::core::result::Result::Ok((solution, rows, extent))
                }
            }
        }
    };
    quote! {
        #[automatically_derived]
        impl #ident {
            #names_item

            #[doc = #all_doc]
            /// A branch that is another's solution again (a double root, at a
            /// tangency) is `SolveError::DoubleRoot`, and its twin is `tangent`.
            pub fn #f_all(params: &#params_ty, q: &[f64; #n_values]) -> [#rt::Branch<#sol_ty, #n_branches>; #n_solutions] {
                #prelude
                let mut all = [#(#branches),*];
                ::pkm::runtime::consistency::mark_double_roots(&mut all, &Self::REVOLUTE, |s: &#sol_ty| &s.q[..]);
                all
            }

            #branch_fns
            /// Follows a trajectory: the branch nearest `previous` (the solution
            /// at the last given values), or, given the one before it too,
            /// nearest the linear prediction from both, which carries through
            /// tangencies where two ± branches exchange.
            pub fn #f_follow(
                params: &#params_ty,
                q: &[f64; #n_values],
                previous: &#sol_ty,
                before: ::core::option::Option<&#sol_ty>,
            ) -> ::core::result::Result<#sol_ty, #rt::SolveError> {
                let target = match before {
                    ::core::option::Option::Some(b) => #rt::extrapolate(&previous.q, &b.q, &Self::REVOLUTE),
                    ::core::option::Option::None => previous.q,
                };
                let all = Self::#f_all(params, q);
                match #rt::nearest_branch(&all, &target, &Self::REVOLUTE, |s: &#sol_ty| &s.q[..]) {
                    ::core::option::Option::Some(i) => all[i].result.clone(),
                    ::core::option::Option::None => all[0].result.clone(),
                }
            }
        }
    }
}
