//! # pkm-dsl
//!
//! The compiler behind `pkm::mechanism!`: the pest grammar of the mechanism
//! language, its syntax tree, diagnostics, the POC topology analysis and the
//! code generator. It is an ordinary library so that every stage can be unit
//! tested on plain strings and [`proc_macro2::TokenStream`]s.
//!
//! One folder per stage, each importing only the stages before it
//! (checked by the test `stage_order` below): [`syntax`] → [`semantics`] →
//! [`topology`] → [`lowering`] → [`plan`] → `codegen`. [`diagnostics`] and
//! [`limits`] serve every stage; [`compile()`] is the front door.
#![deny(missing_docs)]

pub mod diagnostics;
pub mod limits;

mod codegen;
pub mod lowering;
pub mod plan;
pub mod semantics;
pub mod syntax;
pub mod topology;

pub mod compile;

// The paths callers (the CLI, the tests, the benches) name today.
pub use analysis::{analyze_source, Analysis};
pub use codegen::{check_capabilities, expand};
pub use compile::{compile, Compiled, Instance, InstanceError};
pub use diagnostics::{Diagnostic, Diagnostics, Span};
pub use lowering::{numeric, params};
pub use plan::{planner, planner_numeric};
pub use semantics::{geometry, limb_properties, mass_and_loads, mechanism, study};
pub use syntax::parser::parse;
pub use syntax::{ast, expr};
pub use topology::{analysis, screw};
// The pre-stage paths the code generator's dynamics and stiffness files
// (`codegen/dynamics.rs`, `codegen/stiffness.rs`) still name.
use codegen::{emit, trace};

#[cfg(test)]
mod stage_order;
