//! # pkm-dsl
//!
//! The compiler behind `pkm::mechanism!`: the pest grammar of the mechanism
//! language, its syntax tree, diagnostics, the POC topology analysis and the
//! code generator. It is an ordinary library so that every stage can be unit
//! tested on plain strings and [`proc_macro2::TokenStream`]s.
#![deny(missing_docs)]

pub mod diagnostics;
pub mod syntax;
pub use syntax::{ast, expr};
pub mod geometry;
pub mod limb_properties;
pub mod limits;
pub mod mass_and_loads;
use syntax::parser;

pub use diagnostics::{Diagnostic, Diagnostics, Span};
pub use parser::parse;
pub mod analysis;
pub mod mechanism;
pub mod numeric;
pub mod params;
pub mod planner;
pub mod planner_numeric;
pub mod screw;
pub mod study;
pub mod topology;

pub use analysis::{analyze_source, Analysis};
pub mod compile;
pub use compile::{compile, Compiled};
mod codegen;
mod codegen_motion;
mod codegen_solution;
mod codegen_solver;
mod emit;
mod trace;

pub use codegen::{check_capabilities, expand};
