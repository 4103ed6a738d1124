//! Every limit of `pkm_dsl::limits`, at and just beyond: at the limit the
//! text is accepted (no error about the limit, values as counted by hand),
//! beyond it the error states the limit; nothing panics, hangs or overflows
//! the stack (these tests run on the test harness's 2 MiB threads).

use crate::common;
use crate::mechanisms::{Cylinder, FourBar};

use pkm::dsl::limits::{
    MAX_EXPR_OPERATIONS, MAX_FILE_BYTES, MAX_JOINTS, MAX_NESTING, MAX_PARAMETERS, MAX_PLACEMENTS, MAX_RELATIONS,
};
use pkm::dsl::Diagnostics;
use pkm::runtime::model::Place;
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use std::collections::HashMap;

/// A valid planar four-bar to hang parameters and relations on.
const FOUR_BAR: &str = "planar; base R1* ∥ R2 ∥ R3 ∥ R4 base;";

fn with_parameters(body: &str) -> String {
    format!("mechanism m {{ {FOUR_BAR} parameters {{ {body} }} }}")
}

/// The analysis of `text`, checking that every error's span lies in the text
/// and that rendering stays bounded (at most 50 errors, lines cut to 120
/// characters: well under 64 kB whatever the text).
fn analyze(text: &str) -> Result<pkm::dsl::Analysis, Diagnostics> {
    let result = pkm::dsl::analyze_source(text);
    if let Err(d) = &result {
        assert!(!d.is_empty());
        for e in &d.0 {
            if let Some(s) = e.span {
                assert!(
                    s.start <= s.end && s.end <= text.len(),
                    "span {s:?} outside {} bytes",
                    text.len()
                );
            }
        }
        let shown = d.render(text, "limits.pkm");
        assert!(shown.len() < 64_000, "{} bytes rendered", shown.len());
    }
    result
}

/// The messages of the errors, or the value of parameter `a`.
fn value_of_a(text: &str) -> Result<f64, Vec<String>> {
    match analyze(text) {
        Ok(a) => Ok(a.geometry.parameters.iter().find(|p| p.name == "a").unwrap().value),
        Err(d) => Err(d.0.into_iter().map(|e| e.message).collect()),
    }
}

/// `n` layers of nesting around `1`: each layer a parenthesis or `1^`.
fn nested(layers: &[bool]) -> String {
    let mut s = String::from("1");
    for &paren in layers.iter().rev() {
        s = if paren { format!("({s})") } else { format!("1^{s}") };
    }
    s
}

fn run<S: Strategy>(cases: u32, strategy: S, test: impl Fn(S::Value) -> Result<(), TestCaseError>) {
    let mut runner = TestRunner::new(Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    });
    runner.run(&strategy, test).unwrap();
}

#[test]
fn nesting_at_and_beyond_the_limit() {
    let layers = |n: std::ops::RangeInclusive<usize>| n.prop_flat_map(|n| prop::collection::vec(any::<bool>(), n..=n));
    // 1 raised to anything, in any parentheses, is 1.
    run(200, layers(MAX_NESTING - 4..=MAX_NESTING), |l| {
        prop_assert_eq!(value_of_a(&with_parameters(&format!("a = {};", nested(&l)))), Ok(1.0));
        Ok(())
    });
    run(200, layers(MAX_NESTING + 1..=MAX_NESTING + 200), |l| {
        let errors = value_of_a(&with_parameters(&format!("a = {};", nested(&l)))).unwrap_err();
        prop_assert_eq!(
            errors,
            vec!["expression nested more than 64 deep (parentheses and exponents `^` together)".to_string()]
        );
        Ok(())
    });
    // Far beyond: 10⁵ parentheses, 10⁴ exponents, 10⁴ nested calls.
    for text in [
        format!("a = {}1{};", "(".repeat(100_000), ")".repeat(100_000)),
        format!("a = {}1;", "2^".repeat(10_000)),
        format!("a = {}1{};", "sqrt(".repeat(10_000), ")".repeat(10_000)),
    ] {
        let errors = value_of_a(&with_parameters(&text)).unwrap_err();
        assert!(errors[0].contains("more than 64 deep"), "{errors:?}");
    }
}

#[test]
fn exponents_do_not_nest_across_operators() {
    // `1^1 * 1^1 …` never nests deeper than one: each `*` ends an exponent chain,
    // and so does a binary minus, but not the minus of `1e-5` or a unary one.
    let flat = vec!["1^1"; 200].join(" * ");
    assert_eq!(value_of_a(&with_parameters(&format!("a = {flat};"))), Ok(1.0));
    let chain = vec!["1e-5"; MAX_NESTING + 2].join("^");
    assert!(value_of_a(&with_parameters(&format!("a = {chain};"))).unwrap_err()[0].contains("more than 64 deep"));
    let chain = vec!["1"; MAX_NESTING + 2].join("^-");
    assert!(value_of_a(&with_parameters(&format!("a = {chain};"))).unwrap_err()[0].contains("more than 64 deep"));
    // Brackets in comments and strings are not expressions.
    let text = format!(
        "mechanism m {{ title \"{}\"; {FOUR_BAR} // {}\n /* {} */ parameters {{ a = 2; }} }}",
        "(".repeat(1000),
        "(".repeat(1000),
        "^".repeat(1000)
    );
    assert_eq!(value_of_a(&text), Ok(2.0));
}

#[test]
fn operations_per_expression() {
    let too_many = format!("expression with more than {MAX_EXPR_OPERATIONS} operations");
    // n unary minuses: n operations, value (−1)ⁿ.
    run(40, 0..=MAX_EXPR_OPERATIONS, |n| {
        let sign = if n % 2 == 0 { 1.0 } else { -1.0 };
        prop_assert_eq!(
            value_of_a(&with_parameters(&format!("a = {}1;", "-".repeat(n)))),
            Ok(sign)
        );
        Ok(())
    });
    // A sum of n ones: n − 1 operations, value n.
    run(40, 1..=MAX_EXPR_OPERATIONS + 1, |n| {
        let sum = vec!["1"; n].join(" + ");
        prop_assert_eq!(value_of_a(&with_parameters(&format!("a = {sum};"))), Ok(n as f64));
        Ok(())
    });
    for text in [
        format!("a = {}1;", "-".repeat(MAX_EXPR_OPERATIONS + 1)),
        format!("a = {}1;", "-".repeat(100_000)),
        format!("a = {};", vec!["1"; MAX_EXPR_OPERATIONS + 2].join("+")),
        format!("a = {};", vec!["1"; 100_000].join("+")),
        format!("a = {};", vec!["1"; 100_000].join("*")),
        // Operations inside a call's arguments count for the whole expression.
        format!("a = abs({});", vec!["1"; MAX_EXPR_OPERATIONS + 1].join("-")),
    ] {
        assert_eq!(value_of_a(&with_parameters(&text)), Err(vec![too_many.clone()]));
    }
    // The limit is per expression: many expressions at the limit are accepted.
    let at_limit = vec!["1"; MAX_EXPR_OPERATIONS + 1].join("+");
    let body: String = (0..20).map(|i| format!("p{i} = {at_limit}; ")).collect();
    assert_eq!(value_of_a(&with_parameters(&format!("{body} a = p19;"))), Ok(513.0));
}

#[test]
fn parameters_in_reverse_order_resolve_linearly() {
    // p_i = p_{i+1} + 1 and p_{n−1} = 0: p_0 = n − 1, with `a` reading p_0.
    let chain = |n: usize| {
        let mut body: String = (0..n - 2).map(|i| format!("p{i} = p{} + 1; ", i + 1)).collect();
        body.push_str(&format!("p{} = 0; a = p0;", n - 2));
        with_parameters(&body)
    };
    let started = std::time::Instant::now();
    assert_eq!(value_of_a(&chain(MAX_PARAMETERS)), Ok((MAX_PARAMETERS - 2) as f64));
    assert!(started.elapsed().as_secs_f64() < 10.0, "{:?}", started.elapsed());
    assert_eq!(
        value_of_a(&chain(MAX_PARAMETERS + 1)),
        Err(vec![format!("more than {MAX_PARAMETERS} parameters")])
    );
    assert_eq!(
        value_of_a(&with_parameters("a = b; b = c / 2; c = 2 * a;")),
        Err(vec!["parameters defined in a cycle: a → b → c → a".to_string()])
    );
}

/// A chain of `n` revolute joints from the base back to the base.
fn joint_chain(n: usize) -> String {
    let joints: Vec<String> = (1..=n).map(|i| format!("R{i}")).collect();
    format!("mechanism m {{ planar; base {}* base; }}", joints.join(" ∥ "))
}

#[test]
fn joints_at_and_beyond_the_limit() {
    // 64 joints in one planar loop: 61 DOF (Σf − 3), which the error counts.
    let started = std::time::Instant::now();
    assert_eq!(
        value_of_a(&joint_chain(MAX_JOINTS)),
        Err(vec!["the mechanism has 61 DOF but 1 actuated joint".to_string()])
    );
    assert!(started.elapsed().as_secs_f64() < 10.0, "{:?}", started.elapsed());
    for n in [MAX_JOINTS + 1, 4_000, 10_000] {
        assert_eq!(
            value_of_a(&joint_chain(n)),
            Err(vec![format!("the mechanism has {n} joints; the limit is {MAX_JOINTS}")])
        );
    }
    // Compound hinges count k − 1 joints for k links.
    let links: Vec<String> = (1..=MAX_JOINTS + 1).map(|i| format!("k{i}")).collect();
    let text = format!("mechanism m {{ planar; joint A = R(base, {})*; }}", links.join(", "));
    assert_eq!(
        value_of_a(&text),
        Err(vec![format!(
            "the mechanism has {} joints; the limit is {MAX_JOINTS}",
            MAX_JOINTS + 1
        )])
    );
}

#[test]
fn named_links_and_relations() {
    let links = |n: usize| {
        let names: Vec<String> = (0..n).map(|i| format!("k{i}")).collect();
        format!("mechanism m {{ {FOUR_BAR} link {}; }}", names.join(", "))
    };
    // Named links count with the chain's four (base and three between joints).
    assert!(value_of_a(&links(MAX_JOINTS - 4)).unwrap_err()[0].contains("is not connected to the base"));
    assert_eq!(
        value_of_a(&links(MAX_JOINTS - 3)),
        Err(vec![format!(
            "the mechanism has 4 joints and 65 links; the limit is {MAX_JOINTS} of each"
        )])
    );
    assert_eq!(
        value_of_a(&links(MAX_JOINTS + 1)),
        Err(vec![format!(
            "more than {MAX_JOINTS} links are named; the limit is {MAX_JOINTS}"
        )])
    );
    // The chain writes 3 relations; R1 ∥ R2 holds already.
    let relations = |n: usize| format!("mechanism m {{ {FOUR_BAR} {} }}", "R1 ∥ R2; ".repeat(n - 3));
    assert!(analyze(&relations(MAX_RELATIONS)).is_ok());
    assert_eq!(
        value_of_a(&relations(MAX_RELATIONS + 1)),
        Err(vec![format!(
            "the mechanism writes {} relations; the limit is {MAX_RELATIONS}",
            MAX_RELATIONS + 1
        )])
    );
}

#[test]
fn placements_at_and_beyond_the_limit() {
    let points = |n: usize| {
        let body: String = (0..n).map(|i| format!("point E{i} = (0, 0); ")).collect();
        format!("mechanism m {{ {FOUR_BAR} geometry {{ base {{ {body} }} }} }}")
    };
    // At the limit the geometry is checked (and found incomplete).
    assert!(value_of_a(&points(MAX_PLACEMENTS)).unwrap_err()[0].contains("has no place"));
    assert_eq!(
        value_of_a(&points(MAX_PLACEMENTS + 1)),
        Err(vec![format!("more than {MAX_PLACEMENTS} placements in `geometry`")])
    );
}

#[test]
fn file_size_at_and_beyond_the_limit() {
    let text = |bytes: usize| {
        let body = format!("mechanism m {{ {FOUR_BAR} parameters {{ a = 3; }} }}\n// ");
        let pad = bytes - body.len();
        format!("{body}{}", "x".repeat(pad))
    };
    assert_eq!(value_of_a(&text(MAX_FILE_BYTES)), Ok(3.0));
    assert_eq!(
        value_of_a(&text(MAX_FILE_BYTES + 1)),
        Err(vec![format!(
            "the text is {} bytes long; the limit is {MAX_FILE_BYTES} bytes",
            MAX_FILE_BYTES + 1
        )])
    );
}

#[test]
fn many_errors_on_one_long_line_render_briefly() {
    // 3 000 unknown joints, one line of 40 kB: 3 000 errors, 50 rendered.
    let text = format!(
        "mechanism m {{ {FOUR_BAR} {} }}",
        (0..3000).map(|i| format!("Q{i} ∥ x;")).collect::<String>()
    );
    let d = analyze(&text).unwrap_err();
    assert_eq!(d.0.len(), 3000);
    assert!(d
        .render(&text, "m.pkm")
        .ends_with("error: 2950 more errors not shown (at most 50 are shown)\n"));
}

/// Random expressions of brackets, exponents, minuses and operands, some far
/// too deep or too long: analysed or rejected, never a panic.
#[test]
fn random_deep_expressions() {
    let piece = prop::sample::select(&["(", ")", "^", "-", "1", "a", "+", "*", "sqrt(", ",", "2e-3", " "][..]);
    let run_of = (piece, 1..300usize).prop_map(|(p, n)| p.repeat(n));
    let expression = prop::collection::vec(run_of, 1..12).prop_map(|runs| runs.concat());
    run(300, expression, |e| {
        let _ = analyze(&with_parameters(&format!("a = 1; b = {e};")));
        Ok(())
    });
}

const DERIVED: &str = "mechanism m {
    planar;
    base R1* [crank] ∥ R2 [coupler] ∥ R3 [rocker] ∥ R4 base;
    parameters { l4 = 3 * l1; h = sqrt(l2^2 - l1^2); l1 = 100; l2 = 250; l3 = 200; }
    geometry {
        base    { R1 = (0, 0); R4 = (l4, 0); }
        crank   { R1 = (0, 0); R2 = (l1, 0); }
        coupler { R2 = (0, 0); R3 = (l2, 0); }
        rocker  { R3 = (l3, 0); R4 = (0, 0); }
    }
}";

#[test]
fn overrides_recompute_what_reads_them() {
    let a = pkm::dsl::analyze_source(DERIVED).unwrap();
    let model = |values: &[(&str, f64)]| {
        let values: HashMap<String, f64> = values.iter().map(|(k, v)| (k.to_string(), *v)).collect();
        pkm::dsl::numeric::model(&a, &values)
    };
    // R4 on the base lies at (l4, 0) = (3 · l1, 0).
    let r4_on_base = |m: &pkm::runtime::model::Model| match m.joints[3].places[0] {
        Place::Axis { at, .. } => at,
        ref other => panic!("{other:?}"),
    };
    assert_eq!(r4_on_base(&model(&[]).unwrap()), [300.0, 0.0, 0.0]);
    assert_eq!(r4_on_base(&model(&[("l1", 120.0)]).unwrap()), [360.0, 0.0, 0.0]);
    // An override wins over the expression.
    assert_eq!(
        r4_on_base(&model(&[("l1", 120.0), ("l4", 310.0)]).unwrap()),
        [310.0, 0.0, 0.0]
    );
    let errors = |values: &[(&str, f64)]| -> Vec<String> {
        model(values).unwrap_err().0.into_iter().map(|e| e.message).collect()
    };
    // l1 = 300 > l2 = 250 makes h = sqrt(250² − 300²) impossible.
    assert_eq!(
        errors(&[("l1", 300.0)]),
        ["parameter `h` = sqrt(l2^2 - l1^2) is NaN: sqrt of a negative number"]
    );
    assert_eq!(errors(&[("l2", f64::NAN)]), ["parameter `l2` is given the value NaN"]);
    assert_eq!(
        errors(&[("l3", f64::INFINITY)]),
        ["parameter `l3` is given the value infinite"]
    );
    assert_eq!(errors(&[("l9", 1.0)]), ["unknown parameter `l9`"]);
    // The error points at the parameter's definition, `h = sqrt(l2^2 - l1^2)`.
    let d = model(&[("l1", 300.0)]).unwrap_err();
    let span = d.0[0].span.unwrap();
    assert_eq!(&DERIVED[span.start..span.end], "h = sqrt(l2^2 - l1^2)");
}

/// Every branch of `file`'s forward plan at `q`, by the interpreter.
fn interpreted(file: &str, q: &[f64]) -> Vec<Result<pkm::runtime::plan::Solution, pkm::runtime::solution::SolveError>> {
    let (text, _) = common::example_text(file);
    let a = pkm::dsl::analyze_source(&text).unwrap();
    let model = pkm::dsl::numeric::model(&a, &HashMap::new()).unwrap();
    let plan = pkm::dsl::planner::forward_plan(&a).unwrap();
    pkm::runtime::plan::run_all(&model, &plan, q)
        .into_iter()
        .map(|(_, r)| r)
        .collect()
}

/// Issue 29, item 7: `pkm fk four_bar.pkm --q=1e11` reported one branch
/// tangent and the other a double root: the twin tolerance scaled with the
/// unreduced input angle. An angle is its cosine and sine, whatever its
/// size: at 1e11, 1e15, ±1e308 rad both branches are listed, neither a
/// double root, R4 as by hand at the input reduced by 2π in 400 digits
/// (mpmath: 1e11 ≡ 1.1908745855222387, 1e15 ≡ 2.1096981170701126,
/// ±1e308 ≡ ±2.6710203145624654, the doubles nearest those inputs): the
/// rocker closes `A cos ψ + B sin ψ = C` with the crank pin B = l1(cos θ,
/// sin θ), R4 = (l4, 0), A = 2·l3·(l4 − Bx), B = −2·l3·By, C = l2² − |R4 −
/// B|² − l3², ψ = atan2(B, A) ± acos(C/√(A² + B²)), evaluated at the same
/// 400 digits. (The issue's −1.98 for the second root is not the
/// arithmetic's: −2.4286.) Interpreted, generated `FourBar::fk` and the
/// prepared `fk` alike.
#[test]
fn huge_angles_are_reduced() {
    let cases: [(f64, [f64; 2]); 4] = [
        (1e11, [1.7494924528818856, -2.428590097057323]),
        (1e15, [2.1771248776644154, -2.6563382513882687]),
        (1e308, [2.4444413524963045, -2.6764256602354872]),
        (-1e308, [2.6764256602354872, -2.4444413524963045]),
    ];
    let r4 = 3;
    let p = Default::default();
    let prepared = FourBar::prepare(&p);
    for (q, want) in cases {
        let all = interpreted("four_bar", &[q]);
        let generated = FourBar::fk(&p, &[q]);
        let lean = prepared.fk(&[q]);
        for (k, w) in want.iter().enumerate() {
            let s = all[k].as_ref().unwrap_or_else(|e| panic!("{q:e} branch {k}: {e}"));
            assert!(
                (s.values[r4] - w).abs() < 1e-12,
                "{q:e} branch {k}: R4 {} vs {w}",
                s.values[r4]
            );
            let g = generated[k].result.as_ref().unwrap();
            assert!(
                (g.q[r4] - w).abs() < 1e-12 && !generated[k].tangent,
                "{q:e} generated branch {k}"
            );
            assert!(lean[k].result.is_ok() && !lean[k].tangent, "{q:e} prepared branch {k}");
        }
    }
    // The punch's crank at ±1e308 and 1e11 rad: as at the reduced angle
    // (four of eight branches reach there), none a double root.
    for (q, reduced) in [
        (1e308, 2.6710203145624654),
        (-1e308, -2.6710203145624654),
        (1e11, 1.1908745855222387),
        (1e15, 2.1096981170701126),
    ] {
        let (huge, near) = (
            interpreted("seed003_punch", &[q]),
            interpreted("seed003_punch", &[reduced]),
        );
        assert_eq!(huge.iter().filter(|r| r.is_ok()).count(), 4, "{q:e}");
        for (k, (a, b)) in huge.iter().zip(&near).enumerate() {
            match (a, b) {
                (Ok(a), Ok(b)) => {
                    for (x, y) in a.values.iter().zip(&b.values).skip(1) {
                        assert!(
                            pkm::runtime::solution::wrap_angle(x - y).abs() < 1e-9,
                            "{q:e} branch {k}: {x} vs {y}"
                        );
                    }
                }
                (Err(a), Err(b)) => {
                    assert!(
                        !matches!(a, pkm::runtime::solution::SolveError::DoubleRoot { .. }),
                        "{q:e} branch {k}: {a}"
                    );
                    assert_eq!(std::mem::discriminant(a), std::mem::discriminant(b));
                }
                other => panic!("{q:e} branch {k}: {other:?}"),
            }
        }
    }
}

/// A given length beyond `REACH` sizes of the mechanism is out of reach, a
/// typed error at the step that takes it with a finite excess: a slide of
/// ±1e308 (the cylinder's stroke, carried across the rocker; seed 000 A's
/// sliders at ∓1e308, whose difference overflows, and P3), a position of
/// 1e308 given to an inverse solution (seed 000 A's x, which rounded the
/// sliders' x ± 150 into one value and answered ok with every other branch
/// its double root). Just inside the limit the kernels refuse it as they
/// refuse any other miss, with a finite excess. Never NaN, never ok.
#[test]
fn huge_lengths_are_out_of_reach() {
    use pkm::runtime::solution::SolveError;
    let refused = |r: &Result<pkm::runtime::plan::Solution, SolveError>, what: &str| match r {
        Err(SolveError::Unreachable { constraint, by, .. }) => {
            assert!(by.is_finite() && *by > 0.0, "{what}: by {by}");
            *constraint
        }
        other => panic!("{what}: {other:?}"),
    };
    let limit = "|given length| <= 1e10 sizes of the mechanism";
    for (file, q) in [
        ("cylinder_rocker", vec![1e308]),
        ("cylinder_rocker", vec![-1e308]),
        ("seed000_a", vec![-1e308, 1e308, 0.0]),
        ("seed000_a", vec![-100.0, 100.0, 1e308]),
    ] {
        for r in interpreted(file, &q) {
            assert_eq!(refused(&r, file), limit);
        }
    }
    // The generated solvers: the same refusal, by guard.
    for q in [1e308, -1e308] {
        for b in Cylinder::fk(&Default::default(), &[q]) {
            assert!(
                matches!(&b.result, Err(SolveError::Unreachable { constraint, by, .. }) if *constraint == limit && by.is_finite()),
                "{q:e}: {:?}",
                b.result
            );
        }
    }
    // Seed 000 A's size is 450 (the platform's D): 4.4e12 is inside, the
    // sliders 8.8e12 apart where the five-bar reaches 400.
    for r in interpreted("seed000_a", &[-4.4e12, 4.4e12, 0.0]) {
        assert_ne!(refused(&r, "inside the limit"), limit);
    }
    // The inverse solution given x = 1e308.
    let (text, _) = common::example_text("seed000_a");
    let a = pkm::dsl::analyze_source(&text).unwrap();
    let model = pkm::dsl::numeric::model(&a, &HashMap::new()).unwrap();
    let plan = pkm::dsl::planner::inverse_plan(&a).unwrap();
    for (_, r) in pkm::runtime::plan::run_all(&model, &plan, &[1e308, -300.0, 0.0, 0.0]) {
        assert_eq!(refused(&r, "ik at x = 1e308"), limit);
    }
}

/// An x-y table (two slides in series, closed by a second pair): its
/// table never turns, so a given angle contradicts the others.
const XY_TABLE: &str = "mechanism xy_table {
    capabilities ik;
    planar;
    base P1* [s1] ⊥ P2* [table] ⊥ P3 [s3] ⊥ P4 base;
    x ∥ P1 ∥ P3;
    geometry {
        base  { P1 = through (0, 0) along x; P4 = through (0, 50) along y; }
        s1    { P1 = (0, 0); P2 = through (0, 0) along y; }
        table { P2 = (0, 0); P3 = through (0, 0) along x; point o = (0, 0); }
        s3    { P3 = (0, 0); P4 = (0, 0); }
    }
    outputs { x, y, phi = pose of table at o; }
}";

/// The projection that names a contradicted value starts from the given
/// angles reduced: the x-y table given φ = 0.1 is refused naming φ, its
/// nearest 0; given φ = 0.1 + 2π·10¹⁰ (6.28e10 rad, ≡ 0.0903 by 400-digit
/// reduction: the double nearest), the nearest is that angle less its
/// 0.0903, the same turns (unreduced, its ulp of 7.6e-6 swallowed the
/// projection's difference steps of 1e-6 rad).
#[test]
fn contradicted_values_with_a_huge_angle() {
    use pkm::runtime::solution::SolveError;
    let a = pkm::dsl::analyze_source(XY_TABLE).unwrap();
    let model = pkm::dsl::numeric::model(&a, &HashMap::new()).unwrap();
    let plan = pkm::dsl::planner::inverse_plan(&a).unwrap();
    for (phi, reduced) in [(0.1, 0.1), (62831853071.88617, 0.09030466434088233)] {
        for (signs, r) in pkm::runtime::plan::run_all(&model, &plan, &[10.0, 20.0, phi]) {
            match r {
                Err(SolveError::Inconsistent {
                    contradicted: Some(c), ..
                }) => {
                    assert_eq!((c.index, c.given), (2, phi), "φ = {phi} {signs:?}");
                    assert!(
                        (c.nearest - (phi - reduced)).abs() < 1e-6,
                        "φ = {phi} {signs:?}: {}",
                        c.nearest
                    );
                }
                other => panic!("φ = {phi} {signs:?}: {other:?}"),
            }
        }
    }
}
