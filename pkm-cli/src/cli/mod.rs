//! The command line's parts: how it fails, how it solves positions, and inverse dynamics.

pub mod dynamics;
pub mod failure;
pub mod solve;
