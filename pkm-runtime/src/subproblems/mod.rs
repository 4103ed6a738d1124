//! The closed-form kernels the plan's steps are made of, apart from the
//! steps (as IK-Geo keeps its `subproblems/` apart from its solvers): each
//! solves one small geometric problem, is written once over
//! [`crate::scalar::Scalar`] (so the interpreter runs it and the code
//! generator traces it), says in its documentation the equation it solves
//! and which root is `Plus`, and is tested alone against values worked by
//! hand. A step finds its problem in the mechanism's geometry and hands it
//! to one of these.
//!
//! | kernel | solves |
//! |---|---|
//! | [`rotate_onto::turn_onto`] | the turn about an axis that carries a direction onto another (Paden–Kahan subproblem 1) |
//! | [`trig::trig_turns`] | `a·cosθ + b·sinθ = c` (a circle meeting a plane) |
//! | [`line_plane::line_plane`] | a slide onto a plane |
//! | [`circle_distance::circle_distance`] | a circle meeting a sphere (Paden–Kahan subproblem 3) |
//! | [`triangle::kahan_sine`] | a triangle's angle from its sides (Kahan's area) |
//! | [`line_sphere::line_distance`] | a line meeting a sphere |
//! | [`line_sphere::line_circle`] | a slide meeting a circle in its plane |
//! | [`line_through::through`] | a line turned about an axis through a point |
//! | [`three_spheres::three_spheres`] | three spheres meeting (trilateration) |
//! | [`triad::triad`] | the rotation that carries an orthonormal pair onto another |
//!
//! Failures are typed ([`crate::primitives::Error`]): degenerate data, or
//! out of reach by how much; within [`crate::primitives::TANGENCY_TOL`] of
//! tangency a kernel returns the double root.

pub mod circle_distance;
pub mod line_plane;
pub mod line_sphere;
pub mod line_through;
pub mod rotate_onto;
pub mod three_spheres;
pub mod triad;
pub mod triangle;
pub mod trig;
