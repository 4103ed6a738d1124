//! The solution type and the solvers on the mechanism's own type
//! (`Name::fk`, `fk_branch`, `fk_follow` and their `ik` twins): each
//! prepares the solver at the given parameters ([`crate::codegen::solver`])
//! and calls it.

use crate::topology::analysis::Analysis;
use pkm_runtime::plan::Plan;
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

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
    let revolute: Vec<bool> = m
        .joints
        .iter()
        .map(|j| j.kind != crate::semantics::mechanism::JointKind::P)
        .collect();
    let ball_names: Vec<&str> = m
        .joints
        .iter()
        .filter(|j| j.kind == crate::semantics::mechanism::JointKind::S)
        .map(|j| j.name.as_str())
        .collect();
    let n_balls = ball_names.len();
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
                crate::semantics::geometry::OutputKind::Pose { about, .. } => {
                    i == 3 || (m.planar && i == 2 && about.is_none())
                }
                crate::semantics::geometry::OutputKind::Point { .. } => false,
                crate::semantics::geometry::OutputKind::Parts { parts, .. } => {
                    parts.given().nth(i).is_some_and(|p| p >= 3)
                }
                crate::semantics::geometry::OutputKind::Joint(j) => {
                    m.joints[*j].kind != crate::semantics::mechanism::JointKind::P
                }
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
            /// Joint values in declaration order (radians for R, lengths for P,
            /// a ball's rotation angle θ in [0, π] for S); see `JOINTS`.
            pub q: [f64; #n_joints],
            /// Each spherical joint's rotation, in `JOINTS` order (see `BALLS`):
            /// the rotation vector `r = θ·n` of `R_uᵀ·R_v` between the poses of
            /// its two links as declared, the runtime model's form
            /// (`T_v = T_u · Trans(c_u) · Rot(r) · Trans(−c_v)`), the same three
            /// numbers as the interpreter's `Solution::model_values`.
            pub balls: [[f64; 3]; #n_balls],
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
            /// The spherical joints, in the order of a solution's `balls`.
            pub const BALLS: [&'static str; #n_balls] = [#(#ball_names),*];
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
pub fn generate(a: &Analysis, plan: &Plan, ident: &proc_macro2::Ident, direction: Direction) -> TokenStream {
    // The prepared solver (`codegen_solver`) does the work.
    let f = match direction {
        Direction::Forward => format_ident!("fk_solution"),
        Direction::Inverse => format_ident!("ik_solution"),
    };
    let m = &a.mechanism;
    let (n_branches, inputs) = (plan.branches, &plan.inputs);
    let rt = quote! { ::pkm::runtime::__private::solution };
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
    let conventions = crate::codegen::solver::conventions_doc(a, plan);

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
    // Every branch from one prepared solver.
    let branches = (0..n_solutions).map(|i| {
        quote! {{
            let signs = #rt::signs_of::<#n_branches>(#i);
            #rt::Branch { signs, result: prepared.#f(q, signs), tangent: false }
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
    let given = quote! {
        params: &#params_ty,
        q: &[f64; #n_values],
        signs: [::pkm::runtime::__private::primitives::Sign; #n_branches],
    };
    let branch_fns = quote! {
        #[doc = #branch_doc]
        /// Prepares the solver and solves: to solve often at the same
        /// parameters, prepare once (`prepare`) and call its solvers.
        pub fn #f_branch(#given) -> ::core::result::Result<#sol_ty, #rt::SolveError> {
            Self::prepare(params).#f(q, signs)
        }
    };
    quote! {
        #[automatically_derived]
        impl #ident {
            #names_item

            #[doc = #all_doc]
            /// A branch that is another's solution again (a double root, at a
            /// tangency) is `SolveError::DoubleRoot`, and its twin is `tangent`.
            #conventions
            pub fn #f_all(params: &#params_ty, q: &[f64; #n_values]) -> [#rt::Branch<#sol_ty, #n_branches>; #n_solutions] {
                let prepared = Self::prepare(params);
                let mut all = [#(#branches),*];
                ::pkm::runtime::__private::consistency::mark_double_roots(&mut all, &Self::REVOLUTE, |s: &#sol_ty| &s.q[..]);
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
