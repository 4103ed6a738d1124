//! The front door: [`compile`] runs the whole pipeline on a description,
//! the macro, the command line, the report and the tests alike:
//!
//! 1. parse (pest) → 2. model → 3. geometry → 4. topology
//!    ([`crate::topology::analysis::analyze_source`], an [`Analysis`]) → 5. plans (the order in
//!    which a κ = 0 mechanism's joints are solved, [`Compiled::forward`],
//!    [`Compiled::inverse`], planned on first use) → 6. code
//!    ([`crate::expand`], from a [`Compiled`]).
//!
//! A plan is the same for planar and spatial mechanisms
//! ([`pkm_runtime::plan::Plan`], made by [`crate::plan::planner`]).

use crate::diagnostics::Diagnostics;
use crate::topology::analysis::Analysis;
use pkm_runtime::plan::Plan;
use std::cell::OnceCell;

/// A description compiled: its analysis, and its plans on first use.
#[derive(Debug)]
pub struct Compiled {
    /// Parse, model, geometry and topology.
    pub analysis: Analysis,
    forward: OnceCell<Result<Plan, Diagnostics>>,
    inverse: OnceCell<Result<Plan, Diagnostics>>,
}

/// Compiles a description: every error in it, or its analysis with the
/// plans to come.
///
/// ```
/// let c = pkm_dsl::compile(
///     "mechanism m { planar; base R1* [a] ∥ R2 [b] ∥ R3 [c] ∥ R4 base;
///      parameters { l = 100; }
///      geometry { base { R1 = (0, 0); R4 = (3 * l, 0); } a { R1 = (0, 0); R2 = (l, 0); }
///                 b { R2 = (0, 0); R3 = (2.5 * l, 0); } c { R3 = (2 * l, 0); R4 = (0, 0); } } }",
/// )
/// .unwrap();
/// assert_eq!(c.analysis.topology.dof, 1);
/// // The forward plan: the crank given, the rest a dyad with its ± choice.
/// assert_eq!(c.forward().unwrap().choices(), 1);
/// ```
pub fn compile(source: &str) -> Result<Compiled, Diagnostics> {
    Ok(Compiled {
        analysis: crate::topology::analysis::analyze_source(source)?,
        forward: OnceCell::new(),
        inverse: OnceCell::new(),
    })
}

impl Compiled {
    /// The forward plan (inputs to every joint), planned on first use.
    pub fn forward(&self) -> Result<&Plan, Diagnostics> {
        self.forward
            .get_or_init(|| crate::plan::planner::forward_plan(&self.analysis))
            .as_ref()
            .map_err(Clone::clone)
    }

    /// The inverse plan (declared outputs to every joint), planned on first use.
    pub fn inverse(&self) -> Result<&Plan, Diagnostics> {
        self.inverse
            .get_or_init(|| crate::plan::planner::inverse_plan(&self.analysis))
            .as_ref()
            .map_err(Clone::clone)
    }
}
