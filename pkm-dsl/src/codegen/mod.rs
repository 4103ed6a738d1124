//! `pkm::mechanism!` as a library function: parse the macro input, read the
//! description (inline or from a `.pkm` file), analyse it, check what the
//! requested capabilities need, and emit the type. Nothing is generated for
//! a capability that was not requested.

mod ball_legs;
pub(crate) mod emit;
mod motion;
mod solution;
mod solver;
pub(crate) mod trace;

use crate::diagnostics::{Diagnostic, Diagnostics};
use crate::semantics::mechanism::Capability;
use crate::topology::analysis::Analysis;
use proc_macro2::{Span as PmSpan, TokenStream};
use quote::{format_ident, quote};
use syn::parse::{Parse, ParseStream};
use syn::{Attribute, Ident, LitStr, Token, Visibility};

/// The most ± choices a generated `fk` enumerates (it returns 2^choices branches).
const MAX_FK_CHOICES: usize = 10;

/// Where the description comes from.
enum Source {
    Inline(LitStr),
    File(LitStr),
}

/// `#[attrs] pub Name, "inline text"` or `#[attrs] pub Name, file = "path.pkm"`.
struct MacroInput {
    attrs: Vec<Attribute>,
    vis: Visibility,
    ident: Ident,
    source: Source,
}

impl Parse for MacroInput {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        let attrs = input.call(Attribute::parse_outer)?;
        let vis: Visibility = input.parse()?;
        let ident: Ident = input.parse()?;
        input.parse::<Token![,]>()?;
        let source = if input.peek(LitStr) {
            Source::Inline(input.parse()?)
        } else {
            let key: Ident = input.parse()?;
            if key != "file" {
                return Err(syn::Error::new(
                    key.span(),
                    "expected a string literal or `file = \"path.pkm\"`",
                ));
            }
            input.parse::<Token![=]>()?;
            Source::File(input.parse()?)
        };
        let _ = input.parse::<Option<Token![,]>>()?;
        if !input.is_empty() {
            return Err(input.error("unexpected tokens after the mechanism description"));
        }
        Ok(MacroInput {
            attrs,
            vis,
            ident,
            source,
        })
    }
}

/// Expands `pkm::mechanism!`. Errors carry the DSL's line:column and a caret
/// picture, at the span of the description's literal.
///
/// ```
/// let tokens: proc_macro2::TokenStream =
///     r#"pub FourBar, "mechanism four_bar { planar; base R1* ∥ R2 ∥ R3 ∥ R4 base; }""#.parse().unwrap();
/// let out = pkm_dsl::expand(tokens).unwrap().to_string();
/// assert!(out.contains("pub const DOF : usize = 1usize"));
/// ```
pub fn expand(input: TokenStream) -> syn::Result<TokenStream> {
    let input: MacroInput = syn::parse2(input)?;
    let (lit, text, file_name, include) = match &input.source {
        Source::Inline(lit) => (lit, lit.value(), "<inline>".to_string(), None),
        Source::File(lit) => {
            let rel = lit.value();
            let dir = std::env::var("CARGO_MANIFEST_DIR").unwrap_or_else(|_| ".".into());
            let path = std::path::Path::new(&dir).join(&rel);
            let unreadable = |e: std::io::Error| {
                syn::Error::new(
                    lit.span(),
                    format!("cannot read mechanism file `{}`: {e}", path.display()),
                )
            };
            // The size limit before the read: a huge file is refused, not loaded.
            let size = std::fs::metadata(&path).map_err(unreadable)?.len();
            if size > crate::limits::MAX_FILE_BYTES as u64 {
                return Err(syn::Error::new(
                    lit.span(),
                    format!(
                        "mechanism file `{}` is {size} bytes; the limit is {} bytes",
                        path.display(),
                        crate::limits::MAX_FILE_BYTES
                    ),
                ));
            }
            let text = std::fs::read_to_string(&path).map_err(unreadable)?;
            (lit, text, rel.clone(), Some(rel))
        }
    };
    // The pipeline (parse, model, geometry, topology, plans): `crate::compile`.
    let compiled = crate::compile::compile(&text).map_err(|d| to_syn(&d, &text, &file_name, lit.span()))?;
    let checks = check_capabilities(&compiled.analysis);
    if !checks.is_empty() {
        return Err(to_syn(&checks, &text, &file_name, lit.span()));
    }
    let out = generate(&input, &compiled, include.as_deref()).map_err(|d| to_syn(&d, &text, &file_name, lit.span()))?;
    Ok(located_at(out, input.ident.span()))
}

/// Every token of the expansion located at `at` (the mechanism's name, on
/// one line), resolved as before. Generated tokens are spanned at the call
/// site, which for an invocation over several lines spans them all, so
/// clippy would read a line break inside every generated `[a * b, …]`
/// and refuse it as a missing comma (`possible_missing_comma`, denied by
/// default).
fn located_at(tokens: TokenStream, at: PmSpan) -> TokenStream {
    tokens
        .into_iter()
        .map(|tt| match tt {
            proc_macro2::TokenTree::Group(g) => {
                let mut group = proc_macro2::Group::new(g.delimiter(), located_at(g.stream(), at));
                group.set_span(g.span().located_at(at));
                proc_macro2::TokenTree::Group(group)
            }
            mut tt => {
                tt.set_span(tt.span().located_at(at));
                tt
            }
        })
        .collect()
}

fn to_syn(d: &Diagnostics, text: &str, file: &str, span: PmSpan) -> syn::Error {
    // rustc prints its own `error:`; keep the rest of the rendered diagnostic.
    let mut errors = d.0.iter().map(|d| {
        let rendered = d.render(text, file);
        syn::Error::new(span, rendered.strip_prefix("error: ").unwrap_or(&rendered).trim_end())
    });
    let mut first = errors
        .next()
        .unwrap_or_else(|| syn::Error::new(span, "invalid mechanism"));
    for e in errors {
        first.combine(e);
    }
    first
}

/// What the requested capabilities need of the topology and of the rest
/// of the file.
pub fn check_capabilities(a: &Analysis) -> Diagnostics {
    let mut errors = Diagnostics::default();
    let m = &a.mechanism;
    let t = &a.topology;
    for (cap, span) in &m.capabilities {
        if *cap == Capability::Stiffness {
            stiffness_needs(a, *span, &mut errors);
        }
        if *cap == Capability::Workspace && !m.wants(Capability::Fk) && !m.wants(Capability::Ik) {
            errors.push(
                Diagnostic::new(
                    *span,
                    "`workspace` sweeps the position solvers: request `fk` or `ik` too",
                )
                .label("needs `fk` or `ik`"),
            );
        }
        if *cap == Capability::Dynamics {
            dynamics_needs(a, *span, &mut errors);
        }
        if *cap == Capability::FkNumeric {
            use crate::plan::planner_numeric::{ball_legs, by_virtual_variable, forward_numeric_plan};
            let planned = match (by_virtual_variable(a), a.geometry.complete) {
                (true, true) => forward_numeric_plan(a).map(|_| ()),
                (false, true) => ball_legs(a).map(|_| ()),
                (true, false) => Ok(()),
                (false, false) => crate::plan::planner_numeric::coupling(a).or_else(|refused| {
                    if a.topology.kappa >= 1 && m.wants(Capability::Ik) {
                        Ok(())
                    } else {
                        Err(refused)
                    }
                }),
            };
            if let Err(d) = planned {
                errors.0.extend(d.0);
            }
        }
        // κ ≠ 0 closed in closed form all the same (three spheres) is planned.
        if *cap == Capability::Fk
            && t.kappa != 0
            && !(a.geometry.complete && crate::plan::planner::forward_plan(a).is_ok())
        {
            let mut d = Diagnostic::new(
                *span,
                format!(
                    "`fk` needs a closed-form forward position solution, but the coupling degree is κ = {}",
                    t.kappa
                ),
            )
            .label("needs κ = 0");
            for note in t.coupling_notes() {
                d = d.note(note);
            }
            d = d.note("request only `ik` to compile this design, or reduce its coupling degree (for example with compound hinges)");
            errors.push(d);
        }
    }
    errors
}

/// What `dynamics` needs: the forward solution (its generated inverse
/// dynamics solves the position first), the file's units, and every moving
/// link's mass properties or its declaration as massless.
fn dynamics_needs(a: &Analysis, span: crate::diagnostics::Span, errors: &mut Diagnostics) {
    let m = &a.mechanism;
    if !m.wants(Capability::Fk) {
        errors.push(
            Diagnostic::new(
                span,
                "`dynamics` solves the position by the forward solution first: request `fk` too",
            )
            .label("needs `fk`"),
        );
    }
    if a.mass_and_loads.units.is_none() {
        errors.push(
            Diagnostic::new(
                span,
                "`dynamics` needs the file's units: `units { length = mm; mass = kg; }`",
            )
            .label("no `units`"),
        );
    }
    let missing = crate::lowering::numeric::links_without_mass(a);
    if !missing.is_empty() {
        errors.push(
            Diagnostic::new(
                span,
                format!(
                    "`dynamics` needs every moving link's mass: {} ha{} none",
                    missing.join(", "),
                    if missing.len() == 1 { "s" } else { "ve" }
                ),
            )
            .label("links without mass")
            .note("give each a `mass` and `centroid` in `masses`, or declare it `massless`"),
        );
    }
}

/// Where `stiffness` is given, in a file with geometry and `ik`: about the
/// point of the first output that places one, on its link, which the
/// limbs must join to the base (each joint on one serial chain).
fn stiffness_reference_needs(a: &Analysis, span: crate::diagnostics::Span, errors: &mut Diagnostics) {
    if !a.geometry.complete || !a.mechanism.wants(Capability::Ik) {
        return;
    }
    let Some((link, _)) = a.geometry.first_point_output() else {
        errors.push(
            Diagnostic::new(
                span,
                "`stiffness` is given about a platform point: declare the platform's pose, pose parts or a point of it among the outputs",
            )
            .label("no output places a point"),
        );
        return;
    };
    let Ok(model) = crate::lowering::numeric::model(a, &Default::default()) else {
        return;
    };
    if let Err(e) = pkm_runtime::wrench::limbs(&model, link) {
        let why = match e {
            pkm_runtime::wrench::WrenchError::NotLimbs { link, what } => {
                format!("at link `{}`, {what}", a.mechanism.links[link].name)
            }
            other => other.to_string(),
        };
        errors.push(
            Diagnostic::new(
                span,
                format!(
                    "`stiffness` reads the limbs from the base to `{}`, the link the outputs place, and finds none: {why}",
                    a.mechanism.links[link].name
                ),
            )
            .label("not limbs"),
        );
    }
}

/// What `stiffness` needs: the inverse solution (its generated stiffness
/// solves the pose first), the file's units, and every limb's properties
/// in `limbs { … }` (its limbs are the file's branches, each reaching the
/// platform; a mechanism without branches has none to stiffen).
fn stiffness_needs(a: &Analysis, span: crate::diagnostics::Span, errors: &mut Diagnostics) {
    let m = &a.mechanism;
    if !m.wants(Capability::Ik) {
        errors.push(
            Diagnostic::new(
                span,
                "`stiffness` is given at a platform pose, solved by the inverse solution first: request `ik` too",
            )
            .label("needs `ik`"),
        );
    }
    if a.mass_and_loads.units.is_none() {
        errors.push(
            Diagnostic::new(
                span,
                "`stiffness` needs the file's units: `units { length = mm; mass = kg; }`",
            )
            .label("no `units`"),
        );
    }
    if m.branches.is_empty() {
        errors.push(
            Diagnostic::new(
                span,
                "`stiffness` needs the mechanism's limbs: write each leg as `branch NAME { … }` from the base to the platform",
            )
            .label("no branches"),
        );
        return;
    }
    stiffness_reference_needs(a, span, errors);
    let missing: Vec<&str> = m
        .branches
        .iter()
        .enumerate()
        .filter(|(i, _)| !a.limbs.iter().any(|l| l.branch == *i))
        .map(|(_, b)| b.name.as_str())
        .collect();
    if !missing.is_empty() {
        errors.push(
            Diagnostic::new(
                span,
                format!(
                    "`stiffness` needs every limb's properties: {} ha{} none",
                    missing.join(", "),
                    if missing.len() == 1 { "s" } else { "ve" }
                ),
            )
            .label("limbs without properties")
            .note("give each branch its leg's `E`, `A` and `I`, or `axial` and `bending`, in `limbs { … }`"),
        );
    }
}

fn generate(
    input: &MacroInput,
    compiled: &crate::compile::Compiled,
    include: Option<&str>,
) -> Result<TokenStream, Diagnostics> {
    let a = &compiled.analysis;
    let topology = topology_items(input, a, include);
    let params = parameter_struct(input, a);
    let mut solvers = solver_items(input, compiled)?;
    solvers.push(crate::codegen::motion::generate(a, &input.ident)?);
    Ok(quote! {
        #topology
        #params
        #(#solvers)*
    })
}

/// The mechanism's type and its topology as constants (`DOF`, `KAPPA`,
/// `XI`, `DELTA`, the whole `REPORT`), tied to its source file.
fn topology_items(input: &MacroInput, a: &Analysis, include: Option<&str>) -> TokenStream {
    let MacroInput { attrs, vis, ident, .. } = input;
    let m = &a.mechanism;
    let t = &a.topology;
    let name = &m.name;
    let title = m.title.clone().unwrap_or_default();
    let dof = t.dof;
    let kappa = t.kappa;
    let loops = t.loops;
    let skc_count = t.skcs.len();
    let xi = t.xi();
    let delta = t.delta();
    let socs = t.socs.iter().map(|s| {
        let (notation, dof, act, xi, delta) = (&s.notation, s.dof, s.actuators, s.xi, s.delta);
        quote! { ::pkm::runtime::__private::SocReport { notation: #notation, dof: #dof, actuators: #act, xi: #xi, delta: #delta } }
    });
    let skcs = t.skcs.iter().map(|s| {
        let idx: Vec<usize> = s.socs.clone().collect();
        let k = s.kappa;
        quote! { ::pkm::runtime::__private::SkcReport { socs: &[#(#idx),*], kappa: #k } }
    });
    let actuators: Vec<&str> = m
        .joints
        .iter()
        .filter(|j| j.actuated)
        .map(|j| j.name.as_str())
        .collect();
    let platform_poc = match &t.platform_poc {
        Some(p) => {
            let s = p.unicode();
            quote! { ::core::option::Option::Some(#s) }
        }
        None => quote! { ::core::option::Option::None },
    };
    let branch_poc = m.branches.iter().zip(&t.branch_poc).map(|(b, p)| {
        let (n, s) = (&b.name, p.unicode());
        quote! { (#n, #s) }
    });
    let decoupling = t.decoupling.iter().map(|d| {
        let out = &d.output;
        let ins = a.names(&d.inputs);
        quote! { (#out, &[#(#ins),*]) }
    });
    let expression = &t.expression;
    let text = a.report();
    let platform_doc = t
        .platform_poc
        .as_ref()
        .map(|p| format!(" Platform POC set: `{}`.", p.unicode()))
        .unwrap_or_default();
    let default_doc = format!(
        " The mechanism `{name}`{}: F = {dof}, κ = {kappa}.{platform_doc}",
        if title.is_empty() {
            String::new()
        } else {
            format!(" ({title})")
        }
    );
    let has_doc = attrs.iter().any(|a| a.path().is_ident("doc"));
    let doc = if has_doc {
        quote! {}
    } else {
        quote! { #[doc = #default_doc] }
    };
    let source_const = include.map(source_const);
    let kappa_doc = format!(" Coupling degree κ = {kappa}.");
    let dof_doc = format!(" Full-cycle degrees of freedom F = {dof}.");
    quote! {
        #(#attrs)*
        #doc
        #[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
        #vis struct #ident;

        #[automatically_derived]
        #[allow(dead_code)]
        impl #ident {
            /// The mechanism's name in its description.
            pub const NAME: &'static str = #name;
            #[doc = #dof_doc]
            pub const DOF: usize = #dof;
            #[doc = #kappa_doc]
            pub const KAPPA: usize = #kappa;
            /// ξ_Lj of each single open chain, in the chosen order.
            pub const XI: &'static [usize] = &[#(#xi),*];
            /// Δ_j of each single open chain, in the chosen order.
            pub const DELTA: &'static [i32] = &[#(#delta),*];
            /// The number of sub-kinematic chains.
            pub const SKC_COUNT: usize = #skc_count;
            /// The platform's POC set, if there is a platform.
            pub const PLATFORM_POC: ::core::option::Option<&'static str> = #platform_poc;
            /// The whole topology report.
            pub const REPORT: ::pkm::runtime::__private::TopologyReport = ::pkm::runtime::__private::TopologyReport {
                name: #name,
                title: #title,
                dof: #dof,
                loops: #loops,
                kappa: #kappa,
                xi: &[#(#xi),*],
                delta: &[#(#delta),*],
                socs: &[#(#socs),*],
                skcs: &[#(#skcs),*],
                actuators: &[#(#actuators),*],
                platform_poc: #platform_poc,
                branch_poc: &[#(#branch_poc),*],
                expression: #expression,
                decoupling: &[#(#decoupling),*],
                text: #text,
            };
            #source_const
        }

    }
}

/// The constant that ties the build to the description's file, so that
/// edits rebuild.
fn source_const(rel: &str) -> TokenStream {
    let c = format_ident!("__PKM_SOURCE");
    // An absolute path is the file itself (the description was read
    // by `Path::join`, which keeps it); a relative one is the crate's.
    let path = if std::path::Path::new(rel).is_absolute() {
        quote! { #rel }
    } else {
        let rel = format!("/{rel}");
        quote! { ::core::concat!(::core::env!("CARGO_MANIFEST_DIR"), #rel) }
    };
    quote! {
        // Ties the build to the file so that edits rebuild.
        #[doc(hidden)]
        const #c: &'static str = ::core::include_str!(#path);
    }
}

/// The solvers, when asked for and the geometry is there: the solution
/// types, the prepared solvers, and the functions of each direction.
fn solver_items(input: &MacroInput, compiled: &crate::compile::Compiled) -> Result<Vec<TokenStream>, Diagnostics> {
    let a = &compiled.analysis;
    let m = &a.mechanism;
    let MacroInput { vis, ident, .. } = input;
    let mut solvers = Vec::new();
    let mut inverse_groups = Vec::new();
    if a.geometry.complete && (m.wants(Capability::Fk) || m.wants(Capability::Ik)) {
        use crate::codegen::solution::Direction;
        let fk = if m.wants(Capability::Fk) {
            Some(compiled.forward()?)
        } else {
            None
        };
        let ik = if m.wants(Capability::Ik) {
            Some(compiled.inverse()?)
        } else {
            None
        };
        for (cap, plan) in [(Capability::Fk, fk), (Capability::Ik, ik)] {
            let Some(plan) = plan else { continue };
            if plan.branches > MAX_FK_CHOICES {
                return Err(Diagnostic::new(
                    m.name_span(),
                    format!(
                        "the {} solution has {} ± choices; a solver lists at most 2^{MAX_FK_CHOICES} branches",
                        cap.name(),
                        plan.branches
                    ),
                )
                .label("too many branches to list")
                .into());
            }
        }
        solvers.push(crate::codegen::solution::solution_items(a, ident, vis));
        let prepared = crate::codegen::solver::generate(a, ident, vis, fk, ik).map_err(|e| {
            Diagnostic::new(
                m.name_span(),
                format!("internal error: the solver's steps failed on symbols: {e}"),
            )
        })?;
        inverse_groups = prepared.inverse_groups;
        solvers.push(prepared.items);
        for (plan, direction) in [(fk, Direction::Forward), (ik, Direction::Inverse)] {
            let Some(plan) = plan else { continue };
            solvers.push(crate::codegen::solution::generate(a, plan, ident, direction));
        }
    }
    let virtual_variable = crate::plan::planner_numeric::by_virtual_variable(a);
    if a.geometry.complete && m.wants(Capability::FkNumeric) && !virtual_variable {
        // κ ≥ 2: the ball legs' pose equations, each root by the generated `ik`.
        crate::plan::planner_numeric::ball_legs(a)?;
        solvers.push(crate::codegen::ball_legs::generate(
            a,
            ident,
            vis,
            compiled.inverse()?,
            &inverse_groups,
        ));
    }
    if a.geometry.complete && virtual_variable {
        let vp = crate::plan::planner_numeric::forward_numeric_plan(a)?;
        let items = crate::codegen::solver::numeric::generate(a, ident, vis, &vp).map_err(|e| {
            Diagnostic::new(
                m.name_span(),
                format!("internal error: the virtual plan's steps failed on symbols: {e}"),
            )
        })?;
        solvers.push(items);
    }
    Ok(solvers)
}

/// `NameParams` with one `f64` field per parameter; `Default` is the nominal design.
fn parameter_struct(input: &MacroInput, a: &Analysis) -> TokenStream {
    let params = &a.geometry.parameters;
    if params.is_empty() {
        return quote! {};
    }
    let MacroInput { vis, ident, .. } = input;
    let name = format_ident!("{}Params", ident);
    let doc = format!(
        " Dimensions of `{}`; `Default` gives the nominal values.",
        a.mechanism.name
    );
    let fields = params.iter().map(|p| {
        let f = format_ident!("{}", p.name);
        let doc = format!(" `{}` (nominal {}).", p.name, p.value);
        quote! { #[doc = #doc] pub #f: f64 }
    });
    // A value clippy's `approx_constant` takes for a constant of
    // `core::f64::consts` (a parameter of `deg(90)`) is written as that
    // constant, so that user crates stay quiet.
    let value = |v: f64| {
        if v < 0.0 {
            let l = crate::codegen::emit::lit(-v);
            quote! { -#l }
        } else {
            crate::codegen::emit::lit(v)
        }
    };
    let defaults = params.iter().map(|p| {
        let f = format_ident!("{}", p.name);
        let v = value(p.value);
        quote! { #f: #v }
    });
    let list = params.iter().map(|p| {
        let (n, v) = (&p.name, value(p.value));
        quote! { (#n, #v) }
    });
    quote! {
        #[doc = #doc]
        #[derive(Debug, Clone, Copy, PartialEq)]
        #[allow(non_snake_case)]
        #vis struct #name {
            #(#fields,)*
        }

        #[automatically_derived]
        impl ::core::default::Default for #name {
            fn default() -> Self {
                #name { #(#defaults,)* }
            }
        }

        #[automatically_derived]
        impl #ident {
            /// Every parameter's name and nominal value, in declaration order.
            pub const PARAMETERS: &'static [(&'static str, f64)] = &[#(#list),*];
        }
    }
}

#[cfg(test)]
mod tests {
    /// The messages `check_capabilities` gives for a four-bar's capability list.
    fn check(capabilities: &str, want: &[&str]) {
        let text = format!("mechanism m {{ capabilities {capabilities}; planar; base R1* ∥ R2 ∥ R3 ∥ R4 base; }}");
        let a = crate::topology::analysis::analyze_source(&text).unwrap();
        let got: Vec<String> = super::check_capabilities(&a)
            .0
            .iter()
            .map(|d| d.message.clone())
            .collect();
        assert_eq!(got, want, "{capabilities}");
    }

    #[test]
    fn fk_numeric_needs_one_coupled_skc() {
        // The four-bar's κ is 0: `fk` solves it.
        check(
            "fk_numeric",
            &["`fk_numeric` is for κ > 0: this mechanism has κ = 0, request `fk`"],
        );
    }

    /// At κ ≥ 2 `fk_numeric` solves legs that end in balls (seed 004's
    /// 3-RPS): it needs `ik`, and outputs that place the platform.
    #[test]
    fn fk_numeric_at_kappa_two_needs_ball_legs_and_ik() {
        let text =
            std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/mechanisms/rps_3.pkm")).unwrap();
        let messages = |t: &str| -> Vec<String> {
            let a = crate::topology::analysis::analyze_source(t).unwrap();
            super::check_capabilities(&a).0.into_iter().map(|d| d.message).collect()
        };
        assert!(messages(&text).is_empty());
        let refused =
            "`fk_numeric` solves one SKC with κ = 1 (one virtual variable); this mechanism has κ = 2 in 1 SKC; \
                       at κ ≥ 2 it solves legs that each end in a ball, by the platform's pose equations, but ";
        let no_ik = text.replace("capabilities ik, fk_numeric, stiffness;", "capabilities fk_numeric;");
        assert_eq!(
            messages(&no_ik),
            [format!(
                "{refused}each root's joints are solved by the inverse solution: request `ik` too"
            )]
        );
        let joints = text
            .replace(
                "capabilities ik, fk_numeric, stiffness;",
                "capabilities ik, fk_numeric;",
            )
            .replace(
                "outputs { ZA, alpha, beta = pose (z, rx, ry) of platform at o; }",
                "outputs { a = joint P1; b = joint P2; c = joint P3; }",
            );
        assert_eq!(
            messages(&joints),
            [format!("{refused}the outputs are not one platform's pose or point")]
        );
    }

    /// What `check_capabilities` says of a whole text: line, column and message of each error.
    fn check_text(text: &str, want: &[(usize, usize, &str)]) {
        let a = crate::topology::analysis::analyze_source(text).unwrap();
        let got: Vec<(usize, usize, String)> = super::check_capabilities(&a)
            .0
            .into_iter()
            .map(|d| {
                let (l, c) = d.span.map_or((0, 0), |s| s.line_col(text));
                (l, c, d.message)
            })
            .collect();
        let want: Vec<(usize, usize, String)> = want.iter().map(|&(l, c, m)| (l, c, m.to_string())).collect();
        assert_eq!(got, want, "{text}");
    }

    #[test]
    fn stiffness_needs_units_limbs_and_ik() {
        let no_ik = "`stiffness` is given at a platform pose, solved by the inverse solution first: request `ik` too";
        // A four-bar: no units, and no branches to be limbs.
        check_text(
            "mechanism m {\n    capabilities fk, stiffness;\n    planar; base R1* ∥ R2 ∥ R3 ∥ R4 base; }",
            &[
                (2, 22, no_ik),
                (2, 22, "`stiffness` needs the file's units: `units { length = mm; mass = kg; }`"),
                (
                    2,
                    22,
                    "`stiffness` needs the mechanism's limbs: write each leg as `branch NAME { … }` from the base to the platform",
                ),
            ],
        );
        let rps = |limbs: &str| {
            format!(
                "mechanism m {{
    capabilities ik, stiffness;
    branch A {{ base R1 ⊥ P1* - S1 platform; }}
    branch B {{ base R2 ⊥ P2* - S2 platform; }}
    branch C {{ base R3 ⊥ P3* - S3 platform; }}
    units {{ length = mm; mass = kg; }}
    {limbs} }}"
            )
        };
        check_text(
            &rps("limbs { A { axial = 1; bending = 2; } }"),
            &[(2, 22, "`stiffness` needs every limb's properties: B, C have none")],
        );
        // Everything it needs is there.
        check_text(
            &rps("limbs { A, B { axial = 1; bending = 2; } C { E = 1; A = 1; I = 1; } }"),
            &[],
        );
    }

    /// The stiffness's reference: an output that places a point, on a
    /// link the limbs join to the base (seed 004's 3-RPS with its outputs
    /// replaced).
    #[test]
    fn stiffness_needs_a_reference_on_the_limbs_platform() {
        let text =
            std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/mechanisms/rps_3.pkm")).unwrap();
        // (`fk_numeric` left out: these outputs are no platform pose for it either.)
        let with = |outputs: &str| {
            let t = text
                .replace(
                    "outputs { ZA, alpha, beta = pose (z, rx, ry) of platform at o; }",
                    outputs,
                )
                .replace("capabilities ik, fk_numeric, stiffness;", "capabilities ik, stiffness;");
            assert_ne!(t, text, "the outputs line was replaced");
            t
        };
        check_text(&text, &[]);
        let plain = with("outputs { a = joint P1; b = joint P2; c = joint P3; }");
        let at = plain.find("stiffness;").unwrap();
        let (line, col) = crate::diagnostics::Span { start: at, end: at }.line_col(&plain);
        check_text(
            &plain,
            &[(
                line,
                col,
                "`stiffness` is given about a platform point: declare the platform's pose, pose parts or a point of it among the outputs",
            )],
        );
        check_text(
            &with("outputs { x, y, z = point S1 of A2; }"),
            &[(
                line,
                col,
                "`stiffness` reads the limbs from the base to `A2`, the link the outputs place, and finds none: \
                 at link `platform`, an inner link of a limb must carry exactly two joints",
            )],
        );
    }

    #[test]
    fn workspace_needs_a_position_solver() {
        check(
            "workspace",
            &["`workspace` sweeps the position solvers: request `fk` or `ik` too"],
        );
        check("fk, workspace", &[]);
        check("ik, workspace", &[]);
    }

    /// The file a description is read from is the one the expansion ties
    /// the build to: relative to the crate, or absolute as given.
    #[test]
    fn the_source_file_is_included_where_it_was_read() {
        let relative = "../examples/mechanisms/four_bar.pkm";
        let absolute = format!("{}/{relative}", env!("CARGO_MANIFEST_DIR"));
        for (file, want) in [
            (absolute.clone(), format!("include_str ! ({absolute:?})")),
            (
                relative.to_string(),
                format!(
                    r#"include_str ! (:: core :: concat ! (:: core :: env ! ("CARGO_MANIFEST_DIR") , "/{relative}"))"#
                ),
            ),
        ] {
            let tokens: proc_macro2::TokenStream = format!("FourBar, file = {file:?}").parse().unwrap();
            let out = crate::expand(tokens).unwrap().to_string();
            assert!(out.contains(&want), "{file}: no `{want}` in the expansion");
        }
    }
}
