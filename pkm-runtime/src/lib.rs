//! # pkm-runtime
//!
//! The small runtime of pkm: shared types that generated code refers to.
//! What generated code may name is listed in one module, [`__private`]
//! (`contract.rs`).
#![deny(missing_docs)]

#[doc(hidden)]
#[path = "contract.rs"]
pub mod __private;
pub mod ball_legs;
pub mod batch;
pub mod bounded;
pub mod certify;
pub mod consistency;
pub mod fk_follow;
pub mod fk_numeric;
pub mod force_system;
pub mod frame;
pub mod hyper_dual;
pub mod interval;
pub mod kinematics;
pub mod lagrange;
pub mod mass_properties;
pub mod model;
pub mod newton;
pub mod newton_euler;
pub mod plan;
pub mod primitives;
pub mod random;
#[cfg(feature = "high-precision")]
pub mod reference;
pub mod scalar;
pub mod singular;
pub mod skc_reactions;
pub mod solution;
pub mod steps;
pub mod stiffness;
pub mod subproblems;
pub mod topology_report;
pub mod velocity;
pub mod virtual_work;
pub mod workspace;
pub mod wrench;

pub use topology_report::{SkcReport, SocReport, TopologyReport};

/// The linear-algebra crate the runtime's types use, re-exported so that
/// generated code and users name one version.
pub use nalgebra;
