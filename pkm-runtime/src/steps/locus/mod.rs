//! `Step::Locus`: a point of the new link held on a surface, one file per
//! [`crate::plan::Constraint`]: a sphere ([`sphere`]), a plane
//! ([`plane`]), a cylinder ([`cylinder`]) and a slider's plane
//! ([`slider`]).

pub mod cylinder;
pub mod plane;
pub mod slider;
pub mod sphere;
