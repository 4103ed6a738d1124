//! The syntax stage: the pest grammar (`grammar.pest`), the parser and the
//! syntax tree of a mechanism file as written, expressions included. It
//! imports nothing of the later stages; the semantic modules
//! (`crate::semantics::mechanism`, `crate::semantics::mass_and_loads`, `crate::semantics::limb_properties`,
//! `crate::semantics::study`) check what it builds.

pub mod ast;
pub mod expr;
pub mod limbs;
pub mod masses;
pub(crate) mod parser;
pub mod study;
