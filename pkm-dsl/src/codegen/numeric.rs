//! Generated forward solution of a κ = 1 mechanism by one virtual variable
//! (capability `fk_numeric`, [`crate::plan::planner_numeric`]): the virtual
//! plan's steps traced on symbols like every other solver's and written
//! out as straight-line Rust, in a prepared type of their own
//! (`NameFkNumeric`, from `Name::prepare_fk_numeric(&params)`):
//! `residual(&given, signs)` (the compatibility residual, `given` the
//! inputs then the virtual variable), `residual_in(&given, signs)` (the
//! same steps generic over the scalar: on intervals carrying their
//! derivative they enclose the residual over a part of the range),
//! `solution(&given, signs)` (every joint value and point, verified by the
//! plan's other checks), and `fk_numeric(&q)`, which runs the runtime's
//! certified driver (`pkm::runtime::fk_numeric::solve_with`) on them.

use super::{branch, geometry, loop_names, xyz};
use crate::codegen::emit::Emit;
use crate::codegen::trace::{record, Choice};
use crate::topology::analysis::Analysis;
use pkm_runtime::fk_numeric::{Compatibility, VirtualPlan};
use pkm_runtime::steps::RESIDUAL_ROWS;
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

/// The items of `fk_numeric` for the virtual plan `vp` (planned at the
/// nominal dimensions; the residual's zero and a slide's range are the
/// nominal model's, see [`pkm_runtime::fk_numeric::zero_of`]).
pub(crate) fn generate(
    a: &Analysis,
    ident: &proc_macro2::Ident,
    vis: &syn::Visibility,
    vp: &VirtualPlan,
) -> Result<TokenStream, String> {
    let m = &a.mechanism;
    let plan = &vp.plan;
    let (traced, graph) = record(|| {
        let g = geometry(a);
        let signs: Vec<Choice> = (0..plan.branches).map(Choice::Given).collect();
        branch(a, &g, plan, 0, true, &signs, true)
    });
    let b = traced?;
    let emit = Emit::new(&graph, loop_names(a, plan));
    let rt = quote! { ::pkm::runtime::__private };
    // The residual's symbol: a check's row, or the value computed for an
    // input the plan is not given (less that input, written out below).
    let (residual, input) = match vp.compatibility {
        Compatibility::Miss { check, row } => (b.residual[check * RESIDUAL_ROWS + row], None),
        Compatibility::Input { joint, input, arc } => (b.values[joint], Some((input, arc))),
    };
    let of_input = |computed: &TokenStream, (input, arc): (usize, Option<f64>)| {
        let arc = match arc {
            Some(r) => quote! { ::core::option::Option::Some(#r) },
            None => quote! { ::core::option::Option::None },
        };
        quote! { #rt::fk_numeric::Compatibility::input_residual(#arc, #computed, given[#input]) }
    };
    // Every check's rows that can fail verify a solution, the
    // compatibility residual's too (as the interpreter's `plan::run`).
    let others: Vec<_> = (0..b.residual.len())
        .filter(|&i| emit.constant(b.residual[i]) != Some(0.0))
        .map(|i| b.residual[i])
        .collect();
    let guards = |roots: &[crate::codegen::trace::Sym]| emit.needed_guards(roots, &b.guards, &b.waivable);
    let (residual_lets, residual_expr) = emit.straight(&[residual], &guards(&[residual]));
    let (generic_lets, generic_expr) = emit.straight_generic(&[residual], &guards(&[residual]));
    let generic_expr = &generic_expr[0];
    let residual_expr = match input {
        Some(i) => of_input(&residual_expr[0], i),
        None => residual_expr[0].clone(),
    };
    let mut roots = b.values.clone();
    roots.extend(b.points.iter().flatten());
    roots.extend(&others);
    roots.push(b.extent);
    let (lets, exprs) = emit.straight(&roots, &guards(&roots));
    let n_joints = m.joints.len();
    let n_points = b.points.len();
    let (values, rest) = exprs.split_at(n_joints);
    let (points, rest) = rest.split_at(3 * n_points);
    let (rows, extent) = rest.split_at(others.len());
    let extent = &extent[0];
    let dim = if m.planar { 2 } else { 3 };
    let points: Vec<TokenStream> = points.chunks(3).map(|p| xyz(&p[..dim])).collect();
    let n_rows = others.len();
    let n_given = plan.n_inputs;
    let n_inputs = n_given - 1;
    let n_choices = plan.branches;
    let model = crate::lowering::numeric::model(a, &Default::default()).map_err(|d| format!("{d:?}"))?;
    let zero = pkm_runtime::fk_numeric::zero_of(&model);
    let scale = pkm_runtime::kinematics::model_scale(&model);
    let [lo, hi] = vp.range;
    // A turn's ends as the constant, not its digits.
    let end = |x: f64| {
        if x == std::f64::consts::PI {
            quote! { ::core::f64::consts::PI }
        } else if x == -std::f64::consts::PI {
            quote! { -::core::f64::consts::PI }
        } else {
            quote! { #x }
        }
    };
    let (lo_t, hi_t) = (end(lo), end(hi));
    let periodic = vp.periodic;
    let compatibility = match vp.compatibility {
        Compatibility::Miss { check, row } => {
            quote! { #rt::fk_numeric::Compatibility::Miss { check: #check, row: #row } }
        }
        Compatibility::Input { joint, input, arc } => {
            let arc = match arc {
                Some(r) => quote! { ::core::option::Option::Some(#r) },
                None => quote! { ::core::option::Option::None },
            };
            quote! { #rt::fk_numeric::Compatibility::Input { joint: #joint, input: #input, arc: #arc } }
        }
    };
    let prepared = format_ident!("{}FkNumeric", ident);
    let params_ty = format_ident!("{}Params", ident);
    // The parameters, for the model the assemblies are polished on.
    let (fields, prepare) = emit.prepared_with(
        &prepared,
        &quote! { params: #params_ty, },
        &[quote! { params: *params }],
    );
    let virtual_joint = vp.joint;
    let polishable = model.joints.iter().all(|j| j.kind.dof() == 1);
    let polish = if polishable {
        quote! {
            let model = #ident::model(&self.params);
            for f in &mut found {
                #rt::fk_numeric::polish_found(&model, #virtual_joint, q, f);
            }
        }
    } else {
        quote! {}
    };
    let virtual_name = &m.joints[vp.joint].name;
    let fk_doc = format!(
        " Every real assembly at the inputs `q` (the actuated joints in declaration order, [`{prepared}::GIVEN`] but the last), by a virtual variable ([`{prepared}::fk_numeric`])."
    );
    let given_names: Vec<&str> = plan.inputs.iter().map(|&j| m.joints[j].name.as_str()).collect();
    let doc = format!(
        " `{}`'s forward solution by the virtual variable {virtual_name} ([`{ident}::prepare_fk_numeric`]): what depends on the dimensions alone, computed once.",
        m.name
    );
    let residual_doc = format!(
        " The compatibility residual (a length) of branch `signs` at `given` ([`Self::GIVEN`]: the inputs, then the virtual variable {virtual_name}); `Err` where the branch has no real solution there."
    );
    let range_doc = format!(" Where {virtual_name} is searched: [{lo}, {hi}].");
    let generic_doc = format!(
        " The compatibility residual's steps at `given` on any scalar (an interval carrying its derivative encloses it over a part of {virtual_name}'s range): the miss, or the value of the input the plan computes; `None` where a step has no solution (on intervals: nowhere in the part)."
    );
    let verified = if n_rows == 0 {
        quote! {}
    } else {
        quote! {
            let extent = #extent;
            let rows = [#(#rows),*];
            if let ::core::option::Option::Some((_, gap)) = #rt::consistency::beyond(&rows, extent) {
                return ::core::result::Result::Err(#rt::solution::SolveError::Inconsistent {
                    owner: ::std::borrow::Cow::Borrowed("a joint the virtual plan leaves open"),
                    gap,
                    contradicted: ::core::option::Option::None,
                });
            }
        }
    };
    // An input the plan computes meets its given value (the interpreter's
    // `fk_numeric::solve` verifies it to the same zero).
    let verified_input = match (input, vp.compatibility) {
        (Some(i), Compatibility::Input { joint, .. }) => {
            let r = of_input(&values[joint], i);
            quote! {
                let r = #r;
                if !(r.abs() <= #zero) {
                    return ::core::result::Result::Err(#rt::solution::SolveError::Inconsistent {
                        owner: ::std::borrow::Cow::Borrowed("the input the virtual plan computes"),
                        gap: r.abs(),
                        contradicted: ::core::option::Option::None,
                    });
                }
            }
        }
        _ => quote! {},
    };
    let finite = super::given_is_finite();
    let prepared_struct = super::prepared_struct(&doc, vis, &prepared, &fields);
    Ok(quote! {
        #prepared_struct

        #[automatically_derived]
        impl #ident {
            /// The forward solution by a virtual variable prepared at `params`.
            pub fn prepare_fk_numeric(params: &#params_ty) -> #prepared {
                let _ = params;
                #prepare
            }

            #[doc = #fk_doc]
            pub fn fk_numeric(params: &#params_ty, q: &[f64; #n_inputs]) -> #rt::fk_numeric::Assemblies<#rt::fk_numeric::Found<#n_joints, #n_points, #dim, #n_choices>> {
                Self::prepare_fk_numeric(params).fk_numeric(q)
            }
        }

        #[automatically_derived]
        impl #prepared {
            /// The joints `given` holds: the inputs, then the virtual variable.
            pub const GIVEN: [&'static str; #n_given] = [#(#given_names),*];

            #[doc = #range_doc]
            pub const RANGE: #rt::fk_numeric::VirtualRange = #rt::fk_numeric::VirtualRange {
                lo: #lo_t,
                hi: #hi_t,
                periodic: #periodic,
            };

            /// What the compatibility residual is.
            pub const COMPATIBILITY: #rt::fk_numeric::Compatibility = #compatibility;

            #[doc = #generic_doc]
            pub fn residual_in<T: #rt::scalar::Scalar<Choice = #rt::primitives::Sign>>(&self, given: &[T; #n_given], signs: [#rt::primitives::Sign; #n_choices]) -> ::core::option::Option<T> {
                let _ = &signs;
                #generic_lets
                ::core::option::Option::Some(#generic_expr)
            }

            #[doc = #residual_doc]
            pub fn residual(&self, given: &[f64; #n_given], signs: [#rt::primitives::Sign; #n_choices]) -> ::core::result::Result<f64, #rt::solution::SolveError> {
                let _ = &signs;
                #finite
                #residual_lets
                ::core::result::Result::Ok(#residual_expr)
            }

            /// Every joint value and point of branch `signs` at `given`
            /// (inputs, then the virtual variable), verified: every open
            /// joint closes, the compatibility residual's too.
            pub fn solution(&self, given: &[f64; #n_given], signs: [#rt::primitives::Sign; #n_choices]) -> ::core::result::Result<([f64; #n_joints], [[f64; #dim]; #n_points]), #rt::solution::SolveError> {
                let _ = &signs;
                #finite
                #lets
                #verified
                #verified_input
                ::core::result::Result::Ok(([#(#values),*], [#(#points),*]))
            }

            /// Every real assembly at the inputs `q`: the roots of the
            /// compatibility residual on every branch, each certified or
            /// possible (the runtime's certified driver on
            /// [`Self::residual_in`] over intervals), each solved and
            /// verified, an assembly two branches share once; roots
            /// without a verified assembly in `unresolved`.
            pub fn fk_numeric(&self, q: &[f64; #n_inputs]) -> #rt::fk_numeric::Assemblies<#rt::fk_numeric::Found<#n_joints, #n_points, #dim, #n_choices>> {
                let given = |v: f64| -> [f64; #n_given] { ::core::array::from_fn(|i| if i < #n_inputs { q[i] } else { v }) };
                let enclosing = |x: #rt::interval::Interval| -> [#rt::interval::Enclosure<1>; #n_given] {
                    ::core::array::from_fn(|i| {
                        if i < #n_inputs {
                            #rt::interval::Enclosure::constant(#rt::interval::Interval::point(q[i]))
                        } else {
                            #rt::interval::Enclosure::variable(x, 0)
                        }
                    })
                };
                let signs_of = |s: &[#rt::primitives::Sign]| -> [#rt::primitives::Sign; #n_choices] { ::core::array::from_fn(|k| s[k]) };
                let found = #rt::fk_numeric::solve_with(
                    &Self::RANGE,
                    #n_choices,
                    |x, s| {
                        let (raw, took) = #rt::interval::watch(|| self.residual_in(&enclosing(x), signs_of(s)));
                        #rt::fk_numeric::enclosed(&Self::COMPATIBILITY, raw, q, took)
                    },
                    |v, s| self.residual(&given(v), signs_of(s)).ok(),
                    |v, s| self.solution(&given(v), signs_of(s)).ok(),
                    |a: &([f64; #n_joints], [[f64; #dim]; #n_points]), b: &([f64; #n_joints], [[f64; #dim]; #n_points])| {
                        let points = a.1.iter().zip(&b.1).flat_map(|(p, q)| p.iter().zip(q)).map(|(x, y)| (x - y).abs());
                        let values = a.0.iter().zip(&b.0).map(|(x, y)| #rt::fk_numeric::value_distance(*x, *y));
                        points.chain(values).fold(0.0, f64::max) / #scale
                    },
                );
                let unresolved = found.unresolved;
                let mut found: ::std::vec::Vec<_> = found
                    .found
                    .into_iter()
                    .map(|(s, r, (values, points))| #rt::fk_numeric::Found {
                        signs: signs_of(&s),
                        virtual_value: r.x,
                        residual: r.residual,
                        kind: r.kind,
                        cert: r.cert,
                        q: values,
                        points,
                    })
                    .collect();
                #polish
                #rt::fk_numeric::Assemblies { found, unresolved }
            }
        }
    })
}
