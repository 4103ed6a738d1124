//! The lowering stage: from the analysis (a checked model with its
//! topology) to what the runtime computes with at given parameter values:
//! the numeric model, its loading and limb properties (`numeric`), the
//! parameter values given from outside the file, checked (`params`), and
//! the mobility the declared geometry has beyond the topology's
//! (`mobility`).

pub mod mobility;
pub mod numeric;
pub mod params;
