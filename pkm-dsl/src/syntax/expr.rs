//! Dimension expressions: parameters, numbers, `+ − * / ^`, `pi` and a few
//! functions. They are evaluated for nominal values and checks, and turned
//! into Rust for generated code.

use crate::diagnostics::{Diagnostic, Span};
use proc_macro2::TokenStream;
use quote::{format_ident, quote};
use std::collections::HashMap;
use std::fmt;

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
                    errors.push(Diagnostic::new(*span, format!("unknown parameter `{n}`")).label("not a parameter"));
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

impl Expr {
    /// The value with the given parameter values, or why it is not a finite
    /// number: the first operation (innermost first) whose result is NaN or
    /// infinite. Names not in `params` are an error too.
    pub fn eval_checked(&self, params: &HashMap<String, f64>) -> Result<f64, String> {
        let value = match self {
            Expr::Num(v) => *v,
            Expr::Var(n, _) if n == "pi" => std::f64::consts::PI,
            Expr::Var(n, _) => match params.get(n) {
                Some(v) if v.is_finite() => *v,
                Some(v) => return Err(format!("`{n}` is {}", non_finite_name(*v))),
                None => return Err(format!("`{n}` has no value")),
            },
            Expr::Neg(e) => -e.eval_checked(params)?,
            Expr::Bin(op, a, b) => {
                let (x, y) = (a.eval_checked(params)?, b.eval_checked(params)?);
                let v = match op {
                    '+' => x + y,
                    '-' => x - y,
                    '*' => x * y,
                    '/' => x / y,
                    _ => x.powf(y),
                };
                if !v.is_finite() {
                    return Err(match op {
                        '/' if y == 0.0 => "division by zero".to_string(),
                        '^' if x == 0.0 && y < 0.0 => "zero to a negative power".to_string(),
                        '^' if x < 0.0 && y.fract() != 0.0 => "a negative number to a fractional power".to_string(),
                        _ => format!("overflow in `{}`", self),
                    });
                }
                v
            }
            Expr::Call(f, args, _) => {
                let mut v = Vec::with_capacity(args.len());
                for a in args {
                    v.push(a.eval_checked(params)?);
                }
                let r = Expr::Call(f.clone(), v.iter().map(|x| Expr::Num(*x)).collect(), Span::default())
                    .eval(&HashMap::new());
                if !r.is_finite() {
                    return Err(match (f.as_str(), v.as_slice()) {
                        ("sqrt", [x]) if *x < 0.0 => "sqrt of a negative number".to_string(),
                        ("asin", [x]) if x.abs() > 1.0 => "asin of a number outside [−1, 1]".to_string(),
                        _ if !FUNCTIONS.iter().any(|(n, k)| n == f && *k == args.len()) => {
                            format!("`{f}` with {} arguments is not a function", args.len())
                        }
                        _ => format!("overflow in `{}`", self),
                    });
                }
                r
            }
        };
        if value.is_finite() {
            Ok(value)
        } else {
            Err(format!("overflow in `{self}`"))
        }
    }

    /// The smallest span that covers every name and call in the expression
    /// (numbers carry no span), if it has any.
    pub fn span(&self) -> Option<Span> {
        let join = |a: Option<Span>, b: Option<Span>| match (a, b) {
            (Some(a), Some(b)) => Some(Span::new(a.start.min(b.start), a.end.max(b.end))),
            (a, b) => a.or(b),
        };
        match self {
            Expr::Num(_) => None,
            Expr::Var(_, s) | Expr::Call(_, _, s) => Some(*s),
            Expr::Neg(e) => e.span(),
            Expr::Bin(_, a, b) => join(a.span(), b.span()),
        }
    }

    /// Whether the expression reads no parameter (`pi` is a constant): its
    /// value is the same for every parameter set.
    ///
    /// ```
    /// use pkm_dsl::expr::Expr;
    /// assert!(Expr::Num(2.0).is_constant());
    /// assert!(!Expr::Var("l".into(), pkm_dsl::Span::default()).is_constant());
    /// ```
    pub fn is_constant(&self) -> bool {
        let mut names = Vec::new();
        self.names(&mut names);
        names.is_empty()
    }

    /// Every parameter name the expression reads (not `pi`), with repeats.
    fn names<'a>(&'a self, out: &mut Vec<&'a str>) {
        match self {
            Expr::Num(_) => {}
            Expr::Var(n, _) if n == "pi" => {}
            Expr::Var(n, _) => out.push(n),
            Expr::Neg(e) => e.names(out),
            Expr::Bin(_, a, b) => {
                a.names(out);
                b.names(out);
            }
            Expr::Call(_, args, _) => args.iter().for_each(|a| a.names(out)),
        }
    }

    /// Binding strength: sums 1, products 2, negation 3, powers 4, atoms 5.
    fn precedence(&self) -> u8 {
        match self {
            Expr::Bin('+' | '-', ..) => 1,
            Expr::Bin('*' | '/', ..) => 2,
            Expr::Neg(_) => 3,
            Expr::Bin(..) => 4,
            _ => 5,
        }
    }
}

fn non_finite_name(v: f64) -> &'static str {
    if v.is_nan() {
        "NaN"
    } else if v > 0.0 {
        "infinite"
    } else {
        "−infinite"
    }
}

/// The expression as the language writes it, with only the parentheses its
/// precedence needs (`sqrt(l8^2 - (l2 / 2)^2)`).
impl fmt::Display for Expr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let wrap = |e: &Expr, need: bool, f: &mut fmt::Formatter<'_>| {
            if need {
                write!(f, "({e})")
            } else {
                write!(f, "{e}")
            }
        };
        match self {
            Expr::Num(v) => write!(f, "{v}"),
            Expr::Var(n, _) => write!(f, "{n}"),
            Expr::Neg(e) => {
                write!(f, "-")?;
                wrap(e, e.precedence() < 3, f)
            }
            Expr::Bin(op, a, b) => {
                let p = self.precedence();
                if *op == '^' {
                    // Right-associative, and `-a^b` is `-(a^b)`: a base that is
                    // not an atom needs parentheses.
                    wrap(a, a.precedence() <= p, f)?;
                    write!(f, "^")?;
                    wrap(b, b.precedence() < 3, f)
                } else {
                    wrap(a, a.precedence() < p, f)?;
                    write!(f, " {op} ")?;
                    wrap(b, b.precedence() <= p, f)
                }
            }
            Expr::Call(name, args, _) => {
                write!(f, "{name}(")?;
                for (i, a) in args.iter().enumerate() {
                    if i > 0 {
                        write!(f, ", ")?;
                    }
                    write!(f, "{a}")?;
                }
                write!(f, ")")
            }
        }
    }
}

/// One parameter to resolve: its name, where the name is written, and its value's expression.
#[derive(Debug, Clone, Copy)]
pub struct Definition<'a> {
    /// The parameter's name.
    pub name: &'a str,
    /// Where its name is written.
    pub span: Span,
    /// Its defining expression.
    pub expr: &'a Expr,
}

/// The value of every parameter, each computed after the parameters it reads
/// (a parameter may read one defined below it), and the errors: parameters
/// that read each other in a cycle, and values that are not finite numbers,
/// each naming the parameter and its expression. A parameter in `overrides`
/// takes the given value instead of its expression's. Linear in the number of
/// parameters and references (Kahn's algorithm; nothing recurses on the
/// dependency chain). A parameter whose expression reads an unknown name or
/// calls an unknown function is left NaN without an error here: those errors
/// are [`Expr::check`]'s. So is every parameter that reads a failed one.
/// If a name is defined twice the first definition is used.
pub fn resolve(defs: &[Definition], overrides: &HashMap<String, f64>) -> (HashMap<String, f64>, Vec<Diagnostic>) {
    let mut errors = Vec::new();
    let mut index: HashMap<&str, usize> = HashMap::with_capacity(defs.len());
    for (i, d) in defs.iter().enumerate() {
        index.entry(d.name).or_insert(i);
    }
    let known = |n: &str| index.contains_key(n);
    // For each parameter: statically broken (then it is skipped), and the parameters it reads.
    let mut broken = vec![false; defs.len()];
    let mut readers: Vec<Vec<usize>> = vec![Vec::new(); defs.len()];
    let mut waiting_for = vec![0usize; defs.len()];
    for (i, d) in defs.iter().enumerate() {
        if index[d.name] != i || overrides.contains_key(d.name) {
            continue;
        }
        let mut static_errors = Vec::new();
        d.expr.check(&known, &mut static_errors);
        broken[i] = !static_errors.is_empty();
        let mut names = Vec::new();
        d.expr.names(&mut names);
        let mut read: Vec<usize> = names.iter().filter_map(|n| index.get(n).copied()).collect();
        read.sort_unstable();
        read.dedup();
        waiting_for[i] = read.len();
        for r in read {
            readers[r].push(i);
        }
    }
    let mut values: HashMap<String, f64> = HashMap::with_capacity(defs.len());
    let mut failed = vec![false; defs.len()];
    let mut ready: Vec<usize> = (0..defs.len())
        .filter(|&i| index[defs[i].name] == i && waiting_for[i] == 0)
        .collect();
    let mut done = vec![false; defs.len()];
    while let Some(i) = ready.pop() {
        done[i] = true;
        let d = &defs[i];
        let value = match overrides.get(d.name) {
            Some(&v) if v.is_finite() => Ok(v),
            Some(&v) => {
                errors.push(
                    Diagnostic::new(
                        d.span,
                        format!("parameter `{}` is given the value {}", d.name, non_finite_name(v)),
                    )
                    .label("this parameter")
                    .note("a parameter's value must be a finite number"),
                );
                Err(())
            }
            None if broken[i] || failed[i] => Err(()),
            None => {
                let raw = d.expr.eval(&values);
                // An infinite intermediate (`1 / (1 / 0)`) that ends finite is accepted.
                if raw.is_finite() {
                    Ok(raw)
                } else {
                    let why = d.expr.eval_checked(&values).err().unwrap_or_default();
                    errors.push(not_finite(d, raw, &why, overrides));
                    Err(())
                }
            }
        };
        let value = value.unwrap_or_else(|()| {
            failed[i] = true;
            f64::NAN
        });
        values.insert(d.name.to_string(), value);
        for &r in &readers[i] {
            failed[r] |= failed[i];
            waiting_for[r] -= 1;
            if waiting_for[r] == 0 {
                ready.push(r);
            }
        }
    }
    // What is left reads itself through a cycle: report one cycle.
    if let Some(start) = (0..defs.len()).find(|&i| index[defs[i].name] == i && !done[i]) {
        let cycle = find_cycle(defs, &index, &done, start);
        let names: Vec<&str> = cycle.iter().map(|&i| defs[i].name).collect();
        errors.push(
            Diagnostic::new(
                defs[cycle[0]].span,
                format!("parameters defined in a cycle: {} → {}", names.join(" → "), names[0]),
            )
            .label("reads itself through the cycle"),
        );
        for i in 0..defs.len() {
            if index[defs[i].name] == i && !done[i] {
                values.insert(defs[i].name.to_string(), f64::NAN);
            }
        }
    }
    (values, errors)
}

/// The error for parameter `d`, whose value `raw` is not finite because of `why`.
fn not_finite(d: &Definition, raw: f64, why: &str, overrides: &HashMap<String, f64>) -> Diagnostic {
    let span = match d.expr.span() {
        Some(e) => Span::new(d.span.start.min(e.start), d.span.end.max(e.end)),
        None => d.span,
    };
    let mut diagnostic = Diagnostic::new(
        span,
        format!("parameter `{}` = {} is {}: {why}", d.name, d.expr, non_finite_name(raw)),
    )
    .label("not a finite number");
    if !overrides.is_empty() {
        let mut given: Vec<String> = overrides.iter().map(|(k, v)| format!("{k} = {v}")).collect();
        given.sort();
        diagnostic = diagnostic.note(format!("with the values given for {}", given.join(", ")));
    }
    diagnostic
}

/// A cycle among the unresolved parameters, found by walking from `start`
/// to a parameter it reads until one repeats.
fn find_cycle(defs: &[Definition], index: &HashMap<&str, usize>, done: &[bool], start: usize) -> Vec<usize> {
    let mut position: HashMap<usize, usize> = HashMap::new();
    let mut path = Vec::new();
    let mut at = start;
    loop {
        if let Some(&k) = position.get(&at) {
            return path.split_off(k);
        }
        position.insert(at, path.len());
        path.push(at);
        let mut names = Vec::new();
        defs[at].expr.names(&mut names);
        // Every unresolved parameter reads at least one unresolved parameter.
        match names.iter().filter_map(|n| index.get(n).copied()).find(|&r| !done[r]) {
            Some(next) => at = next,
            None => return path,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(source: &str, expected: f64) {
        let ast = crate::syntax::parser::parse(&format!(
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

    /// Resolves `parameters { BODY }` with `overrides`: the value of `name`
    /// (`Ok`) or the errors' messages (`Err`).
    fn resolved(body: &str, overrides: &[(&str, f64)], name: &str) -> Result<f64, Vec<String>> {
        let ast = crate::syntax::parser::parse(&format!("mechanism m {{ parameters {{ {body} }} }}")).unwrap();
        let defs: Vec<Definition> = ast
            .parameters
            .iter()
            .map(|(n, e)| Definition {
                name: &n.text,
                span: n.span,
                expr: e,
            })
            .collect();
        let overrides = overrides.iter().map(|(k, v)| (k.to_string(), *v)).collect();
        let (values, errors) = resolve(&defs, &overrides);
        if errors.is_empty() {
            Ok(values[name])
        } else {
            Err(errors.into_iter().map(|e| e.message).collect())
        }
    }

    #[test]
    fn parameters_resolve_in_dependency_order() {
        assert_eq!(resolved("a = b + 1; b = c * 2; c = 3;", &[], "a"), Ok(7.0));
        // An override replaces the expression; parameters reading it follow it.
        assert_eq!(resolved("a = b + 1; b = c * 2; c = 3;", &[("c", 10.0)], "a"), Ok(21.0));
        assert_eq!(resolved("a = b + 1; b = c * 2; c = 3;", &[("b", 1.0)], "a"), Ok(2.0));
        assert_eq!(
            resolved("a = b + 1; b = c * 2; c = a;", &[], "a"),
            Err(vec!["parameters defined in a cycle: a → b → c → a".to_string()])
        );
        assert_eq!(
            resolved("a = a;", &[], "a"),
            Err(vec!["parameters defined in a cycle: a → a".to_string()])
        );
        // Overriding a member of the cycle breaks it.
        assert_eq!(resolved("a = b + 1; b = c * 2; c = a;", &[("c", 1.0)], "a"), Ok(3.0));
    }

    #[test]
    fn values_that_are_not_finite_name_the_parameter_and_the_reason() {
        let err = |s: &str| Err(vec![s.to_string()]);
        assert_eq!(
            resolved("l8 = 80; l2 = 117; h = sqrt(l8^2 - (l2/2)^2);", &[("l8", 50.0)], "h"),
            err("parameter `h` = sqrt(l8^2 - (l2 / 2)^2) is NaN: sqrt of a negative number")
        );
        // 80² − 58.5² = 2977.75.
        assert_eq!(
            resolved("l8 = 80; l2 = 117; h = sqrt(l8^2 - (l2/2)^2);", &[], "h"),
            Ok(2977.75f64.sqrt())
        );
        assert_eq!(
            resolved("a = 1 / (2 - 2);", &[], "a"),
            err("parameter `a` = 1 / (2 - 2) is infinite: division by zero")
        );
        assert_eq!(
            resolved("a = 10^400;", &[], "a"),
            err("parameter `a` = 10^400 is infinite: overflow in `10^400`")
        );
        assert_eq!(
            resolved("a = asin(2);", &[], "a"),
            err("parameter `a` = asin(2) is NaN: asin of a number outside [−1, 1]")
        );
        assert_eq!(
            resolved("a = 0^-1;", &[], "a"),
            err("parameter `a` = 0^-1 is infinite: zero to a negative power")
        );
        // Only the cause is reported, not the parameters that read it.
        assert_eq!(
            resolved("a = sqrt(-1); b = a + 1;", &[], "b"),
            err("parameter `a` = sqrt(-1) is NaN: sqrt of a negative number")
        );
        assert_eq!(
            resolved("a = 1; b = a + 1;", &[("a", f64::NAN)], "b"),
            err("parameter `a` is given the value NaN")
        );
        assert_eq!(
            resolved("a = 1; b = a + 1;", &[("a", f64::NEG_INFINITY)], "b"),
            err("parameter `a` is given the value −infinite")
        );
        // An infinite intermediate that ends finite is a value: 1 / ∞ = 0.
        assert_eq!(resolved("a = 1 / (1 / 0);", &[], "a"), Ok(0.0));
    }

    #[test]
    fn display_keeps_the_value() {
        for source in [
            "-a^2",
            "(-a)^2",
            "2^3^2",
            "(2^3)^2",
            "a - (b - 1)",
            "a / (b * 2)",
            "-(a + b) * 2",
            "2^-a^2",
            "atan2(b, -a)",
        ] {
            let ast = crate::syntax::parser::parse(&format!(
                "mechanism m {{ parameters {{ a = 3; b = 4; v = {source}; }} }}"
            ))
            .unwrap();
            let shown = ast.parameters[2].1.to_string();
            check(source, {
                let again = crate::syntax::parser::parse(&format!(
                    "mechanism m {{ parameters {{ a = 3; b = 4; v = {shown}; }} }}"
                ))
                .unwrap();
                let values = HashMap::from([("a".to_string(), 3.0), ("b".to_string(), 4.0)]);
                again.parameters[2].1.eval(&values)
            });
        }
    }
}
