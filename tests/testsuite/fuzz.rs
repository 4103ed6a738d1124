//! Parser and analysis never panic: 10⁵+ random and mutated inputs, each
//! either analysed or rejected with diagnostics whose spans lie in the text.

use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};

const EXAMPLES: [&str; 10] = [
    include_str!("../../examples/mechanisms/seed000_a.pkm"),
    include_str!("../../examples/mechanisms/seed000_b.pkm"),
    include_str!("../../examples/mechanisms/seed003_punch_original.pkm"),
    include_str!("../../examples/mechanisms/seed003_punch.pkm"),
    include_str!("../../examples/mechanisms/four_bar.pkm"),
    include_str!("../../examples/mechanisms/slider_crank.pkm"),
    include_str!("../../examples/mechanisms/five_bar.pkm"),
    include_str!("../../examples/mechanisms/planar_3rrr.pkm"),
    include_str!("../../examples/mechanisms/rps_3.pkm"),
    include_str!("../../examples/mechanisms/spr_3.pkm"),
];

const TOKENS: &[&str] = &[
    "mechanism",
    "m",
    "{",
    "}",
    ";",
    ",",
    "=",
    "(",
    ")",
    "[",
    "]",
    "*",
    "-",
    "∥",
    "||",
    "⊥",
    "_|_",
    "≡",
    "==",
    "base",
    "platform",
    "frame",
    "0",
    "1",
    "2",
    "7",
    "R1",
    "R2",
    "R3",
    "R4",
    "P1",
    "P2",
    "Pa",
    "S1",
    "U1",
    "C1",
    "H1",
    "Q1",
    "x",
    "y",
    "z",
    "planar",
    "branch",
    "I",
    "joint",
    "link",
    "capabilities",
    "fk",
    "ik",
    "title",
    "\"t\"",
    "point",
    "o",
    "on",
    "R",
    "P",
    "S",
    "c1",
    "//",
    "/*",
    "*/",
    "\n",
    " ",
    "é",
    "\u{0}",
    "\"",
];

/// Checks one input: analysis or diagnostics, never a panic; spans in bounds;
/// reports and renders complete.
fn check(text: &str) -> Result<(), TestCaseError> {
    match pkm::dsl::analyze_source(text) {
        Ok(a) => {
            let report = a.report();
            prop_assert!(!report.contains("NaN"));
            prop_assert_eq!(a.topology.xi().len(), a.topology.socs.len());
            // With geometry: the model, the plan and the interpreter, at two inputs.
            if a.geometry.complete {
                if let (Ok(model), Ok(plan)) = (
                    pkm::dsl::numeric::model(&a, &Default::default()),
                    pkm::dsl::planner::forward_plan(&a),
                ) {
                    for q in [0.3, -2.0] {
                        let inputs = vec![q; plan.inputs.len()];
                        for (_, result) in pkm::runtime::plan::run_all(&model, &plan, &inputs) {
                            if let Ok(sol) = result {
                                prop_assert!(sol.values.iter().all(|v| !v.is_nan()), "NaN joint value");
                            }
                        }
                    }
                }
            }
        }
        Err(d) => {
            prop_assert!(!d.is_empty());
            for e in &d.0 {
                if let Some(s) = e.span {
                    prop_assert!(
                        s.start <= s.end && s.end <= text.len(),
                        "span {:?} outside {} bytes",
                        s,
                        text.len()
                    );
                }
            }
            let _ = d.render(text, "fuzz.pkm");
        }
    }
    Ok(())
}

/// A mutation of an example: delete, insert, replace or duplicate a piece.
fn mutate(base: &str, ops: &[(u8, usize, usize, usize)]) -> String {
    let mut chars: Vec<char> = base.chars().collect();
    for &(op, at, len, tok) in ops {
        if chars.is_empty() {
            break;
        }
        let at = at % chars.len();
        let end = (at + len % 12).min(chars.len());
        let token: Vec<char> = TOKENS[tok % TOKENS.len()].chars().collect();
        match op % 4 {
            0 => {
                chars.drain(at..end);
            }
            1 => {
                chars.splice(at..at, token);
            }
            2 => {
                chars.splice(at..end, token);
            }
            _ => {
                let piece: Vec<char> = chars[at..end].to_vec();
                chars.splice(at..at, piece);
            }
        }
    }
    chars.into_iter().collect()
}

fn run(cases: u32, strategy: impl Strategy<Value = String>) {
    let mut runner = TestRunner::new(Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    });
    runner.run(&strategy, |text| check(&text)).unwrap();
}

#[test]
fn mutated_examples() {
    let strategy = (
        0..EXAMPLES.len(),
        prop::collection::vec((any::<u8>(), any::<usize>(), any::<usize>(), any::<usize>()), 1..4),
    )
        .prop_map(|(i, ops)| mutate(EXAMPLES[i], &ops));
    run(60_000, strategy);
}

#[test]
fn random_token_sequences() {
    let body = prop::collection::vec(prop::sample::select(TOKENS), 0..40).prop_map(|t| t.join(" "));
    let strategy = (any::<bool>(), body).prop_map(|(wrap, body)| {
        if wrap {
            format!("mechanism m {{ {body} }}")
        } else {
            body
        }
    });
    run(50_000, strategy);
}
