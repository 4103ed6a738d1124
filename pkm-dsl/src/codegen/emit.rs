//! Writes a recorded graph ([`crate::codegen::trace`]) out as straight-line Rust.
//!
//! A node that depends on the parameters alone becomes a slot of the
//! prepared solver, computed once by `prepare`; a node that depends on the
//! given values becomes a `let` where it is used more than once, and is
//! written inline where it is used once; a guard becomes an early return
//! with the step's typed error. Constants are literals.

use crate::codegen::trace::{operands, Failure, Graph, Node, Sym};
use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};
use std::cell::RefCell;
use std::collections::HashMap as StdHashMap;

type HashMap<K, V> = StdHashMap<K, V, std::hash::BuildHasherDefault<crate::codegen::trace::FastHash>>;

/// The emitter of one graph: the prepared slots it has handed out so far.
pub struct Emit<'g> {
    g: &'g Graph,
    slots: RefCell<Vec<Sym>>,
    slot_of: RefCell<HashMap<Sym, usize>>,
    /// Each slot's field of the prepared type, in slot order.
    fields: RefCell<Vec<proc_macro2::Ident>>,
    /// The name of each kernel site's loop, for errors.
    sites: Vec<String>,
    /// Writing a function generic over the scalar `T` ([`Emit::generic`]).
    generic: core::cell::Cell<bool>,
}

/// A literal f64 (NaN and infinities by name).
pub fn lit(x: f64) -> TokenStream {
    if x.is_nan() {
        quote! { ::core::f64::NAN }
    } else if x.is_infinite() {
        if x > 0.0 {
            quote! { ::core::f64::INFINITY }
        } else {
            quote! { ::core::f64::NEG_INFINITY }
        }
    } else if x < 0.0 {
        let l = lit(-x);
        quote! { (-#l) }
    } else if let Some(exact) = named_constant(x) {
        exact
    } else {
        let l = Literal::f64_suffixed(x);
        quote! { #l }
    }
}

/// A literal that clippy's `approx_constant` would take for a constant of
/// `core::f64::consts` (a geometry folded to √2, a right angle's chord),
/// written exactly: the constant by name where it is that constant, else
/// by its bits. Clippy's test: the literal's digits, more than the
/// constant's minimum, start the constant's or equal it rounded.
fn named_constant(x: f64) -> Option<TokenStream> {
    use std::f64::consts as c;
    const KNOWN: [(f64, &str, usize); 19] = [
        (c::E, "E", 4),
        (c::FRAC_1_PI, "FRAC_1_PI", 4),
        (c::FRAC_1_SQRT_2, "FRAC_1_SQRT_2", 5),
        (c::FRAC_2_PI, "FRAC_2_PI", 5),
        (c::FRAC_2_SQRT_PI, "FRAC_2_SQRT_PI", 5),
        (c::FRAC_PI_2, "FRAC_PI_2", 5),
        (c::FRAC_PI_3, "FRAC_PI_3", 5),
        (c::FRAC_PI_4, "FRAC_PI_4", 5),
        (c::FRAC_PI_6, "FRAC_PI_6", 5),
        (c::FRAC_PI_8, "FRAC_PI_8", 5),
        (c::LN_2, "LN_2", 5),
        (c::LN_10, "LN_10", 5),
        (c::LOG2_10, "LOG2_10", 5),
        (c::LOG2_E, "LOG2_E", 5),
        (c::LOG10_2, "LOG10_2", 5),
        (c::LOG10_E, "LOG10_E", 5),
        (c::PI, "PI", 3),
        (c::SQRT_2, "SQRT_2", 5),
        (c::TAU, "TAU", 3),
    ];
    let digits = x.to_string();
    let (value, name, _) = KNOWN.iter().find(|&&(value, _, min)| {
        digits.len() > min
            && (value.to_string().starts_with(&digits)
                || digits == format!("{value:.*}", digits.len().saturating_sub(2)))
    })?;
    Some(if *value == x {
        let name = quote::format_ident!("{}", name);
        quote! { ::core::f64::consts::#name }
    } else {
        let bits = Literal::u64_suffixed(x.to_bits());
        quote! { f64::from_bits(#bits) }
    })
}

/// How many operations deep a name describes a node ([`Emit::label`]).
const LABEL_DEPTH: usize = 3;

/// The longest name a node is given, in characters ([`Emit::label`]).
const LABEL_LEN: usize = 24;

/// A name as an identifier: a description's names may be numbers or
/// non-ASCII words, or Rust's keywords.
fn ident_text(n: &str) -> String {
    let n: String = n
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    if n.starts_with(|c: char| c.is_ascii_digit()) {
        format!("n{n}")
    } else if syn::parse_str::<syn::Ident>(&n).is_err() {
        format!("{n}_")
    } else {
        n
    }
}

/// How a function under emission refers to its nodes.
struct Scope {
    uses: HashMap<Sym, usize>,
    bound: RefCell<HashMap<Sym, TokenStream>>,
}

impl<'g> Emit<'g> {
    /// An emitter for `g`; `sites` names the loop of each guard's site, for errors.
    pub fn new(g: &'g Graph, sites: Vec<String>) -> Self {
        Emit {
            g,
            slots: RefCell::default(),
            slot_of: RefCell::default(),
            fields: RefCell::default(),
            sites,
            generic: core::cell::Cell::new(false),
        }
    }

    fn node(&self, s: Sym) -> &Node {
        &self.g.nodes[s.0 as usize]
    }

    fn live(&self, s: Sym) -> bool {
        self.g.live[s.0 as usize]
    }

    /// The prepared slot of a parameter-only node: a field of the prepared
    /// type named after what it is (`self.l2`, `self.abs_l3_sq`), or
    /// `self.k{i}` where the node has no short name.
    fn slot(&self, s: Sym) -> TokenStream {
        let mut of = self.slot_of.borrow_mut();
        let i = *of.entry(s).or_insert_with(|| {
            let mut slots = self.slots.borrow_mut();
            slots.push(s);
            let i = slots.len() - 1;
            let mut fields = self.fields.borrow_mut();
            let base = self
                .label(s, LABEL_DEPTH)
                .map_or_else(|| format!("k{i}"), |l| ident_text(&l));
            let taken = |f: &str| fields.iter().any(|x| x == f);
            let field = if taken(&base) {
                (2..)
                    .map(|n| format!("{base}_{n}"))
                    .find(|f| !taken(f))
                    .unwrap_or_default()
            } else {
                base
            };
            fields.push(format_ident!("{}", field));
            i
        });
        let field = &self.fields.borrow()[i];
        quote! { self.#field }
    }

    /// What a node is, in words short enough for a name: the tracer's
    /// name for it (a link's coordinate, a joint's cosine), a parameter's
    /// name, or its operation on its operands' names (`l2_sq`,
    /// `half_inv_abs_l3`, `cos_R1_times_l2`); `None` beyond `depth`
    /// operations or [`LABEL_LEN`] characters.
    fn label(&self, s: Sym, depth: usize) -> Option<String> {
        if let Some(n) = &self.g.names[s.0 as usize] {
            return Some(n.clone());
        }
        let sub = |o: Sym| if depth == 0 { None } else { self.label(o, depth - 1) };
        let k = |o: Sym| self.g.constant(o);
        let l = match self.node(s) {
            Node::Param(n) => n.clone(),
            Node::Extent(_) => "extent".into(),
            Node::Chosen(_, _, v) => return self.label(*v, depth),
            Node::Mul(a, b) if a == b => format!("{}_sq", sub(*a)?),
            Node::Mul(a, b) | Node::Mul(b, a) if k(*a).is_some() => {
                let by = [(2.0, "twice"), (0.5, "half"), (-1.0, "neg")]
                    .iter()
                    .find(|c| k(*a) == Some(c.0));
                format!("{}_{}", by?.1, sub(*b)?)
            }
            Node::Div(a, b) if k(*a).is_some() => {
                let by = [(1.0, "inv"), (0.5, "half_inv")].iter().find(|c| k(*a) == Some(c.0));
                format!("{}_{}", by?.1, sub(*b)?)
            }
            Node::Add(a, b) => format!("{}_plus_{}", sub(*a)?, sub(*b)?),
            Node::Sub(a, b) => format!("{}_minus_{}", sub(*a)?, sub(*b)?),
            Node::Mul(a, b) => format!("{}_times_{}", sub(*a)?, sub(*b)?),
            Node::Div(a, b) => format!("{}_over_{}", sub(*a)?, sub(*b)?),
            Node::Neg(a) => format!("neg_{}", sub(*a)?),
            Node::Abs(a) => format!("abs_{}", sub(*a)?),
            Node::Sqrt(a) => format!("sqrt_{}", sub(*a)?),
            Node::Sin(a) => format!("sin_{}", sub(*a)?),
            Node::Cos(a) => format!("cos_{}", sub(*a)?),
            _ => return None,
        };
        (l.chars().count() <= LABEL_LEN).then_some(l)
    }

    /// The constant a node is, if it is one.
    pub fn constant(&self, s: Sym) -> Option<f64> {
        self.g.constant(s)
    }

    /// The guards of `guards` a function computing `roots` must check: all
    /// but those of the steps in `waivable` (each with the values it solves)
    /// whose values `roots` do not read. Such a step (an aim a miss stands
    /// for, [`pkm_runtime::plan::Plan::by_miss`]) is not computed, and
    /// its guards only ask that its turn be defined.
    pub fn needed_guards(&self, roots: &[Sym], guards: &[Sym], waivable: &[(usize, Vec<Sym>)]) -> Vec<Sym> {
        let (order, _) = self.reach(roots);
        let read = |v: &Sym| order.binary_search(v).is_ok();
        guards
            .iter()
            .copied()
            .filter(|&g| match self.node(g) {
                Node::Guard(.., [step, _]) => waivable
                    .iter()
                    .find(|(k, _)| k == step)
                    .is_none_or(|(_, values)| values.iter().any(read)),
                _ => true,
            })
            .collect()
    }

    /// The live nodes reachable from `roots` (not through parameter-only
    /// nodes), in recorded order, with their use counts.
    fn reach(&self, roots: &[Sym]) -> (Vec<Sym>, HashMap<Sym, usize>) {
        self.reach_by(roots, &|n| operands(n))
    }

    /// [`Self::reach`] through the operands `of` each node.
    fn reach_by(&self, roots: &[Sym], of: &dyn Fn(&Node) -> Vec<Sym>) -> (Vec<Sym>, HashMap<Sym, usize>) {
        let mut uses: HashMap<Sym, usize> = HashMap::default();
        let mut seen = vec![false; self.g.nodes.len()];
        let mut stack: Vec<Sym> = roots.to_vec();
        for r in roots {
            *uses.entry(*r).or_default() += 2;
        }
        while let Some(s) = stack.pop() {
            if seen[s.0 as usize] || !self.live(s) {
                continue;
            }
            seen[s.0 as usize] = true;
            for o in of(self.node(s)) {
                *uses.entry(o).or_default() += 1;
                stack.push(o);
            }
        }
        let order = (0..self.g.nodes.len() as u32)
            .map(Sym)
            .filter(|s| seen[s.0 as usize])
            .collect();
        (order, uses)
    }

    /// An f64 expression as the scalar of the function written: itself,
    /// or `T::c(x)` in a generic one.
    fn scalar(&self, x: TokenStream) -> TokenStream {
        if self.generic.get() {
            quote! { T::c(#x) }
        } else {
            x
        }
    }

    /// An expression for `s`, in `scope`.
    fn expr(&self, s: Sym, scope: &Scope) -> TokenStream {
        if let Some(x) = self.g.constant(s) {
            return self.scalar(lit(x));
        }
        if let Some(t) = scope.bound.borrow().get(&s) {
            return t.clone();
        }
        if !self.live(s) {
            return self.scalar(self.slot(s));
        }
        self.compute(s, &|s| self.expr(s, scope))
    }

    /// The node's own operation on its operands' expressions.
    fn compute(&self, s: Sym, e: &dyn Fn(Sym) -> TokenStream) -> TokenStream {
        if self.generic.get() {
            if let Some(t) = self.compute_generic(s, e) {
                return t;
            }
        }
        match self.node(s) {
            Node::Const(b) => lit(f64::from_bits(*b)),
            Node::Param(n) => {
                let id = format_ident!("{}", n);
                quote! { params.#id }
            }
            Node::Given(k) => quote! { given[#k] },
            Node::Rate(k) => quote! { rates[#k] },
            Node::Accel(k) => quote! { accelerations[#k] },
            Node::Add(a, b) => {
                let (a, b) = (e(*a), e(*b));
                quote! { (#a + #b) }
            }
            Node::Sub(a, b) => {
                let (a, b) = (e(*a), e(*b));
                quote! { (#a - #b) }
            }
            Node::Mul(a, b) => {
                let (a, b) = (e(*a), e(*b));
                quote! { (#a * #b) }
            }
            Node::Div(a, b) => {
                let (a, b) = (e(*a), e(*b));
                quote! { (#a / #b) }
            }
            Node::Neg(a) => {
                let a = e(*a);
                quote! { (-#a) }
            }
            Node::Sqrt(a) => {
                let a = e(*a);
                quote! { #a.sqrt() }
            }
            Node::Sin(a) => {
                let a = e(*a);
                quote! { #a.sin() }
            }
            Node::Cos(a) => {
                let a = e(*a);
                quote! { #a.cos() }
            }
            Node::Abs(a) => {
                let a = e(*a);
                quote! { #a.abs() }
            }
            Node::Atan2(a, b) => {
                let (a, b) = (e(*a), e(*b));
                quote! { ::pkm::runtime::__private::scalar::angle(#a, #b) }
            }
            Node::IfLess(a, b, c, d, _) => {
                let (a, b, c, d) = (e(*a), e(*b), e(*c), e(*d));
                quote! { if #a < #b { #c } else { #d } }
            }
            Node::Extent(values) => {
                let values = values.iter().map(|v| e(*v));
                quote! { ::pkm::runtime::__private::consistency::extent(&[[#(#values),*]]) }
            }
            Node::Raw(text) => text.parse().unwrap_or_else(|_| quote! { ::core::f64::NAN }),
            Node::Chosen(_, _, v) => e(*v),
            Node::Pick(k, p, m) => {
                let (p, m) = (e(*p), e(*m));
                quote! {
                    match signs[#k] {
                        ::pkm::runtime::__private::primitives::Sign::Plus => #p,
                        ::pkm::runtime::__private::primitives::Sign::Minus => #m,
                    }
                }
            }
            Node::Guard(a, b, ..) => {
                let (a, b) = (e(*a), e(*b));
                quote! { !(#a < #b) }
            }
        }
    }

    /// [`Self::compute`] in a function generic over `T: Scalar`: the
    /// functions and decisions as the trait's; `None` where the f64 form
    /// serves (arithmetic, the given values, a chosen value).
    fn compute_generic(&self, s: Sym, e: &dyn Fn(Sym) -> TokenStream) -> Option<TokenStream> {
        let sc = quote! { ::pkm::runtime::__private::scalar::Scalar };
        Some(match self.node(s) {
            Node::Const(b) => {
                let x = lit(f64::from_bits(*b));
                quote! { T::c(#x) }
            }
            Node::Param(n) => {
                let id = format_ident!("{}", n);
                quote! { T::c(params.#id) }
            }
            Node::Raw(text) => {
                let x = text.parse().unwrap_or_else(|_| quote! { ::core::f64::NAN });
                quote! { T::c(#x) }
            }
            Node::Sqrt(a) => {
                let a = e(*a);
                quote! { <T as #sc>::sqrt(#a) }
            }
            Node::Sin(a) => {
                let a = e(*a);
                quote! { <T as #sc>::sin(#a) }
            }
            Node::Cos(a) => {
                let a = e(*a);
                quote! { <T as #sc>::cos(#a) }
            }
            Node::Abs(a) => {
                let a = e(*a);
                quote! { <T as #sc>::abs(#a) }
            }
            Node::Atan2(a, b) => {
                let (a, b) = (e(*a), e(*b));
                quote! { <T as #sc>::atan2(#a, #b) }
            }
            Node::IfLess(a, b, c, d, continuous) => {
                let (a, b, c, d) = (e(*a), e(*b), e(*c), e(*d));
                if *continuous {
                    quote! { <T as #sc>::if_less_continuous(#a, #b, #c, #d) }
                } else {
                    quote! { <T as #sc>::if_less(#a, #b, #c, #d) }
                }
            }
            // The interpreter's compatibility residual measures against 1.
            Node::Extent(_) => quote! { T::c(1.0) },
            Node::Pick(k, p, m) => {
                let (p, m) = (e(*p), e(*m));
                quote! { <T as #sc>::pick(signs[#k], #p, #m) }
            }
            _ => return None,
        })
    }

    /// A node bound by a `let` (a value used twice): its name and value;
    /// `None` for one written where it is used.
    fn binding(&self, s: Sym, node: &Node, scope: &Scope) -> Option<(proc_macro2::Ident, TokenStream)> {
        let many = scope.uses.get(&s).copied().unwrap_or(0) >= 2;
        if !many || matches!(node, Node::Given(_) | Node::Rate(_) | Node::Accel(_)) {
            return None;
        }
        Some((self.name(s), self.compute(s, &|o| self.expr(o, scope))))
    }

    /// A `let`'s name: what the node is ([`Emit::label`]) and its number,
    /// unique in the whole graph (`cos_R1_17`), or `v{number}` for a node
    /// with no short name.
    fn name(&self, s: Sym) -> proc_macro2::Ident {
        match self.label(s, LABEL_DEPTH) {
            Some(n) => format_ident!("{}_{}", ident_text(&n), s.0),
            None => format_ident!("v{}", s.0),
        }
    }

    /// `let` statements for the nodes of `order` that `keep` selects, where
    /// bound (used twice); guards' failures go to `fail` (given the error
    /// expression).
    fn lets(
        &self,
        order: &[Sym],
        scope: &Scope,
        keep: &dyn Fn(Sym) -> bool,
        fail: &dyn Fn(TokenStream) -> TokenStream,
    ) -> TokenStream {
        let mut out = TokenStream::new();
        for &s in order {
            if !keep(s) || scope.bound.borrow().contains_key(&s) {
                continue;
            }
            let node = self.node(s);
            if let (Node::Guard(a, b, _, [step, site]), true) = (node, self.generic.get()) {
                let (a, b) = (self.expr(*a, scope), self.expr(*b, scope));
                let sc = quote! { ::pkm::runtime::__private::scalar };
                out.extend(quote! {
                    if <T as #sc::Scalar>::require(#a, #b, #sc::Failure::Degenerate("guard"), [#step, #site]).is_err() {
                        return ::core::option::Option::None;
                    }
                });
                scope.bound.borrow_mut().insert(s, quote! { () });
                continue;
            }
            if let Node::Guard(_, _, failure, [step, site]) = node {
                let cond = self.compute(s, &|o| self.expr(o, scope));
                let geom = quote! { ::pkm::runtime::__private::primitives::Error };
                let error = match failure {
                    Failure::Degenerate(what) => quote! { #geom::Degenerate { what: #what } },
                    Failure::Unreachable(constraint, by) => {
                        let by = self.expr(*by, scope);
                        quote! { #geom::Unreachable { constraint: #constraint, by: #by } }
                    }
                    Failure::Distance(d, dmax, dmin) => {
                        let (d, dmax, dmin) = (self.expr(*d, scope), self.expr(*dmax, scope), self.expr(*dmin, scope));
                        quote! { ::pkm::runtime::__private::scalar::unreachable_distance(#d, #dmax, #dmin) }
                    }
                };
                let name = &self.sites[*site];
                let err = fail(quote! {
                    ::pkm::runtime::__private::solution::step_error(#step, ::std::borrow::Cow::Borrowed(#name), #error)
                });
                out.extend(quote! { if #cond { #err } });
                scope.bound.borrow_mut().insert(s, quote! { () });
                continue;
            }
            let Some((v, e)) = self.binding(s, node, scope) else {
                continue;
            };
            out.extend(quote! { let #v = #e; });
            scope.bound.borrow_mut().insert(s, quote! { #v });
        }
        out
    }

    /// A function body computing `roots` (one branch, signs as given):
    /// the statements, and the roots' expressions.
    pub fn straight(&self, roots: &[Sym], guards: &[Sym]) -> (TokenStream, Vec<TokenStream>) {
        let all: Vec<Sym> = roots.iter().chain(guards).copied().collect();
        let (order, uses) = self.reach(&all);
        let scope = Scope {
            uses,
            bound: RefCell::default(),
        };
        let lets = self.lets(
            &order,
            &scope,
            &|_| true,
            &|e| quote! { return ::core::result::Result::Err(#e) },
        );
        let out = roots.iter().map(|r| self.expr(*r, &scope)).collect();
        (lets, out)
    }

    /// [`Self::straight`] for a function generic over `T: Scalar` (with
    /// `Choice = Sign`) whose given values are `given: &[T; n]`: constants
    /// and prepared slots become `T::c(…)`, the functions and decisions
    /// the trait's, and a guard that fails returns `None` (the
    /// interval enclosure of [`pkm_runtime::interval`] takes a guard that
    /// holds on part of a box as holding, and says so).
    pub fn straight_generic(&self, roots: &[Sym], guards: &[Sym]) -> (TokenStream, Vec<TokenStream>) {
        self.generic.set(true);
        let out = self.straight(roots, guards);
        self.generic.set(false);
        out
    }

    /// One lane of a batch loop computing `roots` (one branch, signs as
    /// given), without control flow where the graph has none: each guard
    /// clears the lane's flag `lane_ok` instead of returning (its error's
    /// values are not computed). What a cleared lane computes after is garbage (NaN, ∞) the
    /// caller must not let out. The statements, and the roots' expressions.
    pub fn lanes(&self, roots: &[Sym], guards: &[Sym]) -> (TokenStream, Vec<TokenStream>) {
        let all: Vec<Sym> = roots.iter().chain(guards).copied().collect();
        // A guard needs its condition's operands only.
        let (order, uses) = self.reach_by(&all, &|n| match n {
            Node::Guard(a, b, ..) => vec![*a, *b],
            n => operands(n),
        });
        let scope = Scope {
            uses,
            bound: RefCell::default(),
        };
        let mut out = TokenStream::new();
        for &s in &order {
            let node = self.node(s);
            if let Node::Guard(a, b, ..) = node {
                let (a, b) = (self.expr(*a, &scope), self.expr(*b, &scope));
                out.extend(quote! { lane_ok &= #a < #b; });
                continue;
            }
            let Some((v, e)) = self.binding(s, node, &scope) else {
                continue;
            };
            out.extend(quote! { let #v = #e; });
            scope.bound.borrow_mut().insert(s, quote! { #v });
        }
        let exprs = roots.iter().map(|r| self.expr(*r, &scope)).collect();
        (out, exprs)
    }

    /// Every branch at once, each branch's roots computed under nested
    /// blocks per ± choice so that what branches share is computed once:
    /// `leaf(b, roots)` writes branch b's result from its roots'
    /// expressions; statements assign `all[b].result`.
    pub fn branches(
        &self,
        roots: &[Vec<Sym>],
        guards: &[Vec<Sym>],
        choices: usize,
        leaf: &dyn Fn(usize, Vec<TokenStream>, &syn::Lifetime) -> TokenStream,
    ) -> TokenStream {
        let all: Vec<Sym> = roots.iter().chain(guards).flatten().copied().collect();
        let (order, uses) = self.reach(&all);
        let scope = Scope {
            uses,
            bound: RefCell::default(),
        };
        self.level(&order, &scope, roots, choices, 0, 0, leaf)
    }

    #[allow(clippy::too_many_arguments)]
    fn level(
        &self,
        order: &[Sym],
        scope: &Scope,
        roots: &[Vec<Sym>],
        choices: usize,
        depth: usize,
        path: u64,
        leaf: &dyn Fn(usize, Vec<TokenStream>, &syn::Lifetime) -> TokenStream,
    ) -> TokenStream {
        let depth_mask = if depth == 0 { 0 } else { (1u64 << depth) - 1 };
        let keep = |s: Sym| {
            let (which, values) = self.g.signs[s.0 as usize];
            let top = if which == 0 {
                0
            } else {
                64 - which.leading_zeros() as usize
            };
            top == depth && which & !depth_mask == 0 && (values & which) == (path & which)
        };
        let label = syn::Lifetime::new(&format!("'b{depth}_{path}"), proc_macro2::Span::call_site());
        // What this block binds goes out of scope with it.
        let outer = scope.bound.borrow().clone();
        let lets = self.lets(
            order,
            scope,
            &keep,
            &|e| quote! { break #label (::core::result::Result::Err(#e)) },
        );
        // The branches below this path.
        let below: Vec<usize> = (0..roots.len()).filter(|&b| (b as u64) & depth_mask == path).collect();
        let inner = if depth == choices {
            let b = below[0];
            let exprs = roots[b].iter().map(|r| self.expr(*r, scope)).collect();
            let body = leaf(b, exprs, &label);
            quote! { all[#b].result = #label: { #lets #body }; }
        } else {
            let mut t = TokenStream::new();
            for bit in [0u64, 1] {
                t.extend(self.level(order, scope, roots, choices, depth + 1, path | (bit << depth), leaf));
            }
            t
        };
        *scope.bound.borrow_mut() = outer;
        if depth == choices {
            inner
        } else {
            let fan = below
                .iter()
                .map(|b| quote! { all[#b].result = ::core::result::Result::Err(e.clone()); });
            quote! {
                let r: ::core::result::Result<(), ::pkm::runtime::__private::solution::SolveError> = #label: {
                    #lets
                    #inner
                    ::core::result::Result::Ok(())
                };
                if let ::core::result::Result::Err(e) = r {
                    #(#fan)*
                }
            }
        }
    }

    /// The prepared type's fields, one per slot handed out
    /// (`l2: f64, abs_l3_sq: f64`), and `prepare`'s body, a value of
    /// `ty` computed from `params`.
    pub fn prepared(&self, ty: &proc_macro2::Ident) -> (TokenStream, TokenStream) {
        self.prepared_with(ty, &TokenStream::new(), &[])
    }

    /// As [`Self::prepared`], with more fields (`extra`, each `name: Type,`)
    /// set by `inits_extra` (each `name: value`).
    pub fn prepared_with(
        &self,
        ty: &proc_macro2::Ident,
        extra: &TokenStream,
        inits_extra: &[TokenStream],
    ) -> (TokenStream, TokenStream) {
        let (lets, values) = self.prepare();
        let fields = self.fields.borrow();
        let inits = fields
            .iter()
            .zip(values)
            .map(|(f, v)| {
                if *f == v.to_string() {
                    quote! { #f }
                } else {
                    quote! { #f: #v }
                }
            })
            .chain(inits_extra.iter().cloned());
        (
            quote! { #(#fields: f64,)* #extra },
            quote! { #lets #ty { #(#inits),* } },
        )
    }

    /// Every slot handed out, computed from `params`: the `let`s of what
    /// two or more slots share, and each slot's value, in slot order.
    fn prepare(&self) -> (TokenStream, Vec<TokenStream>) {
        let slots = self.slots.borrow().clone();
        let (order, uses) = {
            // Parameter-only nodes reachable from the slots.
            let mut uses: HashMap<Sym, usize> = HashMap::default();
            let mut seen = vec![false; self.g.nodes.len()];
            let mut stack = slots.clone();
            for s in &slots {
                *uses.entry(*s).or_default() += 2;
            }
            while let Some(s) = stack.pop() {
                if seen[s.0 as usize] {
                    continue;
                }
                seen[s.0 as usize] = true;
                for o in operands(self.node(s)) {
                    *uses.entry(o).or_default() += 1;
                    stack.push(o);
                }
            }
            let order: Vec<Sym> = (0..self.g.nodes.len() as u32)
                .map(Sym)
                .filter(|s| seen[s.0 as usize])
                .collect();
            (order, uses)
        };
        let scope = Scope {
            uses,
            bound: RefCell::default(),
        };
        let mut lets = TokenStream::new();
        for &s in &order {
            if self.g.constant(s).is_some() || scope.uses.get(&s).copied().unwrap_or(0) < 2 {
                continue;
            }
            // Numbered as in the solvers: a bare name could be a constant
            // of the caller's (`const RB: f64` beside a parameter `RB`).
            let v = self.name(s);
            let e = self.compute(s, &|o| self.prepared_expr(o, &scope));
            lets.extend(quote! { let #v = #e; });
            scope.bound.borrow_mut().insert(s, quote! { #v });
        }
        let values = slots.iter().map(|s| self.prepared_expr(*s, &scope)).collect();
        (lets, values)
    }

    fn prepared_expr(&self, s: Sym, scope: &Scope) -> TokenStream {
        if let Some(x) = self.g.constant(s) {
            return lit(x);
        }
        if let Some(t) = scope.bound.borrow().get(&s) {
            return t.clone();
        }
        self.compute(s, &|o| self.prepared_expr(o, scope))
    }
}

#[cfg(test)]
mod tests {
    /// A prepared slot is a field named after what it is: a parameter, or
    /// an operation on named operands; numbered where it has no short
    /// name, and a number added where two nodes share a name.
    #[test]
    fn prepared_fields_are_named_after_what_they_are() {
        use crate::codegen::trace::{record, Sym};
        use pkm_runtime::scalar::Scalar;
        let (slots, g) = record(|| {
            let (l2, l3) = (Sym::param("l2"), Sym::param("l3"));
            vec![
                l2,
                l2 * l2,
                Sym::c(0.5) / l3.abs(),
                Sym::c(2.0) * l2,
                l3 - l2,
                l2.atan2(l3),
                Sym::param("l2_sq"),
            ]
        });
        let emit = super::Emit::new(&g, vec![]);
        let got: Vec<String> = slots
            .iter()
            .map(|s| emit.slot(*s).to_string().replace(' ', ""))
            .collect();
        let want = [
            "self.l2",
            "self.l2_sq",
            "self.half_inv_abs_l3",
            "self.twice_l2",
            "self.l3_minus_l2",
            "self.k5",
            "self.l2_sq_2",
        ];
        assert_eq!(got, want);
        let (fields, prepare) = emit.prepared(&quote::format_ident!("P"));
        assert_eq!(
            fields.to_string().replace(' ', ""),
            "l2:f64,l2_sq:f64,half_inv_abs_l3:f64,twice_l2:f64,l3_minus_l2:f64,k5:f64,l2_sq_2:f64,"
        );
        // Each slot is a `let` of its own name and its node's number (l2
        // is node 0, l3 node 1, the constants 0.5 and 2 nodes 3 and 6),
        // and its value its field's.
        assert_eq!(
            prepare.to_string().replace(' ', ""),
            "letl2_0=params.l2;letl3_1=params.l3;letl2_sq_2=(l2_0*l2_0);\
             lethalf_inv_abs_l3_5=(0.5f64/l3_1.abs());lettwice_l2_7=(2f64*l2_0);\
             letl3_minus_l2_8=(l3_1-l2_0);letv9=::pkm::runtime::__private::scalar::angle(l2_0,l3_1);\
             letl2_sq_10=params.l2_sq;\
             P{l2:l2_0,l2_sq:l2_sq_2,half_inv_abs_l3:half_inv_abs_l3_5,twice_l2:twice_l2_7,\
             l3_minus_l2:l3_minus_l2_8,k5:v9,l2_sq_2:l2_sq_10}"
        );
    }

    /// What a literal is written as.
    fn check(x: f64, want: &str) {
        assert_eq!(super::lit(x).to_string().replace(' ', ""), want, "{x}");
    }

    #[test]
    fn literals_clippy_takes_for_constants_are_written_exactly() {
        check(1.5, "1.5f64");
        check(100.0, "100f64");
        check(std::f64::consts::SQRT_2, "::core::f64::consts::SQRT_2");
        check(-std::f64::consts::FRAC_PI_2, "(-::core::f64::consts::FRAC_PI_2)");
        // An ulp off √2, and π to three decimals: their bits.
        let near = f64::from_bits(std::f64::consts::SQRT_2.to_bits() - 1);
        check(near, &format!("f64::from_bits({}u64)", near.to_bits()));
        let pi_ish: f64 = "3.14".parse().unwrap(); // written so clippy does not flag the test itself
        check(pi_ish, &format!("f64::from_bits({}u64)", pi_ish.to_bits()));
        // Too few digits to be taken for one.
        check(3.1, "3.1f64");
        check(1.41, "1.41f64");
    }
}
