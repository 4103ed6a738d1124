//! The lowering stage: from the analysis (a checked model with its
//! topology) to what the runtime computes with at given parameter values:
//! the numeric model, its loading and limb properties (`numeric`), and the
//! parameter values given from outside the file, checked (`params`).

pub mod numeric;
pub mod params;
