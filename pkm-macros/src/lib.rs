//! The `mechanism!` procedural macro of pkm. It is a thin shell: the
//! compiler lives in `pkm-dsl`, a library with its own tests. Use it through
//! the `pkm` crate, whose documentation has examples.
#![deny(missing_docs)]

use proc_macro::TokenStream;

/// Declares a mechanism: `pkm::mechanism!(pub Name, "mechanism … { … }")` or
/// `pkm::mechanism!(pub Name, file = "path/relative/to/Cargo.toml.pkm")`.
/// See the `pkm` crate for the language and examples.
#[proc_macro]
pub fn mechanism(input: TokenStream) -> TokenStream {
    pkm_dsl::expand(input.into())
        .unwrap_or_else(syn::Error::into_compile_error)
        .into()
}
