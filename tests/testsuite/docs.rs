//! Docs that run: every ```pkm block in README.md and docs/*.md is a whole
//! mechanism file, and compiles as `pkm::mechanism!` would compile it
//! (analysis, capability checks, solver plans). A block fenced ```pkm,error
//! shows an error instead: its first line is `// error: MESSAGE`, and the
//! compiler must reject it with a diagnostic containing MESSAGE.
//! Fragments are fenced ```text and not checked.

use std::path::{Path, PathBuf};

/// One fenced block of mechanism text.
#[derive(Debug, PartialEq)]
struct Block {
    /// The line of the opening fence, from 1.
    line: usize,
    /// Fenced ```pkm,error: the text must be rejected.
    expect_error: bool,
    /// The text between the fences.
    text: String,
}

/// The ```pkm blocks of a Markdown text, or the line of a fence left open.
fn pkm_blocks(markdown: &str) -> Result<Vec<Block>, usize> {
    let mut blocks = Vec::new();
    // The open block: its line, whether it is pkm, whether it expects an error, its text.
    let mut open: Option<(usize, bool, bool, String)> = None;
    for (i, raw) in markdown.lines().enumerate() {
        let line = raw.trim_start();
        match &mut open {
            None => {
                if let Some(info) = line.strip_prefix("```") {
                    let mut words = info.split([',', ' ']).filter(|w| !w.is_empty());
                    let is_pkm = words.next() == Some("pkm");
                    let expect_error = words.any(|w| w == "error");
                    open = Some((i + 1, is_pkm, expect_error, String::new()));
                }
            }
            Some((start, is_pkm, expect_error, text)) => {
                if line.starts_with("```") {
                    if *is_pkm {
                        blocks.push(Block {
                            line: *start,
                            expect_error: *expect_error,
                            text: std::mem::take(text),
                        });
                    }
                    open = None;
                } else {
                    text.push_str(raw);
                    text.push('\n');
                }
            }
        }
    }
    match open {
        Some((start, ..)) => Err(start),
        None => Ok(blocks),
    }
}

/// What compiling the text says: `Ok` or every error message, rendered.
fn compile(text: &str) -> Result<(), String> {
    let analysis = pkm::dsl::analyze_source(text).map_err(|d| d.render(text, "block"))?;
    let checks = pkm::dsl::check_capabilities(&analysis);
    if !checks.is_empty() {
        return Err(checks.render(text, "block"));
    }
    // The macro's own path: solver plans and code generation.
    let input = format!("Doc, {:?}", text);
    let tokens: proc_macro2::TokenStream = input.parse().map_err(|e| format!("{e}"))?;
    pkm::dsl::expand(tokens).map(|_| ()).map_err(|e| e.to_string())
}

/// The failure of one block, if it fails.
fn check_block(block: &Block) -> Option<String> {
    match (compile(&block.text), block.expect_error) {
        (Ok(()), false) => None,
        (Err(e), false) => Some(e),
        (Ok(()), true) => Some("fenced `pkm,error` but compiles".into()),
        (Err(e), true) => {
            let first = block.text.lines().next().unwrap_or_default().trim();
            match first.strip_prefix("// error:").map(str::trim) {
                None => Some("a `pkm,error` block starts with `// error: MESSAGE`".into()),
                Some(expected) if !e.contains(expected) => {
                    Some(format!("expected an error containing `{expected}`, got:\n{e}"))
                }
                Some(_) => None,
            }
        }
    }
}

/// README.md and every Markdown file in docs/ and docs/history/, so new
/// docs are covered.
fn markdown_files() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files: Vec<PathBuf> = ["docs", "docs/history"]
        .iter()
        .flat_map(|dir| std::fs::read_dir(root.join(dir)).expect("docs/ and docs/history/ exist"))
        .map(|e| e.expect("a readable directory entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    files.sort();
    files.insert(0, root.join("README.md"));
    files
}

#[test]
fn every_pkm_block_in_the_docs_compiles() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut failures = Vec::new();
    let mut checked = Vec::new();
    for path in markdown_files() {
        let name = path.strip_prefix(root).unwrap_or(&path).display().to_string();
        let markdown = std::fs::read_to_string(&path).expect("a readable Markdown file");
        let blocks = match pkm_blocks(&markdown) {
            Ok(blocks) => blocks,
            Err(line) => {
                failures.push(format!("{name}:{line}: a code fence is never closed"));
                continue;
            }
        };
        for block in &blocks {
            if let Some(why) = check_block(block) {
                failures.push(format!("{name}:{}: {why}", block.line));
            }
        }
        checked.push((name, blocks.len()));
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
    // The reference and the README must hold examples: an empty match
    // (a renamed fence, a moved file) would otherwise pass silently.
    let count = |file: &str| checked.iter().find(|(n, _)| n == file).map_or(0, |(_, c)| *c);
    assert!(count("README.md") >= 1, "{checked:?}");
    assert!(count("docs/language.md") >= 20, "{checked:?}");
}

fn check_extract(markdown: &str, expected: Result<Vec<(usize, bool, &str)>, usize>) {
    let got = pkm_blocks(markdown).map(|blocks| {
        blocks
            .iter()
            .map(|b| (b.line, b.expect_error, b.text.clone()))
            .collect::<Vec<_>>()
    });
    let expected = expected.map(|v| v.into_iter().map(|(l, e, t)| (l, e, t.to_string())).collect::<Vec<_>>());
    assert_eq!(got, expected, "{markdown}");
}

#[test]
fn extraction() {
    check_extract(
        "text\n```pkm\nmechanism m {}\n```\n",
        Ok(vec![(2, false, "mechanism m {}\n")]),
    );
    check_extract("```text\nx\n```\n```rust\ny\n```\n", Ok(vec![]));
    check_extract(
        "```pkm,error\n// error: E\nm\n```\n\n```pkm\na\n\nb\n```",
        Ok(vec![(1, true, "// error: E\nm\n"), (6, false, "a\n\nb\n")]),
    );
    // Indented fences (in a list) count; the text keeps its indentation.
    check_extract("- item\n  ```pkm\n  m\n  ```\n", Ok(vec![(2, false, "  m\n")]));
    check_extract("a\n```pkm\nm\n", Err(2));
}

#[test]
fn error_blocks_must_name_their_error() {
    let good = "mechanism m { planar; base R1* ∥ R2 ∥ R3 ∥ R4 base; }\n";
    let bad = "// error: unknown joint `R9`\nmechanism m { planar; base R1* ∥ R2 ∥ R3 ∥ R4 base; R9 ∥ R1; }\n";
    let block = |expect_error, text: &str| Block {
        line: 1,
        expect_error,
        text: text.into(),
    };
    assert_eq!(check_block(&block(false, good)), None);
    assert_eq!(check_block(&block(true, bad)), None);
    assert_eq!(
        check_block(&block(true, good)),
        Some("fenced `pkm,error` but compiles".into())
    );
    let wrong = bad.replace("R9`", "R8`");
    assert!(check_block(&block(true, &wrong)).is_some_and(|e| e.starts_with("expected an error containing")));
    assert!(check_block(&block(false, bad)).is_some_and(|e| e.contains("unknown joint `R9`")));
}
