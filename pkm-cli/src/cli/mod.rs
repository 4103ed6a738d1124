//! The command line's parts: how it fails, how it solves positions, inverse dynamics, static stiffness, and the MuJoCo export; tables for people and CSV for many inputs.

pub mod csv;
pub mod dynamics;
pub mod export;
pub mod failure;
pub mod follow;
pub mod solve;
pub mod stiffness;
pub mod table;
