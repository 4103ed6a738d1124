//! Batch solvers over structure-of-arrays slices: `fk_batch`, `ik_batch`
//! (the lean result of `fk_branch`, `ik_branch`) and `fk_point_batch`,
//! `ik_point_batch` (one point of the solution), written from the same
//! recorded graph as the one-branch solvers ([`crate::codegen::emit::Emit::lanes`]).
//!
//! Each lane is the branch's straight-line body without a return: a guard
//! clears the lane's flag, the open joints' verification clears it too (the
//! tolerance of [`pkm_runtime::consistency::within`]), and a cleared lane
//! writes zeros. Where the body has no call (sqrt, division and selects
//! only), the loop has no control flow and LLVM vectorises it (AVX2 where
//! the processor has it, through `pkm_runtime::batch::wide`; two lanes an
//! iteration, from either half of the slices); sin, cos and atan2 (libm)
//! are calls, and a body with them runs lane after lane.

use super::{Branch, Direction};
use crate::codegen::emit::Emit;
use crate::codegen::trace::Sym;
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

/// How many lanes a batch loop's iteration solves (each from its own part
/// of the slices): their chains of divisions and square roots overlap.
const WAYS: usize = 2;

/// The batch functions of one direction, on `NamePrepared`.
pub(super) fn generate(ident: &proc_macro2::Ident, emit: &Emit, d: &Direction) -> TokenStream {
    let prepared = format_ident!("{}Prepared", ident);
    let name = if d.forward { "fk" } else { "ik" };
    let g = &d.given;
    let n_given = d.plan.n_inputs;
    let n_choices = d.plan.branches;
    // Open joints and pinned points alike (`Plan::checks`), the rows that can fail.
    let verify = !d.rows.is_empty();

    let lean = lanes_fn(
        &prepared,
        emit,
        g,
        g.result.clone(),
        name,
        n_given,
        n_choices,
        verify,
        &|results| quote! { [#(#results),*] },
        g.result.len(),
        None,
        &batch_doc(name, d.forward),
    );

    let n_points = g.points.len();
    let point = lanes_fn(
        &prepared,
        emit,
        g,
        g.points.iter().flatten().copied().collect(),
        &format!("{name}_point"),
        n_given,
        n_choices,
        verify,
        &|coords| {
            let arms = coords.chunks(3).enumerate().map(|(p, c)| quote! { #p => [#(#c),*], });
            quote! {
                match P {
                    #(#arms)*
                    _ => [0.0; 3],
                }
            }
        },
        3,
        Some(n_points),
        &point_doc(name),
    );
    quote! {
        #[automatically_derived]
        impl #prepared {
            #lean
            #point
        }
    }
}

fn batch_doc(name: &str, forward: bool) -> String {
    let what = if forward {
        "the declared outputs (`OUTPUTS`)"
    } else {
        "the actuators' values (`INPUTS`)"
    };
    format!(
        " `{name}_branch` over many lanes, structure of arrays: lane i's given values are `given[k][i]`, its \
         result ({what}) goes to `out[r][i]`, and `ok[i]` says whether it is a verified solution; a lane \
         that fails (unreachable, degenerate, not finite, open joints that do not close) is `false` with \
         zeros, never NaN. Lane i equals `{name}_branch` on lane i's values, bit for bit.\n\n \
         Every slice must have `ok.len()` entries (any number), else `SolveError::BadInput` and no lane \
         is solved. Where the branch needs only arithmetic, square roots and selects, the loop has no \
         control flow and vectorises (four lanes at a time with AVX2, detected at run time on x86-64, \
         else two); sin, cos and atan2 (libm) do not, and a branch with them \
         runs lane after lane."
    )
}

fn point_doc(name: &str) -> String {
    format!(
        " Point `P` (an index into `POINTS`; another is a compile-time error) of `{name}_solution` over \
         many lanes, as [`Self::{name}_batch`]: lane i's point goes to `out[0..3][i]` (zeros where \
         `ok[i]` is `false`), what the other points need is not computed. The workspace sweep's solver."
    )
}

/// A public batch function `{stem}_batch` checking the slices' lengths and
/// running its private loop `{stem}_lanes` (one lane: `{stem}_lane`) through `pkm::runtime::batch::wide` (the loop
/// inlined there, so that it is compiled with AVX2 where the processor has
/// it; its slices, as the loop's arguments, do not alias: what lets LLVM
/// vectorise without run-time overlap checks).
/// `result(exprs)` is the lane's result from the expressions of `roots`; `points`:
/// the function is generic over the point `P` of that many.
#[allow(clippy::too_many_arguments)]
fn lanes_fn(
    prepared: &proc_macro2::Ident,
    emit: &Emit,
    g: &Branch,
    mut roots: Vec<Sym>,
    stem: &str,
    n_given: usize,
    n_choices: usize,
    verify: bool,
    result: &dyn Fn(&[TokenStream]) -> TokenStream,
    n_out: usize,
    points: Option<usize>,
    doc: &str,
) -> TokenStream {
    let n_roots = roots.len();
    let n_rows = g.residual.len();
    if verify {
        roots.extend(&g.residual);
        roots.push(g.extent);
    }
    let (lets, exprs) = emit.lanes(&roots, &emit.needed_guards(&roots, &g.guards, &g.waivable));
    let (values, rest) = exprs.split_at(n_roots);
    let check = if verify {
        let (residual, extent) = rest.split_at(n_rows);
        let extent = &extent[0];
        // As `fk_branch`: every row within `VERIFY_TOL` of the extent (NaN
        // is not); the rows exactly 0 are already dropped.
        let rows = residual.iter().map(|r| quote! { lane_ok &= (#r).abs() <= tol; });
        quote! {
            let extent = #extent;
            let tol = ::pkm::runtime::__private::consistency::VERIFY_TOL * extent;
            #(#rows)*
        }
    } else {
        quote! {}
    };
    let result = result(values);
    let sig = LaneSig {
        prepared,
        f: format_ident!("{stem}_batch"),
        f_lanes: format_ident!("{stem}_lanes"),
        f_lane: format_ident!("{stem}_lane"),
        given: (0..n_given).map(|k| format_ident!("given_{k}")).collect(),
        out: (0..n_out).map(|k| format_ident!("out_{k}")).collect(),
        n_choices,
        points,
    };
    let batch = sig.batch_fn(doc);
    let lane = sig.lane_fn(&lets, &check, &result);
    let lanes = sig.lanes_loop_fn();
    quote! {
        #batch
        #lane
        #lanes
    }
}

/// What the three functions of one batch solver name and share.
struct LaneSig<'a> {
    prepared: &'a proc_macro2::Ident,
    f: proc_macro2::Ident,
    f_lanes: proc_macro2::Ident,
    f_lane: proc_macro2::Ident,
    given: Vec<proc_macro2::Ident>,
    out: Vec<proc_macro2::Ident>,
    n_choices: usize,
    /// Generic over the point `P` of that many.
    points: Option<usize>,
}

impl LaneSig<'_> {
    /// `<const P: usize>`, `::<P>`, the assertion on `P`, `const P: usize`
    /// and `P`, where the function is generic over a point; else nothing.
    fn generics(&self) -> [TokenStream; 5] {
        match self.points {
            Some(n) => [
                quote! { <const P: usize> },
                quote! { ::<P> },
                quote! { const { assert!(P < #n, "P is not an index into POINTS") }; },
                quote! { const P: usize },
                quote! { P },
            ],
            None => Default::default(),
        }
    }

    /// The public function: the slices' lengths checked, then the loop run
    /// through `pkm::runtime::batch::wide`.
    fn batch_fn(&self, doc: &str) -> TokenStream {
        let LaneSig {
            prepared,
            f,
            f_lanes,
            given,
            out,
            n_choices,
            ..
        } = self;
        let (n_given, n_out) = (given.len(), out.len());
        let name = f.to_string();
        let sign = quote! { ::pkm::runtime::__private::primitives::Sign };
        let [generics, turbofish, assert, const_p, p_arg] = self.generics();
        quote! {
        #[doc = #doc]
        pub fn #f #generics(
            &self,
            given: [&[f64]; #n_given],
            signs: [#sign; #n_choices],
            out: [&mut [f64]; #n_out],
            ok: &mut [bool],
        ) -> ::core::result::Result<(), ::pkm::runtime::__private::solution::SolveError> {
            #assert
            ::pkm::runtime::__private::batch::check_lanes(
                #name,
                ok.len(),
                &given.map(|g| g.len()),
                &out.each_ref().map(|o| o.len()),
            )?;
            // The loop, for `wide` to compile with the processor's widest vectors.
            struct Lanes<'a, #const_p> {
                solver: &'a #prepared,
                signs: [#sign; #n_choices],
                given: [&'a [f64]; #n_given],
                out: [&'a mut [f64]; #n_out],
                ok: &'a mut [bool],
            }
            impl<#const_p> ::pkm::runtime::__private::batch::Loop for Lanes<'_, #p_arg> {
                #[inline(always)]
                fn run(self) {
                    let [#(#given),*] = self.given;
                    let [#(#out),*] = self.out;
                    self.solver.#f_lanes #turbofish(self.signs, #(#given,)* #(#out,)* self.ok);
                }
            }
            ::pkm::runtime::__private::batch::wide(Lanes #turbofish { solver: self, signs, given, out, ok });
            ::core::result::Result::Ok(())
        }
        }
    }

    /// One lane: its result (zeros where refused) and whether it is verified.
    fn lane_fn(&self, lets: &TokenStream, check: &TokenStream, result: &TokenStream) -> TokenStream {
        let LaneSig {
            f_lane, n_choices, out, ..
        } = self;
        let n_given = self.given.len();
        let n_out = out.len();
        let sign = quote! { ::pkm::runtime::__private::primitives::Sign };
        let finite = (0..n_given).map(|k| quote! { & given[#k].is_finite() });
        let [generics, ..] = self.generics();
        quote! {
        /// One lane of the loop below: its result (zeros where refused) and
        /// whether it is a verified solution.
        #[inline(always)]
        #[allow(unused_mut)]
        fn #f_lane #generics(&self, signs: [#sign; #n_choices], given: [f64; #n_given]) -> ([f64; #n_out], bool) {
            let _ = &signs;
            let mut lane_ok = true #(#finite)*;
            #lets
            #check
            let result: [f64; #n_out] = #result;
            (if lane_ok { result } else { [0.0; #n_out] }, lane_ok)
        }
        }
    }

    /// The loop over the lanes, `WAYS` an iteration, one from each part of
    /// the slices.
    fn lanes_loop_fn(&self) -> TokenStream {
        let LaneSig {
            f_lanes,
            f_lane,
            given,
            out,
            n_choices,
            ..
        } = self;
        let out_index: Vec<usize> = (0..out.len()).collect();
        let sign = quote! { ::pkm::runtime::__private::primitives::Sign };
        let [generics, turbofish, ..] = self.generics();
        // The loop's parts: slice x cut into `x_0` … (`part` lanes each).
        let part_of = |x: &str, w: usize| format_ident!("{x}_{w}");
        let mut parts = TokenStream::new();
        let slices = given.iter().map(|g| (g.to_string(), false));
        for (x, mutable) in slices
            .chain(out.iter().map(|o| (o.to_string(), true)))
            .chain([("ok".to_string(), true)])
        {
            let whole = format_ident!("{x}");
            let (split, all) = if mutable {
                (quote! { split_at_mut }, quote! { &mut *#whole })
            } else {
                (quote! { split_at }, quote! { #whole })
            };
            parts.extend(quote! { let rest = #all; });
            for w in 0..WAYS {
                let p = part_of(&x, w);
                if w + 1 < WAYS {
                    parts.extend(quote! { let (#p, rest) = rest.#split(part); });
                } else {
                    parts.extend(quote! { let (#p, _) = rest.#split(part); });
                }
            }
        }
        let calls = (0..WAYS).map(|w| {
            let (r, r_ok) = (format_ident!("r_{w}"), format_ident!("r_ok_{w}"));
            let g = given.iter().map(|g| part_of(&g.to_string(), w));
            quote! { let (#r, #r_ok) = self.#f_lane #turbofish(signs, [#(#g[i]),*]); }
        });
        let stores = (0..WAYS).map(|w| {
            let (r, r_ok) = (format_ident!("r_{w}"), format_ident!("r_ok_{w}"));
            let o = out.iter().map(|o| part_of(&o.to_string(), w));
            let ok_w = part_of("ok", w);
            quote! { #(#o[i] = #r[#out_index];)* #ok_w[i] = #r_ok; }
        });
        quote! {
        /// The loop of the function above, its slices checked to `ok.len()`
        /// (as arguments, they do not alias: no run-time overlap checks).
        /// `WAYS` lanes an iteration, one from each part of the slices:
        /// independent chains of dependent divisions and square roots that
        /// the processor overlaps.
        #[inline(always)]
        #[allow(clippy::too_many_arguments)]
        fn #f_lanes #generics(
            &self,
            signs: [#sign; #n_choices],
            #(#given: &[f64],)*
            #(#out: &mut [f64],)*
            ok: &mut [bool],
        ) {
            let lanes = ok.len();
            let part = lanes / #WAYS;
            // Cut to the lane count once, so the loop has no bounds checks.
            #(let #given = &#given[..lanes];)*
            #(let #out = &mut #out[..lanes];)*
            {
                #parts
                for i in 0..part {
                    #(#calls)*
                    #(#stores)*
                }
            }
            for j in part * #WAYS..lanes {
                let (r, r_ok) = self.#f_lane #turbofish(signs, [#(#given[j]),*]);
                #(#out[j] = r[#out_index];)*
                ok[j] = r_ok;
            }
        }
        }
    }
}
