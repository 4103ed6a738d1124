//! # pkm-dsl
//!
//! The compiler behind `pkm::mechanism!`: the pest grammar of the mechanism
//! language, its syntax tree, diagnostics, the POC topology analysis and the
//! code generator. It is an ordinary library so that every stage can be unit
//! tested on plain strings and [`proc_macro2::TokenStream`]s.
#![deny(missing_docs)]

pub mod ast;
pub mod diagnostics;
pub mod expr;
pub mod geometry;
mod parser;

pub use diagnostics::{Diagnostic, Diagnostics, Span};
pub use parser::parse;
pub mod model;
pub mod plan;
pub mod report;
pub mod screw;
pub mod topology;

pub use report::{analyze_source, Analysis};
mod codegen;
mod codegen_fk;

pub use codegen::{check_capabilities, expand};

/// The place of joint `joint` on `link` in a complete geometry.
pub(crate) fn codegen_fk_place(a: &Analysis, joint: usize, link: usize) -> &geometry::JointPlace {
    let side = a.mechanism.joints[joint]
        .links
        .iter()
        .position(|&l| l == link)
        .unwrap_or(0);
    a.geometry.places[joint][side]
        .as_ref()
        .expect("complete geometry places every joint")
}
