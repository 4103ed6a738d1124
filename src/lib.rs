//! pkm
pub use pkm_runtime as runtime;
