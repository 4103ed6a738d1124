//! The `mechanism!` macro (thin shell over pkm-dsl).
