//! # pkm-runtime
//!
//! The small runtime of pkm: shared types that generated code refers to.
#![deny(missing_docs)]

pub mod primitives;
pub mod real;
pub mod topology;

pub use topology::{SkcReport, SocReport, TopologyReport};
