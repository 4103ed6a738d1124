//! # pkm-cli
//!
//! The `pkm` command line's library: the HTML report of a `.pkm` file
//! ([`report`]), its plots ([`plots`]) and drawings of the mechanism
//! ([`drawing`]), and the solution plans the commands and the report run
//! (`pkm_dsl::compile`'s plans). It lives apart from the `pkm` facade so that a user of
//! `pkm::mechanism!` does not compile clap, plotters, csv or serde_json.
#![deny(missing_docs)]

pub mod drawing;

pub mod plots;
pub mod report;
