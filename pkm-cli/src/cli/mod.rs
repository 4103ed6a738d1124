//! The command line's parts: how it fails and how it solves.

pub mod failure;
pub mod solve;
