//! `Step::Locus`: a point of the new link held on a surface, one file per
//! [`crate::plan::Constraint`]: a sphere ([`sphere`]), a plane
//! ([`plane`]), a cylinder ([`cylinder`]), a slider's plane
//! ([`slider`]) and a circle about a pinned link's pin ([`pin`]).

pub mod cylinder;
pub mod pin;
pub mod plane;
pub mod slider;
pub mod sphere;
