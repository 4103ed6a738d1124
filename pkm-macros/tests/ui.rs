//! Compile-fail cases: one per diagnostic, with the committed `.stderr`
//! showing the DSL's line:column and caret picture. And one pass case that
//! checks generated code is warning-free.

#[test]
fn ui() {
    let t = trybuild::TestCases::new();
    t.compile_fail("tests/ui/*.rs");
    t.pass("tests/ui-pass/*.rs");
}
