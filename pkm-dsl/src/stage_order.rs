//! The stages import only earlier stages: this test reads the crate's own
//! sources, gives each file its stage by its folder, and checks every
//! `crate::…` path outside test modules against the order
//! syntax → semantics → topology → lowering → plan → codegen.
//! `diagnostics` and `limits` serve every stage and import none; the front
//! door `compile` runs the stages up to the plans and is what `codegen`
//! reads; `lib.rs` only declares and re-exports.

use std::collections::BTreeMap;
use std::path::Path;

/// The stages in order; an index is a rank.
const ORDER: [&str; 8] = [
    "diagnostics|limits",
    "syntax",
    "semantics",
    "topology",
    "lowering",
    "plan",
    "compile",
    "codegen",
];

fn rank_of_module(first: &str) -> Option<usize> {
    ORDER.iter().position(|s| s.split('|').any(|m| m == first))
}

/// A file's stage: its folder's, or its own name's at the top.
fn rank_of_file(rel: &str) -> Option<usize> {
    let first = rel.split('/').next().unwrap().trim_end_matches(".rs");
    rank_of_module(first)
}

/// `lib.rs`'s re-exports (`pub use semantics::{geometry, …};`): each
/// name at the crate's root with the first segment it comes from.
fn root_aliases(lib: &str) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    for line in lib.lines() {
        let line = line.trim();
        let Some(rest) = line.strip_prefix("pub use ").or_else(|| line.strip_prefix("use ")) else {
            continue;
        };
        let rest = rest.trim_end_matches(';');
        let (path, items) = match rest.find("::{") {
            Some(i) => (&rest[..i], rest[i + 3..].trim_end_matches('}')),
            None => rest.rsplit_once("::").unwrap(),
        };
        let first = path.split("::").next().unwrap().to_string();
        for item in items.split(',') {
            out.insert(item.trim().to_string(), first.clone());
        }
    }
    out
}

/// The source without comments, string literals and `#[cfg(test)]` modules.
fn code_only(src: &str) -> String {
    let b = src.as_bytes();
    let mut out = String::new();
    let mut i = 0;
    while i < b.len() {
        let rest = &src[i..];
        if rest.starts_with("//") {
            i += rest.find('\n').unwrap_or(rest.len());
        } else if let Some(raw) = rest.strip_prefix("r#\"") {
            i += 3 + raw.find("\"#").unwrap() + 2;
        } else if rest.starts_with('"') {
            let mut j = 1;
            while b[i + j] != b'"' {
                j += if b[i + j] == b'\\' { 2 } else { 1 };
            }
            i += j + 1;
            out.push_str("\"\"");
        } else if rest.starts_with("'{'") || rest.starts_with("'}'") || rest.starts_with("'\"'") {
            i += 3;
        } else if rest.starts_with("#[cfg(test)]\nmod ") {
            // A test module in its own file (`mod tests;`): the declaration.
            let semicolon = rest.find(';').unwrap_or(rest.len());
            if rest.find('{').is_none_or(|open| semicolon < open) {
                i += semicolon + 1;
                continue;
            }
            // Skip to the module's closing brace.
            let open = i + rest.find('{').unwrap();
            let (mut depth, mut j) = (0usize, open);
            loop {
                let r = &src[j..];
                if r.starts_with("//") {
                    j += r.find('\n').unwrap_or(r.len());
                    continue;
                }
                if r.starts_with('"') {
                    j += 1;
                    while b[j] != b'"' {
                        j += if b[j] == b'\\' { 2 } else { 1 };
                    }
                } else if r.starts_with("'{'") || r.starts_with("'}'") || r.starts_with("'\"'") {
                    j += 2;
                } else if b[j] == b'{' {
                    depth += 1;
                } else if b[j] == b'}' {
                    depth -= 1;
                    if depth == 0 {
                        break;
                    }
                }
                j += 1;
            }
            i = j + 1;
        } else {
            let c = rest.chars().next().unwrap();
            out.push(c);
            i += c.len_utf8();
        }
    }
    out
}

/// Every first segment after `crate::` (`crate::semantics::geometry` and
/// `crate::{a, b}` alike).
fn crate_paths(code: &str) -> Vec<String> {
    let mut out = Vec::new();
    for (i, _) in code.match_indices("crate::") {
        let before = code[..i].chars().next_back();
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
            continue; // `pkm_dsl_crate::` and the like
        }
        let rest = &code[i + 7..];
        if let Some(group) = rest.strip_prefix('{') {
            let group = &group[..group.find('}').unwrap()];
            out.extend(
                group
                    .split(',')
                    .map(|s| s.trim().split("::").next().unwrap().to_string()),
            );
        } else {
            let end = rest
                .find(|c: char| !(c.is_alphanumeric() || c == '_'))
                .unwrap_or(rest.len());
            out.push(rest[..end].to_string());
        }
    }
    out.retain(|s| !s.is_empty());
    out
}

fn files(dir: &Path, root: &Path, out: &mut Vec<(String, String)>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            files(&path, root, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            let rel = path.strip_prefix(root).unwrap().to_string_lossy().replace('\\', "/");
            out.push((rel, std::fs::read_to_string(&path).unwrap()));
        }
    }
}

/// Each file's imports of later stages, as `file (stage) -> path (stage)`.
fn violations() -> Vec<String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut all = Vec::new();
    files(&root, &root, &mut all);
    let lib = &all.iter().find(|(r, _)| r == "lib.rs").unwrap().1;
    let aliases = root_aliases(lib);
    let mut bad = Vec::new();
    for (rel, src) in &all {
        // Test modules in their own file (`#[cfg(test)] mod tests;`) may use
        // the front door to make their inputs, as the inline ones do.
        if rel == "lib.rs" || rel == "stage_order.rs" || rel.ends_with("/tests.rs") {
            continue;
        }
        let here = rank_of_file(rel).unwrap_or_else(|| panic!("{rel} is in no stage: name its folder in ORDER"));
        for first in crate_paths(&code_only(src)) {
            let module = aliases.get(&first).cloned().unwrap_or(first.clone());
            let module = aliases.get(&module).cloned().unwrap_or(module);
            let there = rank_of_module(&module)
                .unwrap_or_else(|| panic!("{rel}: crate::{first} is in no stage: name it in ORDER or lib.rs"));
            let base_imports_stage = here == 0 && there > 0;
            if there > here || base_imports_stage {
                bad.push(format!("{rel} ({}) -> crate::{first} ({})", ORDER[here], ORDER[there]));
            }
        }
    }
    bad.sort();
    bad.dedup();
    bad
}

#[test]
fn no_stage_imports_a_later_one() {
    let bad = violations();
    assert!(bad.is_empty(), "imports against the stage order:\n{}", bad.join("\n"));
}

#[test]
fn the_check_sees_a_backward_import() {
    // The reader itself: a path in code counts, one in a comment, a string
    // or a test module does not.
    let src = "use crate::plan::planner;\n// crate::codegen\nfn f() { let s = \"crate::codegen\"; }\n#[cfg(test)]\nmod tests {\n    use crate::compile;\n}\n#[cfg(test)]\nmod more;\nuse crate::syntax;\n";
    assert_eq!(crate_paths(&code_only(src)), vec!["plan", "syntax"]);
    assert_eq!(
        crate_paths("use crate::{diagnostics::Span, topology::analysis::Analysis};"),
        vec!["diagnostics", "topology"]
    );
    assert!(rank_of_module("plan") > rank_of_module("semantics"));
    assert_eq!(
        root_aliases("pub use semantics::{geometry, mechanism};")["mechanism"],
        "semantics"
    );
}
