//! The command line's parts: how it fails, how it solves positions, inverse dynamics, static stiffness, and the MuJoCo export.

pub mod dynamics;
pub mod export;
pub mod failure;
pub mod solve;
pub mod stiffness;
