//! Generated forward solution of a coupled mechanism whose legs each end in
//! one ball joint (capability `fk_numeric` at κ ≥ 2: the 6-UPS, the 3-RPS,
//! the 3-SPR, the 3-PRS; [`pkm_runtime::ball_legs`]). Every real root of
//! the platform's pose equations comes from the runtime (parameter
//! homotopy, each real root certified by Krawczyk's operator: the
//! equations are the same few rows for every such mechanism, written once
//! over a ring); each root's assemblies from the generated inverse
//! solution, straight-line code like every other solver's, on the branches
//! whose actuated joints meet the inputs (found by probing the groups of ±
//! choices the trace proves independent, where there are several, else
//! every branch). In a prepared type of its
//! own (`NameFkNumeric`, from `Name::prepare_fk_numeric(&params)`), which
//! holds the model the pose equations are read from, the declared outputs,
//! the actuated joints' check and the prepared inverse solver.

use crate::codegen::solver::ChoiceGroup;
use crate::topology::analysis::Analysis;
use pkm_runtime::plan::Plan;
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

/// The items of `fk_numeric` for a mechanism whose legs end in balls, its
/// inverse plan `inverse` (generated as `ik`).
/// Its inverse solution's branches come from `groups` (the plan's ±
/// choices grouped by the actuated joints they move, proven on the traced
/// solver): where no group holds every choice, each root's branches are
/// found by probing the groups (`ball_legs::branches_to_solve`: the
/// 6-UPS's six legs, each its own slide's sense, take two probes and one
/// solution instead of 64 solutions), else every branch is solved.
pub(crate) fn generate(
    a: &Analysis,
    ident: &proc_macro2::Ident,
    vis: &syn::Visibility,
    inverse: &Plan,
    groups: &[ChoiceGroup],
) -> TokenStream {
    let m = &a.mechanism;
    let rt = quote! { ::pkm::runtime::__private };
    let prepared = format_ident!("{}FkNumeric", ident);
    let solver = format_ident!("{}Prepared", ident);
    let params_ty = format_ident!("{}Params", ident);
    let sol_ty = format_ident!("{}Solution", ident);
    let n_inputs = m.joints.iter().filter(|j| j.actuated).count();
    let n_outputs: usize = a.geometry.outputs.iter().map(|o| o.names.len()).sum();
    let n_choices = inverse.branches;
    let n_solutions = 1usize << n_choices;
    let widest = groups
        .iter()
        .filter(|g| !g.joints.is_empty())
        .map(|g| g.choices.len())
        .max()
        .unwrap_or(0);
    let branches = if widest < n_choices {
        let groups = groups.iter().map(|g| {
            let (c, j) = (&g.choices, &g.joints);
            quote! { #rt::ball_legs::ChoiceGroup { choices: &[#(#c),*], joints: &[#(#j),*] } }
        });
        quote! {
            // The inverse solution's choices, grouped by the actuated joints they move.
            const GROUPS: &[#rt::ball_legs::ChoiceGroup] = &[#(#groups),*];
            #rt::ball_legs::branches_to_solve::<#n_choices, #n_inputs>(
                GROUPS,
                |signs| self.inverse.ik_branch(&given, signs).ok(),
                |i, v| self.meets.input(i, v, q[i]),
            )
            .unwrap_or_else(|| (0..#n_solutions).collect())
        }
    } else {
        quote! { 0..#n_solutions }
    };
    let assemblies = quote! { #rt::ball_legs::Assemblies<#rt::ball_legs::Found<#sol_ty, #n_choices>> };
    let doc = format!(
        " `{}`'s forward solution by its platform's pose equations ([`{ident}::prepare_fk_numeric`]): the model, the declared outputs and the inverse solver, prepared once.",
        m.name
    );
    let fk_doc = format!(
        " Every real assembly at the inputs `q` (the actuated joints in declaration order, [`{ident}::INPUTS`]'s order of the model), by the platform's pose equations ([`{prepared}::fk_numeric`])."
    );
    quote! {
        #[doc = #doc]
        #[derive(Debug, Clone)]
        #vis struct #prepared {
            model: #rt::model::Model,
            outputs: ::std::vec::Vec<#rt::newton::Output>,
            legs: ::core::result::Result<#rt::ball_legs::BallLegs, ::std::string::String>,
            meets: #rt::ball_legs::Meets,
            inverse: #solver,
        }

        #[automatically_derived]
        impl #ident {
            /// The forward solution by the pose equations prepared at `params`.
            pub fn prepare_fk_numeric(params: &#params_ty) -> #prepared {
                let model = Self::model(params);
                let outputs = Self::output_specs(params);
                let legs = #rt::ball_legs::BallLegs::for_outputs(&model, &outputs);
                let meets = #rt::ball_legs::Meets::of(&model);
                #prepared { model, outputs, legs, meets, inverse: Self::prepare(params) }
            }

            #[doc = #fk_doc]
            ///
            /// # Errors
            /// Inputs not finite, or legs without a locus at these inputs.
            pub fn fk_numeric(params: &#params_ty, q: &[f64; #n_inputs]) -> ::core::result::Result<#assemblies, #rt::solution::SolveError> {
                Self::prepare_fk_numeric(params).fk_numeric(q)
            }
        }

        #[automatically_derived]
        impl #prepared {
            /// Every real assembly at the inputs `q`: every real root of the
            /// platform's pose equations (`roots`: certified, or possible
            /// with the paths' counts), each solved by the generated
            /// inverse solution on every branch and kept where its actuated
            /// joints meet `q`; a root no branch meets in `unmet`.
            ///
            /// # Errors
            /// Inputs not finite, or legs without a locus at these inputs
            /// (a leg's two passive axes apart).
            pub fn fk_numeric(&self, q: &[f64; #n_inputs]) -> ::core::result::Result<#assemblies, #rt::solution::SolveError> {
                let bad = |what: ::std::string::String| #rt::solution::SolveError::BadInput {
                    what: ::std::borrow::Cow::Owned(what),
                };
                #rt::fk_numeric::check_inputs(q, #n_inputs)?;
                let legs = self.legs.as_ref().map_err(|why| bad(why.clone()))?;
                let loci = legs.loci(&self.model, q).map_err(bad)?;
                let roots = #rt::ball_legs::roots(&loci, legs.scale);
                ::core::result::Result::Ok(#rt::ball_legs::assemble(roots, |k, root| {
                    let given = legs.given_values(&self.model, &self.outputs, &root.pose);
                    let given: [f64; #n_outputs] =
                        ::core::array::from_fn(|i| given.get(i).copied().unwrap_or(f64::NAN));
                    let branches = { #branches };
                    branches
                        .into_iter()
                        .filter_map(|i| {
                            let signs = #rt::solution::signs_of::<#n_choices>(i);
                            let solution = self.inverse.ik_solution(&given, signs).ok()?;
                            self.meets.at(q, &solution.q).then_some(#rt::ball_legs::Found {
                                root: k,
                                signs,
                                solution,
                            })
                        })
                        .collect()
                }))
            }
        }
    }
}
