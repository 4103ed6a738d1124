//! Snapshots of the code `pkm::mechanism!` generates, pretty-printed with
//! prettyplease (parsing it with syn also proves it is valid Rust). Each
//! snapshot was read line by line against the example's analysis.

fn expansion(file: &str, type_name: &str) -> String {
    let path = format!("{}/examples/mechanisms/{file}.pkm", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(path).unwrap();
    let input: proc_macro2::TokenStream = format!("pub {type_name}, {text:?}").parse().unwrap();
    let tokens = pkm::dsl::expand(input).unwrap();
    prettyplease::unparse(&syn::parse_file(&tokens.to_string()).unwrap())
}

#[test]
fn four_bar() {
    insta::assert_snapshot!(expansion("four_bar", "FourBar"));
}

#[test]
fn seed003_punch() {
    insta::assert_snapshot!(expansion("seed003_punch", "Punch"));
}

#[test]
fn analysis_only_generates_no_solver() {
    // Pay for what you use: no capability beyond analysis is generated yet,
    // so the expansion holds the type, its constants and the report only.
    let code = expansion("planar_3rrr", "ThreeRrr");
    assert!(!code.contains("fn "), "{code}");
}
