//! Dimension expressions: parameters, numbers, `+ − * / ^`, `pi` and a few
//! functions. They are evaluated for nominal values and checks, and turned
//! into Rust for generated code.

use crate::diagnostics::{Diagnostic, Span};
use proc_macro2::TokenStream;
use quote::{format_ident, quote};
use std::collections::HashMap;

/// The functions an expression may call, with their arity.
pub const FUNCTIONS: [(&str, usize); 9] = [
    ("sqrt", 1),
    ("sin", 1),
    ("cos", 1),
    ("tan", 1),
    ("atan2", 2),
    ("abs", 1),
    ("deg", 1),
    ("hypot", 2),
    ("asin", 1),
];

/// An expression.
#[derive(Debug, Clone, PartialEq)]
pub enum Expr {
    /// A number.
    Num(f64),
    /// A parameter (or `pi`).
    Var(String, Span),
    /// −e.
    Neg(Box<Expr>),
    /// Binary operation: `+ - * / ^`.
    Bin(char, Box<Expr>, Box<Expr>),
    /// A function call.
    Call(String, Vec<Expr>, Span),
}

impl Expr {
    /// The value with the given parameter values. Unknown names and calls are
    /// reported by [`Expr::check`]; here they evaluate to NaN.
    pub fn eval(&self, params: &HashMap<String, f64>) -> f64 {
        match self {
            Expr::Num(v) => *v,
            Expr::Var(n, _) if n == "pi" => std::f64::consts::PI,
            Expr::Var(n, _) => params.get(n).copied().unwrap_or(f64::NAN),
            Expr::Neg(e) => -e.eval(params),
            Expr::Bin(op, a, b) => {
                let (a, b) = (a.eval(params), b.eval(params));
                match op {
                    '+' => a + b,
                    '-' => a - b,
                    '*' => a * b,
                    '/' => a / b,
                    _ => a.powf(b),
                }
            }
            Expr::Call(f, args, _) => {
                let v: Vec<f64> = args.iter().map(|a| a.eval(params)).collect();
                match (f.as_str(), v.as_slice()) {
                    ("sqrt", [x]) => x.sqrt(),
                    ("sin", [x]) => x.sin(),
                    ("cos", [x]) => x.cos(),
                    ("tan", [x]) => x.tan(),
                    ("asin", [x]) => x.asin(),
                    ("abs", [x]) => x.abs(),
                    ("deg", [x]) => x.to_radians(),
                    ("atan2", [y, x]) => y.atan2(*x),
                    ("hypot", [x, y]) => x.hypot(*y),
                    _ => f64::NAN,
                }
            }
        }
    }

    /// Reports unknown names (not among `known`) and unknown functions or arities.
    pub fn check(&self, known: &dyn Fn(&str) -> bool, errors: &mut Vec<Diagnostic>) {
        match self {
            Expr::Num(_) => {}
            Expr::Var(n, span) => {
                if n != "pi" && !known(n) {
                    errors.push(
                        Diagnostic::new(*span, format!("unknown parameter `{n}`")).label("not defined before this use"),
                    );
                }
            }
            Expr::Neg(e) => e.check(known, errors),
            Expr::Bin(_, a, b) => {
                a.check(known, errors);
                b.check(known, errors);
            }
            Expr::Call(f, args, span) => {
                match FUNCTIONS.iter().find(|(n, _)| n == f) {
                    None => {
                        let names: Vec<&str> = FUNCTIONS.iter().map(|(n, _)| *n).collect();
                        errors.push(
                            Diagnostic::new(*span, format!("unknown function `{f}`"))
                                .label("not a function")
                                .note(format!("functions: {}", names.join(", "))),
                        );
                    }
                    Some((_, arity)) if *arity != args.len() => errors.push(
                        Diagnostic::new(
                            *span,
                            format!("`{f}` takes {arity} argument{}", if *arity == 1 { "" } else { "s" }),
                        )
                        .label(format!("given {}", args.len())),
                    ),
                    _ => {}
                }
                for a in args {
                    a.check(known, errors);
                }
            }
        }
    }

    /// Rust for the expression; parameters are read as `params.NAME`.
    pub fn to_tokens(&self, params: &TokenStream) -> TokenStream {
        match self {
            Expr::Num(v) => quote! { #v },
            Expr::Var(n, _) if n == "pi" => quote! { ::core::f64::consts::PI },
            Expr::Var(n, _) => {
                let id = format_ident!("{}", n);
                quote! { #params.#id }
            }
            Expr::Neg(e) => {
                let e = e.to_tokens(params);
                quote! { (-#e) }
            }
            Expr::Bin(op, a, b) => {
                let (a, b) = (a.to_tokens(params), b.to_tokens(params));
                match op {
                    '+' => quote! { (#a + #b) },
                    '-' => quote! { (#a - #b) },
                    '*' => quote! { (#a * #b) },
                    '/' => quote! { (#a / #b) },
                    _ => quote! { #a.powf(#b) },
                }
            }
            Expr::Call(f, args, _) => {
                let a: Vec<TokenStream> = args.iter().map(|a| a.to_tokens(params)).collect();
                match (f.as_str(), a.as_slice()) {
                    ("deg", [x]) => quote! { #x.to_radians() },
                    ("atan2", [y, x]) => quote! { #y.atan2(#x) },
                    ("hypot", [x, y]) => quote! { #x.hypot(#y) },
                    (f, [x]) => {
                        let m = format_ident!("{}", f);
                        quote! { #x.#m() }
                    }
                    _ => quote! { ::core::f64::NAN },
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(source: &str, expected: f64) {
        let ast = crate::parse(&format!(
            "mechanism m {{ parameters {{ a = 3; b = 4; v = {source}; }} }}"
        ))
        .unwrap();
        let mut values = HashMap::new();
        for (name, e) in &ast.parameters {
            let v = e.eval(&values);
            values.insert(name.text.clone(), v);
        }
        assert!(
            (values["v"] - expected).abs() <= 1e-15 * expected.abs().max(1.0),
            "{source}: {} vs {expected}",
            values["v"]
        );
    }

    #[test]
    fn precedence_and_functions() {
        check("1 + 2 * 3", 7.0);
        check("(1 + 2) * 3", 9.0);
        check("-a^2", -9.0);
        check("2^3^2", 512.0);
        check("a - b - 1", -2.0);
        check("a / b / 2", 0.375);
        check("sqrt(a^2 + b^2)", 5.0);
        check("hypot(a, b)", 5.0);
        check("atan2(b, a)", (4.0f64).atan2(3.0));
        check("deg(180)", std::f64::consts::PI);
        check("2 * pi", 2.0 * std::f64::consts::PI);
        check("1.5e2", 150.0);
    }
}
